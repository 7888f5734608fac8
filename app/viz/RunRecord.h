#pragma once
/// @file RunRecord.h
/// The per-frame record of one run (pneuma-cli simulate, the Python module's outputs) and its exports:
/// timeseries.csv (one header row of "name [unit]" columns) and the plots (lung-cavity volume, gut volume
/// error, activations, group tensions, and the volume fraction target vs measured when a pattern drives the
/// breathing). Memory stays bounded however long the run: the CSV is written row by row as frames arrive (to
/// a temporary file, renamed by commitCsv()), and the plots keep each series thinned to the minima and maxima
/// of at most kPlotBuckets buckets (MinMaxSeries), so an hour's plot is as small as a minute's.

#include <memory>
#include <string>
#include <vector>

#include "pneuma/sim/Metrics.h"
#include "pneuma/sim/Model.h"
#include "viz/AtomicFile.h"
#include "viz/MinMaxSeries.h"

namespace pneuma::viz {

/// Buckets per plotted series (each keeps a minimum and a maximum): about two per pixel of a 960 px plot.
inline constexpr std::size_t kPlotBuckets = 1024;

class RunRecord {
 public:
  /// @param hasVolumeTarget true when an affect or pattern controller sets a target volume fraction
  /// @param csvPath         where commitCsv() puts timeseries.csv; "" writes no CSV
  /// @throws std::runtime_error "cannot write <csvPath>: <reason>" when the CSV cannot be started.
  RunRecord(const sim::Model& model, bool hasVolumeTarget, const std::string& csvPath = "");

  /// Appends one output frame (a CSV row, and the plotted series). `targetFraction` and `measuredFraction`
  /// [-] are used only with a volume target. @throws std::runtime_error when the CSV row cannot be written.
  void append(const sim::Metrics& m, double targetFraction = 0.0, double measuredFraction = 0.0);
  std::size_t size() const { return m_frames; }

  /// Renames the CSV into place (the rows of every frame appended). @throws std::runtime_error as append().
  void commitCsv();
  /// Writes <dir>/{lung_volume,gut_volume_error,activations,tensions[,volume_fraction]}.{png,svg};
  /// returns the file names written.
  std::vector<std::string> writePlots(const std::string& dir, const std::string& runLabel) const;

 private:
  void writeCsvHeader();
  const sim::Model& m_model;
  bool m_hasVolumeTarget;
  std::unique_ptr<AtomicFileWriter> m_csv;  // null without a CSV
  std::size_t m_frames = 0;
  MinMaxSeries m_lungVolume{kPlotBuckets};      // [m^3]
  MinMaxSeries m_gutVolumeError{kPlotBuckets};  // [-]
  std::vector<MinMaxSeries> m_r, m_alpha;       // [-] per ElementGroup
  std::vector<MinMaxSeries> m_tension;          // [N] per ElementGroup
  MinMaxSeries m_target{kPlotBuckets};          // [-]
  MinMaxSeries m_measured{kPlotBuckets};        // [-]
};

}  // namespace pneuma::viz
