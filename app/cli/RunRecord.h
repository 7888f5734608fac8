#pragma once
/// @file RunRecord.h
/// The per-frame record of one pneuma-cli run and its exports: timeseries.csv (one header row of
/// "name [unit]" columns) and the plots (lung-cavity volume, gut volume error, activations, group
/// tensions, and the volume fraction target vs measured when a pattern drives the breathing).

#include "pneuma/sim/Metrics.h"
#include "pneuma/sim/Model.h"

#include <string>
#include <vector>

namespace pneuma::app {

class RunRecord {
 public:
  /// @param hasVolumeTarget true when an affect or pattern controller sets a target volume fraction
  RunRecord(const sim::Model& model, bool hasVolumeTarget);

  /// Appends one output frame. `targetFraction` and `measuredFraction` [-] are used only with a volume target.
  void append(const sim::Metrics& m, double targetFraction = 0.0, double measuredFraction = 0.0);
  std::size_t size() const { return m_time.size(); }

  /// Writes timeseries.csv to `path` (temporary file, then rename).
  void writeCsv(const std::string& path) const;
  /// Writes <dir>/{lung_volume,gut_volume_error,activations,tensions[,volume_fraction]}.{png,svg};
  /// returns the file names written.
  std::vector<std::string> writePlots(const std::string& dir, const std::string& runLabel) const;

 private:
  const sim::Model& m_model;
  bool m_hasVolumeTarget;
  std::vector<double> m_time;             // [s]
  std::vector<double> m_lungVolume;       // [m^3]
  std::vector<double> m_abdomenVolume;    // [m^3] Metrics::abdomenVolume (the rib-cage volume is the lung minus it)
  std::vector<double> m_gutVolumeError;   // [-]
  std::vector<sim::Activations> m_activations;
  std::vector<std::array<double, sim::kElementGroupCount>> m_tension;  // [N]
  std::vector<Eigen::Matrix3Xd> m_landmarks;  // [m] (3 x #L)
  std::vector<double> m_target;           // [-]
  std::vector<double> m_measured;         // [-]
};

}  // namespace pneuma::app
