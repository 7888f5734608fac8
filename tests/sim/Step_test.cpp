// The implicit integrator's linear solve (Step.h): the factorized preconditioner is the implicit system
// itself (so a fresh factorization solves backward Euler's linear step exactly), and reusing it over
// several steps changes only the CG iterations, not the motion.
#include "pneuma/sim/Step.h"

#include <gtest/gtest.h>

#include "DefaultModel.h"
#include "ToyTorso.h"
#include "pneuma/sim/BreathStyleController.h"

namespace pneuma::sim {
namespace {

// steps `model` through `seconds` of calm breathing with `o`; returns the largest CG count after the first
// step
int breathe(const Model& model, const StepOptions& o, double dt, double seconds, State& s) {
  BreathStyleController calm(loadBreathStyle("calm"));
  StepWork w = makeStepWork(model);
  int most = 0;
  for (int i = 0; s.time < seconds - 0.5 * dt; ++i) {
    step(model, s, dt, calm.activations(s.time, Metrics{}), o, w);
    if (i > 0) most = std::max(most, w.memory.cgIterations);
  }
  return most;
}

// a fresh factorization solves the step directly (no CG): the assembled sparse system (bodies in the joint
// tree's coordinates, their coupling to the gut nodes, joints, the gut's and the pleural rank-one pressure
// stiffness by Sherman-Morrison) must equal the matrix-free operator that CG solves; with the first
// factorization kept for the whole run and CG converged to 1e-10, the motion agrees with the direct solve of
// every step
TEST(ImplicitSolve, FreshFactorizationSolvesTheLinearStepExactly) {
  StepOptions fresh;
  fresh.integrator = IntegratorKind::ImplicitEulerJoints;
  fresh.preconditionerRefresh = 1;
  StepOptions cg = fresh;
  cg.preconditionerRefresh = 1000000;
  cg.refactorIterations = 1000000;
  cg.refactorElementChanges = 1000000;
  cg.cgMaxIterations = 2000;
  cg.cgTolerance = 1e-10;
  const auto agree = [&](const Model& model, double dt, double seconds) {
    State a = makeInitialState(model), b = makeInitialState(model);
    EXPECT_EQ(breathe(model, fresh, dt, seconds, a), 0) << "every step is solved directly";
    EXPECT_GT(breathe(model, cg, dt, seconds, b), 0) << "the kept factorization needs CG";
    const double motion = (a.nodePosition - model.nodes.rest).cwiseAbs().maxCoeff();  // [m]
    EXPECT_GT(motion, 1e-3);
    EXPECT_LT((a.nodePosition - b.nodePosition).cwiseAbs().maxCoeff(), 1e-5 * motion);
  };
  agree(test::makeToyTorso(2), defaultTimeStep(fresh.integrator), 1.0);
  if (const auto model = test::defaultModel()) {
    // without the abdominal wall's upright tone (Gut::wallToneUpright): it changes the forces, not the
    // operator, but it pulls the wall in from the relaxed rest pose at t = 0, a transient that CG cannot
    // follow from the first step's factorization within cgMaxIterations
    Model relaxed = *model;
    relaxed.gut.wallToneUpright = 0.0;
    agree(relaxed, 0.02, 0.6);
    // with the lungs' recoil: its rank-one stiffness rides on the factorization by Sherman-Morrison too
    Model recoil = relaxed;
    recoil.cavity.recoilPressure = 5.0 * 98.0665;  // [Pa] 5 cmH2O
    recoil.cavity.compliance = 0.2e-3 / 98.0665;   // [m^3/Pa] 0.2 L/cmH2O
    agree(recoil, 0.02, 0.6);
  }
}

// the default refresh policy reuses a factorization for several steps: that changes the CG's path, not
// its answer; solved tightly (1e-7), the motion agrees with refactorizing every step
// the abdominal wall's postural tone (Gut::wallToneUpright) shortens the transversus and obliques' set-point
// upright and only there; every other element and every lying posture keeps its rest length
TEST(PosturalTone, ShortensOnlyTheUprightAbdominalWall) {
  Model toy = test::makeToyTorso(2);
  toy.gut.wallToneUpright = 0.1;
  StepOptions upright, supine;
  supine.posture = Posture::Supine;
  int toned = 0;
  for (int e = 0; e < toy.elements.size(); ++e) {
    const double l0 = toy.elements.restLength(e);
    const bool isWall = toy.elements.group[static_cast<std::size_t>(e)] == ElementGroup::TransversusObliques;
    toned += isWall;
    EXPECT_DOUBLE_EQ(effectiveRestLength(toy, e, upright), isWall ? 0.9 * l0 : l0) << e;
    EXPECT_DOUBLE_EQ(effectiveRestLength(toy, e, supine), l0) << e;
  }
  EXPECT_GT(toned, 0);
}

TEST(ImplicitSolve, StaleFactorizationGivesTheSameMotion) {
  const Model toy = test::makeToyTorso(2);
  StepOptions fresh;
  fresh.integrator = IntegratorKind::ImplicitEulerJoints;
  fresh.preconditionerRefresh = 1;
  fresh.cgTolerance = 1e-7;
  StepOptions reused = fresh;
  reused.preconditionerRefresh = StepOptions{}.preconditionerRefresh;
  const double dt = defaultTimeStep(fresh.integrator);
  State a = makeInitialState(toy), b = makeInitialState(toy);
  breathe(toy, fresh, dt, 2.0, a);
  const int most = breathe(toy, reused, dt, 2.0, b);
  EXPECT_GT(most, 0) << "the stale factorization should need some iterations";
  const double motion = (a.nodePosition - toy.nodes.rest).cwiseAbs().maxCoeff();  // [m]
  EXPECT_GT(motion, 1e-3);
  EXPECT_LT((a.nodePosition - b.nodePosition).cwiseAbs().maxCoeff(), 1e-5 * motion);
}

}  // namespace
}  // namespace pneuma::sim

