#pragma once
/// @file CliSupport.h
/// Shared plumbing of the pneuma-cli subcommands: exit codes, error reporting, locating the model and
/// resources, preparing output directories.

#include <cstdint>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>

#include "pneuma/sim/Limits.h"
#include "pneuma/sim/Metrics.h"
#include "pneuma/sim/Step.h"
#include "viz/RunSummary.h"

namespace CLI {
class App;
}

namespace pneuma::app {

/// Exit codes of pneuma-cli (docs/cli.md).
enum ExitCode : int {
  kExitOk = 0,        ///< success
  kExitFailed = 1,    ///< the run or a check failed (validate with a failing check, simulation blow-up)
  kExitBadInput = 2,  ///< bad usage or input: unknown option/name, missing model, unwritable --out, bad value
  kExitInterrupted = 130  ///< stopped by SIGINT (outputs written, summary marked partial)
};

/// Prints "pneuma-cli: error: <message>" on stderr and ends the subcommand with `code`
/// (throws CLI::RuntimeError, which main() turns into the exit code).
[[noreturn]] void fail(int code, const std::string& message);

/// The model directory to use: `requested` when given, else sim::defaultModelDir() ($PNEUMA_MODEL_DIR, else
/// <directory of pneuma-cli>/../share/pneuma/models/default). Fails with kExitBadInput when it has no
/// model.json.
std::string resolveModelDir(const std::string& requested);

/// Adds `--model DIR` to `cmd` (resolved later by resolveModelDir()).
void addModelOption(CLI::App& cmd, std::string& model);

/// Adds `--seed N` to `cmd`: an integer in [0, 2^64 - 1]; a sign or an overflow is a usage error.
void addSeedOption(CLI::App& cmd, std::uint64_t& seed);

/// Adds `--integrator NAME` to `cmd`; applyIntegrator() reads it.
void addIntegratorOption(CLI::App& cmd, std::string& name);

/// Sets `kind` from an --integrator value ("" keeps it); an unknown name fails with kExitBadInput and the
/// valid names.
void applyIntegrator(const std::string& name, sim::IntegratorKind& kind);

/// Adds `--posture NAME` to `cmd`; applyPosture() reads it.
void addPostureOption(CLI::App& cmd, std::string& name);

/// Sets `posture` from a --posture value ("" keeps it); an unknown name fails with kExitBadInput and the
/// valid names.
void applyPosture(const std::string& name, sim::Posture& posture);

/// Fails with kExitBadInput and "<flag>: must be in [lo, hi] unit, got v" unless `range` contains `v`.
void checkOption(const sim::Range& range, const char* flag, double v);

/// Prepares the --out directory `dir` of `pneuma-cli <command>`, which writes only the entries `own` (exact
/// names, or "*.ext" patterns; the exact names first, the one that marks an earlier run first of all, e.g.
/// "summary.json"). An existing `dir` may hold nothing but such entries, so a command never overwrites what
/// it did not write: any other entry fails with kExitBadInput naming it, and an earlier run (any own entry
/// but an empty directory) is replaced only with `force`. Then creates `dir` (and parents) and checks that a
/// file can be written in it; fails with kExitBadInput otherwise.
void prepareOutputDir(const std::string& dir, const char* command, std::initializer_list<const char*> own,
                      bool force);

// number formatting and the motion figures of summary.json: shared with the Python module (viz/RunSummary.h)
using viz::formatNumber;
using viz::jsonNumber;
using viz::writeMotion;

}  // namespace pneuma::app
