#pragma once
// Internal to the step (sim/src/Step*.cpp and Metrics.cpp, not installed): the helpers the stages share and
// the stage entry points that step() calls. The public interface is pneuma/sim/Step.h; the pipeline is
// described in docs/integrator.md.

#include <Eigen/Geometry>
#include <cstddef>
#include <vector>

#include "pneuma/sim/Elements.h"
#include "pneuma/sim/Step.h"

namespace pneuma::sim::detail {

using Eigen::Matrix3d;
using Eigen::Vector3d;

inline std::size_t at(int i) { return static_cast<std::size_t>(i); }

inline Matrix3d skew(const Vector3d& v) {
  Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// [1/s] beta of the visceral drag
inline double effectiveDrag(const Model& model, const StepOptions& o) {
  return model.gut.drag * o.gutDragScale;
}

// muscle parameters of element e under the group's activation (above its recruitment threshold, if any) and
// gain scales (and its half's, for the diaphragm)
inline MuscleParams muscleParams(const Model& model, const StepConstants& c, int e, const Activations& act,
                                 const StepOptions& o) {
  const int g = static_cast<int>(model.elements.group[at(e)]);
  const GroupActivation& ga = act[at(g)];
  MuscleParams p;
  p.restLength = effectiveRestLength(model, e, o);
  p.kac = model.elements.kac(e) * o.activeGainScale[at(g)] * hemidiaphragmScale(model, c, e, o);
  p.kpe = model.elements.kpe(e) * o.passiveGainScale[at(g)];
  p.damping = model.elements.damping(e) * o.passiveGainScale[at(g)];
  // an accessory muscle takes the part of its group's drive above its recruitment threshold
  const double c0 = model.elements.recruitmentOf(e);
  p.alpha = c0 > 0.0 ? recruitedActivation(ga.alpha, ga.r, c0) : ga.alpha;
  p.r = ga.r;
  return p;
}

// offset of node n's entries in the implicit solver's vectors u = [v_b, w_b]_b ++ [v_n]_n
inline Eigen::Index nodeOffset(const Model& m, int n) {
  return 6 * static_cast<Eigen::Index>(m.bodies.size()) + 3 * n;
}

// zero the entries of fixed bodies and nodes
inline void maskFixed(const StepWork& w, Eigen::VectorXd& x) {
  for (Eigen::Index i = 0; i < w.constants.fixedDofs.size(); ++i) x(w.constants.fixedDofs(i)) = 0.0;
}

// zero what is not a coordinate of the joint tree: fixed entries and the linear velocities of jointed bodies
inline void maskReduced(const Joints& joints, const StepWork& w, const std::vector<int>& tree,
                        Eigen::VectorXd& x) {
  maskFixed(w, x);
  for (int j : tree) x.segment<3>(6 * joints.child[at(j)]).setZero();
}

// u <- J u: the linear velocity of each body hanging on a tree joint follows from its parent's motion and
// its own spin, so the anchor points move together: v_c = v_p + w_p x r_p - w_c x r_c (parents first)
template <typename Vec>
void expandJointVelocities(const Joints& joints, const StepWork& w, const std::vector<int>& tree, Vec&& u) {
  for (int j : tree) {
    const int p = joints.parent[at(j)], c = joints.child[at(j)];
    u.template segment<3>(6 * c) = u.template segment<3>(6 * p) +
                                   u.template segment<3>(6 * p + 3).cross(w.scratch.treeLeverParent.col(j)) -
                                   u.template segment<3>(6 * c + 3).cross(w.scratch.treeLeverChild.col(j));
  }
}

// f <- J^T f: a force on a dependent linear velocity acts on the parent's com and, through the levers,
// as torques r_p x f on the parent and -r_c x f on the child (children first)
template <typename Vec>
void gatherJointForces(const Joints& joints, const StepWork& w, const std::vector<int>& tree, Vec&& f) {
  for (auto it = tree.rbegin(); it != tree.rend(); ++it) {
    const int j = *it, p = joints.parent[at(j)], c = joints.child[at(j)];
    const Vector3d fc = f.template segment<3>(6 * c);
    if (fc.isZero(0.0)) continue;  // columns of the assembled system are sparse
    f.template segment<3>(6 * p) += fc;
    f.template segment<3>(6 * p + 3) += w.scratch.treeLeverParent.col(j).cross(fc);
    f.template segment<3>(6 * c + 3) -= w.scratch.treeLeverChild.col(j).cross(fc);
    f.template segment<3>(6 * c).setZero();
  }
}

// rotation vector [rad] of the child relative to the parent, world frame (zero at rest)
inline Vector3d jointRotation(const State& s, int parent, int child) {
  const Eigen::Quaterniond rel = s.bodyOrientation[at(parent)].conjugate() * s.bodyOrientation[at(child)];
  const Eigen::AngleAxisd aa(rel.w() < 0.0 ? Eigen::Quaterniond(-rel.coeffs()) : rel);
  return s.bodyOrientation[at(parent)] * (aa.angle() * aa.axis());
}

// [N m/rad] joint i's rotational stiffness K = k I + k_lock (I - a a^T), a = R_parent axis (world; Joints)
inline Matrix3d jointStiffness(const Joints& j, int i, const Matrix3d& parentRotation) {
  const Vector3d a = parentRotation * j.axis.col(i);
  return j.stiffness(i) * Matrix3d::Identity() +
         j.lockStiffness(i) * (Matrix3d::Identity() - a * a.transpose());
}

// rotates body b by the small rotation vector dtheta [rad] (world frame)
inline void rotateBody(State& s, int b, const Vector3d& dtheta) {
  Eigen::Quaterniond& q = s.bodyOrientation[at(b)];
  const Eigen::Quaterniond dq(0.0, dtheta.x(), dtheta.y(), dtheta.z());
  q.coeffs() += 0.5 * (dq * q).coeffs();
  q.normalize();
}

// ---- stage entry points

// rotation matrices and world inverse inertias of all bodies (StepForces.cpp)
void updateBodyFrames(const Model& model, const State& s, StepWork& w);

// the free coordinates of the implicit solve and the pattern of its matrix, once per model (StepImplicit.cpp)
void analyzeSystem(const Model& model, StepWork& w);

// the tree joints' anchor levers (world, from the body frames) that J and J^T use (StepImplicit.cpp)
void updateTreeLevers(const Model& model, StepWork& w);

// out = K u, the stiffness the implicit step linearises the forces with (elements with their geometric part,
// the gut's rank-one pressure stiffness, the pleural one, joint springs), at the forces computeForces() left
// in w, in full coordinates u = [dx_b, dtheta_b]_b ++ [dx_n]_n (StepImplicit.cpp; for the stiffness tests)
void stiffnessProduct(const Model& model, const StepOptions& o, StepWork& w, const Eigen::VectorXd& u,
                      Eigen::VectorXd& out);

// the matrix the preconditioner factors, J^T (M + dt D + dt^2 K) J over the free coordinates without the
// gut's and the pleural rank-one terms, dense (StepImplicit.cpp; for the stiffness tests)
Eigen::MatrixXd assembledSystem(const Model& model, const StepOptions& o, StepWork& w, double dt);

// linearly implicit Euler of the velocities in the joint tree's coordinates (StepImplicit.cpp)
void implicitVelocityUpdate(const Model& model, State& s, double dt, const StepOptions& o, StepWork& w);

// sequential impulses on the joints' relative velocities (StepJoints.cpp)
void solveJointVelocities(const Model& model, State& s, const StepOptions& o, StepWork& w);

// mass-weighted projection of the joint positions (StepJoints.cpp)
void projectJointPositions(const Model& model, State& s, const StepOptions& o, StepWork& w);

}  // namespace pneuma::sim::detail
