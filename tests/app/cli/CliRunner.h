#pragma once
/// @file CliRunner.h
/// Runs build/bin/pneuma-cli (or the app) as a child process for the CLI and GUI tests: captured
/// stdout/stderr and exit code, optionally interrupted with SIGINT after a delay.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace pneuma::test {

struct CliResult {
  int exitCode = -1;  ///< process exit code, or -1 when killed by a signal
  std::string out;    ///< captured stdout
  std::string err;    ///< captured stderr
};

inline std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Runs build/bin/`program` with `args`. When `sigintAfterSeconds` > 0, sends SIGINT after that delay.
/// `env` entries ("NAME=value") are added to the child's environment.
inline CliResult runProgram(const std::string& program, const std::vector<std::string>& args,
                            double sigintAfterSeconds = 0.0, const std::vector<std::string>& env = {}) {
  static int counter = 0;
  const std::string base =
      testing::TempDir() + "pneuma_cli_" + std::to_string(getpid()) + "_" + std::to_string(++counter);
  const std::string outPath = base + ".out", errPath = base + ".err";
  const std::string exe = std::string(PNEUMA_BIN_DIR) + "/" + program;

  pid_t pid = fork();
  if (pid == 0) {
    // child: redirect output and exec
    int fo = open(outPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    int fe = open(errPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fo, 1);
    dup2(fe, 2);
    for (const auto& e : env) putenv(const_cast<char*>(e.c_str()));
    std::vector<char*> argv{const_cast<char*>(exe.c_str())};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(exe.c_str(), argv.data());
    _exit(127);
  }
  if (sigintAfterSeconds > 0.0) {
    std::this_thread::sleep_for(std::chrono::duration<double>(sigintAfterSeconds));
    kill(pid, SIGINT);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  CliResult r;
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(outPath);
  r.err = slurp(errPath);
  std::remove(outPath.c_str());
  std::remove(errPath.c_str());
  return r;
}

/// Runs pneuma-cli (see runProgram()).
inline CliResult runCli(const std::vector<std::string>& args, double sigintAfterSeconds = 0.0,
                        const std::vector<std::string>& env = {}) {
  return runProgram("pneuma-cli", args, sigintAfterSeconds, env);
}

/// Runs pneuma-cli with `args` into an --out that holds an earlier run's `file` (its path in `out`): expects
/// the run refused with exit 2, naming the file and asking for --force, and the file untouched; then reruns
/// with --force and returns that result.
inline CliResult runReplacingEarlierRun(std::vector<std::string> args, const std::string& out,
                                        const std::string& file) {
  const std::string before = slurp(out + "/" + file);
  const CliResult refused = runCli(args);
  EXPECT_EQ(refused.exitCode, 2) << refused.err;
  EXPECT_NE(refused.err.find("holds an earlier run (" + file + "); add --force to replace it"),
            std::string::npos)
      << refused.err;
  EXPECT_EQ(slurp(out + "/" + file), before);
  args.push_back("--force");
  return runCli(args);
}

/// Number of lines in `s` (a final line without newline counts).
inline int lineCount(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n + (!s.empty() && s.back() != '\n');
}

}  // namespace pneuma::test