namespace pneuma::sim {
namespace {

// a rib on a rib-neck hinge (Joints): a fixed parent, one child, axis a, k about every direction plus k_lock
// off a
Model hingedRib(const Eigen::Vector3d& axis, double k, double kLock) {
  Model m;
  m.gravity.setZero();
  test::addBody(m, "spine", true, 1.0, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity());
  test::addBody(m, "rib", false, 0.02, Eigen::Vector3d(0.1, 0.0, 0.0), 1e-5 * Eigen::Matrix3d::Identity());
  test::addJoint(m, "costovertebral", 0, 1, Eigen::Vector3d::Zero(), 0.0, k, axis, kLock);
  return m;
}

// the torque on a rib turned by theta is -K theta, K = k I + k_lock (I - a a^T): about the neck axis only k
// resists, across it k + k_lock; the same for the potential, whose derivative along theta is the torque
TEST(RibNeckHinge, TorqueIsKThetaAndTheGradientOfItsEnergy) {
  const Eigen::Vector3d a =
      Eigen::Vector3d(std::cos(0.9), -std::sin(0.9), 0.0);  // about 52 degrees from transverse
  const double k = 5.0, kLock = 100.0;                      // [N m/rad]
  const Model m = hingedRib(a, k, kLock);
  const Eigen::Vector3d across = a.cross(Eigen::Vector3d::UnitZ()).normalized();
  for (const Eigen::Vector3d& dir : {a, across, Eigen::Vector3d(a + across).normalized()}) {
    const double angle = 0.01;  // [rad]
    State s = makeInitialState(m);
    s.bodyOrientation[1] = Eigen::Quaterniond(Eigen::AngleAxisd(angle, dir));
    StepWork w = makeStepWork(m);
    computeForces(m, s, relaxedActivations(), StepOptions{}, w);
    const Eigen::Matrix3d K =
        k * Eigen::Matrix3d::Identity() + kLock * (Eigen::Matrix3d::Identity() - a * a.transpose());
    const Eigen::Vector3d expected = -K * (angle * dir);
    EXPECT_LT((w.scratch.bodyTorque.col(1) - expected).norm(), 1e-9 * expected.norm()) << dir.transpose();
    // energy: E(angle) = 1/2 theta^T K theta, so dE/dangle = -tau . dir
    auto energy = [&](double th) {
      State t = makeInitialState(m);
      t.bodyOrientation[1] = Eigen::Quaterniond(Eigen::AngleAxisd(th, dir));
      Metrics out;
      computeMetrics(m, t, relaxedActivations(), StepOptions{}, w, out);
      return out.elasticEnergy;
    };
    const double h = 1e-5;
    EXPECT_NEAR((energy(angle + h) - energy(angle - h)) / (2 * h), -w.scratch.bodyTorque.col(1).dot(dir),
                1e-6);
  }
  // off the axis the rib is (k + k_lock) / k = 21 times stiffer than about it
  State s = makeInitialState(m);
  StepWork w = makeStepWork(m);
  s.bodyOrientation[1] = Eigen::Quaterniond(Eigen::AngleAxisd(0.01, across));
  computeForces(m, s, relaxedActivations(), StepOptions{}, w);
  const double offAxis = w.scratch.bodyTorque.col(1).norm();
  s.bodyOrientation[1] = Eigen::Quaterniond(Eigen::AngleAxisd(0.01, a));
  computeForces(m, s, relaxedActivations(), StepOptions{}, w);
  EXPECT_NEAR(offAxis / w.scratch.bodyTorque.col(1).norm(), (k + kLock) / k, 1e-6);
}

// the hinge's axis turns with its parent: a rotation of the whole pair leaves the joint unloaded, and a rib
// turned about the parent's turned axis meets only k
TEST(RibNeckHinge, AxisFollowsTheParent) {
  const Eigen::Vector3d a = Eigen::Vector3d::UnitX();
  Model m = hingedRib(a, 5.0, 100.0);
  m.bodies.isFixed[0] = 0;  // a moving parent
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, 0.5, 0.8).normalized()));
  State s = makeInitialState(m);
  s.bodyOrientation[0] = turn;
  s.bodyOrientation[1] = Eigen::Quaterniond(Eigen::AngleAxisd(0.02, turn * a)) * turn;
  StepWork w = makeStepWork(m);
  computeForces(m, s, relaxedActivations(), StepOptions{}, w);
  EXPECT_LT((w.scratch.bodyTorque.col(1) + 5.0 * 0.02 * (turn * a)).norm(), 1e-9);
}

}  // namespace
}  // namespace pneuma::sim

