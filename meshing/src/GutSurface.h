#pragma once
/// @file GutSurface.h
/// The sealed gut surface of Section 6: a stack of node rings from the pelvic floor to the costal
/// margin (the abdominal wall), closed below by a fixed floor cap and above by the diaphragm dome. The back
/// of the wall and the posterior arc of the dome's rim (the crura on the lumbar spine and the arcuate
/// ligaments, Gray's Anatomy) are fixed, as the lumbar spine they insert on is.

#include <vector>

#include "Skeleton.h"
#include "pneuma/sim/Model.h"

namespace pneuma::meshing {

/// Gut nodes and their ring structure. Ring node j sits at angle 2 pi j / n around the vertical axis,
/// j = 0 on the anterior midline, increasing toward the right side.
struct GutSurface {
  Eigen::Matrix3Xd rest;                ///< [m] node rest positions (3 x #N)
  std::vector<sim::NodeRegion> region;  ///< (#N)
  Eigen::Matrix3Xi triangles;           ///< outward (3 x #F)
  std::vector<std::vector<int>>
      wallRing;  ///< node indices of the wall rings, floor (0) to just below the rim
  std::vector<std::vector<int>> domeRing;  ///< node indices of the dome rings, rim (0) to the innermost ring
  /// [m] rise of each dome ring above the costal margin's mean level, h_dome (1 - s^2) at radius fraction s
  /// (the dome's profile, buildGut()); 0 for the rim (#domeRing)
  std::vector<double> domeRingRise;
  int apex = -1;  ///< the dome's apex node
};

/// Builds the gut surface of `a` fitted to the skeleton `sk`.
GutSurface buildGut(const AnatomyParams& a, const Skeleton& sk);

}  // namespace pneuma::meshing
