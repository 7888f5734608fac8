// The stiffness the implicit step linearises the forces with (StepImplicit.cpp), against central finite
// differences of the forces themselves, SOFA-style: K u = -(F(q + h u) - F(q - h u)) / 2h on the toy torso,
// for the matrix-free product CG applies and for the matrix the preconditioner factors. q = [x_b, theta_b]_b
// ++ [x_n]_n; a body turns by the rotation vector h theta about its com. K is exact but for two terms the
// step leaves out on purpose (docs/integrator.md): the turning of a lever under a body-end force, d(r x f) =
// (dtheta x r) x f, and the gut pressure's geometric part P d(grad V) (and each volume body's); and the
// negative transverse stiffness of a compressed two-sided spring. The test adds them from the kernels, so
// everything else must agree to rounding. Each test runs on the toy torso and on the toy torso with a
// soft-tissue volume body (VolumeBodies), squeezed like the gut.
#include <gtest/gtest.h>

#include <random>
#include <string>

#include "../../sim/src/StepInternal.h"
#include "ToyTorso.h"
#include "pneuma/sim/Step.h"

namespace pneuma::sim {
namespace {

using Eigen::Vector3d;
using Eigen::VectorXd;

// the toy torso at a loaded configuration: mid-inhale activations (muscles in tension at rest length), the
// gut squeezed by 3 % toward its centroid so its pressure pushes (P > 0) and every node nudged off the rest
// pose, bodies at rest orientation (joint springs unloaded, where their linearisation is exact); at rest (no
// velocity), no gravity, no pleural recoil (its own rank-one term is tested in Step_test); `withTissue` adds
// a volume body (addToyTissueBody()), squeezed with the rest
struct Loaded {
  Model model;
  State state;
  Activations act{};
  StepOptions options;
};

Loaded loaded(bool withTissue = false) {
  Loaded l;
  l.model = test::makeToyTorso(2);
  if (withTissue) test::addToyTissueBody(l.model);
  l.model.cavity.compliance = 0.0;
  l.options.gravity = false;
  for (int g = 0; g < kElementGroupCount; ++g) l.act[static_cast<std::size_t>(g)] = {0.8, 0.6};
  l.state = makeInitialState(l.model);
  const Vector3d centre = l.model.nodes.rest.rowwise().mean();
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int i = 0; i < l.model.nodes.size(); ++i) {
    if (l.model.nodes.isFixed(i)) continue;
    l.state.nodePosition.col(i) = centre + 0.97 * (l.state.nodePosition.col(i) - centre) +
                                  1e-3 * Vector3d(n(rng), n(rng), n(rng));  // [m]
  }
  return l;
}

// generalized forces F(q) = [f_b, tau_b]_b ++ [f_n]_n of stage 1
VectorXd forces(const Loaded& l, const State& s) {
  StepWork w = makeStepWork(l.model);
  computeForces(l.model, s, l.act, l.options, w);
  const int nb = l.model.bodies.size();
  VectorXd f(6 * nb + 3 * l.model.nodes.size());
  for (int b = 0; b < nb; ++b) {
    f.segment<3>(6 * b) = w.scratch.bodyForce.col(b);
    f.segment<3>(6 * b + 3) = w.scratch.bodyTorque.col(b);
  }
  for (int n = 0; n < l.model.nodes.size(); ++n)
    f.segment<3>(detail::nodeOffset(l.model, n)) = w.scratch.nodeForce.col(n);
  return f;
}

// q + h u: bodies moved by h v and turned by the rotation vector h w (exactly), nodes moved by h v
State displaced(const Loaded& l, const VectorXd& u, double h) {
  State s = l.state;
  for (int b = 0; b < l.model.bodies.size(); ++b) {
    s.bodyPosition.col(b) += h * u.segment<3>(6 * b);
    const Vector3d theta = h * u.segment<3>(6 * b + 3);
    if (theta.norm() > 0.0)
      s.bodyOrientation[static_cast<std::size_t>(b)] =
          (Eigen::Quaterniond(Eigen::AngleAxisd(theta.norm(), theta.normalized())) *
           s.bodyOrientation[static_cast<std::size_t>(b)])
              .normalized();
  }
  for (int n = 0; n < l.model.nodes.size(); ++n)
    s.nodePosition.col(n) += h * u.segment<3>(detail::nodeOffset(l.model, n));
  return s;
}

// -dF/dq u by central differences
VectorXd forceDerivative(const Loaded& l, const VectorXd& u) {
  const double h = 1e-6;  // [m], [rad] per unit of u
  return -(forces(l, displaced(l, u, h)) - forces(l, displaced(l, u, -h))) / (2.0 * h);
}

// the terms the step leaves out of K, times u: the lever's turn under each body-end force, -(dtheta x r) x f,
// the gut's and the volume bodies' pressure's geometric part, -P d(grad V)/dx u (grad V is quadratic in x:
// its central difference is exact), and the negative transverse stiffness -F/l (I - d d^T) of a compressed
// two-sided spring (F > 0; the squeezed volume body's springs)
VectorXd omitted(const Loaded& l, const StepWork& w, const VectorXd& u) {
  VectorXd out = VectorXd::Zero(u.size());
  const Elements& el = l.model.elements;
  for (int e = 0; e < el.size(); ++e) {
    const Vector3d f =
        w.outputs.elementForce(e) * w.scratch.elementDirection.col(e);  // on end B; -f on end A
    for (int side = 0; side < 2; ++side) {
      const int b = w.constants.endpointBody(side, e);
      if (b < 0) continue;
      const Vector3d r = side == 0 ? w.scratch.leverA.col(e) : w.scratch.leverB.col(e);
      const Vector3d fe = side == 0 ? Vector3d(-f) : f;
      out.segment<3>(6 * b + 3) -= u.segment<3>(6 * b + 3).cross(r).cross(fe);
    }
    if (w.outputs.elementForce(e) <= 0.0 || isMuscleGroup(el.group[static_cast<std::size_t>(e)])) continue;
    // compressed spring: y = -F/l (I - d d^T) (du_B - du_A) on end B, -y on end A
    Vector3d du[2];
    for (int side = 0; side < 2; ++side) {
      const AnchorSet& a = side == 0 ? el.endA : el.endB;
      const int b = a.body[static_cast<std::size_t>(e)];
      const Vector3d r = side == 0 ? w.scratch.leverA.col(e) : w.scratch.leverB.col(e);
      du[side].setZero();
      if (b >= 0)
        du[side] = u.segment<3>(6 * b) + u.segment<3>(6 * b + 3).cross(r);
      else
        for (int k = 0; k < 3; ++k)
          if (a.nodes(k, e) >= 0)
            du[side] += a.weights(k, e) * u.segment<3>(detail::nodeOffset(l.model, a.nodes(k, e)));
    }
    const Vector3d d = w.scratch.elementDirection.col(e);
    const Vector3d rel = du[1] - du[0];
    const Vector3d y = -w.outputs.elementForce(e) / w.outputs.elementLength(e) * (rel - d.dot(rel) * d);
    for (int side = 0; side < 2; ++side) {
      const AnchorSet& a = side == 0 ? el.endA : el.endB;
      const int b = a.body[static_cast<std::size_t>(e)];
      const Vector3d ys = side == 0 ? Vector3d(-y) : y;
      const Vector3d r = side == 0 ? w.scratch.leverA.col(e) : w.scratch.leverB.col(e);
      if (b >= 0) {
        out.segment<3>(6 * b) += ys;
        out.segment<3>(6 * b + 3) += r.cross(ys);
      } else
        for (int k = 0; k < 3; ++k)
          if (a.nodes(k, e) >= 0)
            out.segment<3>(detail::nodeOffset(l.model, a.nodes(k, e))) += a.weights(k, e) * ys;
    }
  }
  Eigen::Matrix3Xd x = l.state.nodePosition, du(3, l.model.nodes.size());
  for (int n = 0; n < l.model.nodes.size(); ++n) du.col(n) = u.segment<3>(detail::nodeOffset(l.model, n));
  auto geometric = [&](const Eigen::Matrix3Xi& triangles, double pressure) {
    const double p = std::max(pressure, 0.0);
    Eigen::Matrix3Xd gp = Eigen::Matrix3Xd::Zero(3, x.cols()), gm = gp;
    addVolumeGradient(x + du, triangles, 1.0, gp);
    addVolumeGradient(x - du, triangles, 1.0, gm);
    for (int n = 0; n < l.model.nodes.size(); ++n)
      out.segment<3>(detail::nodeOffset(l.model, n)) -= 0.5 * p * (gp.col(n) - gm.col(n));
  };
  geometric(l.model.gut.triangles, w.outputs.gutPressure);
  for (int k = 0; k < l.model.volumes.size(); ++k)
    geometric(l.model.volumes.triangles[static_cast<std::size_t>(k)], w.outputs.volumeBodyPressure(k));
  return out;
}

// |a - b| <= tol |b| on the body entries (the first `bodyEntries`) and on the node entries apart: the gut's
// pressure makes the node forces the larger by far
void expectClose(const VectorXd& a, const VectorXd& b, Eigen::Index bodyEntries, double tol,
                 const std::string& what) {
  const Eigen::Index nodeEntries = b.size() - bodyEntries;
  EXPECT_LT((a.head(bodyEntries) - b.head(bodyEntries)).norm(), tol * b.head(bodyEntries).norm())
      << what << ", bodies";
  EXPECT_LT((a.tail(nodeEntries) - b.tail(nodeEntries)).norm(), tol * b.tail(nodeEntries).norm())
      << what << ", nodes";
}

// a random direction over the moving coordinates
VectorXd randomDirection(const StepWork& w, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  VectorXd u(w.scratch.cgX.size());
  for (Eigen::Index i = 0; i < u.size(); ++i) u(i) = n(rng);
  detail::maskFixed(w, u);
  return u;
}

// the matrix-free product that CG applies, in full coordinates
void expectProductIsMinusTheForceDerivative(const Loaded& l) {
  StepWork w = makeStepWork(l.model);
  computeForces(l.model, l.state, l.act, l.options, w);
  ASSERT_GT(w.outputs.gutPressure, 100.0) << "the squeezed gut pushes";
  for (int k = 0; k < l.model.volumes.size(); ++k)
    ASSERT_GT(w.outputs.volumeBodyPressure(k), 100.0) << "the squeezed volume body pushes";
  ASSERT_GT((w.outputs.elementForce.array() < 0.0).count(), l.model.elements.size() / 4)
      << "muscles in tension";
  for (unsigned seed : {1u, 2u, 3u}) {
    const VectorXd u = randomDirection(w, seed);
    VectorXd ku;
    detail::stiffnessProduct(l.model, l.options, w, u, ku);
    VectorXd expected = forceDerivative(l, u) - omitted(l, w, u);
    detail::maskFixed(w, expected);
    expectClose(ku, expected, 6 * l.model.bodies.size(), 1e-6, "seed " + std::to_string(seed));
    // the left-out terms are real but small beside K u on this configuration
    EXPECT_GT(omitted(l, w, u).norm(), 1e-4 * expected.norm());
  }
}

TEST(Stiffness, ProductIsMinusTheForceDerivative) { expectProductIsMinusTheForceDerivative(loaded()); }

TEST(Stiffness, ProductWithAVolumeBodyIsMinusTheForceDerivative) {
  expectProductIsMinusTheForceDerivative(loaded(true));
}

// the matrix the preconditioner factors, J^T (M + dt D + dt^2 K) J over the free coordinates of the joint
// tree: quadratic in dt, so (A(1) + A(-1)) / 2 - A(0) is J^T K J exactly; with the gut's rank-one term that
// the solver adds by Sherman-Morrison (and the volume bodies'), J^T K J u equals J^T of the force derivative
// along J u
void expectAssembledMatrixIsMinusTheForceDerivative(const Loaded& l) {
  StepWork w = makeStepWork(l.model);
  computeForces(l.model, l.state, l.act, l.options, w);
  const Eigen::MatrixXd k = 0.5 * (detail::assembledSystem(l.model, l.options, w, 1.0) +
                                   detail::assembledSystem(l.model, l.options, w, -1.0)) -
                            detail::assembledSystem(l.model, l.options, w, 0.0);
  const Eigen::VectorXi& free = w.constants.freeCoordinates;
  const std::vector<int>& tree = w.constants.treeJoints;
  ASSERT_FALSE(tree.empty());
  ASSERT_LT(free.size(), w.scratch.cgX.size()) << "the tree's dependent coordinates are eliminated";
  const double kp = effectiveKappa(l.model, l.options) * w.constants.restGutVolume /
                    (w.outputs.gutVolume * w.outputs.gutVolume);  // [Pa/m^3] the rank-one pressure stiffness
  const Eigen::Index nodes = 3 * static_cast<Eigen::Index>(l.model.nodes.size());
  for (unsigned seed : {4u, 5u}) {
    VectorXd u = randomDirection(w, seed);
    detail::maskReduced(l.model.joints, w, tree, u);
    VectorXd ju = u;
    detail::expandJointVelocities(l.model.joints, w, tree, ju);  // J u: anchors move together
    VectorXd expected = forceDerivative(l, ju) - omitted(l, w, ju);
    const Eigen::Map<const VectorXd> g(w.scratch.gutGradient.data(), nodes);
    expected.tail(nodes) -= kp * g.dot(ju.tail(nodes)) * g;
    for (int b = 0; b < l.model.volumes.size(); ++b) {
      const double v = w.outputs.volumeBodyVolume(b);
      const double kb = l.model.volumes.kappa(b) * w.constants.restBodyVolume(b) / (v * v);  // [Pa/m^3]
      const Eigen::Map<const VectorXd> gb(w.scratch.volumeGradient[static_cast<std::size_t>(b)].data(),
                                          nodes);
      expected.tail(nodes) -= kb * gb.dot(ju.tail(nodes)) * gb;
    }
    detail::gatherJointForces(l.model.joints, w, tree, expected);  // J^T
    detail::maskReduced(l.model.joints, w, tree, expected);
    VectorXd uFree(free.size()), expectedFree(free.size());
    for (Eigen::Index i = 0; i < free.size(); ++i) uFree(i) = u(free(i)), expectedFree(i) = expected(free(i));
    Eigen::Index bodyEntries = 0;  // free coordinates are in the order of the full ones: bodies first
    while (bodyEntries < free.size() && free(bodyEntries) < 6 * l.model.bodies.size()) ++bodyEntries;
    expectClose(k * uFree, expectedFree, bodyEntries, 1e-6, "seed " + std::to_string(seed));
  }
  EXPECT_LT((k - k.transpose()).norm(), 1e-9 * k.norm()) << "the factored stiffness is symmetric";
}

TEST(Stiffness, AssembledMatrixIsMinusTheForceDerivativeInTheJointTreesCoordinates) {
  expectAssembledMatrixIsMinusTheForceDerivative(loaded());
}

TEST(Stiffness, AssembledMatrixWithAVolumeBodyIsMinusTheForceDerivative) {
  expectAssembledMatrixIsMinusTheForceDerivative(loaded(true));
}

}  // namespace
}  // namespace pneuma::sim