namespace pneuma::sim {
namespace {

// the pleural pressure (Cavity) is the gradient of its potential: on the node it pulls hardest, the force
// change it makes equals minus the finite-difference derivative of the elastic energy, and it pulls the walls
// inward
TEST(PleuralPressure, ForceIsMinusTheGradientOfTheRecoilEnergy) {
  Model off = test::makeToyTorso();
  off.gravity.setZero();
  ASSERT_GT(off.cavity.triangles.cols(), 0);
  Model on = off;
  on.cavity.recoilPressure = 490.0;  // [Pa] 5 cmH2O
  on.cavity.compliance = 2.0e-6;     // [m^3/Pa] 0.2 L/cmH2O
  const State s0 = makeInitialState(on);
  StepWork wOn = makeStepWork(on), wOff = makeStepWork(off);
  computeForces(on, s0, relaxedActivations(), StepOptions{}, wOn);
  computeForces(off, s0, relaxedActivations(), StepOptions{}, wOff);
  EXPECT_NEAR(wOn.outputs.pleuralPressure, -490.0, 1e-9);  // at the rest volume Ppl = -P0
  const Eigen::Matrix3Xd pull = wOn.scratch.nodeForce - wOff.scratch.nodeForce;
  Eigen::Index node = 0;
  pull.colwise().norm().maxCoeff(&node);
  ASSERT_GT(pull.col(node).norm(), 0.0);
  auto energy = [&](const Model& m, int k, double h) {
    State s = s0;
    s.nodePosition(k, node) += h;
    StepWork w = makeStepWork(m);
    Metrics out;
    computeMetrics(m, s, relaxedActivations(), StepOptions{}, w, out);
    return out.elasticEnergy;
  };
  const double h = 1e-6;  // [m]
  for (int k = 0; k < 3; ++k) {
    const double dOn = (energy(on, k, h) - energy(on, k, -h)) / (2 * h);
    const double dOff = (energy(off, k, h) - energy(off, k, -h)) / (2 * h);
    EXPECT_NEAR(-(dOn - dOff), pull(k, node), 1e-4 * pull.col(node).norm() + 1e-9) << k;
  }
  // suction: the node is pulled into the cavity, against the cavity's outward volume gradient
  Eigen::Matrix3Xd x, grad = Eigen::Matrix3Xd::Zero(3, on.cavity.vertices.size());
  anchorPositions(on.cavity.vertices, s0, x);
  addVolumeGradient(x, on.cavity.triangles, 1.0, grad);
  double outward = 0.0;
  for (int i = 0; i < on.cavity.vertices.size(); ++i)
    for (int j = 0; j < 3; ++j)
      if (on.cavity.vertices.body[static_cast<std::size_t>(i)] < 0 && on.cavity.vertices.nodes(j, i) == node)
        outward += on.cavity.vertices.weights(j, i) * grad.col(i).dot(pull.col(node));
  EXPECT_LT(outward, 0.0);
}

}  // namespace
}  // namespace pneuma::sim

