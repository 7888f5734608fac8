#pragma once
/// @file VtkSeriesWriter.h
/// Export of a running simulation as a ParaView time series: one .pvd collection that lists, per frame,
/// six .vtp parts (VTK XML polydata, SI units), all posed by sim::poseGeometry():
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
/// Every file is written to a temporary name and renamed; the .pvd is written by finish().

#include <memory>
#include <string>

#include "pneuma/sim/Metrics.h"
#include "pneuma/sim/Model.h"
#include "pneuma/sim/State.h"

namespace pneuma::viz {

class VtkSeriesWriter {
 public:
  /// Frames go to `outDir`/`baseName`/, the collection to `outDir`/`baseName`.pvd.
  /// Body meshes are read relative to `modelDir`; bodies without a mesh are exported as a vertex at the com.
  /// @throws sim::Error when a body mesh cannot be read, std::runtime_error when `outDir` is not writable.
  VtkSeriesWriter(const sim::Model& model, const std::string& modelDir, const std::string& outDir,
                  const std::string& baseName);
  ~VtkSeriesWriter();
  VtkSeriesWriter(const VtkSeriesWriter&) = delete;
  VtkSeriesWriter& operator=(const VtkSeriesWriter&) = delete;

  /// Writes the six parts of one frame at `state.time`.
  void writeFrame(const sim::State& state, const sim::Metrics& metrics);
  /// Writes the .pvd collection of all frames written so far; returns its file name ("<baseName>.pvd").
  std::string finish();
  /// Number of frames written.
  int frameCount() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

}  // namespace pneuma::viz
