// step(): the pipeline forces -> integrate -> joints (docs/integrator.md), the explicit integrator and the
// positions, makeStepWork() and the blow-up check. The stages are in StepForces.cpp, StepImplicit.cpp and
// StepJoints.cpp.
#include "pneuma/sim/Step.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "StepInternal.h"
#include "pneuma/sim/Error.h"

namespace pneuma::sim {

using namespace detail;

namespace {

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

// the joints of symplectic Euler, one backward-Euler solve per step: at every ball joint the linear impulse
// lambda that stops the anchors' relative velocity u, and the angular impulse Lambda of the joint's friction
// mu (Eq. 3) and rotational springs K (spine stiffness, rib-neck lock; Joints) with the relative angular
// velocity w' after the step, Lambda = -dt mu w' - dt K (theta + dt w'). Gauss-Seidel over the joints, each
// joint a 6x6 block solve:
//   A lambda + C^T dLambda = -u,   c C lambda + (1 + c W) dLambda = -R,
//   A = sum_b (1/m_b - [r_b] I_b^-1 [r_b]),  C = sum_b I_b^-1 [r_b],  W = sum_b I_b^-1,  c = dt mu + dt^2 K,
// R = Lambda + c w + dt K theta the residual of the angular law (b: the two bodies, [r] the cross-product
// matrix of the lever, world inverse inertias). Solving a joint's angle, friction and anchor together keeps
// the scheme stable: friction and springs on a 10 g rib (mu dt / I ~ 50) applied about its centre of mass,
// then anchor impulses about the joint, fought each other and pumped energy into the rib-neck hinges (issue
// 13: the deep breath blew up at 0.16 s)
void solveJointsImplicitly(const Model& model, State& s, double dt, const StepOptions& o, StepWork& w) {
  constexpr double kVelocityTolerance = 1e-6;  // [m/s], [rad/s] of the residuals, scaled below
  const Joints& j = model.joints;
  const int nj = j.size();
  using Matrix6d = Eigen::Matrix<double, 6, 6>;
  using Vector6d = Eigen::Matrix<double, 6, 1>;
  std::vector<Eigen::PartialPivLU<Matrix6d>> blocks(at(nj));
  std::vector<Matrix3d> damping(at(nj)), spring(at(nj));
  std::vector<Vector3d> springImpulse(at(nj)), leverP(at(nj)), leverC(at(nj)),
      angular(at(nj), Vector3d::Zero());
  auto invMass = [&](int b) { return model.bodies.isFixed[at(b)] ? 0.0 : 1.0 / model.bodies.mass(b); };
  for (int i = 0; i < nj; ++i) {
    const int p = j.parent[at(i)], c = j.child[at(i)];
    leverP[at(i)] = w.scratch.rotation[at(p)] * w.constants.jointLocalParent.col(i);
    leverC[at(i)] = w.scratch.rotation[at(c)] * w.constants.jointLocalChild.col(i);
    const Matrix3d& ip = w.scratch.inverseInertiaWorld[at(p)];
    const Matrix3d& ic = w.scratch.inverseInertiaWorld[at(c)];
    const Matrix3d sp = skew(leverP[at(i)]), sc = skew(leverC[at(i)]);
    const Matrix3d a = (invMass(p) + invMass(c)) * Matrix3d::Identity() - sp * ip * sp - sc * ic * sc;
    const Matrix3d cc = ic * sc + ip * sp;
    spring[at(i)] = jointStiffness(j, i, w.scratch.rotation[at(p)]);
    damping[at(i)] =
        dt * j.friction(i) * o.jointFrictionScale * Matrix3d::Identity() + dt * dt * spring[at(i)];
    springImpulse[at(i)] = dt * (spring[at(i)] * jointRotation(s, p, c));
    Matrix6d m;
    m << a, cc.transpose(), damping[at(i)] * cc, Matrix3d::Identity() + damping[at(i)] * (ic + ip);
    blocks[at(i)].compute(m);
  }
  for (int it = 0; it < o.jointIterations; ++it) {
    double worst = 0.0;
    for (int i = 0; i < nj; ++i) {
      const int p = j.parent[at(i)], c = j.child[at(i)];
      const Vector3d &rp = leverP[at(i)], &rc = leverC[at(i)];
      const Vector3d u = (s.bodyVelocity.col(c) + s.bodyAngularVelocity.col(c).cross(rc)) -
                         (s.bodyVelocity.col(p) + s.bodyAngularVelocity.col(p).cross(rp));
      const Vector3d rel = s.bodyAngularVelocity.col(c) - s.bodyAngularVelocity.col(p);
      const Vector3d r = angular[at(i)] + damping[at(i)] * rel + springImpulse[at(i)];
      worst = std::max({worst, u.norm(), r.norm() * w.scratch.inverseInertiaWorld[at(c)].norm()});
      Vector6d rhs;
      rhs << -u, -r;
      const Vector6d x = blocks[at(i)].solve(rhs);
      const Vector3d lambda = x.head<3>(), dLambda = x.tail<3>();
      angular[at(i)] += dLambda;
      if (!model.bodies.isFixed[at(c)]) {
        s.bodyVelocity.col(c) += lambda / model.bodies.mass(c);
        s.bodyAngularVelocity.col(c) += w.scratch.inverseInertiaWorld[at(c)] * (rc.cross(lambda) + dLambda);
      }
      if (!model.bodies.isFixed[at(p)]) {
        s.bodyVelocity.col(p) -= lambda / model.bodies.mass(p);
        s.bodyAngularVelocity.col(p) -= w.scratch.inverseInertiaWorld[at(p)] * (rp.cross(lambda) + dLambda);
      }
    }
    if (worst < kVelocityTolerance) break;
  }
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

double hemidiaphragmScale(const Model& model, const StepConstants& c, int e, const StepOptions& o) {
  if (model.elements.group[at(e)] != ElementGroup::Diaphragm) return 1.0;
  const double s = c.elementRightShare(e);
  return o.hemidiaphragmActiveScale[0] * (1.0 - s) + o.hemidiaphragmActiveScale[1] * s;
}

StepWork makeStepWork(const Model& model) {
  StepWork w;
  const int nb = model.bodies.size(), nn = model.nodes.size(), ne = model.elements.size(),
            nj = model.joints.size();
  w.constants.restGutVolume =
      model.gut.triangles.cols() > 0 ? enclosedVolume(model.nodes.rest, model.gut.triangles) : 0.0;
  w.outputs.gutVolume = w.constants.restGutVolume;
  {
    // the gut's nodes: all but the volume bodies' (region Tissue)
    std::vector<int> gutNodes;
    for (int n = 0; n < nn; ++n)
      if (model.nodes.region[at(n)] != NodeRegion::Tissue) gutNodes.push_back(n);
    if (static_cast<int>(gutNodes.size()) == nn && nn > 0)
      w.constants.restGutCentroid = model.nodes.rest.rowwise().mean();
    else if (!gutNodes.empty())
      w.constants.restGutCentroid = model.nodes.rest(Eigen::all, gutNodes).rowwise().mean();
  }
  w.constants.restBodyVolume.resize(model.volumes.size());
  for (int k = 0; k < model.volumes.size(); ++k)
    w.constants.restBodyVolume(k) = enclosedVolume(model.nodes.rest, model.volumes.triangles[at(k)]);
  w.outputs.volumeBodyVolume = w.constants.restBodyVolume;
  w.outputs.volumeBodyPressure = Eigen::VectorXd::Zero(model.volumes.size());
  const State rest = makeInitialState(model);
  if (model.cavity.triangles.cols() > 0) {
    anchorPositions(model.cavity.vertices, rest, w.scratch.cavityPosition);
    w.constants.restCavityVolume = enclosedVolume(w.scratch.cavityPosition, model.cavity.triangles);
  }
  // each element's side: the x of its rest midpoint
  w.constants.elementRightShare.resize(ne);
  for (int e = 0; e < ne; ++e)
    w.constants.elementRightShare(e) = rightShare(0.5 * (anchorPosition(model.elements.endA, e, rest).x() +
                                                         anchorPosition(model.elements.endB, e, rest).x()));
  std::vector<int> wall;
  for (Eigen::Index f = 0; f < model.gut.triangles.cols(); ++f) {
    int count = 0;
    for (int k = 0; k < 3; ++k)
      count += model.nodes.region[at(model.gut.triangles(k, f))] == NodeRegion::Wall ? 1 : 0;
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
      const bool single =
          a.body[at(e)] < 0 && a.nodes(1, e) < 0 && a.nodes(2, e) < 0 && a.weights(0, e) == 1.0;
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
  // the joint tree: joints whose child hangs on no other joint, ordered parents first, from the roots: the
  // fixed bodies and the free bodies that hang on no joint (the sternum, on which the shoulder girdle hangs);
  // a joint closing a loop stays with the impulse solver of stage 3 only
  w.scratch.treeLeverParent = Eigen::Matrix3Xd::Zero(3, nj);
  w.scratch.treeLeverChild = Eigen::Matrix3Xd::Zero(3, nj);
  {
    std::vector<char> placed(at(nb), 1), taken(at(nj), 0);
    for (int i = 0; i < nj; ++i)
      if (!model.bodies.isFixed[at(model.joints.child[at(i)])]) placed[at(model.joints.child[at(i)])] = 0;
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
  w.scratch.volumeGradient.assign(at(model.volumes.size()), Eigen::Matrix3Xd::Zero(3, nn));
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
  for (Eigen::VectorXd* v : {&w.scratch.cgX, &w.scratch.cgR, &w.scratch.cgZ, &w.scratch.cgP, &w.scratch.cgQ,
                             &w.scratch.cgB, &w.scratch.cgT})
    *v = Eigen::VectorXd::Zero(n);
  analyzeSystem(model, w);
  return w;
}

void step(const Model& model, State& state, double dt, const Activations& act, const StepOptions& options,
          StepWork& work) {
  // the body frames of this State, so that the step depends on the State and the solver memory only
  updateBodyFrames(model, state, work);
  // joints: the tree solve keeps the anchors together only if the start velocity does (an initial state may
  // not)
  if (options.integrator == IntegratorKind::ImplicitEulerJoints)
    solveJointVelocities(model, state, options, work);

  // forces: muscles, cartilage, gut and volume-body pressure, joint friction and stiffness, gravity
  computeForces(model, state, act, options, work);

  // integrate velocities
  if (options.integrator == IntegratorKind::SymplecticEuler) {
    explicitVelocityUpdate(model, state, dt, work);
    solveJointsImplicitly(model, state, dt, options, work);
  } else {
    implicitVelocityUpdate(model, state, dt, options, work);
    // joints: remove relative velocity at every ball joint
    solveJointVelocities(model, state, options, work);
  }

  // integrate positions with the new velocities
  integratePositions(model, state, dt, work);

  // joints: project positions back onto the constraints
  projectJointPositions(model, state, options, work);

  state.time += dt;
  ++state.steps;
}

void checkState(const Model& model, const State& state, const StepWork& work, double dt) {
  constexpr double kMaxSpeed = 100.0;      // [m/s] nothing in a breathing torso moves this fast
  constexpr double kMaxJointError = 0.01;  // [m]
  auto fail = [&](const std::string& what) {
    std::ostringstream os;
    os << "simulation blew up at t = " << state.time << " s: " << what << " (" << describeBlowUpCause(dt)
       << ")";
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
      fail("node " + std::to_string(n) + " has a non-finite position or velocity");
    if (v > kMaxSpeed) {
      std::ostringstream os;
      os << "node " << n << " speed " << v << " m/s";
      fail(os.str());
    }
  }
  for (int e = 0; e < model.elements.size(); ++e) {
    if (!std::isfinite(work.outputs.elementForce(e)))
      fail("element " + std::to_string(e) + " (" + groupName(model.elements.group[at(e)]) +
           ") has a non-finite force");
  }
  if (work.outputs.maxJointError > kMaxJointError) {
    std::ostringstream os;
    os << "joint error " << work.outputs.maxJointError * 1e3 << " mm exceeds 10 mm";
    fail(os.str());
  }
}

}  // namespace pneuma::sim
