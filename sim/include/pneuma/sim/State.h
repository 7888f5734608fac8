#pragma once
/// @file State.h
/// The mutable simulation state (MuJoCo's mjData to Model's mjModel): everything that changes while
/// Pneuma steps. A State is only meaningful together with the Model it was made for.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "pneuma/sim/Model.h"

namespace pneuma::sim {

/// Positions and velocities of every rigid body and gut node at one instant.
/// Fixed bodies and fixed nodes keep their rest pose and zero velocity.
struct State {
  double time = 0.0;                                ///< [s] simulated time since the start of the run
  Eigen::Matrix3Xd bodyPosition;                    ///< [m] centre of mass, world                 (3 x #B)
  std::vector<Eigen::Quaterniond> bodyOrientation;  ///< [-] unit quaternion, body -> world  (#B)
  Eigen::Matrix3Xd bodyVelocity;                    ///< [m/s] linear velocity of the com, world   (3 x #B)
  Eigen::Matrix3Xd bodyAngularVelocity;             ///< [rad/s] angular velocity, world frame     (3 x #B)
  Eigen::Matrix3Xd nodePosition;                    ///< [m] gut node positions, world             (3 x #N)
  Eigen::Matrix3Xd nodeVelocity;                    ///< [m/s] gut node velocities, world          (3 x #N)
  long long steps = 0;                              ///< [-] number of steps taken since the start
};

/// The rest pose of `model` at t = 0: bodies at their com with identity orientation, nodes at rest,
/// all velocities zero.
State makeInitialState(const Model& model);

/// World position [m] of point `i` of `anchors` in `state`.
/// Body points: x_b + R_b * local; node points: sum_k w_k * x_{n_k}.
inline Eigen::Vector3d anchorPosition(const AnchorSet& anchors, int i, const State& state) {
  const int b = anchors.body[static_cast<std::size_t>(i)];
  if (b >= 0)
    return state.bodyPosition.col(b) +
           state.bodyOrientation[static_cast<std::size_t>(b)] * anchors.local.col(i);
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (int k = 0; k < 3; ++k)
    if (anchors.nodes(k, i) >= 0) p += anchors.weights(k, i) * state.nodePosition.col(anchors.nodes(k, i));
  return p;
}

/// World position [m] of every point of `anchors` in `state` (anchorPosition()), written into `out` (3 x #P,
/// resized).
void anchorPositions(const AnchorSet& anchors, const State& state, Eigen::Matrix3Xd& out);

/// World positions [m] of the vertices of `lung` (LungSurface: x_v = sum_k w_k c_{i_k}) from the posed cavity
/// vertices `cavity` (3 x #C, anchorPositions() of Cavity::vertices), written into `out` (3 x #V, resized).
void lungPositions(const LungSurface& lung, const Eigen::Matrix3Xd& cavity, Eigen::Matrix3Xd& out);

/// World positions [m] of the skin vertices (Skin: x_v = c_v + sum_k w_vk a_{i_vk}) from the posed skin
/// anchors `anchors` (3 x #A, anchorPositions() of Skin::anchors), written into `out` (3 x #V, resized).
void skinPositions(const Skin& skin, const Eigen::Matrix3Xd& anchors, Eigen::Matrix3Xd& out);

}  // namespace pneuma::sim
