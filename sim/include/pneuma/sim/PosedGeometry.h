#pragma once
/// @file PosedGeometry.h
/// The one function that poses a model's geometry for a state. Every consumer of the posed model (the 3D view
/// app/viz/ModelScene, the ParaView series app/viz/VtkSeriesWriter, the exporters) draws what it returns, so
/// they cannot disagree. Posing is an output-time job: the step never calls it.

#include <Eigen/Geometry>
#include <vector>

#include "pneuma/sim/Model.h"
#include "pneuma/sim/State.h"

namespace pneuma::sim {

/// Everything of a Model placed in the world for one State [m].
struct PosedGeometry {
  std::vector<Eigen::Isometry3d> body;  ///< body frame -> world, x = R_b p + x_b                 (#B)
  Eigen::Matrix3Xd elementA;            ///< [m] first endpoints of the elements                 (3 x #E)
  Eigen::Matrix3Xd elementB;            ///< [m] second endpoints                                (3 x #E)
  Eigen::Matrix3Xd gut;                 ///< [m] gut nodes (State::nodePosition)                 (3 x #N)
  Eigen::Matrix3Xd cavity;              ///< [m] lung-cavity vertices (Cavity::vertices)          (3 x #C)
  Eigen::Matrix3Xd lungRight;           ///< [m] right lung vertices (lungPositions())           (3 x #VR)
  Eigen::Matrix3Xd lungLeft;            ///< [m] left lung vertices                              (3 x #VL)
  Eigen::Matrix3Xd landmarks;           ///< [m] named landmarks (Landmarks::points)             (3 x #L)
  Eigen::Matrix3Xd skin;  ///< [m] skin vertices (skinPositions()); empty without a skin (3 x #V)
};

/// Poses `model` for `state` into `out` (every member resized): bones by their rigid transforms, anchored
/// points through anchorPositions(), the lungs through their cavity embedding (lungPositions()) and the skin
/// through its anchors (skinPositions()).
void poseGeometry(const Model& model, const State& state, PosedGeometry& out);

}  // namespace pneuma::sim
