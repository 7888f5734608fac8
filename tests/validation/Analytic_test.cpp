// Analytic checks of the integrators and the joint solver (docs/STYLE "Tests"; Zordan et al. 2004
// Sections 5, 6): a spring-mass period, a pendulum on a ball joint, a pressurised closed spring sphere, and
// the stopping distance of a node under the visceral drag (Gut::drag).
// Every check runs with both integrators at their default time step.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <vector>

#include "ToyTorso.h"
#include "pneuma/sim/Elements.h"
#include "pneuma/sim/Step.h"

namespace pneuma::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

class Integrators : public ::testing::TestWithParam<IntegratorKind> {};

// mean period [s] from the upward zero crossings of signal(state), sampled every step
double measurePeriod(const Model& model, State& s, const StepOptions& o, double duration,
                     const std::function<double(const State&)>& signal) {
  StepWork w = makeStepWork(model);
  const double dt = test::toyTimeStep(o.integrator);
  std::vector<double> crossings;
  double prev = signal(s);
  while (s.time < duration) {
    step(model, s, dt, relaxedActivations(), o, w);
    const double cur = signal(s);
    if (prev < 0.0 && cur >= 0.0) crossings.push_back(s.time - dt * cur / (cur - prev));
    prev = cur;
    EXPECT_LT(w.outputs.maxJointError, 1e-4) << "joint error above 0.1 mm at t = " << s.time;
  }
  if (crossings.size() < 2) return 0.0;
  return (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
}

// undamped spring-mass: T = 2 pi sqrt(m / k), at a breathing-scale frequency (1.6 Hz)
TEST_P(Integrators, SpringMassPeriodWithinOnePercent) {
  Model m;
  m.nodes.rest = Eigen::Matrix3Xd::Zero(3, 2);
  m.nodes.rest(0, 1) = 0.1;
  m.nodes.mass = Eigen::Vector2d(0.0, 0.2);
  m.nodes.region = {NodeRegion::Fixed, NodeRegion::Wall};
  test::addElement(m, ElementGroup::Cartilage, test::End{-1, 0, {}}, test::End{-1, 1, {}}, 0.0, 20.0, 0.0);
  StepOptions o;
  o.integrator = GetParam();
  o.gravity = false;
  State s = makeInitialState(m);
  s.nodePosition(0, 1) += 0.01;
  const double period =
      measurePeriod(m, s, o, 4.0, [](const State& st) { return st.nodePosition(0, 1) - 0.1; });
  const double expected = 2.0 * kPi * std::sqrt(0.2 / 20.0);
  EXPECT_NEAR(period, expected, 0.01 * expected);
}

// compound pendulum on a ball joint: T = 2 pi sqrt(I_pivot / (m g L)), small amplitude
TEST_P(Integrators, PendulumOnBallJointPeriodWithinOnePercent) {
  Model m;
  const double mass = 1.0, length = 0.5, icm = 0.4 * mass * 0.02 * 0.02;
  test::addBody(m, "pivot", true, 1.0, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity());
  test::addBody(m, "bob", false, mass, Eigen::Vector3d(0, 0, -length), Eigen::Matrix3d::Identity() * icm);
  test::addJoint(m, "ball", 0, 1, Eigen::Vector3d::Zero(), 0.0, 0.0);
  StepOptions o;
  o.integrator = GetParam();
  State s = makeInitialState(m);
  const Eigen::AngleAxisd tilt(0.05, Eigen::Vector3d::UnitX());
  s.bodyOrientation[1] = Eigen::Quaterniond(tilt);
  s.bodyPosition.col(1) = tilt * Eigen::Vector3d(0, 0, -length);
  const double period = measurePeriod(m, s, o, 8.0, [](const State& st) { return st.bodyPosition(1, 1); });
  const double expected = 2.0 * kPi * std::sqrt((icm + mass * length * length) / (mass * 9.81 * length)) *
                          (1.0 + 0.05 * 0.05 / 16.0);
  EXPECT_NEAR(period, expected, 0.01 * expected);
}

// closed sphere of two-sided springs inflated by the gut pressure law (Eq. 4, 5). With every edge
// scaled by lambda, equilibrium is k (lambda - s) sum L_e^2 = kappa (lambda^-3 - 1) 3 V_mesh lambda^2,
// where s is the springs' rest scale and V_mesh the polyhedron's rest volume.
TEST_P(Integrators, PressurisedSpringSphereReachesEquilibriumRadius) {
  Model m;
  Eigen::Matrix3Xd unit;
  test::icosphere(2, unit, m.gut.triangles);
  const double r0 = 0.1, restScale = 0.8, k = 500.0;
  m.nodes.rest = r0 * unit;
  m.nodes.mass = Eigen::VectorXd::Constant(unit.cols(), 0.01);
  m.nodes.region.assign(static_cast<std::size_t>(unit.cols()), NodeRegion::Wall);
  m.gut.kappa = 2000.0;
  double sumL2 = 0.0;
  for (Eigen::Index f = 0; f < m.gut.triangles.cols(); ++f) {
    for (int e = 0; e < 3; ++e) {
      const int a = m.gut.triangles(e, f), b = m.gut.triangles((e + 1) % 3, f);
      if (a > b) continue;  // each edge once (the other face has it as b -> a)
      test::addElement(m, ElementGroup::Cartilage, test::End{-1, a, {}}, test::End{-1, b, {}}, 0.0, k, 0.3);
      m.elements.restLength(m.elements.size() - 1) *= restScale;
      const double len = (m.nodes.rest.col(b) - m.nodes.rest.col(a)).norm();
      sumL2 += len * len;
    }
  }
  const double vMesh = enclosedVolume(m.nodes.rest, m.gut.triangles);
  // bisection for the equilibrium scale
  double lo = restScale, hi = 1.0;
  for (int i = 0; i < 100; ++i) {
    const double l = 0.5 * (lo + hi);
    const double residual =
        k * (l - restScale) * sumL2 - m.gut.kappa * (1.0 / (l * l * l) - 1.0) * 3.0 * vMesh * l * l;
    (residual > 0.0 ? hi : lo) = l;
  }
  const double expected = 0.5 * (lo + hi) * r0;

  StepOptions o;
  o.integrator = GetParam();
  o.gravity = false;
  State s = makeInitialState(m);
  StepWork w = makeStepWork(m);
  const double dt = test::toyTimeStep(o.integrator);
  while (s.time < 3.0) step(m, s, dt, relaxedActivations(), o, w);
  const double radius = s.nodePosition.colwise().norm().mean();
  EXPECT_NEAR(radius, expected, 0.002 * expected);
  EXPECT_LT(expected, 0.99 * r0);  // the test is not trivial: the sphere shrinks
  EXPECT_GT(expected, 1.01 * restScale * r0);
}

// a free node launched at v0 under the visceral drag alone (m dv/dt = -beta m v) stops after v0 / beta, with
// beta = gut.drag times StepOptions::gutDragScale
TEST_P(Integrators, VisceralDragStopsAFreeNodeAfterItsAnalyticDistance) {
  Model m;
  m.nodes.rest = Eigen::Matrix3Xd::Zero(3, 1);
  m.nodes.mass = Eigen::VectorXd::Constant(1, 0.05);
  m.nodes.region = {NodeRegion::Wall};
  m.gut.drag = 4.0;
  for (const double scale : {1.0, 2.0}) {
    StepOptions o;
    o.integrator = GetParam();
    o.gravity = false;
    o.gutDragScale = scale;
    State s = makeInitialState(m);
    const Eigen::Vector3d v0(0.1, -0.05, 0.02);
    s.nodeVelocity.col(0) = v0;
    StepWork w = makeStepWork(m);
    const double dt = test::toyTimeStep(o.integrator);
    while (s.time < 5.0) step(m, s, dt, relaxedActivations(), o, w);  // at least 20 time constants
    const Eigen::Vector3d expected = v0 / (m.gut.drag * scale);
    EXPECT_LT((s.nodePosition.col(0) - expected).norm(), 0.005 * expected.norm())
        << "scale " << scale << ": " << s.nodePosition.col(0).transpose();
    EXPECT_LT(s.nodeVelocity.col(0).norm(), 1e-6 * v0.norm());
  }
}

INSTANTIATE_TEST_SUITE_P(Sim, Integrators,
                         ::testing::Values(IntegratorKind::SymplecticEuler,
                                           IntegratorKind::ImplicitEulerJoints),
                         [](const auto& info) { return test::gtestName(integratorName(info.param)); });

}  // namespace
}  // namespace pneuma::sim
