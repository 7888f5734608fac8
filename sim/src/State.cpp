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
  out.resize(3, anchors.size());
  for (int i = 0; i < anchors.size(); ++i) out.col(i) = anchorPosition(anchors, i, state);
}

void lungPositions(const LungSurface& lung, const Eigen::Matrix3Xd& cavity, Eigen::Matrix3Xd& out) {
  out.setZero(3, lung.vertexCount());
  for (int i = 0; i < lung.vertexCount(); ++i)
    for (int k = 0; k < kLungVertexSlots; ++k)
      if (lung.cavityVertex(k, i) >= 0)
        out.col(i) += lung.weights(k, i) * cavity.col(lung.cavityVertex(k, i));
}

void skinPositions(const Skin& skin, const Eigen::Matrix3Xd& anchors, Eigen::Matrix3Xd& out) {
  out = skin.offset;
  for (int i = 0; i < skin.vertexCount(); ++i)
    for (int k = 0; k < kSkinVertexSlots; ++k)
      if (skin.anchor(k, i) >= 0) out.col(i) += skin.weights(k, i) * anchors.col(skin.anchor(k, i));
}

}  // namespace pneuma::sim
