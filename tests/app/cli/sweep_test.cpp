// pneuma-cli sweep: a 3 x 3 grid over two muscle gains on the toy torso, the table against single runs,
// resuming, array-task shares and bad sweep files.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "CliRunner.h"
#include "SweepFiles.h"
#include "ToyModelDir.h"

using pneuma::test::freshOutDir;
using pneuma::test::gainGridSweep;
using pneuma::test::lineCount;
using pneuma::test::runCli;
using pneuma::test::slurp;
using pneuma::test::toyModelDir;
using pneuma::test::writeSweepFile;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

const std::string kDiaphragm = "active_gain_scale.diaphragm";
const std::string kIntercostal = "active_gain_scale.intercostal_external";

std::vector<std::string> sweepArgs(const std::string& file, const std::string& out,
                                   std::vector<std::string> more = {}) {
  std::vector<std::string> a = {"sweep", file, "--out", out, "--model", toyModelDir()};
  a.insert(a.end(), more.begin(), more.end());
  return a;
}

std::vector<std::string> temporaries(const std::string& out) {
  std::vector<std::string> t;
  for (const auto& e : fs::directory_iterator(out + "/variants"))
    if (e.path().extension() == ".tmp") t.push_back(e.path().filename().string());
  return t;
}

}  // namespace

