#pragma once
/// @file Anchors.h
/// Points bound to a rigid body or to gut nodes, as the builder collects them in world coordinates
/// before converting them to sim::AnchorSet entries.

#include "pneuma/sim/Model.h"

namespace pneuma::meshing {

/// A world point [m] bound to body `body` (>= 0) or to up to three gut nodes with barycentric weights.
struct Endpoint {
  int body = -1;
  Eigen::Vector3d world{0, 0, 0};
  Eigen::Vector3i nodes{-1, -1, -1};
  Eigen::Vector3d weights{0, 0, 0};

  static Endpoint onBody(int b, const Eigen::Vector3d& p) { return {b, p, {-1, -1, -1}, {0, 0, 0}}; }
  static Endpoint atNode(int n, const Eigen::Matrix3Xd& rest) {
    return {-1, rest.col(n), {n, -1, -1}, {1, 0, 0}};
  }
};

/// Appends `e` to `set`; body points are stored in the body frame (world - com, axes world-parallel at rest).
inline void addEndpoint(sim::AnchorSet& set, const Endpoint& e, const sim::Bodies& bodies) {
  if (e.body >= 0) {
    set.addBodyPoint(e.body, e.world - bodies.com.col(e.body));
  } else {
    set.addNodePoint(e.nodes, e.weights);
  }
}

}  // namespace pneuma::meshing
