#include "RunRecord.h"

#include "CliSupport.h"
#include "viz/AtomicFile.h"
#include "viz/ModelScene.h"
#include "viz/Plot.h"

#include <cmath>
#include <sstream>

namespace pneuma::app {

namespace {

constexpr double kMl = 1e6;   // [mL/m^3]
constexpr double kMm = 1e3;   // [mm/m]
constexpr double kPct = 1e2;  // [%]

sim::ElementGroup group(int i) { return static_cast<sim::ElementGroup>(i); }

// the 3D view's group colour (Figure 2 of Zordan et al. 2004), so plots and scene agree
viz::Color groupPlotColour(int g) {
  const std::array<double, 3> c = viz::groupColour(group(g));
  return viz::Color{c[0], c[1], c[2]};
}

}  // namespace

RunRecord::RunRecord(const sim::Model& model, bool hasVolumeTarget) : m_model(model), m_hasVolumeTarget(hasVolumeTarget) {}

void RunRecord::append(const sim::Metrics& m, double targetFraction, double measuredFraction) {
  m_time.push_back(m.time);
  m_lungVolume.push_back(m.lungVolume);
  m_abdomenVolume.push_back(m.abdomenVolume);
  m_gutVolumeError.push_back(m.gutVolumeError);
  m_activations.push_back(m.activations);
  m_tension.push_back(m.groupMeanTension);
  m_landmarks.push_back(m.landmarks);
  m_target.push_back(targetFraction);
  m_measured.push_back(measuredFraction);
}

void RunRecord::writeCsv(const std::string& path) const {
  std::ostringstream csv;
  // header: one "name [unit]" column each
  csv << "time [s],lung_volume [mL],gut_volume_error [%],rib_cage_volume [mL],abdomen_volume [mL]";
  for (int g = 0; g < sim::kElementGroupCount; ++g)
    if (sim::isMuscleGroup(group(g))) csv << "," << sim::groupName(group(g)) << ".r [-]," << sim::groupName(group(g)) << ".alpha [-]";
  for (int g = 0; g < sim::kElementGroupCount; ++g) csv << "," << sim::groupName(group(g)) << ".mean_tension [N]";
  for (const std::string& name : m_model.landmarks.name) csv << "," << name << ".x [mm]," << name << ".y [mm]," << name << ".z [mm]";
  if (m_hasVolumeTarget) csv << ",target_volume_fraction [-],measured_volume_fraction [-]";
  csv << "\n";

  // rows
  for (std::size_t i = 0; i < m_time.size(); ++i) {
    csv << formatNumber(m_time[i]) << "," << formatNumber(m_lungVolume[i] * kMl) << "," << formatNumber(m_gutVolumeError[i] * kPct)
        << "," << formatNumber((m_lungVolume[i] - m_abdomenVolume[i]) * kMl) << "," << formatNumber(m_abdomenVolume[i] * kMl);
    for (int g = 0; g < sim::kElementGroupCount; ++g)
      if (sim::isMuscleGroup(group(g)))
        csv << "," << formatNumber(m_activations[i][static_cast<std::size_t>(g)].r) << ","
            << formatNumber(m_activations[i][static_cast<std::size_t>(g)].alpha);
    for (int g = 0; g < sim::kElementGroupCount; ++g) csv << "," << formatNumber(m_tension[i][static_cast<std::size_t>(g)]);
    for (Eigen::Index l = 0; l < m_landmarks[i].cols(); ++l)
      csv << "," << formatNumber(m_landmarks[i](0, l) * kMm) << "," << formatNumber(m_landmarks[i](1, l) * kMm) << ","
          << formatNumber(m_landmarks[i](2, l) * kMm);
    if (m_hasVolumeTarget) csv << "," << formatNumber(m_target[i]) << "," << formatNumber(m_measured[i]);
    csv << "\n";
  }
  viz::writeFileAtomically(path, csv.str());
}

std::vector<std::string> RunRecord::writePlots(const std::string& dir, const std::string& runLabel) const {
  std::vector<std::string> written;
  auto save = [&](const viz::Plot& plot, const std::string& stem) {
    plot.writePng(dir + "/" + stem + ".png");
    plot.writeSvg(dir + "/" + stem + ".svg");
    written.push_back(stem + ".png");
    written.push_back(stem + ".svg");
  };
  auto scaled = [](const std::vector<double>& v, double k) {
    std::vector<double> out(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) out[i] = v[i] * k;
    return out;
  };

  viz::Plot lung("Lung-cavity volume (" + runLabel + ")", "time [s]", "lung-cavity volume [mL]");
  lung.addSeries("lung-cavity volume", m_time, scaled(m_lungVolume, kMl));
  save(lung, "lung_volume");

  viz::Plot gut("Gut volume error (" + runLabel + ")", "time [s]", "gut volume error (V - V0)/V0 [%]");
  gut.addSeries("gut volume error", m_time, scaled(m_gutVolumeError, kPct));
  save(gut, "gut_volume_error");

  // activations: contraction ratio r solid, activation alpha dashed, one colour per group
  viz::Plot act("Muscle activations (" + runLabel + ")", "time [s]", "r, alpha [-]");
  viz::Plot ten("Mean element tension per group (" + runLabel + ")", "time [s]", "mean tension per element [N]");
  for (int g = 0; g < sim::kElementGroupCount; ++g) {
    std::vector<double> r, a, t;
    for (std::size_t i = 0; i < m_time.size(); ++i) {
      r.push_back(m_activations[i][static_cast<std::size_t>(g)].r);
      a.push_back(m_activations[i][static_cast<std::size_t>(g)].alpha);
      t.push_back(m_tension[i][static_cast<std::size_t>(g)]);
    }
    const std::string name = sim::groupName(group(g));
    if (sim::isMuscleGroup(group(g))) {
      viz::Plot::Series rs{name + " r", m_time, r, {}, false};
      viz::Plot::Series as{name + " alpha", m_time, a, {}, true};
      const viz::Color c = groupPlotColour(g);
      rs.color = c;
      as.color = c;
      act.addSeries(rs);
      act.addSeries(as);
    }
    viz::Plot::Series ts{name, m_time, t, groupPlotColour(g), false};
    ten.addSeries(ts);
  }
  save(act, "activations");
  save(ten, "tensions");

  if (m_hasVolumeTarget) {
    viz::Plot vf("Volume fraction: pattern target vs measured (" + runLabel + ")", "time [s]", "volume fraction [-]");
    vf.addSeries(viz::Plot::Series{"target", m_time, m_target, {0.84, 0.15, 0.16}, true});
    vf.addSeries(viz::Plot::Series{"measured", m_time, m_measured, {0.0, 0.0, 0.0}, false});
    save(vf, "volume_fraction");
  }
  return written;
}

}  // namespace pneuma::app
