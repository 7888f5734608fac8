// pneuma-cli bake, play and simulate --gltf: the measured blend error of a calm breath against its target, a
// readable .glb, and bad input (a model without a skin, an unknown affect, a path that cannot be written)
// refused in one line with nothing left under the final name.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "CliRunner.h"
#include "ToyModelDir.h"

namespace {

namespace fs = std::filesystem;
using pneuma::test::freshOutDir;
using pneuma::test::runCli;
using pneuma::test::slurp;
using pneuma::test::toyModelDir;

// nothing under `path` and no temporary file beside it
void expectNothingLeft(const std::string& path) {
  EXPECT_FALSE(fs::exists(path)) << path;
  const fs::path dir = fs::path(path).parent_path();
  if (!fs::is_directory(dir)) return;
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().rfind(fs::path(path).filename().string(), 0), std::string::npos)
        << e.path();
}

TEST(CliGltf, CalmBreathBlendsWithinTwoMillimetresRmsAndWritesAGlb) {
  const std::string out = freshOutDir("gltf_calm");
  const std::string glb = out + ".glb";
  fs::remove(glb);
  const auto r = runCli({"simulate", "--style", "calm", "--duration", "8", "--out", out, "--gltf", glb});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(slurp(out + "/summary.json"));
  // the real-time approximation's cost: under 2 mm RMS over the skin for a calm breath (measured 0.7 mm);
  // its maximum is set by a few posterior gut-bound vertices (docs/patterns.md) and only bounded here
  EXPECT_LT(j.at("morph_blend_rms_mm").get<double>(), 2.0) << j.dump();
  EXPECT_GT(j.at("morph_blend_rms_mm").get<double>(), 0.0);
  EXPECT_LT(j.at("morph_blend_max_mm").get<double>(), 60.0);
  EXPECT_NE(r.out.find("morph blend error over the skin: RMS"), std::string::npos) << r.out;
  // the bones posed by the same weights (sim::blendBones): the rib tips within 3 mm RMS of the simulated ones
  // for a calm breath (measured 1.6 mm), rotations within 2 degrees RMS (0.8)
  const std::string bones = "morph blend error of the bones: rib tips RMS ";
  const std::size_t at = r.out.find(bones);
  ASSERT_NE(at, std::string::npos) << r.out;
  double tipRms = 0.0, tipMax = 0.0, angleRms = 0.0, angleMax = 0.0;
  ASSERT_EQ(
      std::sscanf(r.out.c_str() + at + bones.size(), "%lf mm, max %lf mm; rotations RMS %lf deg, max %lf deg",
                  &tipRms, &tipMax, &angleRms, &angleMax),
      4)
      << r.out;
  EXPECT_GT(tipRms, 0.0);
  EXPECT_LT(tipRms, 3.0);
  EXPECT_GE(tipMax, tipRms);
  EXPECT_LT(angleRms, 2.0);
  // a binary glTF 2.0: magic "glTF", version 2, the length in the header is the file's
  const std::string bytes = slurp(glb);
  ASSERT_GT(bytes.size(), 12u);
  EXPECT_EQ(bytes.substr(0, 4), "glTF");
  EXPECT_EQ(static_cast<unsigned char>(bytes[4]), 2);
  std::uint32_t length = 0;
  std::memcpy(&length, bytes.data() + 8, 4);
  EXPECT_EQ(length, bytes.size());
}

TEST(CliGltf, BadInputIsOneLineErrorWithNothingLeft) {
  const std::string out = freshOutDir("gltf_bad");
  fs::create_directories(out);
  struct Case {
    std::vector<std::string> args;
    std::string glb, mentions;
  };
  const std::vector<Case> cases = {
      {{"simulate", "--model", toyModelDir(), "--style", "calm", "--duration", "1", "--out", out + "/run",
        "--gltf", out + "/toy.glb"},
       out + "/toy.glb",
       "--gltf: model 'toy_torso' has no skin"},
      {{"bake", "--model", toyModelDir(), "--out", out + "/toy.glb"}, out + "/toy.glb", "has no skin"},
      {{"play", "--model", toyModelDir(), "--affect", "fear", "--gltf", out + "/toy.glb"},
       out + "/toy.glb",
       "has no skin"},
      {{"play", "--affect", "glee", "--gltf", out + "/glee.glb"}, out + "/glee.glb", "unknown affect 'glee'"},
      {{"play", "--affect", "fear", "--gltf", out + "/missing/fear.glb"},
       out + "/missing/fear.glb",
       "--gltf: cannot write " + out + "/missing/fear.glb"},
      {{"play", "--affect", "fear", "--gltf", "/proc/pneuma.glb"},
       "/proc/pneuma.glb",
       "--gltf: cannot write"},
      {{"bake", "--out", out + "/missing/morphs.glb"}, out + "/missing/morphs.glb", "--out: cannot write"},
      {{"play", "--affect", "fear", "--gltf", out + "/fear.glb", "--morphs", toyModelDir() + "/model.json"},
       out + "/fear.glb",
       "--morphs: " + toyModelDir() + "/model.json: not a readable .glb"},
  };
  for (const Case& c : cases) {
    const auto r = runCli(c.args);
    EXPECT_EQ(r.exitCode, 2) << c.mentions << ": " << r.err;
    EXPECT_EQ(r.err.rfind("pneuma-cli: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(c.mentions), std::string::npos) << r.err;
    EXPECT_EQ(pneuma::test::lineCount(r.err), 1) << r.err;
    expectNothingLeft(c.glb);
  }
}

}  // namespace
