#include "Silhouettes.h"

#include <cmath>
#include <limits>
#include <sstream>

#include "CliSupport.h"
#include "viz/AtomicFile.h"

namespace pneuma::app {

namespace {

constexpr double kMm = 1e3;           // [mm/m]
constexpr double kBelowBelly = 0.25;  // [m] the overlay's trunk starts this far below the belly line
constexpr double kAboveChest = 0.30;  // [m] and ends this far above the chest line
const char* const kPhase[2] = {"end-expiration", "end-inspiration"};
const viz::Color kPhaseColor[2] = {{0.12, 0.47, 0.71}, {0.84, 0.15, 0.16}};

int viewIndex(sim::SilhouetteView view) { return view == sim::SilhouetteView::Lateral ? 0 : 1; }

// the figures' horizontal axis: anterior from the side; from the front the subject's left, so that the figure
// shows the body as seen from in front of it (u = -x: RAS x runs to the subject's right)
const char* axisName(sim::SilhouetteView view) {
  return view == sim::SilhouetteView::Lateral ? "anterior" : "left";
}
double axisSign(sim::SilhouetteView view) { return view == sim::SilhouetteView::Lateral ? 1.0 : -1.0; }

std::string signedMm(double m) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%+.1f mm", m * kMm);
  return buf;
}

}  // namespace

BreathOutlines traceBreath(sim::SilhouetteBreath breath, const Eigen::Matrix3Xi& triangles, double spacing) {
  BreathOutlines out;
  out.breath = std::move(breath);
  for (sim::SilhouetteView view : kSilhouetteViews) {
    auto& o = out.outline[static_cast<std::size_t>(viewIndex(view))];
    // from the side the trunk, as measured (SilhouetteBreath); from the front the whole body
    const double band = view == sim::SilhouetteView::Lateral ? out.breath.trunkBand : sim::kWholeMesh;
    o[0] = sim::silhouetteOutline(out.breath.skinExpiration, triangles, view, spacing, band);
    o[1] = sim::silhouetteOutline(out.breath.skinInspiration, triangles, view, spacing, band);
  }
  return out;
}

viz::Plot silhouettePlot(const BreathOutlines& b, sim::SilhouetteView view) {
  const sim::SilhouetteBreath& s = b.breath;
  viz::Plot plot(s.style + ": " + sim::silhouetteViewName(view) +
                     (view == sim::SilhouetteView::Lateral ? " silhouette of the trunk" : " silhouette"),
                 std::string(axisName(view)) + " [mm]", "height [mm]");
  const double zLo = s.bellyHeight - kBelowBelly, zHi = s.chestHeight + kAboveChest;  // [m]
  for (int phase = 0; phase < 2; ++phase) {
    // the trunk's part of every loop, closed; leaving the window breaks the line
    viz::Plot::Series series;
    series.label = kPhase[phase];
    series.color = kPhaseColor[phase];
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (const Eigen::Matrix2Xd& loop :
         b.outline[static_cast<std::size_t>(viewIndex(view))][static_cast<std::size_t>(phase)].loops) {
      for (Eigen::Index i = 0; i <= loop.cols(); ++i) {
        const Eigen::Vector2d p = loop.col(i % loop.cols());
        const bool isShown = p.y() >= zLo && p.y() <= zHi;
        series.x.push_back(isShown ? axisSign(view) * p.x() * kMm : nan);
        series.y.push_back(isShown ? p.y() * kMm : nan);
      }
      series.x.push_back(nan);
      series.y.push_back(nan);
    }
    plot.addSeries(std::move(series));
  }
  plot.addReferenceLine("chest line", s.chestHeight * kMm, viz::Color{0.35, 0.35, 0.35});
  plot.addReferenceLine("belly line", s.bellyHeight * kMm, viz::Color{0.6, 0.6, 0.6});
  plot.setEqualAspect(true);
  plot.setSize(view == sim::SilhouetteView::Lateral ? 600 : 900, 860);
  char lung[64];
  std::snprintf(lung, sizeof lung, "lung volume %+.0f mL", s.lungChange * 1e6);
  plot.setNote(view == sim::SilhouetteView::Lateral
                   ? "AP change: chest " + signedMm(s.chestChange) + ", belly " + signedMm(s.bellyChange)
                   : std::string(lung));
  return plot;
}

std::string silhouetteCsv(const BreathOutlines& b, sim::SilhouetteView view) {
  std::ostringstream csv;
  csv << "phase,loop," << axisName(view) << "_mm,superior_mm\n";
  for (int phase = 0; phase < 2; ++phase) {
    const auto& loops =
        b.outline[static_cast<std::size_t>(viewIndex(view))][static_cast<std::size_t>(phase)].loops;
    for (std::size_t l = 0; l < loops.size(); ++l)
      for (Eigen::Index i = 0; i <= loops[l].cols(); ++i) {
        const Eigen::Vector2d p = loops[l].col(i % loops[l].cols());
        csv << kPhase[phase] << "," << l << "," << formatNumber(axisSign(view) * p.x() * kMm) << ","
            << formatNumber(p.y() * kMm) << "\n";
      }
  }
  return csv.str();
}

std::vector<std::string> writeSilhouettes(const BreathOutlines& b, const std::string& dir,
                                          const std::string& prefix) {
  std::vector<std::string> written;
  for (sim::SilhouetteView view : kSilhouetteViews) {
    const std::string stem = prefix + b.breath.style + "_" + sim::silhouetteViewName(view);
    viz::writeFileAtomically(dir + "/" + stem + ".csv", silhouetteCsv(b, view));
    const viz::Plot plot = silhouettePlot(b, view);
    plot.writeSvg(dir + "/" + stem + ".svg");
    plot.writePng(dir + "/" + stem + ".png");
    written.push_back(stem + ".png");
    written.push_back(stem + ".svg");
  }
  return written;
}

nlohmann::json silhouetteJson(const sim::SilhouetteBreath& b) {
  return {{"chest_line_mm", jsonNumber(b.chestHeight * kMm)},
          {"belly_line_mm", jsonNumber(b.bellyHeight * kMm)},
          {"chest_landmarks_lift_mm", jsonNumber(b.chestLift * kMm)},
          {"umbilicus_lift_mm", jsonNumber(b.bellyLift * kMm)},
          {"chest_ap_change_mm", jsonNumber(b.chestChange * kMm)},
          {"belly_ap_change_mm", jsonNumber(b.bellyChange * kMm)},
          {"chest_marker_ventral_mm", jsonNumber(b.chestMarker.y() * kMm)},
          {"chest_marker_cranial_mm", jsonNumber(b.chestMarker.z() * kMm)},
          {"chest_marker_mm", jsonNumber(b.chestMarker.norm() * kMm)},
          {"lung_volume_change_ml", jsonNumber(b.lungChange * 1e6)}};
}

}  // namespace pneuma::app
