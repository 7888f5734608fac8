#pragma once
/// @file Activation.h
/// Per-group control input of the muscle law (Zordan et al. 2004, Eq. 2 and Section 7):
///   F = min[-alpha kac (l - r l0) - kpe (l - l0) - b dl/dt, 0].

#include <array>

#include "pneuma/sim/Model.h"

namespace pneuma::sim {

/// Control input of one element group (Eq. 2).
struct GroupActivation {
  double r = 1.0;      ///< [-] contraction ratio: the active rest length is r * l0; valid range (0, 1.5]
  double alpha = 0.0;  ///< [-] activation level in [0, 1]
};

/// One GroupActivation per ElementGroup, indexed by static_cast<int>(ElementGroup). The Cartilage
/// entry is ignored (structural springs are passive).
using Activations = std::array<GroupActivation, kElementGroupCount>;

/// Relaxed activations: r = 1, alpha = 0 for every group.
Activations relaxedActivations();

/// Checks every group's r in (0, 1.5] and alpha in [0, 1] (finite).
/// @throws Error naming the group and the value, e.g. "activations.diaphragm.r: must be in (0, 1.5], got 0".
void validateActivations(const Activations& a);

}  // namespace pneuma::sim
