// pneuma-cli simulate under adverse conditions (issue 15): Ctrl-C at any output rate and during the drive
// calibration (class 10), and a disk that fills up during the run (class 4).
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "CliRunner.h"
#include "ToyModelDir.h"

using pneuma::test::freshOutDir;
using pneuma::test::lineCount;
using pneuma::test::runCli;
using pneuma::test::slurp;
using pneuma::test::toyModelDir;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

struct Interrupted {
  int exitCode = -1;         // -1 when ended by a signal
  int signal = 0;            // the signal that ended it, or 0
  double secondsToExit = 0;  // [s] wall time from the first SIGINT to the end of the process
  std::string err;
};

// starts pneuma-cli with `args`, stdout to /dev/null and stderr to `errPath`; returns its pid
pid_t startCli(const std::vector<std::string>& args, const std::string& errPath) {
  const std::string exe = std::string(PNEUMA_BIN_DIR) + "/pneuma-cli";
  const pid_t pid = fork();
  if (pid == 0) {
    const int fe = open(errPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int fo = open("/dev/null", O_WRONLY);
    dup2(fo, 1);
    dup2(fe, 2);
    std::vector<char*> argv{const_cast<char*>(exe.c_str())};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(exe.c_str(), argv.data());
    _exit(127);
  }
  return pid;
}

// Runs pneuma-cli with `args`, waits until its stderr holds `waitFor` (or `delay` seconds when waitFor is
// ""), sends SIGINT, and measures how long the process takes to end.
Interrupted interruptCli(const std::vector<std::string>& args, const std::string& waitFor, double delay) {
  const std::string errPath = testing::TempDir() + "pneuma_robust_" + std::to_string(getpid()) + ".err";
  const pid_t pid = startCli(args, errPath);
  const auto start = Clock::now();
  while (!waitFor.empty() && slurp(errPath).find(waitFor) == std::string::npos &&
         Clock::now() - start < std::chrono::seconds(60))
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  std::this_thread::sleep_for(std::chrono::duration<double>(delay));
  kill(pid, SIGINT);
  const auto sent = Clock::now();
  int status = 0;
  waitpid(pid, &status, 0);
  Interrupted r;
  r.secondsToExit = std::chrono::duration<double>(Clock::now() - sent).count();
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
  r.err = slurp(errPath);
  std::remove(errPath.c_str());
  return r;
}

// every file under `dir` whose name marks it as a temporary of the atomic writer
std::vector<std::string> temporaries(const std::string& dir) {
  std::vector<std::string> found;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.path().filename().string().find(".tmp-") != std::string::npos) found.push_back(e.path().string());
  return found;
}

// every .vtp under `dir` is a whole VTK XML file (none empty or cut short)
void expectCompleteFrames(const std::string& dir, int& count) {
  count = 0;
  if (!fs::exists(dir)) return;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() != ".vtp") continue;
    ++count;
    const std::string text = slurp(e.path().string());
    ASSERT_GT(text.size(), 100u) << e.path();
    EXPECT_EQ(text.substr(text.size() - 11), "</VTKFile>\n") << e.path() << " is truncated";
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// class 10: Ctrl-C

// at the lowest output rate a frame falls due every 100 simulated seconds: the run must stop within a step
// anyway
TEST(CliInterrupt, CtrlCStopsWithinHalfASecondWhateverTheOutputRate) {
  const std::string out = freshOutDir("sigint_rate");
  const Interrupted r = interruptCli({"simulate", "--model", toyModelDir(), "--style", "calm", "--duration",
                                      "3000", "--dt", "0.0005", "--output-rate", "0.01", "--out", out},
                                     "", 1.5);
  EXPECT_EQ(r.exitCode, 130) << r.err;
  EXPECT_LT(r.secondsToExit, 0.5) << r.err;
  const nlohmann::json s = nlohmann::json::parse(slurp(out + "/summary.json"));
  EXPECT_TRUE(s["interrupted"].get<bool>());
  EXPECT_GT(s["simulated_time_s"].get<double>(), 0.0);
  EXPECT_LT(s["simulated_time_s"].get<double>(), 100.0);  // stopped before the second frame was due
}

TEST(CliInterrupt, CtrlCDuringTheDriveCalibrationStillWritesTheOutputs) {
  const std::string out = freshOutDir("sigint_calibration");
  const Interrupted r = interruptCli(
      {"simulate", "--model", toyModelDir(), "--affect", "neutral", "--duration", "30", "--out", out},
      "calibrating", 0.2);
  EXPECT_EQ(r.exitCode, 130) << "signal " << r.signal << ": " << r.err;
  EXPECT_LT(r.secondsToExit, 0.5) << r.err;
  ASSERT_TRUE(fs::exists(out + "/summary.json")) << r.err;
  const nlohmann::json s = nlohmann::json::parse(slurp(out + "/summary.json"));
  EXPECT_TRUE(s["partial"].get<bool>());
  EXPECT_TRUE(s["interrupted"].get<bool>());
  EXPECT_EQ(s["frames"].get<int>(), 0);
  EXPECT_TRUE(s["tidal_volume_ml"].is_null());
  EXPECT_EQ(s["controller_kind"], "affect");
  EXPECT_TRUE(temporaries(out).empty());
}

// ---------------------------------------------------------------------------------------------
// class 4: a full disk

