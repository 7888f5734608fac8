#pragma once
/// @file ParameterSweep.h
/// Sweep files: a base scenario plus the scenario overrides to vary, expanded into one scenario per variant
/// (`pneuma-cli sweep`, docs/cli.md "sweep"). Every value goes through the scenario file's overrides rule
/// (applyOverride(), Scenario.h), so a sweep accepts exactly the keys, bounds and names a scenario does.
///
///   {
///     "format": "pneuma-sweep", "version": 1, "name": "gains",
///     "scenario": "calm.json",                       // or an inline scenario object
///     "design": "grid",                              // or "list", "random"
///     "parameters": {
///       "active_gain_scale.diaphragm": [0.8, 1, 1.2],                              // values
///       "active_gain_scale.intercostal_external": {"from": 0.8, "to": 1.2, "steps": 3}  // evenly spaced
///     },
///     "samples": 20, "seed": 1,                      // random: N uniform draws in each {"from", "to"}
///     "outputs": ["tidal_volume_ml"]                 // summary figures to plot against the parameters
///   }

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "pneuma/sim/Scenario.h"

namespace pneuma::sim {

/// Current sweep-file format version.
constexpr int kSweepFormatVersion = 1;
/// [-] most variants one sweep may expand to.
constexpr std::size_t kMaxSweepVariants = 100000;

/// How the parameters' values combine into variants.
enum class SweepDesign {
  Grid,   ///< every combination (the first parameter varies slowest)
  List,   ///< variant i takes the i-th value of every parameter (lists of one length)
  Random  ///< `samples` variants, each parameter drawn uniformly in [from, to] (SplitMix64, `seed`)
};

/// One variant: the base scenario with `settings` applied.
struct SweepVariant {
  std::vector<std::pair<std::string, std::string>> settings;  ///< (override key, value as JSON text)
  Scenario scenario;                                          ///< the base with the settings applied
};

struct Sweep {
  std::string name;
  SweepDesign design = SweepDesign::Grid;
  std::vector<std::string> parameters;  ///< override keys, in the file's order
  std::vector<SweepVariant> variants;   ///< in run order
  std::vector<std::string> outputs;     ///< summary.json figures to plot (not checked here)
  std::uint64_t seed = 0;               ///< random design's seed
};

/// Parses a sweep file's text; a scenario path is resolved against `baseDir`.
/// @throws Error "<sourceName>: <json path>: <reason>", a parameter's value out of its override's bounds
///         as "<sourceName>: parameters: <key>: must be in [1e-06, 0.05] s, got 1" (all before any run).
Sweep parseSweep(const std::string& jsonText, const std::string& sourceName, const std::string& baseDir);

/// Reads and parses a sweep file. @throws Error as parseSweep(), or when the file cannot be read.
Sweep loadSweep(const std::string& path);

}  // namespace pneuma::sim
