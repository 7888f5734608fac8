// pneuma-cli silhouette: the outlines and overlays of a breath on the default model (the build's, as
// pneuma-cli finds it), and bad input: a model without a skin, an outline spacing out of range.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "CliRunner.h"
#include "ToyModelDir.h"

using pneuma::test::freshOutDir;
using pneuma::test::lineCount;
using pneuma::test::runCli;
using pneuma::test::slurp;
using pneuma::test::toyModelDir;

TEST(CliSilhouette, WritesOutlinesOverlaysAndFiguresOfACalmBreath) {
  const std::string out = freshOutDir("silhouette");
  const auto r = runCli({"silhouette", "--quick", "--style", "calm", "--out", out});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  for (const char* f : {"calm_lateral.csv", "calm_lateral.svg", "calm_lateral.png", "calm_frontal.csv",
                        "calm_frontal.svg", "calm_frontal.png", "silhouette.json"})
    EXPECT_TRUE(std::filesystem::exists(out + "/" + f)) << f;

  // the figures: the chest moves forward on a calm inhale, and the CSV holds both phases' closed outlines
  const nlohmann::json j = nlohmann::json::parse(slurp(out + "/silhouette.json"));
  const nlohmann::json& calm = j.at("styles").at("calm");
  EXPECT_GT(calm.at("chest_ap_change_mm").get<double>(), 0.0);
  EXPECT_GT(calm.at("chest_line_mm").get<double>(), calm.at("belly_line_mm").get<double>());
  EXPECT_GT(calm.at("lung_volume_change_ml").get<double>(), 300.0);
  EXPECT_GT(calm.at("chest_marker_ventral_mm").get<double>(), 0.0);
  EXPECT_EQ(j.at("checks").size(), 3u) << "calm chest, chest marker and belly";
  std::istringstream csv(slurp(out + "/calm_lateral.csv"));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "phase,loop,anterior_mm,superior_mm");
  int expiration = 0, inspiration = 0;
  double top = -1e9, bottom = 1e9;
  while (std::getline(csv, line)) {
    expiration += line.rfind("end-expiration,", 0) == 0;
    inspiration += line.rfind("end-inspiration,", 0) == 0;
    const double z = std::stod(line.substr(line.rfind(',') + 1));
    top = std::max(top, z), bottom = std::min(bottom, z);
  }
  EXPECT_GT(expiration, 500);
  EXPECT_GT(inspiration, 500);
  EXPECT_GT(top - bottom, 800.0) << "the trunk and the head, seen from the side [mm]";
  EXPECT_EQ(slurp(out + "/calm_frontal.csv").rfind("phase,loop,left_mm,superior_mm\n", 0), 0u);
  EXPECT_NE(slurp(out + "/calm_lateral.svg").find("AP change: chest +"), std::string::npos);
  EXPECT_NE(r.out.find("silhouette.calm.chest"), std::string::npos) << r.out;
}

TEST(CliSilhouette, BadInputIsOneLineAndWritesNothing) {
  const std::string out = freshOutDir("silhouette_bad");
  for (const auto& [args, message] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"silhouette", "--model", toyModelDir(), "--out", out}, "has no skin"},
           {{"silhouette", "--spacing", "0", "--out", out}, "--spacing: must be in [0.5, 20] mm, got 0"},
           {{"silhouette", "--style", "yodel", "--out", out}, "unknown breath style 'yodel'"}}) {
    const auto r = runCli(args);
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_EQ(lineCount(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << "nothing written";
  }
}
