#pragma once
/// @file Sweep.h
/// Generalised tubes: an elliptical cross-section swept along a centreline. Ribs, sternum, vertebral
/// bodies and the pelvis are built from them.

#include <Eigen/Core>
#include <vector>

#include "pneuma/meshing/TriangleMesh.h"

namespace pneuma::meshing {

/// One cross-section of a swept tube.
struct SweepStation {
  Eigen::Vector3d centre{0, 0, 0};  ///< [m] centreline point
  Eigen::Vector3d up{0, 0, 1};  ///< direction of the cross-section's height axis (made normal to the tangent)
  double halfHeight = 0.0;      ///< [m] semi-axis along `up`
  double halfWidth = 0.0;       ///< [m] semi-axis along tangent x up
};

/// Sweeps ellipses through `stations` (at least 2; 3 for a loop) with `around` points each.
/// Open tubes are closed by a fan cap at both ends; a loop (`isLoop`) joins its last station to its
/// first (a torus). The result is closed and oriented outward.
TriangleMesh sweepTube(const std::vector<SweepStation>& stations, int around, bool isLoop);

}  // namespace pneuma::meshing
