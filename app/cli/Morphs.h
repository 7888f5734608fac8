#pragma once
/// @file Morphs.h
/// What `bake`, `play` and `simulate --gltf` share: the morph targets of a model (baked, or read back from a
/// baked .glb), and the checks of a glTF export.

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

}  // namespace pneuma::app
