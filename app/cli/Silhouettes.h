#pragma once
/// @file Silhouettes.h
/// The body's silhouettes at end-expiration and end-inspiration of a breath-style run, as files: the outline
/// curves (CSV) and their overlay (SVG and PNG, drawn to scale in mm). Shared by `pneuma-cli silhouette` and
/// `pneuma-cli validate` (docs/cli.md).

#include <array>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pneuma/sim/Experiments.h"
#include "pneuma/sim/Silhouette.h"
#include "viz/Plot.h"

namespace pneuma::app {

/// One style's breath and its outlines, traced from the posed skin.
struct BreathOutlines {
  sim::SilhouetteBreath breath;
  /// [view][phase]: view 0 lateral, 1 frontal; phase 0 end-expiration, 1 end-inspiration
  std::array<std::array<sim::SilhouetteOutline, 2>, 2> outline;
};

/// The views in file order: lateral, frontal.
constexpr std::array<sim::SilhouetteView, 2> kSilhouetteViews{sim::SilhouetteView::Lateral,
                                                              sim::SilhouetteView::Frontal};

/// Traces both views of both phases of `breath` on the skin's `triangles`, `spacing` [m] apart.
BreathOutlines traceBreath(sim::SilhouetteBreath breath, const Eigen::Matrix3Xi& triangles, double spacing);

/// The overlay of one view: end-expiration and end-inspiration in two colours, to scale with mm axes, the
/// trunk only (from 250 mm below the belly line to 300 mm above the chest line), with the chest and belly
/// lines dashed and their AP changes in the note.
viz::Plot silhouettePlot(const BreathOutlines& b, sim::SilhouetteView view);

/// The outline as CSV: "phase,loop,<u>_mm,superior_mm" (u: anterior for the lateral view, the subject's left
/// for the frontal one, as seen from the front), one row per outline point, loops closed by their first
/// point.
std::string silhouetteCsv(const BreathOutlines& b, sim::SilhouetteView view);

/// Writes `<prefix><style>_<view>.csv`, `.svg` and `.png` for both views into `dir`; returns the PNG and SVG
/// names written, relative to `dir`. @throws std::runtime_error on I/O failure.
std::vector<std::string> writeSilhouettes(const BreathOutlines& b, const std::string& dir,
                                          const std::string& prefix);

/// The figures of `b` for summary files: chest and belly lines [mm above the model origin] and their AP
/// change [mm], the lung volume change [mL].
nlohmann::json silhouetteJson(const sim::SilhouetteBreath& b);

}  // namespace pneuma::app
