// The Simulation logic layer: parameter validation before running, blow-up detection, determinism
// (bit-identical recordings), the recorder, the breath-style controller (Zordan et al. 2004,
// Section 7, Table 2) and the Summary's cycle analysis.
#include "ToyTorso.h"

#include "pneuma/sim/BreathStyleController.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/Simulation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

namespace pneuma::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::shared_ptr<const Model> toy() {
  static const auto model = std::make_shared<const Model>(test::makeToyTorso(1));
  return model;
}

std::unique_ptr<Controller> calm() { return std::make_unique<BreathStyleController>(loadBreathStyle("calm")); }

// expects an Error whose message contains `needle`
template <typename F>
void expectError(F&& f, const std::string& needle) {
  try {
    f();
    ADD_FAILURE() << "no Error thrown, expected one mentioning '" << needle << "'";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(SimulationInput, RejectsBadOptionsBeforeRunning) {
  SimulationOptions o;
  o.dt = -1e-3;
  expectError([&] { Simulation(toy(), calm(), o); }, "dt");
  o = {};
  o.outputRate = 0.0;
  expectError([&] { Simulation(toy(), calm(), o); }, "outputRate");
  o = {};
  o.step.activeGainScale[2] = -1.0;
  expectError([&] { Simulation(toy(), calm(), o); }, "activeGainScale.diaphragm");
  o = {};
  o.settleTime = std::nan("");
  expectError([&] { Simulation(toy(), calm(), o); }, "settleTime");
  o = {};
  o.step.gutDragScale = -0.5;
  expectError([&] { Simulation(toy(), calm(), o); }, "gutDragScale");
}

// a controller may cap the default time step (the pattern drive's 10 ms); an explicit dt still wins, and a
// controller installed mid-run brings its cap with it
TEST(Simulation, TimeStepFollowsTheControllersCapUnlessDtIsGiven) {
  struct Capped : BreathStyleController {
    Capped() : BreathStyleController(loadBreathStyle("calm")) {}
    double maxTimeStep() const override { return 0.004; }
  };
  SimulationOptions o;
  Simulation byDefault(toy(), calm(), o);
  EXPECT_DOUBLE_EQ(byDefault.dt(), defaultTimeStep(o.step.integrator));
  Simulation capped(toy(), std::make_unique<Capped>(), o);
  EXPECT_DOUBLE_EQ(capped.dt(), 0.004);
  capped.advance(0.02);
  EXPECT_EQ(capped.state().steps, 5);
  byDefault.setController(std::make_unique<Capped>());
  EXPECT_DOUBLE_EQ(byDefault.dt(), 0.004);
  o.dt = 0.002;
  Simulation given(toy(), std::make_unique<Capped>(), o);
  EXPECT_DOUBLE_EQ(given.dt(), 0.002);
}

TEST(SimulationInput, RejectsNegativeGainsAndMasses) {
  Model bad = *toy();
  bad.elements.kac(3) = -5.0;
  expectError([&] { Simulation(std::make_shared<const Model>(bad), calm()); }, "kac");
  bad = *toy();
  bad.bodies.mass(2) = -1.0;
  expectError([&] { Simulation(std::make_shared<const Model>(bad), calm()); }, "mass");
}

TEST(SimulationInput, RejectsContractionRatioOutOfRange) {
  BreathStyle s = loadBreathStyle("calm");
  s.diaphragmR = 1.6;
  expectError([&] { BreathStyleController c(s); }, "diaphragm_r");
  s = loadBreathStyle("calm");
  s.intercostalAmplitude = 0.95;  // mean - amplitude < 0
  expectError([&] { BreathStyleController c(s); }, "intercostal_mean - intercostal_amplitude");
  Activations a = relaxedActivations();
  a[0].r = 0.0;
  expectError([&] { validateActivations(a); }, "activations.intercostal_external.r");
}

TEST(SimulationInput, UnknownPresetListsValidNames) {
  expectError([] { loadBreathStyle("yawning"); }, "valid: calm, deep, forced-exhale, panting");
  expectError([] { parseBreathStyle("{\"name\": \"x\", \"breaths_per_minute\": -3, \"diaphragm_r\": 0.8, "
                                    "\"intercostal_mean\": 0.9, \"intercostal_amplitude\": 0.1}", "x.json"); },
              "breaths_per_minute");
}

// a step that cannot be integrated stably names the time, the part and the likely cause
TEST(SimulationInput, BlowUpIsReportedWithCause) {
  Model stiff = *toy();
  stiff.elements.kpe *= 1e6;
  SimulationOptions o;
  o.step.integrator = IntegratorKind::SymplecticEuler;
  o.dt = 0.01;
  Simulation sim(std::make_shared<const Model>(stiff), calm(), o);
  expectError([&] { sim.advance(2.0); }, "too large for the stiffness");
}

// Section 7 / Table 2: diaphragm step, out-of-phase intercostal sinusoids, rectus only when forced
TEST(BreathStyleController, SignalsFollowSection7) {
  BreathStyleController c(loadBreathStyle("calm"));
  const double period = 4.0;
  const Metrics none;
  auto at = [&](double t, ElementGroup g) { return c.activations(t, none)[static_cast<std::size_t>(g)]; };
  EXPECT_EQ(at(0.1 * period, ElementGroup::Diaphragm).alpha, 1.0);
  EXPECT_DOUBLE_EQ(at(0.1 * period, ElementGroup::Diaphragm).r, 0.85);
  EXPECT_EQ(at(0.6 * period, ElementGroup::Diaphragm).alpha, 0.0);
  // outer intercostals: r = 1.0 at the start of inhale, 0.84 at its end; inner the opposite
  EXPECT_NEAR(at(0.0, ElementGroup::IntercostalExternal).r, 1.0, 1e-12);
  EXPECT_NEAR(at(0.5 * period, ElementGroup::IntercostalExternal).r, 0.84, 1e-12);
  EXPECT_NEAR(at(0.0, ElementGroup::IntercostalInternal).r, 0.84, 1e-12);
  EXPECT_NEAR(at(0.5 * period, ElementGroup::IntercostalInternal).r, 1.0, 1e-12);
  for (double t = 0.0; t < period; t += 0.1) {
    EXPECT_EQ(at(t, ElementGroup::Rectus).alpha, 0.0);
    EXPECT_NEAR(at(t, ElementGroup::IntercostalExternal).r + at(t, ElementGroup::IntercostalInternal).r, 1.84, 1e-12);
  }
  BreathStyleController forced(loadBreathStyle("forced-exhale"));
  EXPECT_EQ(forced.activations(1.0, none)[static_cast<std::size_t>(ElementGroup::Rectus)].alpha, 0.0);   // inhale
  EXPECT_EQ(forced.activations(4.0, none)[static_cast<std::size_t>(ElementGroup::Rectus)].alpha, 1.0);   // exhale
  EXPECT_DOUBLE_EQ(forced.activations(4.0, none)[static_cast<std::size_t>(ElementGroup::Rectus)].r, 0.5);
  EXPECT_EQ(forced.activations(7.0, none)[static_cast<std::size_t>(ElementGroup::Rectus)].alpha, 0.0);   // after the one cycle
}

TEST(BreathStyle, PresetsLoadWithTable2Rates) {
  EXPECT_EQ(breathStyleNames(), (std::vector<std::string>{"calm", "deep", "forced-exhale", "panting"}));
  EXPECT_EQ(loadBreathStyle("calm").breathsPerMinute, 15.0);
  EXPECT_EQ(loadBreathStyle("deep").breathsPerMinute, 12.0);
  EXPECT_EQ(loadBreathStyle("panting").breathsPerMinute, 60.0);
  EXPECT_TRUE(loadBreathStyle("forced-exhale").rectusActive);
  for (const auto& n : breathStyleNames()) EXPECT_FALSE(loadBreathStyle(n).note.empty()) << n;
}

// partial activation levels (panting) reach the muscles, and a preset survives serialisation
TEST(BreathStyle, ActivationLevelsApplyAndRoundTrip) {
  const BreathStyle panting = loadBreathStyle("panting");
  BreathStyleController c(panting);
  const Metrics none;
  const Activations a = c.activations(0.3, none);  // inhale, after the diaphragm's 0.2 s rise
  EXPECT_DOUBLE_EQ(a[static_cast<std::size_t>(ElementGroup::Diaphragm)].alpha, panting.diaphragmAlpha);
  EXPECT_DOUBLE_EQ(a[static_cast<std::size_t>(ElementGroup::IntercostalExternal)].alpha, panting.intercostalAlpha);
  EXPECT_LT(panting.diaphragmAlpha, 1.0);
  const std::string text = serializeBreathStyle(panting);
  EXPECT_EQ(serializeBreathStyle(parseBreathStyle(text, "panting.json")), text);
  BreathStyle bad = panting;
  bad.intercostalAlpha = 1.5;
  EXPECT_THROW(validateBreathStyle(bad), Error);
}

// the diaphragm's step rises and falls as s(x) = 3x^2 - 2x^3 over the rise time, so its activation is continuous
// across the inhale and exhale edges; the rise must fit into both phases
TEST(BreathStyle, DiaphragmStepRisesAndFallsSmoothly) {
  BreathStyle calm = loadBreathStyle("calm");  // period 4 s, inhale 1.6 s
  calm.diaphragmRiseTime = 0.2;
  BreathStyleController c(calm);
  const Metrics none;
  const auto alpha = [&](double t) { return c.activations(t, none)[static_cast<std::size_t>(ElementGroup::Diaphragm)].alpha; };
  EXPECT_DOUBLE_EQ(alpha(0.0), 0.0);
  EXPECT_NEAR(alpha(0.05), calm.diaphragmAlpha * (3 * 0.0625 - 2 * 0.015625), 1e-12);
  EXPECT_NEAR(alpha(0.1), 0.5 * calm.diaphragmAlpha, 1e-12);
  EXPECT_DOUBLE_EQ(alpha(1.0), calm.diaphragmAlpha);
  EXPECT_NEAR(alpha(1.6 - 1e-9), calm.diaphragmAlpha, 1e-9);
  EXPECT_NEAR(alpha(1.6 + 1e-9), calm.diaphragmAlpha, 1e-6);
  EXPECT_NEAR(alpha(1.7), 0.5 * calm.diaphragmAlpha, 1e-12);
  EXPECT_DOUBLE_EQ(alpha(1.9), 0.0);
  EXPECT_DOUBLE_EQ(c.activations(1.0, none)[static_cast<std::size_t>(ElementGroup::Diaphragm)].r, calm.diaphragmR);
  BreathStyle tooSlow = calm;
  tooSlow.diaphragmRiseTime = 1.7;  // longer than the 1.6 s inhale
  EXPECT_THROW(validateBreathStyle(tooSlow), Error);
  tooSlow.diaphragmRiseTime = -0.1;
  EXPECT_THROW(validateBreathStyle(tooSlow), Error);
}

// Summary: a pure sine of amplitude A at f gives tidal volume 2 A and 60 f b/m
TEST(Summary, CycleAnalysisOfASine) {
  Trace t;
  Metrics m;
  m.landmarks = Eigen::Matrix3Xd::Zero(3, 1);
  for (int i = 0; i <= 3000; ++i) {
    m.time = i * 0.01;
    m.lungVolume = 3e-3 + 2.5e-4 * std::sin(2 * kPi * 0.25 * m.time);
    m.gutVolumeError = 0.001 * std::cos(m.time);
    m.landmarks(2, 0) = -0.004 * std::sin(2 * kPi * 0.25 * m.time);  // the dome descends as the volume rises
    m.abdomenVolume = 1e-4 * std::sin(2 * kPi * 0.25 * m.time + kPi / 9.0);  // leads by 20 degrees
    t.append(m);
  }
  const Summary s = summarize(t, {"diaphragm_apex"}, 2.0);
  EXPECT_NEAR(s.tidalVolume, 5e-4, 1e-7);
  EXPECT_NEAR(s.breathsPerMinute, 15.0, 1e-3);
  EXPECT_NEAR(s.endExpiratoryVolume, 2.75e-3, 1e-7);
  EXPECT_NEAR(s.maxGutVolumeError, 0.001, 1e-6);
  EXPECT_GE(s.cycles, 6);
  // motion: end-inspiration (phase pi/2) minus end-expiration (3 pi/2)
  EXPECT_NEAR(s.motion.domeDescent, 0.008, 1e-6);
  EXPECT_NEAR(s.motion.abdomenTidal, 2e-4 * std::cos(kPi / 9.0), 1e-7);
  EXPECT_NEAR(s.motion.ribCageTidal, 5e-4 - s.motion.abdomenTidal, 1e-9);
  EXPECT_TRUE(std::isnan(s.motion.xiphoidAnterior));  // no such landmark
  // the rib-cage signal 2.5 sin(wt) - 1.0 sin(wt + 20 deg) has phase atan2(-sin 20, 2.5 - cos 20) = -13.3 degrees
  const double rcPhase = std::atan2(-std::sin(kPi / 9.0), 2.5 - std::cos(kPi / 9.0));
  EXPECT_NEAR(s.motion.phaseAngle, kPi / 9.0 - rcPhase, 2e-3);
  EXPECT_NEAR(s.motion.flowSignChanges, 2.0, 1e-9);
  EXPECT_LT(s.motion.maxFlowJump, 0.05);  // 100 frames per cycle: a smooth flow
}

// same inputs -> bit-identical recordings (STYLE: deterministic)
TEST(Simulation, DeterministicRecordings) {
  SimulationOptions o;
  o.settleTime = 0.2;
  Simulation a(toy(), calm(), o), b(toy(), calm(), o);
  a.advance(1.0);
  b.advance(1.0);
  ASSERT_EQ(a.recorder().size(), b.recorder().size());
  ASSERT_GT(a.recorder().size(), 50u);
  for (std::size_t i = 0; i < a.recorder().size(); ++i) {
    EXPECT_EQ(a.recorder().frame(i).nodePosition, b.recorder().frame(i).nodePosition);
    EXPECT_EQ(a.recorder().frame(i).bodyPose, b.recorder().frame(i).bodyPose);
    EXPECT_EQ(a.recorder().frame(i).elementForce, b.recorder().frame(i).elementForce);
  }
  EXPECT_EQ(a.state().nodePosition, b.state().nodePosition);
  // and a reset replays the same run
  const Eigen::Matrix3Xd end = a.state().nodePosition;
  a.reset();
  a.advance(1.0);
  EXPECT_EQ(a.state().nodePosition, end);
}

TEST(Recorder, RandomAccessAndRestore) {
  SimulationOptions o;
  o.settleTime = 0.0;
  o.outputRate = 50.0;
  o.recordSeconds = 0.5;
  o.dt = 0.01;  // [s] frames on whole steps of the 50 Hz output
  Simulation sim(toy(), calm(), o);
  sim.advance(1.0);
  const Recorder& r = sim.recorder();
  EXPECT_EQ(r.size(), 26u);  // capacity: 0.5 s at 50 Hz, plus one
  EXPECT_NEAR(r.frame(r.size() - 1).time, 1.0, 1e-9);
  const std::size_t i = r.indexAt(0.715);
  EXPECT_NEAR(r.frame(i).time, 0.72, 1e-9);
  State s;
  r.restore(r.size() - 1, s);
  EXPECT_LT((s.nodePosition - sim.state().nodePosition).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LT((s.bodyPosition - sim.state().bodyPosition).cwiseAbs().maxCoeff(), 1e-6);
}

}  // namespace
}  // namespace pneuma::sim