namespace pneuma::sim {
namespace {

// the posture turns gravity into the body frame (postureGravity()): each posture pulls every free node and
// body with m g along its own axis (supine posteriorly, -y), and the gravity energy of computeMetrics() is
// the potential of that force (its finite-difference gradient on a displaced node equals minus the force)
TEST(Posture, GravityPointsAlongThePostureAxisAndIsTheGradientOfItsEnergy) {
  const Model toy = test::makeToyTorso();
  const double g = toy.gravity.norm();
  ASSERT_GT(g, 0.0);
  const std::pair<const char*, Eigen::Vector3d> expected[] = {{"upright", -Eigen::Vector3d::UnitZ()},
                                                              {"supine", -Eigen::Vector3d::UnitY()},
                                                              {"prone", Eigen::Vector3d::UnitY()},
                                                              {"left-lateral", -Eigen::Vector3d::UnitX()},
                                                              {"right-lateral", Eigen::Vector3d::UnitX()}};
  const State s0 = makeInitialState(toy);
  int node = -1;
  for (int n = 0; n < toy.nodes.size() && node < 0; ++n)
    if (!toy.nodes.isFixed(n)) node = n;
  ASSERT_GE(node, 0);
  for (const auto& [name, down] : expected) {
    SCOPED_TRACE(name);
    StepOptions on, off;
    ASSERT_TRUE(postureFromName(name, on.posture));
    EXPECT_EQ(postureName(on.posture), std::string(name));
    off.gravity = false;
    off.posture = on.posture;
    EXPECT_EQ(postureGravity(toy, on), g * down);  // quarter turns are exact
    EXPECT_EQ(postureGravity(toy, off), Eigen::Vector3d::Zero());
    StepWork wOn = makeStepWork(toy), wOff = makeStepWork(toy);
    computeForces(toy, s0, relaxedActivations(), on, wOn);
    computeForces(toy, s0, relaxedActivations(), off, wOff);
    const Eigen::Vector3d pull = wOn.scratch.nodeForce.col(node) - wOff.scratch.nodeForce.col(node);
    EXPECT_LT((pull - toy.nodes.mass(node) * g * down).norm(), 1e-12 * toy.nodes.mass(node) * g);
    auto energy = [&](int k, double h) {
      State s = s0;
      s.nodePosition(k, node) += h;
      StepWork w = makeStepWork(toy);
      Metrics out;
      computeMetrics(toy, s, relaxedActivations(), on, w, out);
      return out.gravityEnergy;
    };
    const double h = 1e-4;  // [m] the energy is linear in x
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(-(energy(k, h) - energy(k, -h)) / (2 * h), pull(k), 1e-9 * toy.nodes.mass(node) * g) << k;
  }
  Posture p = Posture::Supine;
  EXPECT_FALSE(postureFromName("sitting", p));
  EXPECT_EQ(p, Posture::Supine);
  EXPECT_EQ(postureNames(), "upright, supine, prone, left-lateral, right-lateral");
}

}  // namespace
}  // namespace pneuma::sim