TEST(CliSweep, GridOfTwoGainsGivesOneFolderPerVariantAndATableThatSingleRunsReproduce) {
  const std::string file = gainGridSweep();
  const std::string out = freshOutDir("sweep_grid");
  const auto r = runCli(sweepArgs(file, out, {"--jobs", "2"}));
  ASSERT_EQ(r.exitCode, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("9 variants, 0 finished earlier, 9 to run on 2 worker(s)"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("[9/9] variant"), std::string::npos) << r.out;
  EXPECT_TRUE(temporaries(out).empty());

  // the grid in order, the first parameter slowest; each variant's own folder
  const json table = json::parse(slurp(out + "/table.json"));
  ASSERT_EQ(table["variants"].size(), 9u);
  const double levels[3] = {0.5, 1.0, 1.5};
  double tidal[3][3];
  for (int i = 0; i < 9; ++i) {
    const json& row = table["variants"][i];
    EXPECT_EQ(row["parameters"][kDiaphragm].get<double>(), levels[i / 3]);
    EXPECT_EQ(row["parameters"][kIntercostal].get<double>(), levels[i % 3]);
    const json summary = json::parse(slurp(out + "/variants/000" + std::to_string(i) + "/summary.json"));
    EXPECT_FALSE(summary["partial"].get<bool>());
    ASSERT_TRUE(row["tidal_volume_ml"].is_number()) << row.dump();
    EXPECT_EQ(row["tidal_volume_ml"], summary["tidal_volume_ml"]);
    EXPECT_FALSE(row.contains("real_time_factor"));  // the table is the same wherever the variants ran
    tidal[i / 3][i % 3] = row["tidal_volume_ml"].get<double>();
  }
  // physics: a stronger inspiratory muscle breathes deeper, whichever the other's gain
  for (int k = 0; k < 3; ++k) {
    EXPECT_LT(tidal[0][k], tidal[1][k]) << "diaphragm gain, intercostal " << levels[k];
    EXPECT_LT(tidal[1][k], tidal[2][k]) << "diaphragm gain, intercostal " << levels[k];
    EXPECT_LT(tidal[k][0], tidal[k][2]) << "intercostal gain, diaphragm " << levels[k];
  }

  // the CSV holds the same numbers, one row per variant
  const std::string csv = slurp(out + "/table.csv");
  EXPECT_EQ(lineCount(csv), 10);
  EXPECT_EQ(csv.rfind("variant," + kDiaphragm + "," + kIntercostal + ",tidal_volume_ml,", 0), 0u) << csv;
  EXPECT_NE(csv.find("\n0007,1.5,1,"), std::string::npos) << csv;

  // a plot per chosen figure, one line per intercostal gain
  const std::string svg = slurp(out + "/plot_tidal_volume_ml.svg");
  for (const char* level : {" 0.5<", " 1<", " 1.5<"})
    EXPECT_NE(svg.find(kIntercostal + level), std::string::npos) << level;
  EXPECT_TRUE(fs::exists(out + "/plot_rib_cage_fraction.svg"));

  // variant 7 is `simulate --set` of its two gains, bit for bit
  const std::string base = fs::path(file).parent_path().string() + "/base.json";
  std::ofstream(base) << pneuma::test::kSweepBaseScenario;
  const std::string single = freshOutDir("sweep_single");
  const auto s = runCli({"simulate", "--model", toyModelDir(), "--scenario", base, "--out", single, "--set",
                         kDiaphragm + "=1.5", "--set", kIntercostal + "=1"});
  ASSERT_EQ(s.exitCode, 0) << s.err;
  const json summary = json::parse(slurp(single + "/summary.json"));
  for (const char* f : {"tidal_volume_ml", "breaths_per_minute", "dome_descent_mm", "steps"})
    EXPECT_EQ(summary[f], table["variants"][7][f]) << f;

  // resuming: nothing runs again, the table is the same; a lost variant is the only one rerun
  const auto again = runCli(sweepArgs(file, out, {"--jobs", "2"}));
  ASSERT_EQ(again.exitCode, 0) << again.err;
  EXPECT_NE(again.out.find("9 finished earlier, 0 to run"), std::string::npos) << again.out;
  EXPECT_EQ(slurp(out + "/table.csv"), csv);
  fs::remove_all(out + "/variants/0004");
  const auto rerun = runCli(sweepArgs(file, out, {"--jobs", "2"}));
  ASSERT_EQ(rerun.exitCode, 0) << rerun.err;
  EXPECT_NE(rerun.out.find("8 finished earlier, 1 to run"), std::string::npos) << rerun.out;
  EXPECT_NE(rerun.out.find("[1/1] variant 0004 (" + kDiaphragm + "=1 " + kIntercostal + "=1)"),
            std::string::npos)
      << rerun.out;
  EXPECT_EQ(slurp(out + "/table.csv"), csv);

  // array tasks run their shares; --collect merges them into the same table
  const std::string shared = freshOutDir("sweep_tasks");
  const auto slurm = runCli(sweepArgs(file, shared, {"--slurm", "--task-count", "3"}));
  ASSERT_EQ(slurm.exitCode, 0) << slurm.err;
  const std::string script = slurp(shared + "/sweep.sbatch");
  EXPECT_NE(script.find("#SBATCH --array=0-2\n"), std::string::npos) << script;
  EXPECT_NE(script.find("--task-index \"$SLURM_ARRAY_TASK_ID\" --task-count 3"), std::string::npos) << script;
  const json manifest = json::parse(slurp(shared + "/manifest.json"));
  EXPECT_EQ(manifest["variants"], 9);
  EXPECT_EQ(manifest["variant_list"][5]["task"], 2);
  EXPECT_FALSE(fs::exists(shared + "/variants/0000"));  // nothing ran
  const auto task1 =
      runCli(sweepArgs(file, shared, {"--task-index", "1", "--task-count", "3", "--jobs", "2"}));
  ASSERT_EQ(task1.exitCode, 0) << task1.err;
  for (int i = 0; i < 9; ++i)
    EXPECT_EQ(fs::exists(shared + "/variants/000" + std::to_string(i) + "/summary.json"), i % 3 == 1) << i;
  const auto early = runCli(sweepArgs(file, shared, {"--collect"}));
  EXPECT_EQ(early.exitCode, 1);
  EXPECT_NE(early.err.find("6 of 9 variants not finished (0000, 0002, 0003, 0005, 0006, 0008)"),
            std::string::npos)
      << early.err;
  for (const char* task : {"0", "2"})
    ASSERT_EQ(
        runCli(sweepArgs(file, shared, {"--task-index", task, "--task-count", "3", "--jobs", "2"})).exitCode,
        0);
  const auto collect = runCli(sweepArgs(file, shared, {"--collect"}));
  ASSERT_EQ(collect.exitCode, 0) << collect.err;
  EXPECT_EQ(slurp(shared + "/table.csv"), csv);
  EXPECT_EQ(slurp(shared + "/table.json"), slurp(out + "/table.json"));
}

TEST(CliSweep, CtrlCKeepsFinishedVariantsAndTheNextRunResumes) {
  const std::string file = writeSweepFile("interrupt", R"("design": "list", "parameters": {
      "active_gain_scale.diaphragm": [0.8, 0.9, 1.0, 1.1, 1.2, 1.3],
      "dt_s": [0.0005, 0.0005, 0.0005, 0.0005, 0.0005, 0.0005]})");  // 8 x the steps: the Ctrl-C finds work
  const std::string out = freshOutDir("sweep_interrupt");
  const auto r = runCli(sweepArgs(file, out, {"--jobs", "1"}), 1.5);
  ASSERT_EQ(r.exitCode, 130) << r.err << r.out;
  EXPECT_NE(r.out.find("interrupted: finished variants are kept"), std::string::npos) << r.out;
  EXPECT_TRUE(temporaries(out).empty());  // the stopped variant is discarded, not left half-written
  int kept = 0;
  for (int i = 0; i < 6; ++i) kept += fs::exists(out + "/variants/000" + std::to_string(i) + "/summary.json");
  EXPECT_LT(kept, 6);
  const auto resumed = runCli(sweepArgs(file, out, {"--jobs", "2"}));
  ASSERT_EQ(resumed.exitCode, 0) << resumed.err;
  EXPECT_NE(
      resumed.out.find(std::to_string(kept) + " finished earlier, " + std::to_string(6 - kept) + " to run"),
      std::string::npos)
      << resumed.out;
  EXPECT_EQ(json::parse(slurp(out + "/table.json"))["variants"].size(), 6u);
}

