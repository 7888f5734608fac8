#pragma once
/// @file Scenario.h
/// Scenario files: a versioned JSON description of one simulation run (model, duration, controller,
/// parameter overrides, outputs, seed), shared by pneuma-cli (`simulate --scenario`) and the desktop app
/// (open/save). Format: docs/cli.md, "Scenario files"; examples in resources/scenarios/.
///
///   {
///     "format": "pneuma-scenario", "version": 1,
///     "name": "calm-30s", "description": "...",
///     "model": "default",                         // or a model directory, relative to the scenario file
///     "duration_s": 30, "seed": 1,
///     "controller": {"style": "calm"},            // or {"affect": "startle"}, or {"pattern": "file.json"},
///                                                 // or {"pattern": { ...inline pattern file... }},
///                                                 // or {"trace": "volume.csv"} (VolumeTrace.h)
///     "overrides": {"integrator": "implicit-euler-joints", "dt_s": 0.002, "settle_time_s": 2,
///                   "gravity": true, "posture": "upright", "joint_friction_scale": 1, "kappa_pa": 2e4,
///                   "active_gain_scale": {"diaphragm": 1.1}, "passive_gain_scale": {"cartilage": 2}},
///     "outputs": {"output_rate_hz": 60, "csv": true, "plots": true, "vtk": false}
///   }

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "pneuma/sim/Simulation.h"

namespace pneuma::sim {

/// Current scenario-file format version written by serializeScenario(); parseScenario() reads it.
constexpr int kScenarioFormatVersion = 1;

/// What drives the muscles.
enum class ControllerKind { Style, Affect, Pattern, Trace };

/// Stable names "style", "affect", "pattern", "trace".
const char* controllerKindName(ControllerKind k);

/// Which files a run writes (at SimulationOptions::outputRate, the file's outputs.output_rate_hz).
struct ScenarioOutputs {
  bool csv = true;    ///< timeseries.csv
  bool plots = true;  ///< PNG + SVG plots
  bool vtk = false;   ///< .pvd series of .vtp frames
};

/// One run.
struct Scenario {
  std::string name;               ///< short identifier
  std::string description;        ///< free text
  std::string model = "default";  ///< "default" (the built default model) or a model directory path
  double duration = 0.0;          ///< [s] simulated time after the settling phase, > 0
  std::uint64_t seed = 0;         ///< seed of the pattern irregularity streams
  ControllerKind controller = ControllerKind::Style;
  std::string controllerName;  ///< Style: preset name; Affect: affect name; Pattern: pattern file path (""
                               ///< when inline); Trace: volume-trace CSV path
  std::string patternText;     ///< Pattern given inline: the pattern file's JSON text ("" otherwise)
  SimulationOptions options;   ///< overrides: step options, dt, settle time; outputs.output_rate_hz
  ScenarioOutputs outputs;
};

/// Parses the text of a scenario file. Relative "model" and "pattern" paths are resolved against
/// `baseDir` (the scenario file's directory). Checks every field's type and range, the integrator,
/// group and posture names; the style, affect or pattern itself is checked when the controller is made.
/// @throws Error "<sourceName>: <json path>: <reason>", e.g. "run.json: overrides.dt_s: must be > 0, got -1".
Scenario parseScenario(const std::string& jsonText, const std::string& sourceName,
                       const std::string& baseDir);

/// The keys of the scenario file's "overrides" object, as `simulate --set` and sweeps name them: "dt_s",
/// "posture", ..., and "active_gain_scale.<group>" / "passive_gain_scale.<group>" for one muscle group.
std::string overrideKeys();

/// Applies one override KEY=VALUE to `options` by the rule of the scenario file's "overrides" object (the
/// same keys, bounds and messages: parseScenario() and this share one parser). `key` is an overrides key,
/// a dot descending into an object ("active_gain_scale.diaphragm"); `value` is JSON text (1.2, true,
/// "supine") or, when it is not JSON, a bare string (supine). Nothing is changed when it throws.
/// @throws Error "<source>: <key>: <reason>", e.g. "--set: dt_s: must be in [1e-06, 0.05] s, got -1" or
///         "--set: dt: unknown field (did you mean dt_s?)".
void applyOverride(SimulationOptions& options, const std::string& key, const std::string& value,
                   const std::string& source = "--set");

/// Reads and parses a scenario file. @throws Error as parseScenario(), or when the file cannot be read.
Scenario loadScenario(const std::string& path);

/// The JSON text of a scenario (all fields written). Deterministic.
std::string serializeScenario(const Scenario& scenario);

/// Loads and checks the scenario's style preset, affect preset or pattern (file or inline) without
/// running anything. @throws Error as makeController().
void checkController(const Scenario& scenario, const std::string& resourceDir);

/// The controller a scenario asks for: a BreathStyleController for a style (presets in
/// `resourceDir`/presets), or a pattern::PatternController for an affect (`resourceDir`/presets/affect)
/// or a pattern, or following a volume trace (VolumeTrace.h), seeded with `scenario.seed` and calibrated on
/// `model` with pattern::calibrateDrive() (a few simulated seconds per muscle group) under
/// `scenario.options`; `stop` (may be null) stops the calibration (Simulation::setStopFlag()).
/// @throws Error "controller.<kind>: <reason>", listing the valid names for an unknown style or affect;
///         Interrupted when `*stop` became true during the calibration.
std::unique_ptr<Controller> makeController(const Scenario& scenario, std::shared_ptr<const Model> model,
                                           const std::string& resourceDir,
                                           const std::atomic<bool>* stop = nullptr);

/// Writes serializeScenario() to `path` through a temporary file and a rename. @throws Error on I/O failure.
void saveScenario(const Scenario& scenario, const std::string& path);

}  // namespace pneuma::sim
