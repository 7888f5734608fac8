// Element laws of Zordan et al. 2004: the muscle law (Eq. 1, 2), structural springs, and the gut
// pressure (Eq. 4, 5); forces against finite differences of the elastic energy, and invariance of the
// assembled forces under a random rigid transform (as SOFA's SpringForceField_test).
#include "pneuma/sim/Elements.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <random>

#include "ToyTorso.h"
#include "pneuma/sim/Step.h"

namespace pneuma::sim {
namespace {

MuscleParams params(double alpha, double r) {
  MuscleParams p;
  p.restLength = 0.1;
  p.kac = 400.0;
  p.kpe = 50.0;
  p.damping = 2.0;
  p.alpha = alpha;
  p.r = r;
  return p;
}

// Section 4: muscles act in tension only; zero force in compression (Eq. 1, 2)
TEST(MuscleLaw, ZeroInCompression) {
  const MuscleParams p = params(0.0, 1.0);
  EXPECT_EQ(muscleForce(0.09, 0.0, p), 0.0);
  EXPECT_EQ(muscleForce(0.05, -1.0, p), 0.0);
  EXPECT_DOUBLE_EQ(muscleForce(0.11, 0.0, p), -50.0 * 0.01);
  // an active muscle is slack below its slack length and pulls above it
  const MuscleParams a = params(1.0, 0.8);
  EXPECT_EQ(muscleForce(0.99 * muscleSlackLength(a), 0.0, a), 0.0);
  EXPECT_LT(muscleForce(1.01 * muscleSlackLength(a), 0.0, a), 0.0);
}

// Eq. 2: activation adds -alpha kac (l - r l0); at l = l0 only the active part pulls
TEST(MuscleLaw, Activation) {
  const double l0 = 0.1;
  EXPECT_DOUBLE_EQ(muscleForce(l0, 0.0, params(1.0, 0.8)), -400.0 * (l0 - 0.8 * l0));
  EXPECT_DOUBLE_EQ(muscleForce(l0, 0.0, params(0.5, 0.8)), -0.5 * 400.0 * (l0 - 0.8 * l0));
  EXPECT_EQ(muscleForce(l0, 0.0, params(0.0, 0.8)), 0.0);
  // the slack length lies between r l0 and l0, weighted by the two gains
  EXPECT_NEAR(muscleSlackLength(params(1.0, 0.8)), (400.0 * 0.8 + 50.0) * l0 / 450.0, 1e-15);
}

// Section 4: damping resists shortening, may be "virtually positive" while the total stays in tension
TEST(MuscleLaw, Damping) {
  const MuscleParams p = params(1.0, 0.8);
  const double l = 0.1, elastic = muscleForce(l, 0.0, p);
  EXPECT_DOUBLE_EQ(muscleForce(l, -1.0, p), elastic + 2.0);  // shortening: less tension
  EXPECT_DOUBLE_EQ(muscleForce(l, 1.0, p), elastic - 2.0);   // lengthening: more tension
  EXPECT_EQ(muscleForce(l, -100.0, p), 0.0);                 // never pushes
}

// an accessory muscle recruited above a threshold c0 of its group's command c = alpha (1 - r): silent up to
// it, then its active tension at rest length is kac l0 (c - c0), never more than the group's
TEST(MuscleLaw, RecruitmentThreshold) {
  const double l0 = 0.1, c0 = 0.2;
  // calm's external intercostal command peaks at 0.16 (r 0.84, alpha 1): below the threshold, no activation
  EXPECT_EQ(recruitedActivation(1.0, 0.84, c0), 0.0);
  EXPECT_EQ(recruitedActivation(0.4, 0.6, c0), 0.0);  // deep's at 40 % drive: c = 0.16
  // deep's at full drive: c = 0.4, half of it above the threshold
  const double a = recruitedActivation(1.0, 0.6, c0);
  EXPECT_DOUBLE_EQ(a, 0.5);
  EXPECT_DOUBLE_EQ(-muscleForce(l0, 0.0, params(a, 0.6)), 400.0 * l0 * (0.4 - c0));
  // continuous in the drive, never above the group's activation, and silent for a lengthening command
  for (double alpha = 0.0; alpha <= 1.0; alpha += 0.05) {
    const double e = recruitedActivation(alpha, 0.6, c0);
    EXPECT_GE(e, 0.0);
    EXPECT_LE(e, alpha);
    EXPECT_NEAR(e, std::max(0.0, alpha - c0 / 0.4), 1e-12);
  }
  EXPECT_EQ(recruitedActivation(1.0, 1.0, c0), 0.0);
  EXPECT_EQ(recruitedActivation(1.0, 1.2, c0), 0.0);
  // no threshold: the group's activation
  EXPECT_DOUBLE_EQ(recruitedActivation(0.7, 0.8, 0.0), 0.7);
}

// structural springs are two-sided and damped
TEST(SpringLaw, TwoSided) {
  EXPECT_NEAR(springForce(0.09, 0.0, 0.1, 1000.0, 0.0), 10.0, 1e-12);   // compressed: pushes
  EXPECT_NEAR(springForce(0.11, 0.0, 0.1, 1000.0, 0.0), -10.0, 1e-12);  // stretched: pulls
  EXPECT_NEAR(springForce(0.1, 0.5, 0.1, 1000.0, 3.0), -1.5, 1e-12);
}

// F = -dE/dl for muscles and springs (central differences)
TEST(ElementEnergy, ForceIsMinusEnergyGradient) {
  const double h = 1e-7;
  for (const MuscleParams& p : {params(0.0, 1.0), params(1.0, 0.8), params(0.3, 0.9)}) {
    for (double l : {0.085, 0.096, 0.105, 0.12}) {  // away from the kink at the slack length
      const double fd = -(muscleEnergy(l + h, p) - muscleEnergy(l - h, p)) / (2 * h);
      EXPECT_NEAR(muscleForce(l, 0.0, p), fd, 1e-6) << "l = " << l << " alpha = " << p.alpha;
    }
  }
  for (double l : {0.08, 0.1, 0.13}) {
    const double fd = -(springEnergy(l + h, 0.1, 700.0) - springEnergy(l - h, 0.1, 700.0)) / (2 * h);
    EXPECT_NEAR(springForce(l, 0.0, 0.1, 700.0, 0.0), fd, 1e-6);
  }
}

// Eq. 5 pressure forces equal -dE/dx of the gut energy (Eq. 4 integrated), by finite differences
TEST(GutPressure, ForcesAreMinusEnergyGradient) {
  Eigen::Matrix3Xd x;
  Eigen::Matrix3Xi f;
  test::icosphere(1, x, f);
  const double kappa = 1e4, v0 = enclosedVolume(x, f);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.02, 0.0);
  Eigen::Matrix3Xd y = 0.97 * x;  // compressed: positive pressure
  for (Eigen::Index i = 0; i < y.size(); ++i) y.data()[i] += u(rng);
  const double v = enclosedVolume(y, f);
  Eigen::Matrix3Xd force = Eigen::Matrix3Xd::Zero(3, y.cols());
  addVolumeGradient(y, f, std::max(0.0, gutPressure(kappa, v0, v)), force);
  const double h = 1e-5;  // the energy is O(100 J): smaller steps drown in round-off
  for (Eigen::Index i = 0; i < y.cols(); i += 5) {
    for (int k = 0; k < 3; ++k) {
      Eigen::Matrix3Xd yp = y, ym = y;
      yp(k, i) += h;
      ym(k, i) -= h;
      const double fd =
          -(gutEnergy(kappa, v0, enclosedVolume(yp, f)) - gutEnergy(kappa, v0, enclosedVolume(ym, f))) /
          (2 * h);
      EXPECT_NEAR(force(k, i), fd, 1e-6 * std::max(1.0, std::abs(fd)));
    }
  }
}

// Section 6.2: the centroid-to-face volume of a closed surface is exact for a cube and
// independent of translation
TEST(GutPressure, EnclosedVolumeOfCube) {
  Eigen::Matrix3Xd x(3, 8);
  for (int i = 0; i < 8; ++i) x.col(i) = Eigen::Vector3d(i & 1, (i >> 1) & 1, (i >> 2) & 1) * 0.2;
  Eigen::Matrix3Xi f(3, 12);
  f << 0, 0, 4, 4, 0, 0, 2, 2, 0, 0, 1, 1,  //
      2, 3, 5, 7, 1, 5, 6, 7, 4, 6, 3, 7,   //
      3, 1, 7, 6, 5, 4, 7, 3, 6, 2, 7, 5;
  EXPECT_NEAR(enclosedVolume(x, f), 0.008, 1e-15);
  EXPECT_NEAR(enclosedVolume(x, f), enclosedVolume(x.colwise() + Eigen::Vector3d(3, -1, 2), f), 1e-14);
}

// forces of the whole pipeline rotate with the body: F(Q x + t) = Q F(x) (gravity off)
TEST(ForceAssembly, InvariantUnderRigidTransform) {
  const Model model = test::makeToyTorso(1);
  StepOptions o;
  o.gravity = false;
  Activations act = relaxedActivations();
  act[static_cast<std::size_t>(ElementGroup::Diaphragm)] = {0.8, 1.0};
  act[static_cast<std::size_t>(ElementGroup::IntercostalExternal)] = {0.85, 1.0};

  // a deformed, moving state
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  State s = makeInitialState(model);
  for (Eigen::Index i = 0; i < s.nodePosition.size(); ++i) {
    s.nodePosition.data()[i] += 0.005 * n(rng);
    s.nodeVelocity.data()[i] = 0.05 * n(rng);
  }
  for (int b = 1; b < model.bodies.size(); ++b) {
    s.bodyOrientation[static_cast<std::size_t>(b)] =
        Eigen::AngleAxisd(0.05, Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized());
    s.bodyAngularVelocity.col(b) = 0.1 * Eigen::Vector3d(n(rng), n(rng), n(rng));
  }
  StepWork w1 = makeStepWork(model);
  computeForces(model, s, act, o, w1);

  // the same state seen from a randomly rotated and translated frame
  const Eigen::Matrix3d q = Eigen::Quaterniond::UnitRandom().toRotationMatrix();
  const Eigen::Vector3d t(0.3, -0.2, 1.1);
  State r = s;
  r.nodePosition = (q * s.nodePosition).colwise() + t;
  r.nodeVelocity = q * s.nodeVelocity;
  r.bodyPosition = (q * s.bodyPosition).colwise() + t;
  r.bodyVelocity = q * s.bodyVelocity;
  r.bodyAngularVelocity = q * s.bodyAngularVelocity;
  for (auto& o2 : r.bodyOrientation) o2 = Eigen::Quaterniond(q) * o2;
  StepWork w2 = makeStepWork(model);
  computeForces(model, r, act, o, w2);

  EXPECT_LT((w2.scratch.nodeForce - q * w1.scratch.nodeForce).norm(), 1e-9 * w1.scratch.nodeForce.norm());
  EXPECT_LT((w2.scratch.bodyForce - q * w1.scratch.bodyForce).norm(), 1e-9 * w1.scratch.bodyForce.norm());
  EXPECT_LT((w2.scratch.bodyTorque - q * w1.scratch.bodyTorque).norm(), 1e-9 * w1.scratch.bodyTorque.norm());
  EXPECT_LT((w2.outputs.elementForce - w1.outputs.elementForce).norm(),
            1e-9 * w1.outputs.elementForce.norm());
  EXPECT_GT(w1.outputs.elementForce.cwiseAbs().maxCoeff(), 0.0);
}

}  // namespace
}  // namespace pneuma::sim
