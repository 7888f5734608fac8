// pneuma-cli bench: a real-time factor per breath style, and step time growing with the element count.
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "CliRunner.h"
#include "ToyModelDir.h"

using pneuma::test::freshOutDir;
using pneuma::test::runCli;
using pneuma::test::runReplacingEarlierRun;
using pneuma::test::slurp;
using pneuma::test::toyModelDir;

TEST(CliBench, ReportsEveryStyleAndIncreasingElementCounts) {
  // an earlier bench.json in --out: refused, untouched, then replaced with --force
  const std::string out = freshOutDir("bench");
  std::filesystem::create_directories(out);
  std::ofstream(out + "/bench.json") << "earlier";
  const std::vector<std::string> args = {"bench",     "--model", toyModelDir(), "--seconds", "0.3",
                                         "--posture", "supine",  "--out",       out};
  const auto r = runReplacingEarlierRun(args, out, "bench.json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(slurp(out + "/bench.json"));
  EXPECT_EQ(j["posture"], "supine");
  std::vector<std::string> styles;
  for (const auto& s : j.at("styles")) {
    styles.push_back(s["style"]);
    EXPECT_GT(s["real_time_factor"].get<double>(), 0.0);
    // rtf = dt / step time when stepping dominates: both come from the same timing
    EXPECT_NEAR(s["real_time_factor"].get<double>() * s["step_time_ms"].get<double>() * 1e-3,
                j["dt_s"].get<double>(), 0.05 * j["dt_s"].get<double>());
  }
  for (const char* name : {"calm", "deep", "panting", "forced-exhale"})
    EXPECT_NE(std::find(styles.begin(), styles.end(), name), styles.end()) << name;
  const auto& el = j.at("elements");
  ASSERT_EQ(el.size(), 4u);
  for (std::size_t i = 1; i < el.size(); ++i)
    EXPECT_GT(el[i]["elements"].get<int>(), el[i - 1]["elements"].get<int>());
  EXPECT_NE(r.out.find("real-time factor"), std::string::npos);
}

// data loss: bench writes only into a new or empty folder or over an earlier bench.json, never over other
// files
TEST(CliBench, FolderOfOtherFilesIsRefused) {
  const std::string out = freshOutDir("bench_foreign");
  std::filesystem::create_directories(out);
  std::ofstream(out + "/results.csv") << "mine";
  const auto r = runCli({"bench", "--model", toyModelDir(), "--seconds", "0.3", "--force", "--out", out});
  EXPECT_EQ(r.exitCode, 2) << r.err;
  EXPECT_NE(r.err.find("holds 'results.csv', which pneuma-cli bench does not write"), std::string::npos)
      << r.err;
  EXPECT_EQ(slurp(out + "/results.csv"), "mine");
  EXPECT_FALSE(std::filesystem::exists(out + "/bench.json"));
}
