// Stage 3 of step(), ball joints: sequential impulses on the relative velocity at every joint, then the
// mass-weighted projection of the positions (docs/integrator.md).
#include <Eigen/LU>
#include <algorithm>
#include <tuple>
#include <utility>

#include "StepInternal.h"

namespace pneuma::sim::detail {

namespace {

// inverse of the 3x3 effective mass of a point constraint between bodies p and c at levers rp, rc
Matrix3d jointEffectiveMassInverse(const Model& model, const StepWork& w, int p, int c, const Vector3d& rp,
                                   const Vector3d& rc) {
  Matrix3d k = Matrix3d::Zero();
  for (const auto& [b, r] : {std::pair<int, Vector3d>{p, rp}, std::pair<int, Vector3d>{c, rc}}) {
    if (model.bodies.isFixed[at(b)]) continue;
    const Matrix3d rx = skew(r);
    k += Matrix3d::Identity() / model.bodies.mass(b) - rx * w.scratch.inverseInertiaWorld[at(b)] * rx;
  }
  return k.inverse();
}

// inverse effective mass of every joint at the current pose, into w.scratch.jointMassInverse
void updateJointMasses(const Model& model, StepWork& w) {
  const Joints& j = model.joints;
  for (int i = 0; i < j.size(); ++i) {
    const int p = j.parent[at(i)], c = j.child[at(i)];
    w.scratch.jointMassInverse[at(i)] = jointEffectiveMassInverse(
        model, w, p, c, w.scratch.rotation[at(p)] * w.constants.jointLocalParent.col(i),
        w.scratch.rotation[at(c)] * w.constants.jointLocalChild.col(i));
  }
}

// [m/s] relative velocity of joint i's two anchor points (child minus parent)
Vector3d jointVelocityError(const Model& model, const State& s, const StepWork& w, int i, Vector3d& rp,
                            Vector3d& rc) {
  const int p = model.joints.parent[at(i)], c = model.joints.child[at(i)];
  rp = w.scratch.rotation[at(p)] * w.constants.jointLocalParent.col(i);
  rc = w.scratch.rotation[at(c)] * w.constants.jointLocalChild.col(i);
  return (s.bodyVelocity.col(c) + s.bodyAngularVelocity.col(c).cross(rc)) -
         (s.bodyVelocity.col(p) + s.bodyAngularVelocity.col(p).cross(rp));
}

}  // namespace

// sequential impulses: the relative velocity of the two anchor points of every joint goes to zero; nothing to
// do when they already move together to kJointVelocityTolerance (the usual case: the implicit step solves the
// tree joints, and the last step left every joint so)
void solveJointVelocities(const Model& model, State& s, const StepOptions& o, StepWork& w) {
  constexpr double kJointVelocityTolerance = 1e-5;  // [m/s] 0.17 um of separation over a 1/60 s step
  const Joints& j = model.joints;
  Vector3d rp, rc;
  double worst = 0.0;
  for (int i = 0; i < j.size(); ++i)
    worst = std::max(worst, jointVelocityError(model, s, w, i, rp, rc).norm());
  if (worst <= kJointVelocityTolerance) return;
  updateJointMasses(model, w);
  const int iterations = std::max(1, o.jointIterations / 3);
  for (int it = 0; it < iterations && worst > kJointVelocityTolerance; ++it) {
    worst = 0.0;
    for (int i = 0; i < j.size(); ++i) {
      const int p = j.parent[at(i)], c = j.child[at(i)];
      const Vector3d vrel = jointVelocityError(model, s, w, i, rp, rc);
      worst = std::max(worst, vrel.norm());
      const Vector3d impulse = -w.scratch.jointMassInverse[at(i)] * vrel;
      if (!model.bodies.isFixed[at(c)]) {
        s.bodyVelocity.col(c) += impulse / model.bodies.mass(c);
        s.bodyAngularVelocity.col(c) += w.scratch.inverseInertiaWorld[at(c)] * rc.cross(impulse);
      }
      if (!model.bodies.isFixed[at(p)]) {
        s.bodyVelocity.col(p) -= impulse / model.bodies.mass(p);
        s.bodyAngularVelocity.col(p) -= w.scratch.inverseInertiaWorld[at(p)] * rp.cross(impulse);
      }
    }
  }
}

// mass-weighted position projection until every joint error is below the tolerance (velocities kept);
// the effective masses are those of the pose before the first correction
void projectJointPositions(const Model& model, State& s, const StepOptions& o, StepWork& w) {
  const Joints& j = model.joints;
  w.outputs.maxJointError = 0.0;
  bool massesCurrent = false;
  for (int it = 0; it < o.jointIterations; ++it) {
    double worst = 0.0;
    for (int i = 0; i < j.size(); ++i) {
      const int p = j.parent[at(i)], c = j.child[at(i)];
      const Vector3d rp = w.scratch.rotation[at(p)] * w.constants.jointLocalParent.col(i);
      const Vector3d rc = w.scratch.rotation[at(c)] * w.constants.jointLocalChild.col(i);
      const Vector3d err = (s.bodyPosition.col(c) + rc) - (s.bodyPosition.col(p) + rp);
      const double e = err.norm();
      worst = std::max(worst, e);
      if (e < 0.1 * o.jointTolerance) continue;
      if (!massesCurrent) updateJointMasses(model, w);
      massesCurrent = true;
      const Vector3d impulse = -w.scratch.jointMassInverse[at(i)] * err;
      for (const auto& [b, r, sign] : {std::tuple<int, Vector3d, double>{c, rc, 1.0}, {p, rp, -1.0}}) {
        if (model.bodies.isFixed[at(b)]) continue;
        s.bodyPosition.col(b) += (sign / model.bodies.mass(b)) * impulse;
        rotateBody(s, b, sign * (w.scratch.inverseInertiaWorld[at(b)] * r.cross(impulse)));
        w.scratch.rotation[at(b)] = s.bodyOrientation[at(b)].toRotationMatrix();
      }
    }
    w.outputs.maxJointError = worst;
    if (worst < o.jointTolerance) break;
  }
  // refresh the world inertias for the next stage
  updateBodyFrames(model, s, w);
}

}  // namespace pneuma::sim::detail