namespace pneuma::sim {
namespace {

// the diaphragm's halves follow the side of each strand's rest midpoint (RAS: +x right), strands on the
// midline belong to both, and a paralysed half scales only its own strands' active gain
TEST(Step, HemidiaphragmHalvesFollowTheSideOfTheRestMidpoint) {
  const Model toy = test::makeToyTorso();
  const StepWork w = makeStepWork(toy);
  const State rest = makeInitialState(toy);
  StepOptions leftParalysed;
  leftParalysed.hemidiaphragmActiveScale = {0.0, 1.0};
  const StepOptions normal;
  int left = 0, right = 0;
  for (int e = 0; e < toy.elements.size(); ++e) {
    const double x = 0.5 * (anchorPosition(toy.elements.endA, e, rest).x() +
                            anchorPosition(toy.elements.endB, e, rest).x());
    const double share = w.constants.elementRightShare(e);
    EXPECT_EQ(share, x > 1e-3 ? 1.0 : x < -1e-3 ? 0.0 : 0.5) << "element " << e << " at x = " << x;
    EXPECT_EQ(hemidiaphragmScale(toy, w.constants, e, normal), 1.0);
    const bool isDiaphragm = toy.elements.group[static_cast<std::size_t>(e)] == ElementGroup::Diaphragm;
    EXPECT_EQ(hemidiaphragmScale(toy, w.constants, e, leftParalysed), isDiaphragm ? share : 1.0);
    left += isDiaphragm && share == 0.0 ? 1 : 0;
    right += isDiaphragm && share == 1.0 ? 1 : 0;
  }
  EXPECT_GT(left, 0);  // both halves have strands of their own
  EXPECT_GT(right, 0);
}

}  // namespace
}  // namespace pneuma::sim