namespace {

struct FullDiskRun {
  pneuma::test::CliResult result;
  std::string out;
};

// simulate --vtk on the toy model with the directory `fullDir` (under out) able to take `bytes` more bytes
FullDiskRun runOnFullDisk(const std::string& name, const std::string& fullSubdir, long long bytes) {
  FullDiskRun run;
  run.out = freshOutDir(name);
  fs::create_directories(run.out + "/" + fullSubdir);
  const std::string full = fs::canonical(run.out + "/" + fullSubdir).string();
  run.result =
      runCli({"simulate", "--model", toyModelDir(), "--style", "calm", "--duration", "2", "--settle", "0.5",
              "--output-rate", "20", "--vtk", "--out", run.out},
             0.0,
             {std::string("LD_PRELOAD=") + PNEUMA_FULLDISK_LIB, "PNEUMA_FULLDISK_DIR=" + full,
              "PNEUMA_FULLDISK_BYTES=" + std::to_string(bytes), "ASAN_OPTIONS=verify_asan_link_order=0"});
  return run;
}

}  // namespace

// the frames' file system fills after a few frames: the run ends with a clear error naming the frame, the
// frames written before it stay whole, and the summary, CSV and plots on the other file system are still
// written
TEST(CliFullDisk, FramesDiskFullEndsTheRunWithAPartialSummary) {
  const FullDiskRun run = runOnFullDisk("fulldisk_frames", "frames", 400000);
  const auto& r = run.result;
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_EQ(r.err.rfind("pneuma-cli: error: cannot write " + run.out + "/frames/", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(".vtp: No space left on device"), std::string::npos) << r.err;
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  int frames = 0;
  expectCompleteFrames(run.out + "/frames", frames);
  EXPECT_GT(frames, 0);
  EXPECT_TRUE(temporaries(run.out).empty());

  ASSERT_TRUE(fs::exists(run.out + "/summary.json")) << r.err;
  const nlohmann::json s = nlohmann::json::parse(slurp(run.out + "/summary.json"));
  EXPECT_TRUE(s["partial"].get<bool>());
  EXPECT_FALSE(s["interrupted"].get<bool>());
  EXPECT_NE(s["error"].get<std::string>().find("No space left on device"), std::string::npos);
  EXPECT_LT(s["simulated_time_s"].get<double>(), 2.5);
  EXPECT_TRUE(fs::exists(run.out + "/timeseries.csv"));
  EXPECT_TRUE(fs::exists(run.out + "/frames.pvd"));
}

// the whole output disk fills: nothing under a final name is empty or cut short, and the error says that
// not even the summary could be written
TEST(CliFullDisk, WholeDiskFullLeavesNothingTruncated) {
  const FullDiskRun run = runOnFullDisk("fulldisk_all", ".", 300000);
  const auto& r = run.result;
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << r.err;
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  int frames = 0;
  expectCompleteFrames(run.out + "/frames", frames);
  EXPECT_TRUE(temporaries(run.out).empty());
  for (const auto& e : fs::recursive_directory_iterator(run.out)) {
    if (e.is_regular_file()) {
      EXPECT_GT(e.file_size(), 0u) << e.path();
    }
  }
  if (fs::exists(run.out + "/summary.json")) {
    EXPECT_NO_THROW(nlohmann::json::parse(slurp(run.out + "/summary.json")));
  } else {
    EXPECT_NE(r.err.find("(no summary.json)"), std::string::npos) << r.err;
  }
}

// ---------------------------------------------------------------------------------------------
// class 12: memory and plot size stay bounded on long runs

namespace {

// runs pneuma-cli to the end; returns its exit code and peak resident memory [kB]
std::pair<int, long> runMeasured(const std::vector<std::string>& args) {
  const pid_t pid = startCli(args, "/dev/null");
  int status = 0;
  struct rusage usage {};
  wait4(pid, &status, 0, &usage);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, usage.ru_maxrss};
}

}  // namespace

// an hour of calm breathing at 60 Hz (216,000 frames) on the toy torso: resident memory under 100 MB and no
// more than a short run's plus 20 MB, every plot under 1 MB, and the CSV still complete
TEST(CliLongRun, AnHourOfCalmStaysSmallInMemoryAndPlots) {
  const std::string shortOut = freshOutDir("minute"), longOut = freshOutDir("hour");
  const auto [shortCode, shortKb] = runMeasured(
      {"simulate", "--model", toyModelDir(), "--style", "calm", "--duration", "60", "--out", shortOut});
  const auto [longCode, longKb] = runMeasured(
      {"simulate", "--model", toyModelDir(), "--style", "calm", "--duration", "3600", "--out", longOut});
  ASSERT_EQ(shortCode, 0);
  ASSERT_EQ(longCode, 0);
  RecordProperty("max_rss_60s_kB", std::to_string(shortKb));
  RecordProperty("max_rss_3600s_kB", std::to_string(longKb));
  EXPECT_LT(longKb, 100 * 1024) << "an hour's run peaked at " << longKb / 1024 << " MB";
  EXPECT_LT(longKb - shortKb, 20 * 1024) << "60 s: " << shortKb << " kB, 3600 s: " << longKb << " kB";
  for (const auto& e : fs::directory_iterator(longOut)) {
    if (e.path().extension() == ".svg" || e.path().extension() == ".png") {
      EXPECT_LT(e.file_size(), 1000000u) << e.path();
    }
  }

  const nlohmann::json s = nlohmann::json::parse(slurp(longOut + "/summary.json"));
  const long long frames = s["frames"].get<long long>();
  EXPECT_EQ(frames, 60 * 3602);  // settling included
  EXPECT_NEAR(s["breaths_per_minute"].get<double>(), 15.0, 0.5);
  std::ifstream csv(longOut + "/timeseries.csv");
  long long lines = 0;
  for (std::string line; std::getline(csv, line);) ++lines;
  EXPECT_EQ(lines, frames + 1);  // the header and every frame
}
