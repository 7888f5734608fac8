#pragma once
/// @file Morphs.h
/// What `bake`, `play` and `simulate --gltf` share: the morph targets of a model (baked, or read back from a
/// baked .glb), the check of a glTF output path, and a run's blend error.

#include <memory>
#include <string>

#include "pneuma/sim/Model.h"
#include "pneuma/sim/MorphTargets.h"

namespace pneuma::app {

/// The morph targets of `model`: read from `morphsFile` (a .glb written by `pneuma-cli bake`) when given,
/// else baked now with one progress line per run on stderr. Fails with kExitBadInput (a model without a
/// skin, an unreadable or mismatched file) or kExitFailed (a run that fails).
sim::MorphTargets morphTargetsFor(const std::shared_ptr<const sim::Model>& model,
                                  const std::string& morphsFile);

/// Fails with kExitBadInput and "<flag>: cannot write <path>: <reason>" unless a file can be created at
/// `path` (its folder exists and is writable; the probe is removed again). Run before any work.
void checkGltfOutput(const char* flag, const std::string& path);

/// Fails with kExitBadInput when `model` has no skin ("<flag>: model '<name>' has no skin ...").
void checkHasSkin(const char* flag, const sim::Model& model);

/// The blend error over the frames of a run: RMS over every vertex of every frame, maximum over all [m].
class BlendErrorSum {
 public:
  void add(const sim::BlendError& frame) {
    m_squares += frame.rms * frame.rms;
    m_max = frame.max > m_max ? frame.max : m_max;
    ++m_frames;
  }
  sim::BlendError total() const;
  long long frames() const { return m_frames; }

 private:
  double m_squares = 0.0;  // [m^2] sum over frames of the frame's mean squared distance
  double m_max = 0.0;      // [m]
  long long m_frames = 0;
};

}  // namespace pneuma::app