namespace pneuma::sim {
namespace {

// a postural support carries its body's weight in every posture (postureSupport()): an arm held out
// horizontally from a fixed shoulder on a free ball joint stays where it is in all five postures, and
// without the support gravity swings it
TEST(PosturalSupport, CarriesItsBodyAgainstGravityInEveryPosture) {
  Model m;
  test::addBody(m, "neck", true, 1.0, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity());
  const double mass = 2.0;  // [kg] an upper arm
  test::addBody(m, "arm", false, mass, Eigen::Vector3d(0.15, 0.05, 0.0), 0.01 * Eigen::Matrix3d::Identity());
  test::addJoint(m, "shoulder", 0, 1, Eigen::Vector3d::Zero(), 0.0, 0.0);
  m.bodies.isSupported = {0, 1};
  for (const char* name : {"upright", "supine", "prone", "left-lateral", "right-lateral"}) {
    SCOPED_TRACE(name);
    StepOptions o;
    ASSERT_TRUE(postureFromName(name, o.posture));
    EXPECT_EQ(postureSupport(m, 1, o), -mass * postureGravity(m, o));
    EXPECT_EQ(postureSupport(m, 0, o), Eigen::Vector3d::Zero());
    State s = makeInitialState(m);
    StepWork w = makeStepWork(m);
    for (int i = 0; i < 100; ++i) step(m, s, 0.01, relaxedActivations(), o, w);
    EXPECT_LT((s.bodyPosition.col(1) - m.bodies.com.col(1)).norm(), 1e-9);
  }
  // unsupported, the arm falls about its joint
  m.bodies.isSupported.clear();
  State s = makeInitialState(m);
  StepWork w = makeStepWork(m);
  for (int i = 0; i < 30; ++i) step(m, s, 0.01, relaxedActivations(), StepOptions{}, w);
  EXPECT_GT((s.bodyPosition.col(1) - m.bodies.com.col(1)).norm(), 0.01);
}

// a support carried a height h above the centre of mass (Bodies::supportHeight) leaves the body weightless
// and turns it back to its rest orientation as a pendulum of length h: torque m |g| h sin(angle) (against
// the derivative of computeMetrics()'s gravity energy, m |g| h (1 - cos(angle))) in every posture, and a free
// body released 0.05 rad off its rest orientation swings back through it after a quarter period
// (pi / 2) sqrt(I / (m |g| h)), its centre of mass still
TEST(PosturalSupport, ABodyCarriedAboveItsCentreOfMassTurnsBackAsAPendulum) {
  Model m;
  test::addBody(m, "neck", true, 1.0, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity());
  const double mass = 2.0, inertia = 0.01, h = 0.3;  // [kg], [kg m^2], [m]
  test::addBody(m, "arm", false, mass, Eigen::Vector3d(0.15, 0.05, -0.2),
                inertia * Eigen::Matrix3d::Identity());
  m.bodies.isSupported = {0, 1};
  m.bodies.supportHeight = Eigen::Vector2d(0.0, h);
  const Eigen::Vector3d axis = Eigen::Vector3d(1.0, 0.0, 0.0);
  for (const char* name : {"upright", "supine", "left-lateral"}) {
    SCOPED_TRACE(name);
    StepOptions o;
    ASSERT_TRUE(postureFromName(name, o.posture));
    const double g = postureGravity(m, o).norm();
    auto turned = [&](double angle) {
      State s = makeInitialState(m);
      s.bodyOrientation[1] = Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis));
      return s;
    };
    auto energy = [&](double angle) {
      StepWork w = makeStepWork(m);
      Metrics out;
      computeMetrics(m, turned(angle), relaxedActivations(), o, w, out);
      return out.gravityEnergy;
    };
    // the support's axis is vertical in this posture; the body turns about x, across it except on its side
    const double across = postureGravity(m, o).normalized().cross(axis).norm();
    const double angle = 0.2;
    StepWork w = makeStepWork(m);
    computeForces(m, turned(angle), relaxedActivations(), o, w);
    EXPECT_LT(w.scratch.bodyForce.col(1).norm(), 1e-12) << "weightless";
    EXPECT_NEAR(energy(angle), mass * g * h * (1.0 - std::cos(across * angle)), 1e-3 * mass * g * h * angle);
    const double d = 1e-6;
    EXPECT_NEAR(w.scratch.bodyTorque.col(1).dot(axis), -(energy(angle + d) - energy(angle - d)) / (2 * d),
                1e-6);
    if (across == 1.0) {
      EXPECT_NEAR(w.scratch.bodyTorque.col(1).dot(axis), -mass * g * h * std::sin(angle), 1e-9);
    }
  }
  // released upright: it swings back through its rest orientation after a quarter period
  State s = makeInitialState(m);
  s.bodyOrientation[1] = Eigen::Quaterniond(Eigen::AngleAxisd(0.05, axis));
  StepWork w = makeStepWork(m);
  const double dt = 1e-4, quarter = 0.5 * M_PI * std::sqrt(inertia / (mass * 9.81 * h));
  double t = 0.0;
  while (Eigen::AngleAxisd(s.bodyOrientation[1]).axis().dot(axis) *
                 Eigen::AngleAxisd(s.bodyOrientation[1]).angle() >
             0.0 &&
         t < 4.0 * quarter) {
    step(m, s, dt, relaxedActivations(), StepOptions{}, w);
    t += dt;
  }
  EXPECT_NEAR(t, quarter, 0.02 * quarter);
  EXPECT_LT((s.bodyPosition.col(1) - m.bodies.com.col(1)).norm(), 1e-9);
}

}  // namespace
}  // namespace pneuma::sim
