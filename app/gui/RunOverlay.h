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

struct RunOverlay {
  QString name;                     ///< shown in the legends: the scenario's name or the recording's folder
  std::vector<PlotSample> samples;  ///< one per output frame, oldest first (no element forces)
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
