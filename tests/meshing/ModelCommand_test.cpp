// `pneuma-cli model build` and `model info`, run as a child process (tests/app/cli/CliRunner.h).
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "CliRunner.h"
#include "pneuma/meshing/ModelSummary.h"
#include "pneuma/sim/ModelIO.h"

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

TEST(ModelCommand, CorruptAnatomyFailsNamingTheFieldAndWritesNothing) {
  // a copy of the male preset with a negative rib length, beside its gains file
  const fs::path dir = scratch("corrupt");
  fs::create_directories(dir);
  nlohmann::json j = nlohmann::json::parse(test::slurp(kAnatomy + "male.json"));
  j["ribs"][2]["arc_length_mm"] = -10;
  { std::ofstream(dir / "male.json") << j.dump(); }
  fs::copy_file(kAnatomy + "muscle_gains.json", dir / "muscle_gains.json");
  const fs::path out = dir / "model";
  const test::CliResult r = runCli(
      {"model", "build", "--anatomy", (dir / "male.json").string(), "--out", out.string(), "--no-preview"});
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

TEST(ModelCommand, InfoOnAMissingModelIsBadInput) {
  const test::CliResult r = runCli({"model", "info", scratch("missing").string()});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.err.find("model.json"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace pneuma::meshing
