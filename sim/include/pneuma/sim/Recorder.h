#pragma once
/// @file Recorder.h
/// Compact in-memory recording of states at the output rate, with random access, for timeline
/// scrubbing: what the views show of a frame (poses, element forces, lung volume, gut volume error and
/// pressure), stored as it was measured, so that a restored frame shows what the run showed then. Poses and
/// forces are stored as float (half the memory of double, ample for display); a bounded capacity keeps the
/// most recent frames. Resuming a run is Simulation::checkpoint() / save(), not this.

#include <cstddef>
#include <deque>
#include <vector>

#include "pneuma/sim/Metrics.h"
#include "pneuma/sim/State.h"

namespace pneuma::sim {

/// One recorded output frame.
struct RecordedFrame {
  double time = 0.0;                ///< [s]
  std::vector<float> bodyPose;      ///< per body: x, y, z [m], then qw, qx, qy, qz [-]   (7 #B)
  std::vector<float> nodePosition;  ///< [m] per node x, y, z                             (3 #N)
  std::vector<float> elementForce;  ///< [N] signed scalar force per element              (#E)
  double lungVolume = 0.0;          ///< [m^3]
  double gutVolumeError = 0.0;      ///< [-]
  double gutPressure = 0.0;         ///< [Pa] Metrics::gutPressure, with the kappa of the run at that frame
  Activations activations{};        ///< r and alpha per group (Metrics::activations)
};

class Recorder {
 public:
  /// @param capacity maximum number of frames kept (oldest dropped first); 0 = unlimited.
  explicit Recorder(std::size_t capacity = 0) : m_capacity(capacity) {}

  /// Appends a frame made from `state` and `metrics`.
  void record(const State& state, const Metrics& metrics);
  /// Number of frames held.
  std::size_t size() const { return m_frames.size(); }
  bool empty() const { return m_frames.empty(); }
  /// Frame `i`, 0 = oldest held.
  const RecordedFrame& frame(std::size_t i) const { return m_frames.at(i); }
  /// Index of the frame nearest to `time` [s]; 0 when empty.
  std::size_t indexAt(double time) const;
  /// Writes frame `i`'s positions and orientations into `state` (resized to match), with zero
  /// velocities and state.time = frame time; poses at float precision, for display (an exact restart is
  /// Simulation::checkpoint()).
  void restore(std::size_t i, State& state) const;
  /// As restore(i, state), and sets the recorded fields of `metrics` to the frame's: time, lungVolume,
  /// gutVolumeError, gutPressure, activations and elementForce (others are left as they are; isSlack is
  /// cleared).
  void restore(std::size_t i, State& state, Metrics& metrics) const;
  void clear() { m_frames.clear(); }
  std::size_t capacity() const { return m_capacity; }
  /// Changes the capacity (0 = unlimited), dropping the oldest frames beyond it.
  void setCapacity(std::size_t capacity);

 private:
  std::size_t m_capacity;
  std::deque<RecordedFrame> m_frames;
};

}  // namespace pneuma::sim
