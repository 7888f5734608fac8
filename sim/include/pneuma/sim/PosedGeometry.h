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

/// `state` with its motion from `reference` magnified `factor` times, for display (motion magnification: a
/// calm breath moves the chest wall a few millimetres; at 5x a lecture hall sees it). Pose the result with
/// poseGeometry(), so that every part stays attached as the model attaches it. With k = factor:
///   gut nodes and body centres  x = x_ref + k (x - x_ref);
///   body orientations           q = exp(k log(q q_ref^-1)) q_ref  (the rotation from the reference, k times
///                                                                   the angle about the same axis).
/// To first order in the motion every posed point (anchors, lungs, skin) then moves k times as far from its
/// reference position as in `state`. Velocities and time are `state`'s. factor 1 returns `state`.
State magnifyMotion(const State& reference, const State& state, double factor);

}  // namespace pneuma::sim
