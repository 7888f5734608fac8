#include "CliSupport.h"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <vector>

#include "pneuma/sim/Resources.h"

namespace fs = std::filesystem;

namespace pneuma::app {

void fail(int code, const std::string& message) {
  std::cerr << "pneuma-cli: error: " << message << "\n";
  throw CLI::RuntimeError(code);
}

std::string resolveModelDir(const std::string& requested) {
  const std::string dir = requested.empty() ? sim::defaultModelDir() : requested;
  if (!fs::is_directory(dir))
    fail(kExitBadInput,
         "model directory '" + dir + "' does not exist (build the default model or pass --model DIR)");
  if (!fs::is_regular_file(fs::path(dir) / "model.json"))
    fail(kExitBadInput, "model directory '" + dir + "' has no model.json");
  return dir;
}

void prepareOutputDir(const std::string& dir, const char* command, std::initializer_list<const char*> own,
                      bool force) {
  if (dir.empty()) fail(kExitBadInput, "--out: must not be empty");
  std::error_code ec;
  if (fs::is_directory(dir, ec)) {
    // only this command's own entries, and those only with --force
    auto isOwn = [&](const std::string& name) {
      for (const std::string pattern : own) {
        const bool isSuffix = pattern.size() > 1 && pattern[0] == '*';
        if (isSuffix ? name.size() > pattern.size() - 1 && name.compare(name.size() - (pattern.size() - 1),
                                                                        std::string::npos, pattern, 1) == 0
                     : name == pattern)
          return true;
      }
      return false;
    };
    std::vector<std::string> entries;
    bool isEarlierRun = false;  // an own entry with something in it (an empty frames/ may be a mount point)
    for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
      entries.push_back(e.path().filename().string());
      isEarlierRun = isEarlierRun || !(e.is_directory(ec) && fs::is_empty(e.path(), ec));
    }
    std::sort(entries.begin(), entries.end());
    for (const std::string& name : entries)
      if (!isOwn(name))
        fail(kExitBadInput, "--out: '" + dir + "' holds '" + name.substr(0, 60) + "', which pneuma-cli " +
                                command + " does not write; give a new or empty directory");
    if (isEarlierRun && !force) {
      std::string earlier = entries.front();
      for (const std::string name : own)
        if (name[0] != '*' && fs::exists(fs::path(dir) / name)) {
          earlier = name;
          break;
        }
      fail(kExitBadInput,
           "--out: '" + dir + "' holds an earlier run (" + earlier + "); add --force to replace it");
    }
  }
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    fail(kExitBadInput, "--out: cannot create directory '" + dir + "'" + (ec ? ": " + ec.message() : ""));
  // probe: can we create a file there?
  const fs::path probe =
      fs::path(dir) / (".pneuma-write-test-" + std::to_string(static_cast<long>(getpid())));
  {
    std::ofstream out(probe);
    if (!out) fail(kExitBadInput, "--out: directory '" + dir + "' is not writable");
  }
  fs::remove(probe, ec);
}

void checkOption(const sim::Range& range, const char* flag, double v) {
  if (!range.contains(v)) fail(kExitBadInput, std::string(flag) + ": " + range.problem(v));
}

void addModelOption(CLI::App& cmd, std::string& model) {
  cmd.add_option(
      "--model", model,
      "Model directory (default: $PNEUMA_MODEL_DIR, else <bindir>/../share/pneuma/models/default)");
}

namespace {

// help text of an option naming one of `names`: "<what>: one of a, b (default a)"
std::string choiceHelp(const std::string& what, const std::string& names, const char* defaultName) {
  return what + ": one of " + names + " (default " + defaultName + ")";
}

// "<flag>: unknown <kind> 'value' (valid: a, b)", exit 2
[[noreturn]] void failUnknown(const char* flag, const char* kind, const std::string& value,
                              const std::string& names) {
  fail(kExitBadInput,
       std::string(flag) + ": unknown " + kind + " '" + value.substr(0, 60) + "' (valid: " + names + ")");
}

}  // namespace

void addSeedOption(CLI::App& cmd, std::uint64_t& seed) {
  // digits only and in range: CLI11 would read -1 as 2^64 - 1 and saturate 2^64
  cmd.add_option("--seed", seed, "Seed of the pattern irregularity streams, 0 to 2^64 - 1 (default 0)")
      ->check(CLI::Validator(
          [](const std::string& v) {
            std::uint64_t x = 0;
            const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), x);
            const bool ok = !v.empty() && v[0] != '-' && ec == std::errc() && end == v.data() + v.size();
            return ok ? std::string()
                      : "must be an integer in [0, 18446744073709551615], got " + v.substr(0, 60);
          },
          "UINT64"));
}

void addIntegratorOption(CLI::App& cmd, std::string& name) {
  cmd.add_option("--integrator", name,
                 choiceHelp("Time integration scheme", sim::integratorNames(),
                            sim::integratorName(sim::StepOptions{}.integrator)));
}

void applyIntegrator(const std::string& name, sim::IntegratorKind& kind) {
  if (!name.empty() && !sim::integratorFromName(name, kind))
    failUnknown("--integrator", "integrator", name, sim::integratorNames());
}

void addPostureOption(CLI::App& cmd, std::string& name) {
  cmd.add_option("--posture", name,
                 choiceHelp("Gravity relative to the body", sim::postureNames(),
                            sim::postureName(sim::StepOptions{}.posture)));
}

void applyPosture(const std::string& name, sim::Posture& posture) {
  if (!name.empty() && !sim::postureFromName(name, posture))
    failUnknown("--posture", "posture", name, sim::postureNames());
}

}  // namespace pneuma::app
