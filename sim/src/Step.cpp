#include "pneuma/sim/Step.h"

#include "pneuma/sim/Elements.h"
#include "pneuma/sim/Error.h"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <sstream>

namespace pneuma::sim {

namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

std::size_t at(int i) { return static_cast<std::size_t>(i); }

Matrix3d skew(const Vector3d& v) {
  Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

double effectiveKappa(const Model& model, const StepOptions& o) { return o.kappa >= 0.0 ? o.kappa : model.gut.kappa; }
// [1/s] beta of the visceral drag
double effectiveDrag(const Model& model, const StepOptions& o) { return model.gut.drag * o.gutDragScale; }

// muscle parameters of element e under the group's activation and gain scales
MuscleParams muscleParams(const Model& model, int e, const Activations& act, const StepOptions& o) {
  const int g = static_cast<int>(model.elements.group[at(e)]);
  const GroupActivation& ga = act[at(g)];
  MuscleParams p;
  p.restLength = model.elements.restLength(e);
  p.kac = model.elements.kac(e) * o.activeGainScale[at(g)];
  p.kpe = model.elements.kpe(e) * o.passiveGainScale[at(g)];
  p.damping = model.elements.damping(e) * o.passiveGainScale[at(g)];
  p.alpha = ga.alpha;
  p.r = ga.r;
  return p;
}

// world position, velocity and lever arm (point - com, bodies only) of endpoint `side` of element i
// (w: its classification as a body point, a single node, or weighted nodes)
void anchorKinematics(const AnchorSet& a, int side, int i, const State& s, const StepWork& w, Vector3d& p,
                      Vector3d& v, Vector3d& lever) {
  const int b = w.constants.endpointBody(side, i);
  if (b >= 0) {
    lever = w.scratch.rotation[at(b)] * a.local.col(i);
    p = s.bodyPosition.col(b) + lever;
    v = s.bodyVelocity.col(b) + s.bodyAngularVelocity.col(b).cross(lever);
    return;
  }
  lever.setZero();
  const int n = w.constants.endpointNode(side, i);
  if (n >= 0) {
    p = s.nodePosition.col(n);
    v = s.nodeVelocity.col(n);
    return;
  }
  p.setZero();
  v.setZero();
  for (int k = 0; k < 3; ++k) {
    const int nk = a.nodes(k, i);
    if (nk < 0) continue;
    p += a.weights(k, i) * s.nodePosition.col(nk);
    v += a.weights(k, i) * s.nodeVelocity.col(nk);
  }
}

// adds force f [N] acting at endpoint `side` of element i to the body (force and torque about the com) or to
// its nodes
void applyAnchorForce(const AnchorSet& a, int side, int i, const Vector3d& lever, const Vector3d& f, StepWork& w) {
  const int b = w.constants.endpointBody(side, i);
  if (b >= 0) {
    w.scratch.bodyForce.col(b) += f;
    w.scratch.bodyTorque.col(b) += lever.cross(f);
    return;
  }
  const int n = w.constants.endpointNode(side, i);
  if (n >= 0) {
    w.scratch.nodeForce.col(n) += f;
    return;
  }
  for (int k = 0; k < 3; ++k)
    if (a.nodes(k, i) >= 0) w.scratch.nodeForce.col(a.nodes(k, i)) += a.weights(k, i) * f;
}

// ---- generalized-velocity helpers for the implicit solve: u = [v_b, w_b]_b ++ [v_n]_n ----

Eigen::Index nodeOffset(const Model& m, int n) { return 6 * static_cast<Eigen::Index>(m.bodies.size()) + 3 * n; }

// velocity of a weighted-node endpoint (the rare case of anchorVelocity)
Vector3d weightedNodeVelocity(const Model& m, const AnchorSet& a, int e, const double* x) {
  Vector3d v = Vector3d::Zero();
  for (int k = 0; k < 3; ++k) {
    const int nk = a.nodes(k, e);
    if (nk >= 0) v += a.weights(k, e) * Eigen::Map<const Vector3d>(x + nodeOffset(m, nk));
  }
  return v;
}

// velocity of endpoint `side` (0 = A, 1 = B) of element e under generalized velocity u, using the
// per-element endpoint classification of StepWork (body, single node, or weighted nodes)
inline Vector3d anchorVelocity(const Model& m, const StepWork& w, int side, int e, const Vector3d& lever,
                               const Eigen::VectorXd& u) {
  const double* x = u.data();
  const int b = w.constants.endpointBody(side, e);
  if (b >= 0) return Eigen::Map<const Vector3d>(x + 6 * b) + Eigen::Map<const Vector3d>(x + 6 * b + 3).cross(lever);
  const int n = w.constants.endpointNode(side, e);
  if (n >= 0) return Eigen::Map<const Vector3d>(x + nodeOffset(m, n));
  return weightedNodeVelocity(m, side == 0 ? m.elements.endA : m.elements.endB, e, x);
}

// adds a point force f at a weighted-node endpoint to the generalized force out (the rare case of addAnchorGeneralized)
void addWeightedNodeForce(const Model& m, const AnchorSet& a, int e, const Vector3d& f, double* out) {
  for (int k = 0; k < 3; ++k) {
    const int nk = a.nodes(k, e);
    if (nk >= 0) Eigen::Map<Vector3d>(out + nodeOffset(m, nk)) += a.weights(k, e) * f;
  }
}

// adds the generalized force of a point force f at endpoint `side` of element e to out
inline void addAnchorGeneralized(const Model& m, const StepWork& w, int side, int e, const Vector3d& lever,
                                 const Vector3d& f, Eigen::VectorXd& out) {
  double* x = out.data();
  const int b = w.constants.endpointBody(side, e);
  if (b >= 0) {
    Eigen::Map<Vector3d>(x + 6 * b) += f;
    Eigen::Map<Vector3d>(x + 6 * b + 3) += lever.cross(f);
    return;
  }
  const int n = w.constants.endpointNode(side, e);
  if (n >= 0) {
    Eigen::Map<Vector3d>(x + nodeOffset(m, n)) += f;
    return;
  }
  addWeightedNodeForce(m, side == 0 ? m.elements.endA : m.elements.endB, e, f, x);
}

// zero the entries of fixed bodies and nodes
void maskFixed(const StepWork& w, Eigen::VectorXd& x) {
  for (Eigen::Index i = 0; i < w.constants.fixedDofs.size(); ++i) x(w.constants.fixedDofs(i)) = 0.0;
}

// zero what is not a coordinate of the joint tree: fixed entries and the linear velocities of jointed bodies
void maskReduced(const Joints& joints, const StepWork& w, const std::vector<int>& tree, Eigen::VectorXd& x) {
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

// what the body stiffness blocks need of an element end with lever r and direction d: g = J^T d = [d; r x d]
// and [r]x, for the point Jacobian J = [I, -[r]x]
struct EndJacobian {
  Eigen::Matrix<double, 6, 1> g;
  Matrix3d s;
};
EndJacobian endJacobian(const Vector3d& d, const Vector3d& r) {
  EndJacobian e;
  e.g << d, r.cross(d);
  e.s = skew(r);
  return e;
}

// J_i^T K_e J_j (6 x 6) for the ends i, j and the element stiffness K_e = ka d d^T + kg (I - d d^T):
// (ka - kg) g_i g_j^T + kg J_i^T J_j with J_i^T J_j = [I, -[rj]x; [ri]x, -[ri]x [rj]x]
Eigen::Matrix<double, 6, 6> pointStiffness(double ka, double kg, const EndJacobian& i, const EndJacobian& j) {
  Eigen::Matrix<double, 6, 6> m = (ka - kg) * i.g * j.g.transpose();
  if (kg == 0.0) return m;
  m.block<3, 3>(0, 0).diagonal().array() += kg;
  m.block<3, 3>(0, 3) -= kg * j.s;
  m.block<3, 3>(3, 0) += kg * i.s;
  m.block<3, 3>(3, 3) -= kg * i.s * j.s;
  return m;
}

// ---------------------------------------------------------------------------------------------
// stage 1: forces

// rotation matrices and world inverse inertias of all bodies
void updateBodyFrames(const Model& model, const State& s, StepWork& w) {
  for (int b = 0; b < model.bodies.size(); ++b) {
    w.scratch.rotation[at(b)] = s.bodyOrientation[at(b)].toRotationMatrix();
    const Matrix3d& r = w.scratch.rotation[at(b)];
    w.scratch.inverseInertiaWorld[at(b)] = r * w.constants.inverseInertiaBody[at(b)] * r.transpose();
  }
}

// muscles (Eq. 2) and structural springs, with their linearisation for the implicit solve
void accumulateElementForces(const Model& model, const State& s, const Activations& act, const StepOptions& o,
                             StepWork& w) {
  const Elements& el = model.elements;
  for (int e = 0; e < el.size(); ++e) {
    Vector3d pa, va, ra, pb, vb, rb;
    anchorKinematics(el.endA, 0, e, s, w, pa, va, ra);
    anchorKinematics(el.endB, 1, e, s, w, pb, vb, rb);
    const Vector3d delta = pb - pa;
    const double l = std::max(delta.norm(), 1e-12);
    const Vector3d d = delta / l;
    const double ldot = d.dot(vb - va);
    const MuscleParams p = muscleParams(model, e, act, o);

    double f = 0.0, k = 0.0, b = 0.0;
    if (isMuscleGroup(el.group[at(e)])) {
      f = muscleForce(l, ldot, p);
      if (f < 0.0) {
        k = p.alpha * p.kac + p.kpe;
        b = p.damping;
      }
    } else {
      f = springForce(l, ldot, p.restLength, p.kpe, p.damping);
      k = p.kpe;
      b = p.damping;
    }
    w.outputs.elementForce(e) = f;
    w.outputs.elementLength(e) = l;
    w.scratch.elementDirection.col(e) = d;
    w.scratch.leverA.col(e) = ra;
    w.scratch.leverB.col(e) = rb;
    w.scratch.elementStiffness(e) = k;
    w.scratch.elementDamping(e) = b;
    w.scratch.elementGeometric(e) = std::max(-f, 0.0) / l;
    applyAnchorForce(el.endA, 0, e, ra, -f * d, w);
    applyAnchorForce(el.endB, 1, e, rb, f * d, w);
  }
}

// gut pressure: P = kappa (V0/V - 1) (Eq. 4), force max(0, P) A n / 3 per face and vertex (Eq. 5)
void accumulateGutPressure(const Model& model, const State& s, const StepOptions& o, StepWork& w) {
  if (model.gut.triangles.cols() == 0) return;
  w.outputs.gutVolume = enclosedVolume(s.nodePosition, model.gut.triangles);
  w.outputs.gutPressure =
      gutPressure(effectiveKappa(model, o), w.constants.restGutVolume, w.outputs.gutVolume);
  w.scratch.gutGradient.setZero();
  addVolumeGradient(s.nodePosition, model.gut.triangles, 1.0, w.scratch.gutGradient);
  if (w.outputs.gutPressure > 0.0) w.scratch.nodeForce += w.outputs.gutPressure * w.scratch.gutGradient;
}

// [Pa] pleural pressure Ppl = min(0, -(P0 + (V - Vr) / C)) of Cavity, 0 when it has no compliance
double pleuralPressure(const Cavity& c, double volume, double restVolume) {
  if (!(c.compliance > 0.0)) return 0.0;
  return std::min(0.0, -(c.recoilPressure + (volume - restVolume) / c.compliance));
}

// pleural pressure on the cavity walls, f_i = Ppl dV/dx_i, carried to the bones and gut nodes the vertices are
// bound to; also dV/dq over the implicit solver's entries and the stiffness 1/C it has while Ppl < 0
void accumulatePleuralPressure(const Model& model, const State& s, StepWork& w) {
  const Cavity& c = model.cavity;
  w.scratch.pleuralStiffness = 0.0;
  if (!(c.compliance > 0.0) || c.triangles.cols() == 0) return;
  anchorPositions(c.vertices, s, w.scratch.cavityPosition);
  w.outputs.pleuralPressure =
      pleuralPressure(c, enclosedVolume(w.scratch.cavityPosition, c.triangles), w.constants.restCavityVolume);
  if (w.outputs.pleuralPressure == 0.0) return;
  w.scratch.pleuralStiffness = 1.0 / c.compliance;
  w.scratch.cavityGradient.setZero(3, w.scratch.cavityPosition.cols());
  addVolumeGradient(w.scratch.cavityPosition, c.triangles, 1.0, w.scratch.cavityGradient);
  // dV/dq: a vertex on a body moves with v_b + w_b x r, one on nodes with their weighted velocities
  Eigen::VectorXd& g = w.scratch.cavityGeneralized;
  g.setZero();
  for (int i = 0; i < c.vertices.size(); ++i) {
    const Vector3d gi = w.scratch.cavityGradient.col(i);
    const int b = c.vertices.body[at(i)];
    if (b >= 0) {
      g.segment<3>(6 * b) += gi;
      g.segment<3>(6 * b + 3) += (w.scratch.cavityPosition.col(i) - s.bodyPosition.col(b)).cross(gi);
      continue;
    }
    for (int k = 0; k < 3; ++k)
      if (c.vertices.nodes(k, i) >= 0) g.segment<3>(nodeOffset(model, c.vertices.nodes(k, i))) += c.vertices.weights(k, i) * gi;
  }
  maskFixed(w, g);
  // the force Ppl dV/dq
  for (int b = 0; b < model.bodies.size(); ++b) {
    w.scratch.bodyForce.col(b) += w.outputs.pleuralPressure * g.segment<3>(6 * b);
    w.scratch.bodyTorque.col(b) += w.outputs.pleuralPressure * g.segment<3>(6 * b + 3);
  }
  for (int n = 0; n < model.nodes.size(); ++n)
    w.scratch.nodeForce.col(n) += w.outputs.pleuralPressure * g.segment<3>(nodeOffset(model, n));
}

// rotation vector [rad] of the child relative to the parent, world frame (zero at rest)
Vector3d jointRotation(const State& s, int parent, int child) {
  const Eigen::Quaterniond rel = s.bodyOrientation[at(parent)].conjugate() * s.bodyOrientation[at(child)];
  const Eigen::AngleAxisd aa(rel.w() < 0.0 ? Eigen::Quaterniond(-rel.coeffs()) : rel);
  return s.bodyOrientation[at(parent)] * (aa.angle() * aa.axis());
}

// [N m/rad] joint i's rotational stiffness K = k I + k_lock (I - a a^T), a = R_parent axis (world; Joints)
Matrix3d jointStiffness(const Joints& j, int i, const Matrix3d& parentRotation) {
  const Vector3d a = parentRotation * j.axis.col(i);
  return j.stiffness(i) * Matrix3d::Identity() + j.lockStiffness(i) * (Matrix3d::Identity() - a * a.transpose());
}

// joint friction tau = -mu (w_child - w_parent) (Eq. 3) and passive rotational stiffness tau = -K theta;
// the friction is left out for symplectic Euler, which integrates it implicitly (integrateJointFriction)
void accumulateJointTorques(const Model& model, const State& s, const StepOptions& o, StepWork& w) {
  const Joints& j = model.joints;
  const double frictionScale = o.integrator != IntegratorKind::SymplecticEuler ? o.jointFrictionScale : 0.0;
  for (int i = 0; i < j.size(); ++i) {
    const int p = j.parent[at(i)], c = j.child[at(i)];
    const double mu = j.friction(i) * frictionScale;
    Vector3d tau = -mu * (s.bodyAngularVelocity.col(c) - s.bodyAngularVelocity.col(p));
    if (j.stiffness(i) > 0.0 || j.lockStiffness(i) > 0.0)
      tau -= jointStiffness(j, i, w.scratch.rotation[at(p)]) * jointRotation(s, p, c);
    w.scratch.bodyTorque.col(c) += tau;
    w.scratch.bodyTorque.col(p) -= tau;
  }
}

// visceral drag on the free nodes: f = -beta m v (Gut::drag)
void accumulateVisceralDrag(const Model& model, const State& s, const StepOptions& o, StepWork& w) {
  const double beta = effectiveDrag(model, o);
  if (beta == 0.0) return;
  for (int n = 0; n < model.nodes.size(); ++n)
    if (!model.nodes.isFixed(n))
      w.scratch.nodeForce.col(n) -= beta * model.nodes.mass(n) * s.nodeVelocity.col(n);
}

// gravity on moving bodies and nodes; gyroscopic torque -w x (I w)
void accumulateGravityAndGyroscopic(const Model& model, const State& s, const StepOptions& o, StepWork& w) {
  for (int b = 0; b < model.bodies.size(); ++b) {
    if (model.bodies.isFixed[at(b)]) continue;
    if (o.gravity) w.scratch.bodyForce.col(b) += model.bodies.mass(b) * model.gravity;
    const Matrix3d& r = w.scratch.rotation[at(b)];
    const Vector3d om = s.bodyAngularVelocity.col(b);
    w.scratch.bodyTorque.col(b) -= om.cross(r * (model.bodies.inertia[at(b)] * (r.transpose() * om)));
  }
  if (o.gravity) {
    for (int n = 0; n < model.nodes.size(); ++n)
      w.scratch.nodeForce.col(n) += model.nodes.mass(n) * model.gravity;
  }
}

// ---------------------------------------------------------------------------------------------
// stage 2: integrate velocities

// paper's scheme (Section 6.1): v += F/m dt for nodes, and the Newton-Euler analogue for bodies
void explicitVelocityUpdate(const Model& model, State& s, double dt, StepWork& w) {
  for (int b = 0; b < model.bodies.size(); ++b) {
    if (model.bodies.isFixed[at(b)]) continue;
    s.bodyVelocity.col(b) += (dt / model.bodies.mass(b)) * w.scratch.bodyForce.col(b);
    s.bodyAngularVelocity.col(b) += dt * (w.scratch.inverseInertiaWorld[at(b)] * w.scratch.bodyTorque.col(b));
  }
  for (int n = 0; n < model.nodes.size(); ++n) {
    if (model.nodes.isFixed(n)) continue;
    s.nodeVelocity.col(n) += (dt / model.nodes.mass(n)) * w.scratch.nodeForce.col(n);
  }
}

// joint friction (Eq. 3) for symplectic Euler, backward Euler per joint: the relative angular velocity
// w_rel decays as (1 + dt mu W) w_rel' = w_rel with W = I_c^-1 + I_p^-1 (world), so any mu / I is stable
void integrateJointFriction(const Model& model, State& s, double dt, const StepOptions& o, const StepWork& w) {
  const Joints& j = model.joints;
  for (int i = 0; i < j.size(); ++i) {
    const double mu = j.friction(i) * o.jointFrictionScale;
    if (mu == 0.0) continue;
    const int p = j.parent[at(i)], c = j.child[at(i)];
    const Matrix3d inv = w.scratch.inverseInertiaWorld[at(c)] + w.scratch.inverseInertiaWorld[at(p)];
    const Vector3d rel = s.bodyAngularVelocity.col(c) - s.bodyAngularVelocity.col(p);
    const Vector3d relNew = (Matrix3d::Identity() + dt * mu * inv).inverse() * rel;
    const Vector3d impulse = -dt * mu * relNew;  // [N m s] angular impulse on the child
    s.bodyAngularVelocity.col(c) += w.scratch.inverseInertiaWorld[at(c)] * impulse;
    s.bodyAngularVelocity.col(p) -= w.scratch.inverseInertiaWorld[at(p)] * impulse;
  }
}

// packs the elements that take part in kScale K + dScale D (taut or in tension) for applyStiffnessDamping:
// elements between two single nodes with their solver offsets, the others by index
void linearizeElements(const Model& model, double kScale, double dScale, StepWork& w) {
  w.scratch.linearKScale = kScale;
  w.scratch.linearDScale = dScale;
  w.scratch.linearNodeCount = 0;
  w.scratch.linearBodyCount = 0;
  w.scratch.linearOtherCount = 0;
  for (int e = 0; e < model.elements.size(); ++e) {
    const double ka = kScale * w.scratch.elementStiffness(e) + dScale * w.scratch.elementDamping(e);
    const double kg = kScale * w.scratch.elementGeometric(e);
    if (ka == 0.0 && kg == 0.0) continue;
    const int na = w.constants.endpointNode(0, e), nb = w.constants.endpointNode(1, e);
    const int ba = w.constants.endpointBody(0, e), bb = w.constants.endpointBody(1, e);
    if (na >= 0 && nb >= 0) {
      const int i = w.scratch.linearNodeCount++;
      w.scratch.linearNodes.col(i) << static_cast<int>(nodeOffset(model, na)),
          static_cast<int>(nodeOffset(model, nb));
      w.scratch.linearNodeCoeffs.col(i) << ka, kg, w.scratch.elementDirection.col(e);
    } else if (ba >= 0 && bb >= 0) {
      const int i = w.scratch.linearBodyCount++;
      w.scratch.linearBodies.col(i) << 6 * ba, 6 * bb;
      w.scratch.linearBodyCoeffs.col(i) << ka, kg, w.scratch.elementDirection.col(e), w.scratch.leverA.col(e),
          w.scratch.leverB.col(e);
    } else {
      const int i = w.scratch.linearOtherCount++;
      w.scratch.linearOther(i) = e;
      w.scratch.linearOtherCoeffs.col(i) << ka, kg;
    }
  }
}

// out = kScale K u + dScale D u: the linearised stiffness and damping of elements, gut pressure and joints,
// with the scales and elements packed by linearizeElements()
void applyStiffnessDamping(const Model& model, const StepOptions& o, const StepWork& w,
                           const Eigen::VectorXd& u, Eigen::VectorXd& out) {
  const double kScale = w.scratch.linearKScale, dScale = w.scratch.linearDScale;
  out.setZero();
  // elements between two single nodes (most gut strands)
  for (int i = 0; i < w.scratch.linearNodeCount; ++i) {
    const double* c = w.scratch.linearNodeCoeffs.col(i).data();
    const Eigen::Index oa = w.scratch.linearNodes(0, i), ob = w.scratch.linearNodes(1, i);
    const Vector3d d(c[2], c[3], c[4]);
    const Vector3d du = Eigen::Map<const Vector3d>(u.data() + ob) - Eigen::Map<const Vector3d>(u.data() + oa);
    const double along = d.dot(du);
    const Vector3d y = c[0] * along * d + c[1] * (du - along * d);
    Eigen::Map<Vector3d>(out.data() + oa) -= y;
    Eigen::Map<Vector3d>(out.data() + ob) += y;
  }
  // elements between two bodies (intercostals, shoulder): the anchor velocity is v + w x r
  for (int i = 0; i < w.scratch.linearBodyCount; ++i) {
    const double* c = w.scratch.linearBodyCoeffs.col(i).data();
    const Eigen::Index oa = w.scratch.linearBodies(0, i), ob = w.scratch.linearBodies(1, i);
    const Vector3d d(c[2], c[3], c[4]), ra(c[5], c[6], c[7]), rb(c[8], c[9], c[10]);
    const Vector3d va = Eigen::Map<const Vector3d>(u.data() + oa) + Eigen::Map<const Vector3d>(u.data() + oa + 3).cross(ra);
    const Vector3d vb = Eigen::Map<const Vector3d>(u.data() + ob) + Eigen::Map<const Vector3d>(u.data() + ob + 3).cross(rb);
    const Vector3d du = vb - va;
    const double along = d.dot(du);
    const Vector3d y = c[0] * along * d + c[1] * (du - along * d);
    Eigen::Map<Vector3d>(out.data() + oa) -= y;
    Eigen::Map<Vector3d>(out.data() + oa + 3) -= ra.cross(y);
    Eigen::Map<Vector3d>(out.data() + ob) += y;
    Eigen::Map<Vector3d>(out.data() + ob + 3) += rb.cross(y);
  }
  // elements with a weighted-node end or a body and a node end
  for (int i = 0; i < w.scratch.linearOtherCount; ++i) {
    const int e = w.scratch.linearOther(i);
    const double ka = w.scratch.linearOtherCoeffs(0, i), kg = w.scratch.linearOtherCoeffs(1, i);
    const Vector3d d = w.scratch.elementDirection.col(e);
    const Vector3d ra = w.scratch.leverA.col(e), rb = w.scratch.leverB.col(e);
    const Vector3d du = anchorVelocity(model, w, 1, e, rb, u) - anchorVelocity(model, w, 0, e, ra, u);
    const double along = d.dot(du);
    const Vector3d y = ka * along * d + kg * (du - along * d);
    addAnchorGeneralized(model, w, 0, e, ra, -y, out);
    addAnchorGeneralized(model, w, 1, e, rb, y, out);
  }
  // rank-one gut pressure stiffness kappa V0 / V^2 g g^T, kept while the gut is over-full (V >= V0, where
  // Eq. 5 clamps the force to 0): the step then sees the pressure that compressing the gut raises; without
  // it one step of a suddenly contracting rectus squeezed the gut by 10 % at dt 20 ms
  if (w.constants.restGutVolume > 0.0 && kScale != 0.0) {
    const double kp = kScale * effectiveKappa(model, o) * w.constants.restGutVolume /
                      (w.outputs.gutVolume * w.outputs.gutVolume);
    const Eigen::Index nodes = 3 * static_cast<Eigen::Index>(model.nodes.size());
    const Eigen::Map<const Eigen::VectorXd> g(w.scratch.gutGradient.data(), nodes);
    const double gu = g.dot(u.tail(nodes));
    out.tail(nodes) += (kp * gu) * g;
  }
  // rank-one pleural stiffness g_c g_c^T / C while the lungs pull (Ppl < 0), g_c = dV/dq of the cavity (its
  // geometric part -Ppl A^T H A, like the gut pressure's, is left out: it changed no energy figure measurably)
  if (w.scratch.pleuralStiffness > 0.0 && kScale != 0.0)
    out += (kScale * w.scratch.pleuralStiffness * w.scratch.cavityGeneralized.dot(u)) *
           w.scratch.cavityGeneralized;
  // joint springs and friction act on the relative angular velocity
  const Joints& j = model.joints;
  for (int i = 0; i < j.size(); ++i) {
    const double mu = dScale * j.friction(i) * o.jointFrictionScale;
    if (mu == 0.0 && (kScale == 0.0 || (j.stiffness(i) == 0.0 && j.lockStiffness(i) == 0.0))) continue;
    const int p = j.parent[at(i)], c = j.child[at(i)];
    const Matrix3d kj = kScale * jointStiffness(j, i, w.scratch.rotation[at(p)]) + mu * Matrix3d::Identity();
    const Vector3d y = kj * (u.segment<3>(6 * c + 3) - u.segment<3>(6 * p + 3));
    out.segment<3>(6 * c + 3) += y;
    out.segment<3>(6 * p + 3) -= y;
  }
  maskFixed(w, out);
}

// out = (M + dt D_drag) u (block diagonal: m I for translations, world inertia for rotations; the visceral
// drag is mass-proportional, so it scales the node masses by 1 + dt beta, dt as packed by linearizeElements)
void applyMass(const Model& model, const StepOptions& o, const StepWork& w, const Eigen::VectorXd& u,
               Eigen::VectorXd& out) {
  const double nodeScale = 1.0 + w.scratch.linearDScale * effectiveDrag(model, o);
  for (int b = 0; b < model.bodies.size(); ++b) {
    const Matrix3d& r = w.scratch.rotation[at(b)];
    out.segment<3>(6 * b) = model.bodies.mass(b) * u.segment<3>(6 * b);
    out.segment<3>(6 * b + 3) = r * (model.bodies.inertia[at(b)] * (r.transpose() * u.segment<3>(6 * b + 3)));
  }
  for (int n = 0; n < model.nodes.size(); ++n)
    out.segment<3>(nodeOffset(model, n)) = nodeScale * model.nodes.mass(n) * u.segment<3>(nodeOffset(model, n));
}

// the dense body block of M + dt D + dt^2 K (6 #B square) and the coupling of the body entries to the
// attached nodes' entries (6 #B x 3 #attached), both restricted to the joint tree (J^T . J on the free rows,
// J^T .)
void assembleBodyBlocks(const Model& model, const StepOptions& o, const std::vector<int>& tree, StepWork& w,
                        double dt) {
  const int nb = model.bodies.size();
  Eigen::MatrixXd& a = w.scratch.bodyBlock;
  Eigen::MatrixXd& c = w.scratch.bodyNodeBlock;
  a.setZero();
  c.setZero();
  for (int b = 0; b < nb; ++b) {
    const Matrix3d& r = w.scratch.rotation[at(b)];
    a.block<3, 3>(6 * b, 6 * b) = model.bodies.mass(b) * Matrix3d::Identity();
    a.block<3, 3>(6 * b + 3, 6 * b + 3) = r * model.bodies.inertia[at(b)] * r.transpose();
  }
  // elements: J_i^T K_e J_j with J = [I, -[lever]x] for body endpoints, w_k I for node k, sign -1 across the
  // ends (fixed bodies do not move)
  const Elements& el = model.elements;
  for (int e = 0; e < el.size(); ++e) {
    const int ba = w.constants.endpointBody(0, e), bb = w.constants.endpointBody(1, e);
    if (ba < 0 && bb < 0) continue;
    const double ka = dt * dt * w.scratch.elementStiffness(e) + dt * w.scratch.elementDamping(e),
                 kg = dt * dt * w.scratch.elementGeometric(e);
    if (ka == 0.0 && kg == 0.0) continue;
    const Vector3d d = w.scratch.elementDirection.col(e), ra = w.scratch.leverA.col(e),
                   rb = w.scratch.leverB.col(e);
    const bool movingA = ba >= 0 && !model.bodies.isFixed[at(ba)], movingB = bb >= 0 && !model.bodies.isFixed[at(bb)];
    const EndJacobian ea = endJacobian(d, ra), eb = endJacobian(d, rb);
    if (movingA) a.block<6, 6>(6 * ba, 6 * ba) += pointStiffness(ka, kg, ea, ea);
    if (movingB) a.block<6, 6>(6 * bb, 6 * bb) += pointStiffness(ka, kg, eb, eb);
    if (movingA && movingB) {
      const Eigen::Matrix<double, 6, 6> cab = pointStiffness(ka, kg, ea, eb);
      a.block<6, 6>(6 * ba, 6 * bb) -= cab;
      a.block<6, 6>(6 * bb, 6 * ba) -= cab.transpose();
    }
    // a moving body at one end, nodes at the other: -J_b^T K_e w_k = -[K_e; [lever]x K_e] w_k
    if ((ba >= 0) == (bb >= 0) || !(movingA || movingB)) continue;
    const int b = movingA ? ba : bb;
    const AnchorSet& nodes = movingA ? el.endB : el.endA;
    const Matrix3d ke = (ka - kg) * d * d.transpose() + kg * Matrix3d::Identity();
    Eigen::Matrix<double, 6, 3> jk;
    jk << ke, skew(movingA ? ra : rb) * ke;
    for (int k = 0; k < 3; ++k) {
      const int n = nodes.nodes(k, e);
      if (n >= 0) c.block<6, 3>(6 * b, 3 * w.constants.attachedColumn(n)) -= nodes.weights(k, e) * jk;
    }
  }
  // joint springs and friction on relative angular velocity
  const Joints& j = model.joints;
  for (int i = 0; i < j.size(); ++i) {
    const int p = j.parent[at(i)], ch = j.child[at(i)];
    const Matrix3d kj = dt * dt * jointStiffness(j, i, w.scratch.rotation[at(p)]) +
                        dt * j.friction(i) * o.jointFrictionScale * Matrix3d::Identity();
    a.block<3, 3>(6 * ch + 3, 6 * ch + 3) += kj;
    a.block<3, 3>(6 * p + 3, 6 * p + 3) += kj;
    a.block<3, 3>(6 * ch + 3, 6 * p + 3) -= kj;
    a.block<3, 3>(6 * p + 3, 6 * ch + 3) -= kj;
  }
  // restrict to the joint tree's coordinates: J^T A by columns (fixed bodies' columns are not needed), then
  // J^T A J as the gathered columns of its transpose (the free columns only)
  if (!tree.empty()) {
    for (int b = 0; b < nb; ++b)
      for (int k = 6 * b; k < 6 * b + 6 && !model.bodies.isFixed[at(b)]; ++k)
        gatherJointForces(model.joints, w, tree, a.col(k));
    a.transposeInPlace();  // (J^T A)^T = A J: its columns, gathered, are those of J^T A J
    for (Eigen::Index k = 0;
         k < w.constants.freeCoordinates.size() && w.constants.freeCoordinates(k) < a.rows(); ++k)
      gatherJointForces(model.joints, w, tree, a.col(w.constants.freeCoordinates(k)));
    for (Eigen::Index k = 0; k < c.cols(); ++k) gatherJointForces(model.joints, w, tree, c.col(k));
  }
}

// streams the lower triangle of the implicit system without the gut's rank-one term, J^T (M + dt D + dt^2 K0)
// J, by 3 x 3 blocks as add(row, col, block) with row >= col the first entries of the block in full
// coordinates (a diagonal block is passed whole); the sequence of (row, col) depends on the model's topology
// only
template <typename Sink>
void streamSystem(const Model& model, const StepOptions& o, const StepWork& w, double dt, Sink&& add) {
  // bodies, where they can couple
  for (Eigen::Index i = 0; i < w.constants.bodyEntries.cols(); ++i)
    add(w.constants.bodyEntries(0, i), w.constants.bodyEntries(1, i),
        w.scratch.bodyBlock.block<3, 3>(w.constants.bodyEntries(0, i), w.constants.bodyEntries(1, i)));
  // attached nodes and bodies, where they can couple (bodyNodeBlock holds body rows, node columns)
  for (Eigen::Index i = 0; i < w.constants.couplingEntries.cols(); ++i)
    add(w.constants.couplingEntries(0, i), w.constants.couplingEntries(1, i),
        w.scratch.bodyNodeBlock
            .block<3, 3>(w.constants.couplingEntries(1, i), w.constants.couplingEntries(2, i))
            .transpose());
  // node masses and the visceral drag, (1 + dt beta) m I
  const double dragScale = 1.0 + dt * effectiveDrag(model, o);
  for (int n = 0; n < model.nodes.size(); ++n)
    add(nodeOffset(model, n), nodeOffset(model, n), dragScale * model.nodes.mass(n) * Matrix3d::Identity());
  // elements between nodes: w_k w_l s_k s_l K_e for every pair of node terms of the two endpoints
  const Elements& el = model.elements;
  for (int e = 0; e < el.size(); ++e) {
    if (w.constants.endpointBody(0, e) >= 0 && w.constants.endpointBody(1, e) >= 0) continue;
    const double ka = dt * dt * w.scratch.elementStiffness(e) + dt * w.scratch.elementDamping(e),
                 kg = dt * dt * w.scratch.elementGeometric(e);
    const Vector3d d = w.scratch.elementDirection.col(e);
    const Matrix3d ke = (ka - kg) * d * d.transpose() + kg * Matrix3d::Identity();
    // two distinct single nodes (most elements): K_e on both diagonals, -K_e between them
    const int n0 = w.constants.endpointNode(0, e), n1 = w.constants.endpointNode(1, e);
    if (n0 >= 0 && n1 >= 0 && n0 != n1) {
      add(nodeOffset(model, n0), nodeOffset(model, n0), ke);
      add(nodeOffset(model, n1), nodeOffset(model, n1), ke);
      add(nodeOffset(model, std::max(n0, n1)), nodeOffset(model, std::min(n0, n1)), -ke);
      continue;
    }
    for (int sa = 0; sa < 2; ++sa) {
      if (w.constants.endpointBody(sa, e) >= 0) continue;
      const AnchorSet& a = sa == 0 ? el.endA : el.endB;
      for (int sb = 0; sb < 2; ++sb) {
        if (w.constants.endpointBody(sb, e) >= 0) continue;
        const AnchorSet& b = sb == 0 ? el.endA : el.endB;
        for (int ka3 = 0; ka3 < 3; ++ka3) {
          for (int kb3 = 0; kb3 < 3; ++kb3) {
            const int na = a.nodes(ka3, e), nb = b.nodes(kb3, e);
            if (na < 0 || nb < 0 || na < nb) continue;
            const double s = (sa == sb ? 1.0 : -1.0) * a.weights(ka3, e) * b.weights(kb3, e);
            add(nodeOffset(model, na), nodeOffset(model, nb), s * ke);
          }
        }
      }
    }
  }
}

// the free coordinates of the implicit solve and the pattern of its matrix, from the model's topology (the
// joint tree, the elements' endpoints): once per model, by makeStepWork(); the streamed values do not matter
// here
void analyzeSystem(const Model& model, StepWork& w) {
  const std::vector<int>& tree = w.constants.treeJoints;
  const StepOptions o;
  const double dt = 0.0;
  Eigen::VectorXd mask = Eigen::VectorXd::Ones(w.scratch.cgX.size());
  maskReduced(model.joints, w, tree, mask);
  w.constants.freeIndex.setConstant(mask.size(), -1);
  std::vector<int> free;
  for (Eigen::Index i = 0; i < mask.size(); ++i)
    if (mask(i) != 0.0) {
      w.constants.freeIndex(i) = static_cast<int>(free.size());
      free.push_back(static_cast<int>(i));
    }
  w.constants.freeCoordinates =
      Eigen::Map<const Eigen::VectorXi>(free.data(), static_cast<Eigen::Index>(free.size()));
  // which entries can be nonzero: a body couples to the bodies it shares an element or a joint with, an
  // attached node to the bodies of its elements; in the joint tree's coordinates each body stands for
  // itself and its ancestors (its motion is theirs plus its own)
  const int nb = model.bodies.size();
  std::vector<int> parentOf(at(nb), -1);
  for (int j : tree) parentOf[at(model.joints.child[at(j)])] = model.joints.parent[at(j)];
  Eigen::Matrix<char, Eigen::Dynamic, Eigen::Dynamic> bodyMask, couplingMask;  // #B x #B, #B x #attached
  bodyMask.setZero(nb, nb);
  const auto coupleBodies = [&](int b1, int b2) {
    for (int x = b1; x >= 0; x = parentOf[at(x)])
      for (int y = b2; y >= 0; y = parentOf[at(y)]) bodyMask(x, y) = bodyMask(y, x) = 1;
  };
  for (int b = 0; b < nb; ++b) coupleBodies(b, b);
  for (int i = 0; i < model.joints.size(); ++i)
    coupleBodies(model.joints.parent[at(i)], model.joints.child[at(i)]);
  couplingMask.setZero(nb, static_cast<Eigen::Index>(w.constants.attachedNodes.size()));
  const Elements& el = model.elements;
  for (int e = 0; e < el.size(); ++e) {
    if (w.constants.endpointBody(0, e) >= 0 && w.constants.endpointBody(1, e) >= 0)
      coupleBodies(w.constants.endpointBody(0, e), w.constants.endpointBody(1, e));
    for (int side = 0; side < 2; ++side) {
      const int body = w.constants.endpointBody(1 - side, e);
      if (w.constants.endpointBody(side, e) >= 0 || body < 0 || model.bodies.isFixed[at(body)]) continue;
      const AnchorSet& a = side == 0 ? el.endA : el.endB;
      for (int k = 0; k < 3; ++k)
        for (int b = body; b >= 0 && a.nodes(k, e) >= 0; b = parentOf[at(b)])
          couplingMask(b, w.constants.attachedColumn(a.nodes(k, e))) = 1;
    }
  }
  // the masks as lists of 3 x 3 blocks over the free body coordinates (which come first, by whole blocks)
  std::vector<int> bodyEntries, couplingEntries;
  std::size_t freeBodies = 0;
  while (freeBodies < free.size() && free[freeBodies] < 6 * nb) freeBodies += 3;
  for (std::size_t c = 0; c < freeBodies; c += 3)
    for (std::size_t r = c; r < freeBodies; r += 3)
      if (bodyMask(free[r] / 6, free[c] / 6)) bodyEntries.insert(bodyEntries.end(), {free[r], free[c]});
  for (std::size_t k = 0; k < w.constants.attachedNodes.size(); ++k) {
    const int column = 3 * static_cast<int>(k),
              row = static_cast<int>(nodeOffset(model, w.constants.attachedNodes[k]));
    for (std::size_t c = 0; c < freeBodies; c += 3)
      if (couplingMask(free[c] / 6, static_cast<Eigen::Index>(k)))
        couplingEntries.insert(couplingEntries.end(), {row, free[c], column});
  }
  w.constants.bodyEntries = Eigen::Map<const Eigen::Matrix2Xi>(
      bodyEntries.data(), 2, static_cast<Eigen::Index>(bodyEntries.size() / 2));
  w.constants.couplingEntries = Eigen::Map<const Eigen::Matrix3Xi>(
      couplingEntries.data(), 3, static_cast<Eigen::Index>(couplingEntries.size() / 3));
  // every streamed block in free blocks, (-1, -1) when fixed or dependent (free coordinates come in whole
  // blocks: a node's three, a jointed body's rotation, a free body's translation and rotation)
  std::vector<std::array<int, 2>> blocks;
  streamSystem(model, o, w, dt, [&](Eigen::Index r, Eigen::Index c, const auto&) {
    const int fr = w.constants.freeIndex(r), fc = w.constants.freeIndex(c);
    blocks.push_back(fr >= 0 && fc >= 0 ? std::array<int, 2>{fr / 3, fc / 3} : std::array<int, 2>{-1, -1});
  });
  const Eigen::Index nf = w.constants.freeCoordinates.size();
  std::vector<std::array<int, 2>> pattern;
  std::copy_if(blocks.begin(), blocks.end(), std::back_inserter(pattern),
               [](const auto& b) { return b[0] >= 0; });
  w.memory.system.analyze(static_cast<int>(nf / 3), pattern);
  // the value slot of every streamed block, -1 when dropped
  w.constants.systemPattern.clear();
  for (const auto& [r, c] : blocks)
    w.constants.systemPattern.push_back(r >= 0 ? w.memory.system.slot(r, c) : -1);
  w.scratch.compactR.setZero(nf);
  w.scratch.compactZ.setZero(nf);
}

// the preconditioner: a sparse LDLT factorization of the reduced system without the gut's rank-one term,
// kept for several steps, plus that term by Sherman-Morrison; u = sqrt(kp) g over the free coordinates
void factorSystem(const Model& model, const StepOptions& o, const std::vector<int>& tree, StepWork& w,
                  double dt) {
  // values (the free coordinates and the pattern are analyzeSystem()'s), then the numeric factorization
  assembleBodyBlocks(model, o, tree, w, dt);
  w.memory.system.clearValues();
  std::size_t slot = 0;
  streamSystem(model, o, w, dt, [&](Eigen::Index, Eigen::Index, const auto& block) {
    const int k = w.constants.systemPattern[slot++];
    if (k >= 0) w.memory.system.value(k) += block;
  });
  if (!w.memory.system.factorize())
    throw Error(
        "implicit solve: the system matrix is not positive definite (likely cause: a negative stiffness or "
        "mass)");
  // the gut pressure's rank-one stiffness kp g g^T = u u^T by Sherman-Morrison:
  // (A + u u^T)^-1 = A^-1 - A^-1 u u^T A^-1 / (1 + u^T A^-1 u)
  const Eigen::Index nf = w.constants.freeCoordinates.size();
  w.memory.rankOne.setZero(nf);
  if (w.constants.restGutVolume > 0.0) {
    const double su =
        dt * std::sqrt(effectiveKappa(model, o) * w.constants.restGutVolume) / w.outputs.gutVolume;
    for (Eigen::Index k = 0; k < nf; ++k) {
      const Eigen::Index i =
          w.constants.freeCoordinates(k) - 6 * static_cast<Eigen::Index>(model.bodies.size());
      if (i >= 0) w.memory.rankOne(k) = su * w.scratch.gutGradient(i % 3, i / 3);
    }
  }
  w.memory.rankOneSolve = w.memory.rankOne;
  w.memory.system.solve(w.memory.rankOneSolve);
  w.memory.rankOneScale = 1.0 / (1.0 + w.memory.rankOne.dot(w.memory.rankOneSolve));
  // and the pleural one, v v^T with v = dt J^T g_c / sqrt(C), on top: (A1 + v v^T)^-1 = A1^-1 - A1^-1 v v^T A1^-1 /
  // (1 + v^T A1^-1 v), A1 = A0 + u u^T
  w.memory.rankTwo.resize(0);
  if (w.scratch.pleuralStiffness > 0.0) {
    Eigen::VectorXd& v = w.scratch.cavityReduced;
    v = w.scratch.cavityGeneralized;
    gatherJointForces(model.joints, w, tree, v);
    maskReduced(model.joints, w, tree, v);
    const double sv = dt * std::sqrt(w.scratch.pleuralStiffness);
    w.memory.rankTwo.resize(nf);
    for (Eigen::Index k = 0; k < nf; ++k) w.memory.rankTwo(k) = sv * v(w.constants.freeCoordinates(k));
    w.memory.rankTwoSolve = w.memory.rankTwo;
    w.memory.system.solve(w.memory.rankTwoSolve);
    w.memory.rankTwoSolve -=
        (w.memory.rankOneScale * w.memory.rankOne.dot(w.memory.rankTwoSolve)) * w.memory.rankOneSolve;
    w.memory.rankTwoScale = 1.0 / (1.0 + w.memory.rankTwo.dot(w.memory.rankTwoSolve));
  }
  w.memory.hasFactorization = true;
  w.memory.factorDt = dt;
  w.memory.factorAge = 0;
  w.memory.factorAxial = dt * dt * w.scratch.elementStiffness + dt * w.scratch.elementDamping;
  w.memory.factorTransverse = dt * dt * w.scratch.elementGeometric;
  w.memory.factorDirection = w.scratch.elementDirection;
}

// z = P^-1 r with the factored system (zero on the masked coordinates)
void applyPreconditioner(StepWork& w, const Eigen::VectorXd& r, Eigen::VectorXd& z) {
  const Eigen::Index nf = w.constants.freeCoordinates.size();
  for (Eigen::Index k = 0; k < nf; ++k) w.scratch.compactR(k) = r(w.constants.freeCoordinates(k));
  w.scratch.compactZ = w.scratch.compactR;
  w.memory.system.solve(w.scratch.compactZ);
  w.scratch.compactZ -=
      (w.memory.rankOneScale * w.memory.rankOne.dot(w.scratch.compactZ)) * w.memory.rankOneSolve;
  if (w.memory.rankTwo.size() > 0)
    w.scratch.compactZ -=
        (w.memory.rankTwoScale * w.memory.rankTwo.dot(w.scratch.compactZ)) * w.memory.rankTwoSolve;
  z.setZero();
  for (Eigen::Index k = 0; k < nf; ++k) z(w.constants.freeCoordinates(k)) = w.scratch.compactZ(k);
}

// out = J^T (M + dt D + dt^2 K) J u in the joint tree's coordinates, dt as packed by linearizeElements (t, z:
// scratch)
void applySystem(const Model& model, const StepOptions& o, const StepWork& w, const std::vector<int>& tree,
                 const Eigen::VectorXd& u, Eigen::VectorXd& t, Eigen::VectorXd& z, Eigen::VectorXd& out) {
  t = u;
  expandJointVelocities(model.joints, w, tree, t);
  applyStiffnessDamping(model, o, w, t, out);
  applyMass(model, o, w, t, z);
  out += z;
  gatherJointForces(model.joints, w, tree, out);
  maskReduced(model.joints, w, tree, out);
}

// linearly implicit Euler (Baraff & Witkin 1998): (M + dt D + dt^2 K) dv = dt (f - dt K v), by PCG, in the
// coordinates of the joint tree (dv = J dv': the tree joints hold exactly in the linearised step)
void implicitVelocityUpdate(const Model& model, State& s, double dt, const StepOptions& o, StepWork& w) {
  const int nb = model.bodies.size(), nn = model.nodes.size();
  Eigen::VectorXd &x = w.scratch.cgX, &r = w.scratch.cgR, &z = w.scratch.cgZ, &p = w.scratch.cgP,
                  &q = w.scratch.cgQ, &rhs = w.scratch.cgB, &t = w.scratch.cgT;
  const std::vector<int>& tree = w.constants.treeJoints;
  for (int j : tree) {
    w.scratch.treeLeverParent.col(j) =
        w.scratch.rotation[at(model.joints.parent[at(j)])] * w.constants.jointLocalParent.col(j);
    w.scratch.treeLeverChild.col(j) =
        w.scratch.rotation[at(model.joints.child[at(j)])] * w.constants.jointLocalChild.col(j);
  }

  // current generalized velocity and forces
  for (int b = 0; b < nb; ++b) {
    p.segment<3>(6 * b) = s.bodyVelocity.col(b);
    p.segment<3>(6 * b + 3) = s.bodyAngularVelocity.col(b);
    rhs.segment<3>(6 * b) = w.scratch.bodyForce.col(b);
    rhs.segment<3>(6 * b + 3) = w.scratch.bodyTorque.col(b);
  }
  for (int n = 0; n < nn; ++n) {
    p.segment<3>(nodeOffset(model, n)) = s.nodeVelocity.col(n);
    rhs.segment<3>(nodeOffset(model, n)) = w.scratch.nodeForce.col(n);
  }
  linearizeElements(model, dt * dt, 0.0, w);
  applyStiffnessDamping(model, o, w, p, q);
  rhs = dt * rhs - q;
  gatherJointForces(model.joints, w, tree, rhs);
  maskReduced(model.joints, w, tree, rhs);

  // preconditioned conjugate gradient on M + dt D + dt^2 K; a stale factorization is a good preconditioner
  // for a few steps: refresh it when it has aged, when the last solve needed many iterations, when the
  // stiffness of several elements changed much (muscles going slack or taut, activation steps, fast
  // rotation), or when dt changed
  int changed = 0;
  for (Eigen::Index e = 0; e < w.memory.factorAxial.size(); ++e) {
    // |K_e - K_e0| <= |a - a0| + |g - g0| + 2 max(a, a0) |d - d0| for K_e = a d d^T + g (I - d d^T)
    const double a = dt * dt * w.scratch.elementStiffness(e) + dt * w.scratch.elementDamping(e),
                 g = dt * dt * w.scratch.elementGeometric(e);
    const double a0 = w.memory.factorAxial(e), g0 = w.memory.factorTransverse(e);
    const double change =
        std::abs(a - a0) + std::abs(g - g0) +
        2.0 * std::max(a, a0) * (w.scratch.elementDirection.col(e) - w.memory.factorDirection.col(e)).norm();
    changed += change > 0.25 * std::max(a0, g0) && change > 0.0;
  }
  const bool stale = !w.memory.hasFactorization || w.memory.factorAge >= o.preconditionerRefresh ||
                     w.memory.cgIterations > o.refactorIterations || changed > o.refactorElementChanges ||
                     dt != w.memory.factorDt ||
                     (w.scratch.pleuralStiffness > 0.0) != (w.memory.rankTwo.size() > 0);
  if (stale) factorSystem(model, o, tree, w, dt);
  ++w.memory.factorAge;
  linearizeElements(model, dt * dt, dt, w);
  // start from x = P^-1 rhs, which is the solution right after a refactorization (P is then the system
  // itself); else rhs^T P^-1 rhs scales the stop test: a relative residual, or the residual's energy norm
  // r^T P^-1 r below 1e-12 J
  applyPreconditioner(w, rhs, x);
  int it = 0;
  if (!stale) {
    const double stop = std::max(o.cgTolerance * o.cgTolerance * rhs.dot(x), 1e-24);
    applySystem(model, o, w, tree, x, t, z, q);
    r = rhs - q;
    applyPreconditioner(w, r, z);
    p = z;
    double rz = r.dot(z);
    for (; it < o.cgMaxIterations && rz > stop; ++it) {
      applySystem(model, o, w, tree, p, t, z, q);
      const double alpha = rz / p.dot(q);
      x += alpha * p;
      r -= alpha * q;
      applyPreconditioner(w, r, z);
      const double rzNew = r.dot(z);
      p = z + (rzNew / rz) * p;
      rz = rzNew;
    }
  }
  w.memory.cgIterations = it;

  // v += J dv'
  t = x;
  expandJointVelocities(model.joints, w, tree, t);
  for (int b = 0; b < nb; ++b) {
    if (model.bodies.isFixed[at(b)]) continue;
    s.bodyVelocity.col(b) += t.segment<3>(6 * b);
    s.bodyAngularVelocity.col(b) += t.segment<3>(6 * b + 3);
  }
  for (int n = 0; n < nn; ++n) {
    if (!model.nodes.isFixed(n)) s.nodeVelocity.col(n) += t.segment<3>(nodeOffset(model, n));
  }
}

// ---------------------------------------------------------------------------------------------
// stage 3: ball joints

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
Vector3d jointVelocityError(const Model& model, const State& s, const StepWork& w, int i, Vector3d& rp, Vector3d& rc) {
  const int p = model.joints.parent[at(i)], c = model.joints.child[at(i)];
  rp = w.scratch.rotation[at(p)] * w.constants.jointLocalParent.col(i);
  rc = w.scratch.rotation[at(c)] * w.constants.jointLocalChild.col(i);
  return (s.bodyVelocity.col(c) + s.bodyAngularVelocity.col(c).cross(rc)) -
         (s.bodyVelocity.col(p) + s.bodyAngularVelocity.col(p).cross(rp));
}

// sequential impulses: the relative velocity of the two anchor points of every joint goes to zero; nothing to do
// when they already move together to kJointVelocityTolerance (the usual case: the implicit step solves the tree
// joints, and the last step left every joint so)
void solveJointVelocities(const Model& model, State& s, const StepOptions& o, StepWork& w) {
  constexpr double kJointVelocityTolerance = 1e-5;  // [m/s] 0.17 um of separation over a 1/60 s step
  const Joints& j = model.joints;
  Vector3d rp, rc;
  double worst = 0.0;
  for (int i = 0; i < j.size(); ++i) worst = std::max(worst, jointVelocityError(model, s, w, i, rp, rc).norm());
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

// rotates body b by the small rotation vector dtheta [rad] (world frame)
void rotateBody(State& s, int b, const Vector3d& dtheta) {
  Eigen::Quaterniond& q = s.bodyOrientation[at(b)];
  const Eigen::Quaterniond dq(0.0, dtheta.x(), dtheta.y(), dtheta.z());
  q.coeffs() += 0.5 * (dq * q).coeffs();
  q.normalize();
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

// x += v dt for bodies (quaternion update with the new angular velocity) and moving nodes
void integratePositions(const Model& model, State& s, double dt, StepWork& w) {
  for (int b = 0; b < model.bodies.size(); ++b) {
    if (model.bodies.isFixed[at(b)]) continue;
    s.bodyPosition.col(b) += dt * s.bodyVelocity.col(b);
    rotateBody(s, b, dt * s.bodyAngularVelocity.col(b));
    w.scratch.rotation[at(b)] = s.bodyOrientation[at(b)].toRotationMatrix();
  }
  for (int n = 0; n < model.nodes.size(); ++n) {
    if (!model.nodes.isFixed(n)) s.nodePosition.col(n) += dt * s.nodeVelocity.col(n);
  }
  updateBodyFrames(model, s, w);
}

std::string describeBlowUpCause(double dt) {
  std::ostringstream os;
  os << "likely cause: dt = " << dt << " s too large for the stiffness or the forces (lower dt or the gains; "
     << "symplectic-euler needs dt of about 10 us)";
  return os.str();
}

}  // namespace

// ---------------------------------------------------------------------------------------------

void computeForces(const Model& model, const State& s, const Activations& act, const StepOptions& o, StepWork& w) {
  w.scratch.bodyForce.setZero();
  w.scratch.bodyTorque.setZero();
  w.scratch.nodeForce.setZero();
  updateBodyFrames(model, s, w);
  accumulateElementForces(model, s, act, o, w);
  accumulateGutPressure(model, s, o, w);
  accumulatePleuralPressure(model, s, w);
  accumulateJointTorques(model, s, o, w);
  accumulateVisceralDrag(model, s, o, w);
  accumulateGravityAndGyroscopic(model, s, o, w);
}

namespace {
const std::pair<IntegratorKind, const char*> kIntegratorNames[] = {
    {IntegratorKind::SymplecticEuler, "symplectic-euler"},
    {IntegratorKind::ImplicitEulerJoints, "implicit-euler-joints"}};
}  // namespace

const char* integratorName(IntegratorKind k) {
  for (const auto& [kind, name] : kIntegratorNames)
    if (kind == k) return name;
  return "?";
}

std::string integratorNames() {
  std::string out;
  for (const auto& [kind, name] : kIntegratorNames) out += (out.empty() ? "" : ", ") + std::string(name);
  return out;
}

bool integratorFromName(const std::string& name, IntegratorKind& out) {
  for (const auto& [kind, n] : kIntegratorNames)
    if (name == n) {
      out = kind;
      return true;
    }
  return false;
}

double defaultTimeStep(IntegratorKind k) { return k == IntegratorKind::SymplecticEuler ? 1e-5 : 1.0 / 60.0; }

void validateStepOptions(const StepOptions& o) {
  auto fail = [](const std::string& field, double v, const char* rule) {
    std::ostringstream os;
    os << field << ": " << rule << ", got " << v;
    throw Error(os.str());
  };
  if (!std::isfinite(o.jointFrictionScale) || o.jointFrictionScale < 0.0)
    fail("jointFrictionScale", o.jointFrictionScale, "must be finite and >= 0");
  if (!std::isfinite(o.gutDragScale) || o.gutDragScale < 0.0)
    fail("gutDragScale", o.gutDragScale, "must be finite and >= 0");
  if (!std::isfinite(o.kappa)) fail("kappa", o.kappa, "must be finite (< 0 selects the model's value)");
  for (int g = 0; g < kElementGroupCount; ++g) {
    const std::string name = groupName(static_cast<ElementGroup>(g));
    if (!std::isfinite(o.activeGainScale[at(g)]) || o.activeGainScale[at(g)] < 0.0)
      fail("activeGainScale." + name, o.activeGainScale[at(g)], "must be finite and >= 0");
    if (!std::isfinite(o.passiveGainScale[at(g)]) || o.passiveGainScale[at(g)] < 0.0)
      fail("passiveGainScale." + name, o.passiveGainScale[at(g)], "must be finite and >= 0");
  }
  if (o.jointIterations < 1) fail("jointIterations", o.jointIterations, "must be >= 1");
  if (!(o.jointTolerance > 0.0)) fail("jointTolerance", o.jointTolerance, "must be > 0");
  if (o.cgMaxIterations < 1) fail("cgMaxIterations", o.cgMaxIterations, "must be >= 1");
  if (o.preconditionerRefresh < 1) fail("preconditionerRefresh", o.preconditionerRefresh, "must be >= 1");
  if (o.refactorIterations < 0) fail("refactorIterations", o.refactorIterations, "must be >= 0");
  if (o.refactorElementChanges < 0) fail("refactorElementChanges", o.refactorElementChanges, "must be >= 0");
  if (!(o.cgTolerance > 0.0)) fail("cgTolerance", o.cgTolerance, "must be > 0");
}

StepWork makeStepWork(const Model& model) {
  StepWork w;
  const int nb = model.bodies.size(), nn = model.nodes.size(), ne = model.elements.size(), nj = model.joints.size();
  w.constants.restGutVolume =
      model.gut.triangles.cols() > 0 ? enclosedVolume(model.nodes.rest, model.gut.triangles) : 0.0;
  w.outputs.gutVolume = w.constants.restGutVolume;
  if (model.nodes.size() > 0) w.constants.restGutCentroid = model.nodes.rest.rowwise().mean();
  if (model.cavity.triangles.cols() > 0) {
    const State rest = makeInitialState(model);
    anchorPositions(model.cavity.vertices, rest, w.scratch.cavityPosition);
    w.constants.restCavityVolume = enclosedVolume(w.scratch.cavityPosition, model.cavity.triangles);
  }
  std::vector<int> wall;
  for (Eigen::Index f = 0; f < model.gut.triangles.cols(); ++f) {
    int count = 0;
    for (int k = 0; k < 3; ++k) count += model.nodes.region[at(model.gut.triangles(k, f))] == NodeRegion::Wall ? 1 : 0;
    if (count >= 2) wall.push_back(static_cast<int>(f));
  }
  w.constants.wallTriangles.resize(3, static_cast<Eigen::Index>(wall.size()));
  for (std::size_t i = 0; i < wall.size(); ++i)
    w.constants.wallTriangles.col(static_cast<Eigen::Index>(i)) = model.gut.triangles.col(wall[i]);
  w.outputs.elementForce = Eigen::VectorXd::Zero(ne);
  w.outputs.elementLength = Eigen::VectorXd::Zero(ne);
  w.scratch.elementDirection = Eigen::Matrix3Xd::Zero(3, ne);
  w.scratch.leverA = Eigen::Matrix3Xd::Zero(3, ne);
  w.scratch.leverB = Eigen::Matrix3Xd::Zero(3, ne);
  w.scratch.elementStiffness = Eigen::VectorXd::Zero(ne);
  w.scratch.elementGeometric = Eigen::VectorXd::Zero(ne);
  w.scratch.elementDamping = Eigen::VectorXd::Zero(ne);
  w.scratch.linearNodes = Eigen::Matrix2Xi::Zero(2, ne);
  w.scratch.linearNodeCoeffs = Eigen::Matrix<double, 5, Eigen::Dynamic>::Zero(5, ne);
  w.scratch.linearBodies = Eigen::Matrix2Xi::Zero(2, ne);
  w.scratch.linearBodyCoeffs = Eigen::Matrix<double, 11, Eigen::Dynamic>::Zero(11, ne);
  w.scratch.linearOther = Eigen::VectorXi::Zero(ne);
  w.scratch.linearOtherCoeffs = Eigen::Matrix2Xd::Zero(2, ne);
  w.constants.inverseInertiaBody.resize(at(nb));
  for (int b = 0; b < nb; ++b)
    w.constants.inverseInertiaBody[at(b)] =
        model.bodies.isFixed[at(b)] ? Matrix3d::Zero() : Matrix3d(model.bodies.inertia[at(b)].inverse());
  w.constants.jointLocalParent.resize(3, nj);
  w.constants.jointLocalChild.resize(3, nj);
  for (int i = 0; i < nj; ++i) {
    w.constants.jointLocalParent.col(i) =
        model.joints.anchor.col(i) - model.bodies.com.col(model.joints.parent[at(i)]);
    w.constants.jointLocalChild.col(i) =
        model.joints.anchor.col(i) - model.bodies.com.col(model.joints.child[at(i)]);
  }
  w.constants.endpointBody.resize(2, ne);
  w.constants.endpointNode.resize(2, ne);
  for (int e = 0; e < ne; ++e) {
    for (int side = 0; side < 2; ++side) {
      const AnchorSet& a = side == 0 ? model.elements.endA : model.elements.endB;
      w.constants.endpointBody(side, e) = a.body[at(e)];
      const bool single = a.body[at(e)] < 0 && a.nodes(1, e) < 0 && a.nodes(2, e) < 0 && a.weights(0, e) == 1.0;
      w.constants.endpointNode(side, e) = single ? a.nodes(0, e) : -1;
    }
  }
  std::vector<int> fixed;
  for (int b = 0; b < nb; ++b)
    if (model.bodies.isFixed[at(b)])
      for (int k = 0; k < 6; ++k) fixed.push_back(6 * b + k);
  for (int i = 0; i < nn; ++i)
    if (model.nodes.isFixed(i))
      for (int k = 0; k < 3; ++k) fixed.push_back(6 * nb + 3 * i + k);
  w.constants.fixedDofs =
      Eigen::Map<const Eigen::VectorXi>(fixed.data(), static_cast<Eigen::Index>(fixed.size()));
  w.scratch.jointMassInverse.assign(at(nj), Matrix3d::Zero());
  // the joint tree: joints whose child hangs on no other joint, ordered parents first (a joint closing a
  // loop stays with the impulse solver of stage 3 only)
  w.scratch.treeLeverParent = Eigen::Matrix3Xd::Zero(3, nj);
  w.scratch.treeLeverChild = Eigen::Matrix3Xd::Zero(3, nj);
  {
    std::vector<char> placed(at(nb), 0), taken(at(nj), 0);
    for (int b = 0; b < nb; ++b) placed[at(b)] = model.bodies.isFixed[at(b)];
    for (bool grew = true; grew;) {
      grew = false;
      for (int i = 0; i < nj; ++i) {
        const int p = model.joints.parent[at(i)], c = model.joints.child[at(i)];
        if (taken[at(i)] || !placed[at(p)] || placed[at(c)]) continue;
        w.constants.treeJoints.push_back(i);
        taken[at(i)] = placed[at(c)] = 1;
        grew = true;
      }
    }
  }
  w.scratch.rotation.assign(at(nb), Matrix3d::Identity());
  w.scratch.inverseInertiaWorld = w.constants.inverseInertiaBody;
  w.scratch.bodyForce = Eigen::Matrix3Xd::Zero(3, nb);
  w.scratch.bodyTorque = Eigen::Matrix3Xd::Zero(3, nb);
  w.scratch.nodeForce = Eigen::Matrix3Xd::Zero(3, nn);
  w.scratch.gutGradient = Eigen::Matrix3Xd::Zero(3, nn);
  const Eigen::Index n = 6 * static_cast<Eigen::Index>(nb) + 3 * static_cast<Eigen::Index>(nn);
  w.scratch.cavityGeneralized = Eigen::VectorXd::Zero(n);
  w.scratch.bodyBlock = Eigen::MatrixXd::Zero(6 * nb, 6 * nb);
  // nodes tied by an element to a moving body: their coupling columns in bodyNodeBlock
  w.constants.attachedColumn.setConstant(nn, -1);
  for (int e = 0; e < ne; ++e) {
    for (int side = 0; side < 2; ++side) {
      const int body = w.constants.endpointBody(1 - side, e);
      if (w.constants.endpointBody(side, e) >= 0 || body < 0 || model.bodies.isFixed[at(body)]) continue;
      const AnchorSet& a = side == 0 ? model.elements.endA : model.elements.endB;
      for (int k = 0; k < 3; ++k) {
        const int node = a.nodes(k, e);
        if (node < 0 || w.constants.attachedColumn(node) >= 0) continue;
        w.constants.attachedColumn(node) = static_cast<int>(w.constants.attachedNodes.size());
        w.constants.attachedNodes.push_back(node);
      }
    }
  }
  w.scratch.bodyNodeBlock =
      Eigen::MatrixXd::Zero(6 * nb, 3 * static_cast<Eigen::Index>(w.constants.attachedNodes.size()));
  for (Eigen::VectorXd* v : {&w.scratch.cgX, &w.scratch.cgR, &w.scratch.cgZ, &w.scratch.cgP, &w.scratch.cgQ,
                             &w.scratch.cgB, &w.scratch.cgT})
    *v = Eigen::VectorXd::Zero(n);
  analyzeSystem(model, w);
  return w;
}

void syncBodyFrames(const Model& model, const State& state, StepWork& work) {
  updateBodyFrames(model, state, work);
}

void step(const Model& model, State& state, double dt, const Activations& act, const StepOptions& options,
          StepWork& work) {
  // joints: the tree solve keeps the anchors together only if the start velocity does (an initial state may not)
  if (options.integrator == IntegratorKind::ImplicitEulerJoints) solveJointVelocities(model, state, options, work);

  // forces: muscles, cartilage, gut pressure, joint friction and stiffness, gravity
  computeForces(model, state, act, options, work);

  // integrate velocities
  if (options.integrator == IntegratorKind::SymplecticEuler) {
    explicitVelocityUpdate(model, state, dt, work);
    integrateJointFriction(model, state, dt, options, work);
  } else
    implicitVelocityUpdate(model, state, dt, options, work);

  // joints: remove relative velocity at every ball joint
  solveJointVelocities(model, state, options, work);

  // integrate positions with the new velocities
  integratePositions(model, state, dt, work);

  // joints: project positions back onto the constraints
  projectJointPositions(model, state, options, work);

  state.time += dt;
  ++state.steps;
}

void computeMetrics(const Model& model, const State& state, const Activations& act, const StepOptions& options,
                    const StepWork& work, Metrics& out) {
  out.time = state.time;
  out.activations = act;

  // volumes: lung cavity from its bound surface, gut from the node surface
  Eigen::Matrix3Xd cavity;
  anchorPositions(model.cavity.vertices, state, cavity);
  out.lungVolume = model.cavity.triangles.cols() > 0 ? enclosedVolume(cavity, model.cavity.triangles) : 0.0;
  out.gutVolume = model.gut.triangles.cols() > 0 ? enclosedVolume(state.nodePosition, model.gut.triangles) : 0.0;
  out.gutVolumeError = work.constants.restGutVolume > 0.0
                           ? (out.gutVolume - work.constants.restGutVolume) / work.constants.restGutVolume
                           : 0.0;
  const double kappa = effectiveKappa(model, options);
  out.gutPressure = work.constants.restGutVolume > 0.0
                        ? gutPressure(kappa, work.constants.restGutVolume, out.gutVolume)
                        : 0.0;
  out.abdomenVolume =
      coneVolume(state.nodePosition, work.constants.wallTriangles, work.constants.restGutCentroid);

  // element forces of the last step, slack state and group tensions
  const Elements& el = model.elements;
  out.elementForce = work.outputs.elementForce;
  out.isSlack.assign(at(el.size()), 0);
  out.groupMeanTension.fill(0.0);
  std::array<int, kElementGroupCount> count{};
  for (int e = 0; e < el.size(); ++e) {
    const double f = work.outputs.elementForce(e);
    if (isMuscleGroup(el.group[at(e)]) && f >= 0.0) out.isSlack[at(e)] = 1;
    out.groupMeanTension[at(static_cast<int>(el.group[at(e)]))] += std::max(-f, 0.0);
    ++count[at(static_cast<int>(el.group[at(e)]))];
  }
  for (int g = 0; g < kElementGroupCount; ++g)
    if (count[at(g)] > 0) out.groupMeanTension[at(g)] /= count[at(g)];

  // energies: kinetic, elastic (elements at the current pose, gut, joint springs), gravity
  double kinetic = 0.0, gravity = 0.0;
  for (int b = 0; b < model.bodies.size(); ++b) {
    if (model.bodies.isFixed[at(b)]) continue;
    const Matrix3d r = state.bodyOrientation[at(b)].toRotationMatrix();
    const Vector3d om = r.transpose() * state.bodyAngularVelocity.col(b);
    kinetic += 0.5 * model.bodies.mass(b) * state.bodyVelocity.col(b).squaredNorm() +
               0.5 * om.dot(model.bodies.inertia[at(b)] * om);
    if (options.gravity)
      gravity -= model.bodies.mass(b) * model.gravity.dot(state.bodyPosition.col(b) - model.bodies.com.col(b));
  }
  for (int n = 0; n < model.nodes.size(); ++n) {
    if (model.nodes.isFixed(n)) continue;
    kinetic += 0.5 * model.nodes.mass(n) * state.nodeVelocity.col(n).squaredNorm();
    if (options.gravity)
      gravity -= model.nodes.mass(n) * model.gravity.dot(state.nodePosition.col(n) - model.nodes.rest.col(n));
  }
  double elastic = 0.0;
  for (int e = 0; e < el.size(); ++e) {
    const double l = (anchorPosition(el.endB, e, state) - anchorPosition(el.endA, e, state)).norm();
    const MuscleParams p = muscleParams(model, e, act, options);
    elastic += isMuscleGroup(el.group[at(e)]) ? muscleEnergy(l, p) : springEnergy(l, p.restLength, p.kpe);
  }
  if (work.constants.restGutVolume > 0.0)
    elastic += gutEnergy(kappa, work.constants.restGutVolume, out.gutVolume);
  // lung recoil: E = P0 dV + dV^2 / (2 C) while Ppl < 0, the potential of the pleural pressure
  if (model.cavity.compliance > 0.0) {
    const double dv = out.lungVolume - work.constants.restCavityVolume;
    const double c = model.cavity.compliance, p0 = model.cavity.recoilPressure;
    const double dvZero = -p0 * c;  // [m^3] where Ppl reaches 0
    const double d = std::max(dv, dvZero);
    elastic += p0 * (d - dvZero) + (d * d - dvZero * dvZero) / (2.0 * c);
  }
  for (int i = 0; i < model.joints.size(); ++i) {
    const int p = model.joints.parent[at(i)];
    const Vector3d th = jointRotation(state, p, model.joints.child[at(i)]);
    elastic += 0.5 * th.dot(jointStiffness(model.joints, i, state.bodyOrientation[at(p)].toRotationMatrix()) * th);
  }
  out.kineticEnergy = kinetic;
  out.elasticEnergy = elastic;
  out.gravityEnergy = gravity;
  out.maxJointError = work.outputs.maxJointError;

  // landmarks
  anchorPositions(model.landmarks.points, state, out.landmarks);
}

void checkState(const Model& model, const State& state, const StepWork& work, double dt) {
  constexpr double kMaxSpeed = 100.0;      // [m/s] nothing in a breathing torso moves this fast
  constexpr double kMaxJointError = 0.01;  // [m]
  auto fail = [&](const std::string& what) {
    std::ostringstream os;
    os << "simulation blew up at t = " << state.time << " s: " << what << " (" << describeBlowUpCause(dt) << ")";
    throw Error(os.str());
  };
  for (int b = 0; b < model.bodies.size(); ++b) {
    const double v = state.bodyVelocity.col(b).norm() + state.bodyAngularVelocity.col(b).norm();
    if (!std::isfinite(v) || !state.bodyPosition.col(b).allFinite())
      fail("body '" + model.bodies.name[at(b)] + "' has a non-finite position or velocity");
    if (state.bodyVelocity.col(b).norm() > kMaxSpeed) {
      std::ostringstream os;
      os << "body '" << model.bodies.name[at(b)] << "' speed " << state.bodyVelocity.col(b).norm() << " m/s";
      fail(os.str());
    }
  }
  for (int n = 0; n < model.nodes.size(); ++n) {
    const double v = state.nodeVelocity.col(n).norm();
    if (!std::isfinite(v) || !state.nodePosition.col(n).allFinite())
      fail("gut node " + std::to_string(n) + " has a non-finite position or velocity");
    if (v > kMaxSpeed) {
      std::ostringstream os;
      os << "gut node " << n << " speed " << v << " m/s";
      fail(os.str());
    }
  }
  for (int e = 0; e < model.elements.size(); ++e) {
    if (!std::isfinite(work.outputs.elementForce(e)))
      fail("element " + std::to_string(e) + " (" + groupName(model.elements.group[at(e)]) + ") has a non-finite force");
  }
  if (work.outputs.maxJointError > kMaxJointError) {
    std::ostringstream os;
    os << "joint error " << work.outputs.maxJointError * 1e3 << " mm exceeds 10 mm";
    fail(os.str());
  }
}

}  // namespace pneuma::sim
