#include "pneuma/sim/State.h"

namespace pneuma::sim {

State makeInitialState(const Model& model) {
  State s;
  const int nb = model.bodies.size();
  const int nn = model.nodes.size();
  s.bodyPosition = model.bodies.com;
  s.bodyOrientation.assign(static_cast<std::size_t>(nb), Eigen::Quaterniond::Identity());
  s.bodyVelocity = Eigen::Matrix3Xd::Zero(3, nb);
  s.bodyAngularVelocity = Eigen::Matrix3Xd::Zero(3, nb);
  s.nodePosition = model.nodes.rest;
  s.nodeVelocity = Eigen::Matrix3Xd::Zero(3, nn);
  return s;
}

void anchorPositions(const AnchorSet& anchors, const State& state, Eigen::Matrix3Xd& out) {
  const int n = anchors.size();
  out.resize(3, n);
  for (int i = 0; i < n; ++i) {
    const int b = anchors.body[static_cast<std::size_t>(i)];
    if (b >= 0) {
      out.col(i) = state.bodyPosition.col(b) +
                   state.bodyOrientation[static_cast<std::size_t>(b)] * anchors.local.col(i);
    } else {
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      for (int k = 0; k < 3; ++k) {
        const int nd = anchors.nodes(k, i);
        if (nd >= 0) p += anchors.weights(k, i) * state.nodePosition.col(nd);
      }
      out.col(i) = p;
    }
  }
}

}  // namespace pneuma::sim
