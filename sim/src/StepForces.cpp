// Stage 1 of step(), forces: muscles (Eq. 2) and structural springs with their linearisation, gut and
// volume-body pressure (Eq. 4, 5), pleural pressure (Cavity), joint friction (Eq. 3) and stiffness, visceral
// drag, gravity and the gyroscopic torque (docs/integrator.md).
#include <algorithm>
#include <cmath>

#include "StepInternal.h"

namespace pneuma::sim {

namespace detail {

// rotation matrices and world inverse inertias of all bodies
void updateBodyFrames(const Model& model, const State& s, StepWork& w) {
  for (int b = 0; b < model.bodies.size(); ++b) {
    w.scratch.rotation[at(b)] = s.bodyOrientation[at(b)].toRotationMatrix();
    const Matrix3d& r = w.scratch.rotation[at(b)];
    w.scratch.inverseInertiaWorld[at(b)] = r * w.constants.inverseInertiaBody[at(b)] * r.transpose();
  }
}

namespace {

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
void applyAnchorForce(const AnchorSet& a, int side, int i, const Vector3d& lever, const Vector3d& f,
                      StepWork& w) {
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
    const MuscleParams p = muscleParams(model, w.constants, e, act, o);

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

// pressure of one sealed node surface (the gut, a volume body): its volume V, P = kappa (V0/V - 1) (Eq. 4),
// the gradient dV/dx, and the force max(0, P) A n / 3 per face and vertex (Eq. 5) = max(0, P) dV/dx
void accumulateVolumePressure(const Eigen::Matrix3Xi& triangles, double kappa, double restVolume,
                              const State& s, Eigen::Matrix3Xd& gradient, double& volume, double& pressure,
                              StepWork& w) {
  volume = enclosedVolume(s.nodePosition, triangles);
  pressure = gutPressure(kappa, restVolume, volume);
  gradient.setZero();
  addVolumeGradient(s.nodePosition, triangles, 1.0, gradient);
  if (pressure > 0.0) w.scratch.nodeForce += pressure * gradient;
}

// gut pressure (Gut) and the soft-tissue volume bodies' (VolumeBodies), Eq. 4 and 5
void accumulateGutPressure(const Model& model, const State& s, const StepOptions& o, StepWork& w) {
  if (model.gut.triangles.cols() > 0)
    accumulateVolumePressure(model.gut.triangles, effectiveKappa(model, o), w.constants.restGutVolume, s,
                             w.scratch.gutGradient, w.outputs.gutVolume, w.outputs.gutPressure, w);
  for (int k = 0; k < model.volumes.size(); ++k)
    accumulateVolumePressure(model.volumes.triangles[at(k)], model.volumes.kappa(k),
                             w.constants.restBodyVolume(k), s, w.scratch.volumeGradient[at(k)],
                             w.outputs.volumeBodyVolume(k), w.outputs.volumeBodyPressure(k), w);
}

// [Pa] pleural pressure Ppl = min(0, -(P0 + (V - Vr) / C)) of Cavity, 0 when it has no compliance
double pleuralPressure(const Cavity& c, double volume, double restVolume) {
  if (!(c.compliance > 0.0)) return 0.0;
  return std::min(0.0, -(c.recoilPressure + (volume - restVolume) / c.compliance));
}

// pleural pressure on the cavity walls, f_i = Ppl dV/dx_i, carried to the bones and gut nodes the vertices
// are bound to; also dV/dq over the implicit solver's entries and the stiffness 1/C it has while Ppl < 0
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
      if (c.vertices.nodes(k, i) >= 0)
        g.segment<3>(nodeOffset(model, c.vertices.nodes(k, i))) += c.vertices.weights(k, i) * gi;
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

// joint friction tau = -mu (w_child - w_parent) (Eq. 3) and passive rotational stiffness tau = -K theta;
// left out for symplectic Euler, which integrates both implicitly with the joints (solveJointsImplicitly)
void accumulateJointTorques(const Model& model, const State& s, const StepOptions& o, StepWork& w) {
  const Joints& j = model.joints;
  if (o.integrator == IntegratorKind::SymplecticEuler) return;
  const double frictionScale = o.jointFrictionScale;
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

// gravity (the posture's, postureGravity()) on moving bodies and nodes, and the postural supports
// (postureSupport(), at postureSupportPoint()); gyroscopic torque -w x (I w)
void accumulateGravityAndGyroscopic(const Model& model, const State& s, const StepOptions& o, StepWork& w) {
  const Vector3d g = postureGravity(model, o);
  for (int b = 0; b < model.bodies.size(); ++b) {
    if (model.bodies.isFixed[at(b)]) continue;
    const Matrix3d& r = w.scratch.rotation[at(b)];
    if (o.gravity) {
      const Vector3d support = postureSupport(model, b, o);
      w.scratch.bodyForce.col(b) += model.bodies.mass(b) * g + support;
      w.scratch.bodyTorque.col(b) += (r * postureSupportPoint(model, b, o)).cross(support);
    }
    const Vector3d om = s.bodyAngularVelocity.col(b);
    w.scratch.bodyTorque.col(b) -= om.cross(r * (model.bodies.inertia[at(b)] * (r.transpose() * om)));
  }
  if (o.gravity) {
    for (int n = 0; n < model.nodes.size(); ++n) w.scratch.nodeForce.col(n) += model.nodes.mass(n) * g;
  }
}

}  // namespace

}  // namespace detail

using namespace detail;

void computeForces(const Model& model, const State& s, const Activations& act, const StepOptions& o,
                   StepWork& w) {
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

}  // namespace pneuma::sim
