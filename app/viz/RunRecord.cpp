#include "viz/RunRecord.h"

#include <cmath>
#include <sstream>

#include "viz/AtomicFile.h"
#include "viz/ModelScene.h"
#include "viz/Plot.h"
#include "viz/RunSummary.h"

namespace pneuma::viz {

namespace {

constexpr double kMl = 1e6;   // [mL/m^3]
constexpr double kMm = 1e3;   // [mm/m]
constexpr double kPct = 1e2;  // [%]

sim::ElementGroup group(int i) { return static_cast<sim::ElementGroup>(i); }

// the 3D view's group colour (Figure 2 of Zordan et al. 2004), so plots and scene agree
Color groupPlotColour(int g) {
  const std::array<double, 3> c = groupColour(group(g));
  return Color{c[0], c[1], c[2]};
}

}  // namespace

RunRecord::RunRecord(const sim::Model& model, bool hasVolumeTarget, const std::string& csvPath)
    : m_model(model),
      m_hasVolumeTarget(hasVolumeTarget),
      m_r(sim::kElementGroupCount, MinMaxSeries(kPlotBuckets)),
      m_alpha(sim::kElementGroupCount, MinMaxSeries(kPlotBuckets)),
      m_tension(sim::kElementGroupCount, MinMaxSeries(kPlotBuckets)) {
  if (csvPath.empty()) return;
  m_csv = std::make_unique<AtomicFileWriter>(csvPath);
  writeCsvHeader();
}

void RunRecord::writeCsvHeader() {
  std::ostringstream csv;
  csv << "time [s],lung_volume [mL],gut_volume_error [%],rib_cage_volume [mL],abdomen_volume [mL],"
         "right_lung_volume [mL],left_lung_volume [mL],thoracic_cavity_volume [mL]";
  for (int g = 0; g < sim::kElementGroupCount; ++g)
    if (sim::isMuscleGroup(group(g)))
      csv << "," << sim::groupName(group(g)) << ".r [-]," << sim::groupName(group(g)) << ".alpha [-]";
  for (int g = 0; g < sim::kElementGroupCount; ++g)
    csv << "," << sim::groupName(group(g)) << ".mean_tension [N]";
  for (const std::string& name : m_model.landmarks.name)
    csv << "," << name << ".x [mm]," << name << ".y [mm]," << name << ".z [mm]";
  if (m_hasVolumeTarget) csv << ",target_volume_fraction [-],measured_volume_fraction [-]";
  csv << "\n";
  m_csv->write(csv.str());
}

void RunRecord::append(const sim::Metrics& m, double targetFraction, double measuredFraction) {
  ++m_frames;
  const double t = m.time;
  m_lungVolume.append(t, m.lungVolume);
  m_gutVolumeError.append(t, m.gutVolumeError);
  for (std::size_t g = 0; g < static_cast<std::size_t>(sim::kElementGroupCount); ++g) {
    m_r[g].append(t, m.activations[g].r);
    m_alpha[g].append(t, m.activations[g].alpha);
    m_tension[g].append(t, m.groupMeanTension[g]);
  }
  m_target.append(t, targetFraction);
  m_measured.append(t, measuredFraction);
  if (!m_csv) return;

  std::ostringstream csv;
  csv << formatNumber(t) << "," << formatNumber(m.lungVolume * kMl) << ","
      << formatNumber(m.gutVolumeError * kPct) << "," << formatNumber((m.lungVolume - m.abdomenVolume) * kMl)
      << "," << formatNumber(m.abdomenVolume * kMl) << "," << formatNumber(m.rightLungVolume * kMl) << ","
      << formatNumber(m.leftLungVolume * kMl) << "," << formatNumber(m.thoracicCavityVolume * kMl);
  for (int g = 0; g < sim::kElementGroupCount; ++g)
    if (sim::isMuscleGroup(group(g)))
      csv << "," << formatNumber(m.activations[static_cast<std::size_t>(g)].r) << ","
          << formatNumber(m.activations[static_cast<std::size_t>(g)].alpha);
  for (int g = 0; g < sim::kElementGroupCount; ++g)
    csv << "," << formatNumber(m.groupMeanTension[static_cast<std::size_t>(g)]);
  for (Eigen::Index l = 0; l < m.landmarks.cols(); ++l)
    csv << "," << formatNumber(m.landmarks(0, l) * kMm) << "," << formatNumber(m.landmarks(1, l) * kMm) << ","
        << formatNumber(m.landmarks(2, l) * kMm);
  if (m_hasVolumeTarget) csv << "," << formatNumber(targetFraction) << "," << formatNumber(measuredFraction);
  csv << "\n";
  m_csv->write(csv.str());
}

void RunRecord::commitCsv() {
  if (m_csv) m_csv->commit();
}

std::vector<std::string> RunRecord::writePlots(const std::string& dir, const std::string& runLabel) const {
  std::vector<std::string> written;
  auto save = [&](const Plot& plot, const std::string& stem) {
    plot.writePng(dir + "/" + stem + ".png");
    plot.writeSvg(dir + "/" + stem + ".svg");
    written.push_back(stem + ".png");
    written.push_back(stem + ".svg");
  };
  // the thinned curve of `s`, values times k
  auto curve = [](const MinMaxSeries& s, double k, std::vector<double>& t, std::vector<double>& v) {
    s.points(t, v);
    for (double& x : v) x *= k;
  };
  std::vector<double> t, v;

  Plot lung("Lung volume (" + runLabel + ")", "time [s]", "lung volume [mL]");
  curve(m_lungVolume, kMl, t, v);
  lung.addSeries("lung volume", t, v);
  save(lung, "lung_volume");

  Plot gut("Gut volume error (" + runLabel + ")", "time [s]", "gut volume error (V - V0)/V0 [%]");
  curve(m_gutVolumeError, kPct, t, v);
  gut.addSeries("gut volume error", t, v);
  save(gut, "gut_volume_error");

  Plot act("Muscle activations (" + runLabel + ")", "time [s]", "r, alpha [-]");
  Plot ten("Mean element tension per group (" + runLabel + ")", "time [s]", "mean tension per element [N]");
  for (int g = 0; g < sim::kElementGroupCount; ++g) {
    const std::size_t i = static_cast<std::size_t>(g);
    const std::string name = sim::groupName(group(g));
    const Color c = groupPlotColour(g);
    if (sim::isMuscleGroup(group(g))) {
      curve(m_r[i], 1.0, t, v);
      act.addSeries(Plot::Series{name + " r", t, v, c, false});
      curve(m_alpha[i], 1.0, t, v);
      act.addSeries(Plot::Series{name + " alpha", t, v, c, true});
    }
    curve(m_tension[i], 1.0, t, v);
    ten.addSeries(Plot::Series{name, t, v, c, false});
  }
  save(act, "activations");
  save(ten, "tensions");

  if (m_hasVolumeTarget) {
    Plot vf("Volume fraction: pattern target vs measured (" + runLabel + ")", "time [s]",
            "volume fraction [-]");
    curve(m_target, 1.0, t, v);
    vf.addSeries(Plot::Series{"target", t, v, {0.84, 0.15, 0.16}, true});
    curve(m_measured, 1.0, t, v);
    vf.addSeries(Plot::Series{"measured", t, v, {0.0, 0.0, 0.0}, false});
    save(vf, "volume_fraction");
  }
  return written;
}

}  // namespace pneuma::viz
