// `pneuma-cli model build` and `model info`, run as a child process (tests/app/cli/CliRunner.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>

#include "CliRunner.h"
#include "pneuma/meshing/ModelSummary.h"
#include "pneuma/sim/ModelIO.h"
#include "pneuma/sim/State.h"

namespace pneuma::meshing {
namespace {

namespace fs = std::filesystem;
using test::runCli;

const std::string kAnatomy = std::string(PNEUMA_RESOURCE_DIR) + "/anatomy/";

fs::path scratch(const std::string& name) {
  const fs::path p =
      fs::path(testing::TempDir()) / ("pneuma_model_cmd_" + std::to_string(getpid()) + "_" + name);
  fs::remove_all(p);
  return p;
}

/// A copy of the male preset in a new folder `dir`, beside its gains file, changed by `edit`; returns its
/// path.
fs::path writePresetCopy(const fs::path& dir, const std::function<void(nlohmann::json&)>& edit) {
  fs::create_directories(dir);
  nlohmann::json j = nlohmann::json::parse(test::slurp(kAnatomy + "male.json"));
  edit(j);
  { std::ofstream(dir / "male.json") << j.dump(); }
  fs::copy_file(kAnatomy + "muscle_gains.json", dir / "muscle_gains.json");
  return dir / "male.json";
}

TEST(ModelCommand, InfoJsonDescribesTheDefaultModel) {
  const test::CliResult r = runCli({"model", "info", PNEUMA_DEFAULT_MODEL_DIR, "--json"});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const ModelSummary s = summarizeModel(sim::loadModel(PNEUMA_DEFAULT_MODEL_DIR));
  EXPECT_EQ(j.at("bodies").get<int>(), s.bodies);
  EXPECT_EQ(j.at("moving_bodies").get<int>(), s.movingBodies);
  EXPECT_EQ(j.at("joints").get<int>(), s.joints);
  EXPECT_EQ(j.at("nodes").get<int>(), s.nodes);
  EXPECT_EQ(j.at("fixed_nodes").get<int>(), s.fixedNodes);
  for (int g = 0; g < sim::kElementGroupCount; ++g) {
    const char* name = sim::groupName(static_cast<sim::ElementGroup>(g));
    EXPECT_EQ(j.at("elements").at(name).get<int>(), s.elements[static_cast<std::size_t>(g)]) << name;
  }
  EXPECT_NEAR(j.at("gut_volume_ml").get<double>(), s.gutVolume * 1e6, 0.1);
  EXPECT_NEAR(j.at("cavity_volume_ml").get<double>(), s.cavityVolume * 1e6, 0.1);
  EXPECT_NEAR(j.at("gut_wall_mass_kg").get<double>(), 8.0, 1e-4);
  EXPECT_GT(j.at("bone_mass_kg").get<double>(), 0.5);
}

TEST(ModelCommand, BuildWithoutDisplayWritesTheModelAndSkipsPreviews) {
  const fs::path out = scratch("female");
  const test::CliResult r = runCli(
      {"model", "build", "--anatomy", kAnatomy + "female.json", "--out", out.string()}, 0.0, {"DISPLAY="});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("cavity volume"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("previews skipped"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(out / "model.json"));
  EXPECT_TRUE(fs::exists(out / "meshes" / "rib7_left.vtp"));
  EXPECT_FALSE(fs::exists(out / "preview_front.png"));
  fs::remove_all(out);
}

// --shoulder-girdle turns on the shoulder_girdle of a preset that has it off: the model gains the clavicles,
// scapulae and arms, the neck and the accessory muscles of the default model
TEST(ModelCommand, ShoulderGirdleFlagAddsTheGirdleToThePreset) {
  const fs::path dir = scratch("girdle");
  const fs::path anatomy = writePresetCopy(dir, [](nlohmann::json& j) { j["shoulder_girdle"] = false; });
  const fs::path out = dir / "model";
  const test::CliResult r = runCli({"model", "build", "--anatomy", anatomy.string(), "--shoulder-girdle",
                                    "--out", out.string(), "--no-preview"});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const sim::Model m = sim::loadModel(out.string());
  const sim::Model girdle = sim::loadModel(PNEUMA_DEFAULT_MODEL_DIR);
  EXPECT_EQ(m.bodies.name, girdle.bodies.name);
  EXPECT_GE(m.landmarks.find("acromion_right"), 0);
  fs::remove_all(dir);
}

// --no-shoulder-girdle turns the option off in the shipped preset, which has it on: the model loses the
// clavicles, scapulae, arms and head, and the acromions
TEST(ModelCommand, NoShoulderGirdleFlagTakesTheGirdleOutOfThePreset) {
  const fs::path out = scratch("nogirdle");
  const test::CliResult r = runCli({"model", "build", "--anatomy", kAnatomy + "male.json",
                                    "--no-shoulder-girdle", "--out", out.string(), "--no-preview"});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const sim::Model m = sim::loadModel(out.string());
  const sim::Model girdle = sim::loadModel(PNEUMA_DEFAULT_MODEL_DIR);
  for (const char* bone : {"clavicle_right", "scapula_left", "humerus_right", "forearm_left", "head"}) {
    EXPECT_NE(std::find(girdle.bodies.name.begin(), girdle.bodies.name.end(), bone),
              girdle.bodies.name.end());
    EXPECT_EQ(std::find(m.bodies.name.begin(), m.bodies.name.end(), bone), m.bodies.name.end()) << bone;
  }
  EXPECT_EQ(m.bodies.size() + 10, girdle.bodies.size());
  EXPECT_GE(girdle.landmarks.find("acromion_right"), 0);
  EXPECT_LT(m.landmarks.find("acromion_right"), 0);
  fs::remove_all(out);
}

TEST(ModelCommand, CorruptAnatomyFailsNamingTheFieldAndWritesNothing) {
  // a copy of the male preset with a negative rib length
  const fs::path dir = scratch("corrupt");
  const fs::path anatomy =
      writePresetCopy(dir, [](nlohmann::json& j) { j["ribs"][2]["arc_length_mm"] = -10; });
  const fs::path out = dir / "model";
  const test::CliResult r =
      runCli({"model", "build", "--anatomy", anatomy.string(), "--out", out.string(), "--no-preview"});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.err.find("ribs[2].arc_length_mm: must be in [30, 600], got -10"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  fs::remove_all(dir);
}

// data loss: a non-empty folder that is not a model is refused with its contents intact
TEST(ModelCommand, BuildRefusesAFolderThatIsNotAModel) {
  const fs::path out = scratch("notamodel");
  fs::create_directories(out);
  { std::ofstream(out / "notes.txt") << "keep me"; }
  const test::CliResult r = runCli(
      {"model", "build", "--anatomy", kAnatomy + "male.json", "--out", out.string() + "/", "--no-preview"});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.err.find("not a model directory (no model.json) and not empty; refusing to replace it"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(test::slurp((out / "notes.txt").string()), "keep me");
  fs::remove_all(out);
}

// --skin: a body of the user's in another format and unit: the default model's skin as an OBJ in centimetres,
// in the file axes the reader expects (Y up, facing +Z), registered to the female preset
TEST(ModelCommand, BuildWithAnObjSkinRegistersIt) {
  const sim::Model m = sim::loadModel(PNEUMA_DEFAULT_MODEL_DIR);
  ASSERT_GT(m.skin.vertexCount(), 0);
  Eigen::Matrix3Xd x;
  sim::skinPositions(m.skin, restPoints(m.skin.anchors, m), x);
  const fs::path dir = scratch("objskin");
  fs::create_directories(dir);
  {
    std::ofstream obj(dir / "body.obj");
    for (Eigen::Index i = 0; i < x.cols(); ++i)
      obj << "v " << -100.0 * x(0, i) << " " << 100.0 * x(2, i) << " " << 100.0 * x(1, i) << "\n";
    for (Eigen::Index f = 0; f < m.skin.triangles.cols(); ++f)
      obj << "f " << m.skin.triangles(0, f) + 1 << " " << m.skin.triangles(1, f) + 1 << " "
          << m.skin.triangles(2, f) + 1 << "\n";
  }
  const fs::path out = dir / "model";
  const test::CliResult r = runCli({"model", "build", "--anatomy", kAnatomy + "female.json", "--skin",
                                    (dir / "body.obj").string(), "--out", out.string(), "--no-preview"});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const ModelSummary s = summarizeModel(sim::loadModel(out.string()));
  EXPECT_GT(s.skinVertices, 5000);
  EXPECT_GT(s.skinTetrahedra, s.skinVertices);
  // model info counts the skin
  const test::CliResult info = runCli({"model", "info", out.string(), "--json"});
  ASSERT_EQ(info.exitCode, 0) << info.err;
  EXPECT_EQ(nlohmann::json::parse(info.out).at("skin").at("vertices").get<int>(), s.skinVertices);
  fs::remove_all(dir);
}

// a skin file assimp cannot read, or one that is not closed: one line naming the file, nothing written
TEST(ModelCommand, CorruptOrOpenSkinFailsInOneLineAndWritesNothing) {
  const fs::path dir = scratch("badskin");
  fs::create_directories(dir);
  {
    std::ofstream(dir / "corrupt.ply")
        << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n";
  }
  // a tetrahedron with one face missing
  { std::ofstream(dir / "open.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\n"; }
  for (const auto& [file, problem] :
       {std::pair<std::string, std::string>{"corrupt.ply", "assimp cannot read it"},
        {"open.obj", "is not closed (3 edges without"}}) {
    const fs::path out = dir / "model";
    const test::CliResult r =
        runCli({"model", "build", "--skin", (dir / file).string(), "--out", out.string(), "--no-preview"});
    EXPECT_EQ(r.exitCode, 2) << file;
    EXPECT_NE(r.err.find("pneuma-cli: error: " + (dir / file).string() + ": "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(problem), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(out)) << file;
  }
  fs::remove_all(dir);
}

TEST(ModelCommand, InfoOnAMissingModelIsBadInput) {
  const test::CliResult r = runCli({"model", "info", scratch("missing").string()});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.err.find("model.json"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace pneuma::meshing