TEST(CliSweep, BadParametersAreOneLineNamingTheKeyBeforeAnythingRuns) {
  struct Case {
    const char* body;
    const char* message;
  };
  const Case cases[] = {
      {R"("parameters": {"active_gain_scale.diaphram": [1, 2]})",
       "parameters: active_gain_scale.diaphram: unknown muscle group"},
      {R"("parameters": {"dt": [0.01]})", "parameters: dt: unknown field (did you mean dt_s?)"},
      {R"("parameters": {"dt_s": [0.001, 0.1]})", "parameters: dt_s: must be in [1e-06, 0.05] s, got 0.1"},
      {R"("design": "random", "samples": 4, "parameters": {"settle_time_s": {"from": 0, "to": 900}})",
       "parameters: settle_time_s: must be in [0, 600] s, got 900"},
      {R"("parameters": {"joint_friction_scale": {"from": -1, "to": 1, "steps": 3}})",
       "parameters: joint_friction_scale: must be >= 0, got -1"},
      {R"("design": "list", "parameters": {"dt_s": [0.01, 0.02], "gravity": [true]})",
       "parameters.gravity: has 1 values, dt_s has 2"},
      {R"("design": "lattice", "parameters": {"dt_s": [0.01]})", "design: unknown design 'lattice'"},
      {R"("parameters": {"dt_s": [0.01]}, "outputs": ["tidal_volume"])",
       "outputs[0]: unknown summary figure 'tidal_volume'"},
  };
  for (const Case& c : cases) {
    const std::string file = writeSweepFile("bad", c.body);
    const std::string out = freshOutDir("sweep_bad");
    const auto r = runCli(sweepArgs(file, out));
    EXPECT_EQ(r.exitCode, 2) << c.body;
    EXPECT_EQ(lineCount(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out + "/variants")) << c.body;
  }
}

TEST(CliSimulate, SetOverridesByTheScenarioRuleAndRefusesBadKeysBeforeRunning) {
  const std::string out = freshOutDir("set_bad");
  for (const auto& [set, message] : std::vector<std::pair<std::string, std::string>>{
           {"dt=0.01", "--set: dt: unknown field (did you mean dt_s?)"},
           {"dt_s=1", "--set: dt_s: must be in [1e-06, 0.05] s, got 1"},
           {"posture=sideways", "--set: posture: unknown posture 'sideways'"},
           {"active_gain_scale.diaphragm=-1", "--set: active_gain_scale.diaphragm: must be >= 0, got -1"},
           {"dt_s", "--set: expected KEY=VALUE, got 'dt_s'"}}) {
    const auto r = runCli({"simulate", "--model", toyModelDir(), "--style", "calm", "--duration", "1",
                           "--out", out, "--set", set});
    EXPECT_EQ(r.exitCode, 2) << set;
    EXPECT_EQ(lineCount(r.err), 1) << r.err;
    EXPECT_EQ(r.err.rfind("pneuma-cli: error: " + message, 0), 0u) << r.err;
    EXPECT_FALSE(fs::exists(out + "/summary.json"));
  }
  // a set override reaches the run: the summary's dt and posture
  const auto r =
      runCli({"simulate", "--model", toyModelDir(), "--style", "calm", "--duration", "0.5", "--out", out,
              "--set", "dt_s=0.004", "--set", "posture=supine", "--set", "settle_time_s=0.2"});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const json summary = json::parse(slurp(out + "/summary.json"));
  EXPECT_EQ(summary["dt_s"], 0.004);
  EXPECT_EQ(summary["posture"], "supine");
  EXPECT_EQ(summary["settle_time_s"], 0.2);
}
