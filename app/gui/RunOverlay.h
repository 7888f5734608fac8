#pragma once
/// @file RunOverlay.h
/// A second run to draw over the live plots (runs side by side, e.g. normal against a paralysed
/// hemidiaphragm): a scenario run headless on the window's model, or a recording written by
/// `pneuma-cli simulate` (its timeseries.csv, with the summary.json beside it naming the model).
/// Either must be of the model the window shows; another model is refused with a message naming both.

#include <QString>
#include <functional>
#include <memory>
#include <vector>

#include "gui/SimWorker.h"

namespace pneuma::app {

/// [1/s] states kept per simulated second for the ghost of a compared scenario: a smooth ghost at the 3D
/// view's frame rate, about 1 MB per simulated second on the default model
constexpr double kGhostRate = 30.0;

/// The poses of a compared run for its ghost in the 3D view (viz::ModelScene::setGhost()). A scenario run has
/// them; a recording (timeseries.csv) has none.
struct RunGhost {
  std::vector<sim::State> states;  ///< kGhostRate per simulated second, oldest first
  std::vector<std::shared_ptr<const sim::State>> endExpirations;  ///< each breath's (EndExpirationFinder)
  /// The state to show at simulated time `t` [s]: the last one at or before it (null when none).
  const sim::State* at(double t) const;
  /// The end-expiratory state of the breath in progress at `t` [s] (null before the first).
  const sim::State* endExpirationAt(double t) const;
};

struct RunOverlay {
  QString name;                     ///< shown in the legends: the scenario's name or the recording's folder
  std::vector<PlotSample> samples;  ///< one per output frame, oldest first (no element forces)
  RunGhost ghost;                   ///< empty for a recording
};

/// Runs the scenario at `path` on `model` (the window's, read from `modelDir`) for its duration after its
/// settling, at its output rate, sampling every frame with plotSample(). `progress` gets the fraction done
/// after each frame and stops the run by returning false (then the result is empty).
/// @throws std::exception naming the file: a bad scenario, or one that names another model directory than
///         `modelDir` ("overlay: <file> runs the model in '<dir>', the window shows '<dir>'").
RunOverlay runScenarioOverlay(const QString& path, std::shared_ptr<const sim::Model> model,
                              const QString& modelDir, const std::function<bool(double)>& progress = {});

/// Reads a recording: `path` is a timeseries.csv of `pneuma-cli simulate` (columns "time [s]" and
/// "lung_volume [mL]"; flow is the backward difference, pressures are not recorded there) or its folder.
/// @throws std::exception naming the file: missing columns or summary.json, or a recording of another model
///         than `model` ("overlay: <file> was recorded on model '<name>', the window shows '<name>'").
RunOverlay readRecordingOverlay(const QString& path, const sim::Model& model);

}  // namespace pneuma::app
