// pneuma-cli simulate --trace (issue 19): the default model follows the shipped example trace and its own
// recorded breathing played back, both with tracking RMS under 5 % of the trace's peak-to-peak, as
// summary.json reports it; a bad trace is one line naming the file, line and column before anything runs.
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "../../sim/DefaultModel.h"
#include "CliRunner.h"
#include "ToyModelDir.h"

using pneuma::test::freshOutDir;
using pneuma::test::lineCount;
using pneuma::test::runCli;
using pneuma::test::slurp;
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

// summary.json of `simulate --trace trace` on the default model
json followTrace(const std::string& trace, const std::string& name) {
  const std::string out = freshOutDir(name);
  const auto r = runCli({"simulate", "--model", PNEUMA_DEFAULT_MODEL_DIR, "--trace", trace, "--out", out});
  EXPECT_EQ(r.exitCode, 0) << r.err;
  return json::parse(slurp(out + "/summary.json"));
}

}  // namespace

TEST(CliTrace, FollowsTheShippedExampleUnderFivePercent) {
  REQUIRE_DEFAULT_MODEL();
  const json summary =
      followTrace(std::string(PNEUMA_RESOURCE_DIR) + "/traces/calm-sigh.csv", "trace_example");
  EXPECT_EQ(summary["controller_kind"], "trace");
  // the trace runs for its own 30 s
  EXPECT_NEAR(summary["duration_s"].get<double>(), 30.0, 1e-9);
  RecordProperty("tracking_rms_pct", std::to_string(summary["tracking_rms_pct"].get<double>()));
  EXPECT_LT(summary["tracking_rms_pct"].get<double>(), 5.0);
  EXPECT_GT(summary["tidal_volume_ml"].get<double>(), 300.0);  // it breathed, it did not sit still
}

TEST(CliTrace, FollowsARecordedRunOfTheModelPlayedBack) {
  REQUIRE_DEFAULT_MODEL();
  // a calm run's timeseries.csv, with only its time and lung-volume columns, is the trace
  const std::string calm = freshOutDir("trace_calm");
  const auto r = runCli({"simulate", "--model", PNEUMA_DEFAULT_MODEL_DIR, "--style", "calm", "--duration",
                         "20", "--out", calm});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  std::ifstream in(calm + "/timeseries.csv");
  const std::string trace = calm + "/lung-volume.csv";
  std::ofstream csv(trace);
  std::string line;
  while (std::getline(in, line)) {
    const auto second = line.find(',', line.find(',') + 1);
    csv << line.substr(0, second) << "\n";
  }
  csv.close();
  ASSERT_EQ(slurp(trace).rfind("time [s],lung_volume [mL]\n", 0), 0u) << slurp(trace).substr(0, 80);

  const json recorded = json::parse(slurp(calm + "/summary.json"));
  const json played = followTrace(trace, "trace_played");
  RecordProperty("tracking_rms_pct", std::to_string(played["tracking_rms_pct"].get<double>()));
  EXPECT_LT(played["tracking_rms_pct"].get<double>(), 5.0);
  // and the played-back breath is the recorded one: its tidal volume within 5 %
  EXPECT_NEAR(played["tidal_volume_ml"].get<double>(), recorded["tidal_volume_ml"].get<double>(),
              0.05 * recorded["tidal_volume_ml"].get<double>());
}

TEST(CliTrace, BadTraceIsOneLineNamingLineAndColumnBeforeAnythingRuns) {
  struct Case {
    const char* text;
    const char* message;  // after "<file>:"
  };
  const Case cases[] = {
      {"time [s],volume [L]\n0,2.4\n0.5,2.6\n0.4,2.5\n",
       "4: column 1 'time [s]': time must increase, got 0.4 after line 3"},
      {"time,volume [L]\n0,2.4\n1,2.5\n", "1: column 1 'time': missing unit (write 'time [s]')"},
      {"time [s],volume\n0,2.4\n1,2.5\n",
       "1: column 2 'volume': missing unit (write 'volume [L]' or 'volume [mL]')"},
      {"time [s],volume [L]\n0,2.4\n0.5,NaN\n1,2.4\n",
       "3: column 2 'volume [L]': not a finite number: 'NaN'"},
      {"time [s],volume [mL]\n0,2400\n0.5,9000\n1,2400\n", "3: column 2 'volume [mL]': volume swing 6.6"},
      {"time [s],volume [L]\n0,2.4\n0.5,-1\n", "3: column 2 'volume [L]': negative volume -1"},
  };
  const std::string dir = freshOutDir("trace_bad_files");
  fs::create_directories(dir);
  int i = 0;
  for (const Case& c : cases) {
    const std::string file = dir + "/bad" + std::to_string(++i) + ".csv";
    std::ofstream(file) << c.text;
    // with and without --duration: the trace is read before the run either way
    for (const bool hasDuration : {false, true}) {
      const std::string out = freshOutDir("trace_bad");
      std::vector<std::string> args = {"simulate", "--model", pneuma::test::toyModelDir(), "--trace", file,
                                       "--out",    out};
      if (hasDuration) args.insert(args.end(), {"--duration", "1"});
      const auto r = runCli(args);
      EXPECT_EQ(r.exitCode, 2) << c.text;
      EXPECT_EQ(lineCount(r.err), 1) << r.err;
      EXPECT_NE(r.err.find("pneuma-cli: error: --trace: " + file + ":" + c.message), std::string::npos)
          << r.err;
      EXPECT_FALSE(fs::exists(out + "/summary.json")) << c.text;
    }
  }
}
