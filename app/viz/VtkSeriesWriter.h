#pragma once
/// @file VtkSeriesWriter.h
/// Export of a running simulation as a ParaView time series: one .pvd collection that lists, per frame,
/// seven .vtp parts (VTK XML polydata, SI units), all posed by sim::poseGeometry():
///   part 0 bones    body meshes posed in world [m]; cell data body_id
///   part 1 muscles  one line per element [m]; cell data force_N (signed, <= 0 is tension), tension_N,
///                   group (ElementGroup index), is_slack
///   part 2 gut      the gut surface [m]; point data displacement_m (3), field data pressure_Pa
///   part 3 cavity   the lung-cavity surface [m]; field data thoracic_cavity_volume_m3, lung_volume_m3
///   part 4 lungs    the right and the left lung surfaces [m] (empty for a model without them); cell data
///                   side (0 right, 1 left), field data right_lung_volume_m3, left_lung_volume_m3,
///                   lung_volume_m3
///   part 5 skin     the body surface [m] (empty for a model without one); point data displacement_m (3) from
///                   the rest pose
///   part 6 tissue   the soft-tissue volume bodies (Model::volumes: pectorals, shoulders) over the nodes [m]
///                   (empty for a model without them); cell data body (index in Model::volumes), point data
///                   displacement_m (3) from the rest pose, field data volume_error (one tuple per body)
/// Every file is written to a temporary name and renamed; the .pvd is written by finish(). With
/// Staging::TemporaryFolder (the app's export) the frames go into a folder of the writer's own
/// ("<baseName>.tmp-<pid>"), renamed to <baseName>/ by finish(), and a writer destroyed unfinished (a
/// cancelled or failed export) removes the files it wrote and its folder, and nothing else. With
/// Staging::Direct (the CLI's run, whose --out folder is its own and whose partial results are kept) they go
/// straight into <baseName>/, which may be a file system of its own.

#include <cstddef>
#include <limits>
#include <memory>
#include <string>

#include "pneuma/sim/Metrics.h"
#include "pneuma/sim/Model.h"
#include "pneuma/sim/State.h"

namespace pneuma::viz {

/// Which output frames a series keeps: those from `from` to `to` [s] (both included, within kTimeTolerance),
/// every `stride`-th of them starting with the first. The app's export and `pneuma-cli simulate --vtk` share
/// it.
struct SeriesRange {
  double from = 0.0;                                    ///< [s]
  double to = std::numeric_limits<double>::infinity();  ///< [s]
  int stride = 1;                                       ///< keep one frame in `stride` (>= 1)
  static constexpr double kTimeTolerance = 1e-6;        ///< [s] a frame this close to a bound is inside

  /// An empty string, or what is wrong ("<field>: ..."), the fields named by `fromName`, `toName`,
  /// `strideName`.
  std::string error(const std::string& fromName, const std::string& toName,
                    const std::string& strideName) const;
  /// How many of `frames` frames spaced evenly from `first` to `last` [s] (a recording) are kept.
  int count(std::size_t frames, double first, double last) const;
};

/// Picks a series' frames from a stream of output frames in time order (SeriesRange).
class SeriesSelector {
 public:
  explicit SeriesSelector(SeriesRange range) : m_range(range) {}
  /// True when the frame at `time` [s] is kept; call once per frame, in time order.
  bool take(double time);

 private:
  SeriesRange m_range;
  long long m_inRange = 0;  // frames seen inside the range so far
};

class VtkSeriesWriter {
 public:
  enum class Staging { Direct, TemporaryFolder };

  /// Frames go to `outDir`/`baseName`/ (through the temporary folder), the collection to
  /// `outDir`/`baseName`.pvd. Body meshes are read relative to `modelDir`; bodies without a mesh are exported
  /// as a vertex at the com.
  /// @throws sim::Error when a body mesh cannot be read, std::runtime_error when `outDir` is not writable.
  VtkSeriesWriter(const sim::Model& model, const std::string& modelDir, const std::string& outDir,
                  const std::string& baseName, Staging staging = Staging::Direct);
  ~VtkSeriesWriter();
  VtkSeriesWriter(const VtkSeriesWriter&) = delete;
  VtkSeriesWriter& operator=(const VtkSeriesWriter&) = delete;

  /// Writes the seven parts of one frame at `state.time`.
  void writeFrame(const sim::State& state, const sim::Metrics& metrics);
  /// Renames the frames' folder to `outDir`/`baseName` (replacing an earlier series there; a folder that
  /// holds anything but series frames is refused) and writes the .pvd collection of all frames written so
  /// far; returns its file name ("<baseName>.pvd"). @throws std::runtime_error naming the folder or file.
  std::string finish();
  /// The bytes one frame of `state` takes on disk, its seven parts encoded as writeFrame() writes them,
  /// without writing anything: a series' size before it is written (its frames differ by a few per cent).
  static std::size_t frameBytes(const sim::Model& model, const std::string& modelDir, const sim::State& state,
                                const sim::Metrics& metrics);
  /// Number of frames written.
  int frameCount() const;
  /// Bytes written so far (the frames' files).
  std::size_t bytesWritten() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

}  // namespace pneuma::viz
