#include "pneuma/sim/PosedGeometry.h"

#include <cmath>

namespace pneuma::sim {

void poseGeometry(const Model& model, const State& state, PosedGeometry& out) {
  // bones: rigid transforms body -> world
  const int nb = model.bodies.size();
  out.body.resize(static_cast<std::size_t>(nb));
  for (int b = 0; b < nb; ++b) {
    Eigen::Isometry3d& T = out.body[static_cast<std::size_t>(b)];
    T.setIdentity();
    T.linear() = state.bodyOrientation[static_cast<std::size_t>(b)].toRotationMatrix();
    T.translation() = state.bodyPosition.col(b);
  }

  // anchored points
  anchorPositions(model.elements.endA, state, out.elementA);
  anchorPositions(model.elements.endB, state, out.elementB);
  out.gut = state.nodePosition;
  anchorPositions(model.cavity.vertices, state, out.cavity);
  lungPositions(model.lungs.right, out.cavity, out.lungRight);
  lungPositions(model.lungs.left, out.cavity, out.lungLeft);
  anchorPositions(model.landmarks.points, state, out.landmarks);

  // skin: through its anchors
  Eigen::Matrix3Xd anchors;
  anchorPositions(model.skin.anchors, state, anchors);
  skinPositions(model.skin, anchors, out.skin);
}

State magnifyMotion(const State& reference, const State& state, double factor) {
  State out = state;
  if (factor == 1.0) return out;
  out.bodyPosition = reference.bodyPosition + factor * (state.bodyPosition - reference.bodyPosition);
  out.nodePosition = reference.nodePosition + factor * (state.nodePosition - reference.nodePosition);
  for (std::size_t b = 0; b < state.bodyOrientation.size(); ++b) {
    // the rotation from the reference as an angle about an axis, the angle scaled
    const Eigen::AngleAxisd turn(state.bodyOrientation[b] * reference.bodyOrientation[b].conjugate());
    const double angle = turn.angle() > M_PI ? turn.angle() - 2.0 * M_PI : turn.angle();
    out.bodyOrientation[b] =
        (Eigen::Quaterniond(Eigen::AngleAxisd(factor * angle, turn.axis())) * reference.bodyOrientation[b])
            .normalized();
  }
  return out;
}

}  // namespace pneuma::sim
