#pragma once
/// @file RunSummary.h
/// summary.json of one run, the same for every program that writes it (pneuma-cli simulate, the Python
/// module's write_outputs()): the run's settings and status, and the figures of sim::Summary at the edges'
/// units (mL, mm, degrees, %; the keys of docs/cli.md). Also the number formatting of the run's CSV and JSON
/// files.

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pneuma/sim/Metrics.h"
#include "pneuma/sim/Model.h"
#include "pneuma/sim/Scenario.h"
#include "pneuma/sim/Simulation.h"

namespace pneuma::viz {

/// Shortest round-trip text of a double for CSV/JSON ("%.9g"); "nan" never appears: non-finite gives "".
std::string formatNumber(double v);

/// A JSON number, or null when `v` is not finite.
nlohmann::json jsonNumber(double v);

/// Writes the motion figures into `j` at the edges' units: mm, mL, degrees, % (the keys of docs/cli.md, e.g.
/// "dome_descent_mm", "rib_cage_fraction", "rc_ab_phase_deg"); a missing figure is null.
void writeMotion(const sim::Motion& m, nlohmann::json& j);

/// How a run went, besides what the simulation itself holds.
struct RunStatus {
  std::string modelDir;              ///< the model's directory, as given
  std::string controllerText;        ///< what drove the muscles (Controller::describe())
  bool isInterrupted = false;        ///< stopped early on request (Ctrl-C)
  std::string error;                 ///< why the run or an output failed; empty: none
  std::size_t frames = 0;            ///< output frames recorded
  std::vector<std::string> files;    ///< the output files written, relative to the output folder
  double morphBlendRms = sim::kNaN;  ///< [m] skin error of a glTF export's morph blend; NaN without one
  double morphBlendMax = sim::kNaN;  ///< [m] its largest vertex error
};

/// summary.json's object for `scenario` run as `simulation` (null when it never started): settings (model,
/// controller, integrator, posture, dt, settle time, duration, seed), status (partial, interrupted, error,
/// frames, files, the glTF morph blend's error) and the figures of Simulation::summary() (tidal volume, rate,
/// end-expiratory volumes and their split, gut volume errors, motion, tracking RMS), each null when it was
/// not measured (no full breath, no volume target). Keys and units: docs/cli.md, "simulate".
nlohmann::json runSummary(const sim::Model& model, const sim::Scenario& scenario,
                          const sim::Simulation* simulation, const RunStatus& status);

}  // namespace pneuma::viz
