// The Simulation logic layer: parameter validation before running, blow-up detection, determinism
// (bit-identical recordings), the recorder, the breath-style controller (Zordan et al. 2004,
// Section 7, Table 2) and the Summary's cycle analysis.
#include "pneuma/sim/Simulation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "ToyTorso.h"
#include "pneuma/sim/BreathStyleController.h"
#include "pneuma/sim/Error.h"

namespace pneuma::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::shared_ptr<const Model> toy() {
  static const auto model = std::make_shared<const Model>(test::makeToyTorso(1));
  return model;
}

std::unique_ptr<Controller> calm() {
  return std::make_unique<BreathStyleController>(loadBreathStyle("calm"));
}

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

// unset options take the model's kappa and the integrator's dt under the controller's cap, set ones win; the
// step measures its gut pressure with the kappa resolveOptions() reports: P = kappa (V0/V - 1), Eq. 4
TEST(Simulation, ResolveOptionsIsTheRuleTheRunFollows) {
  const auto model = toy();
  SimulationOptions o;
  EXPECT_EQ(resolveOptions(*model, o).kappa, model->gut.kappa);
  EXPECT_EQ(resolveOptions(*model, o).dt, defaultTimeStep(o.step.integrator));
  EXPECT_EQ(resolveOptions(*model, o, 0.004).dt, 0.004);
  o.dt = 0.01;
  EXPECT_EQ(resolveOptions(*model, o, 0.004).dt, 0.01);
  o.step.kappa = 3.0 * model->gut.kappa;
  EXPECT_EQ(resolveOptions(*model, o).kappa, 3.0 * model->gut.kappa);
  o.step.kappa = 0.0;
  expectError([&] { Simulation(model, calm(), o); }, "kappa");
  for (const std::optional<double> kappa :
       {std::optional<double>{}, std::optional<double>{4.0 * model->gut.kappa}}) {
    o.step.kappa = kappa;
    Simulation sim(model, calm(), o);
    sim.advance(0.2);
    const Metrics& m = sim.latestMetrics();
    ASSERT_NE(m.gutVolumeError, 0.0);
    EXPECT_NEAR(m.gutPressure, resolveOptions(*model, o).kappa * (1.0 / (1.0 + m.gutVolumeError) - 1.0),
                1e-9 * std::abs(m.gutPressure));
  }
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
  expectError(
      [] {
        parseBreathStyle(
            "{\"name\": \"x\", \"breaths_per_minute\": -3, \"diaphragm_r\": 0.8, "
            "\"intercostal_mean\": 0.9, \"intercostal_amplitude\": 0.1}",
            "x.json");
      },
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

// the muscles take turns: diaphragm and external intercostals on the inspiratory drive, internal intercostals
// quiet in calm breathing, rectus only in the forced exhale's expiration
TEST(BreathStyleController, InspiratoryAndExpiratoryMusclesTakeTurns) {
  BreathStyle calm = loadBreathStyle("calm");
  calm.driveDecayFraction = 0.6;  // the drive is off for the last 40 % of the exhale
  BreathStyleController c(calm);
  const double period = 4.0, inhale = 1.6, exhale = 2.4;  // [s]
  const Metrics none;
  auto at = [&](double t, ElementGroup g) { return c.activations(t, none)[static_cast<std::size_t>(g)]; };
  // a rounded rise over the inhale: (1 - cos(pi t / Ti)) / 2, 0.5 at mid-inhale, full at its end
  EXPECT_NEAR(at(0.5 * inhale, ElementGroup::Diaphragm).alpha, 0.5 * calm.diaphragmAlpha, 1e-12);
  EXPECT_NEAR(at(inhale - 1e-9, ElementGroup::Diaphragm).alpha, calm.diaphragmAlpha, 1e-9);
  EXPECT_DOUBLE_EQ(at(0.5 * inhale, ElementGroup::Diaphragm).r, calm.diaphragmR);
  // the external intercostals run intercostalLead ahead of the diaphragm (the rib cage lags them)
  ASSERT_GT(calm.intercostalLead, 0.0);
  EXPECT_NEAR(at(0.5 * inhale - calm.intercostalLead, ElementGroup::IntercostalExternal).alpha,
              0.5 * calm.intercostalAlpha, 1e-12);
  EXPECT_GT(at(0.01, ElementGroup::IntercostalExternal).alpha, at(0.01, ElementGroup::Diaphragm).alpha);
  EXPECT_NEAR(at(0.5 * inhale, ElementGroup::IntercostalExternal).r,
              calm.intercostalMean - calm.intercostalAmplitude, 1e-12);
  // post-inspiratory braking: half-way down at half the decay window, off after it
  EXPECT_NEAR(at(inhale + 0.5 * calm.driveDecayFraction * exhale, ElementGroup::Diaphragm).alpha,
              0.5 * calm.diaphragmAlpha, 1e-9);
  EXPECT_EQ(at(inhale + 1.01 * calm.driveDecayFraction * exhale, ElementGroup::Diaphragm).alpha, 0.0);
  // the drive is continuous: no step larger than a smooth curve's over 1 ms
  for (double t = 0.001; t < 2 * period; t += 0.001)
    EXPECT_LT(std::abs(at(t, ElementGroup::Diaphragm).alpha - at(t - 0.001, ElementGroup::Diaphragm).alpha),
              0.005)
        << t;
  for (double t = 0.0; t < period; t += 0.05) {
    EXPECT_EQ(at(t, ElementGroup::Rectus).alpha, 0.0);
    EXPECT_EQ(at(t, ElementGroup::IntercostalInternal).alpha, 0.0);  // quiet expiration is passive recoil
  }
  BreathStyleController forced(loadBreathStyle("forced-exhale"));  // 6 s cycle, 2.4 s inhale
  auto forcedAt = [&](double t, ElementGroup g) {
    return forced.activations(t, none)[static_cast<std::size_t>(g)];
  };
  EXPECT_EQ(forcedAt(1.0, ElementGroup::Rectus).alpha, 0.0);         // inhale
  EXPECT_DOUBLE_EQ(forcedAt(4.0, ElementGroup::Rectus).alpha, 1.0);  // exhale, after the drive's rise
  EXPECT_DOUBLE_EQ(forcedAt(4.0, ElementGroup::Rectus).r, 0.5);
  EXPECT_DOUBLE_EQ(forcedAt(4.0, ElementGroup::IntercostalInternal).alpha, 1.0);
  EXPECT_EQ(forcedAt(7.0, ElementGroup::Rectus).alpha, 0.0);  // after the one cycle
  EXPECT_EQ(forcedAt(7.0, ElementGroup::Diaphragm).alpha, 0.0);
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
  const Activations a =
      c.activations(0.5 - 1e-9, none);  // the end of the 0.5 s inhale, at full inspiratory drive
  EXPECT_NEAR(a[static_cast<std::size_t>(ElementGroup::Diaphragm)].alpha, panting.diaphragmAlpha, 1e-9);
  EXPECT_NEAR(a[static_cast<std::size_t>(ElementGroup::IntercostalExternal)].alpha, panting.intercostalAlpha,
              1e-9);
  EXPECT_LT(panting.diaphragmAlpha, 1.0);
  const std::string text = serializeBreathStyle(panting);
  EXPECT_EQ(serializeBreathStyle(parseBreathStyle(text, "panting.json")), text);
  BreathStyle bad = panting;
  bad.intercostalAlpha = 1.5;
  EXPECT_THROW(validateBreathStyle(bad), Error);
}

// the expiratory drive's rise and fall windows shape one smooth bump over the exhale: e rises over the first
// `rise` of it and returns to 0 over the last `fall`, with zero slope at both ends (panting: 0.5 / 0.5, so
// the expiratory muscles let go gradually instead of in the exhale's last 75 ms)
TEST(BreathStyle, ExpiratoryDriveIsASmoothBumpOverTheExhale) {
  BreathStyle s = loadBreathStyle("calm");
  s.inhaleFraction = 0.5;
  s.expiratoryRiseFraction = 0.5;
  s.expiratoryFallFraction = 0.5;
  EXPECT_EQ(expiratoryDrive(s, 0.25), 0.0);            // inhale
  EXPECT_NEAR(expiratoryDrive(s, 0.75), 1.0, 1e-12);   // the exhale's middle
  EXPECT_NEAR(expiratoryDrive(s, 0.625), 0.5, 1e-12);  // half way up
  EXPECT_NEAR(expiratoryDrive(s, 0.875), 0.5, 1e-12);  // and half way down
  EXPECT_LT(expiratoryDrive(s, 0.995), 2e-3);          // near 0, flat, just before the next inhale
  s.expiratoryFallFraction = 0.15;  // the default: still at full drive at 80 % of the exhale
  EXPECT_NEAR(expiratoryDrive(s, 0.9), 1.0, 1e-12);
  s.expiratoryRiseFraction = 0.9;  // the two windows may not overlap
  EXPECT_THROW(validateBreathStyle(s), Error);
  s.expiratoryRiseFraction = 0.0;
  EXPECT_THROW(validateBreathStyle(s), Error);
  EXPECT_THROW(parseBreathStyle(R"({"name": "x", "breaths_per_minute": 60, "diaphragm_r": 0.8,
      "intercostal_mean": 0.9, "intercostal_amplitude": 0.1, "expiratory_fall_fraction": 1.2})",
                                "x.json"),
               Error);
}

// the drive's decay window must be a fraction of the exhale, the internal layer's level in [0, 1]
TEST(BreathStyle, DriveFieldsAreRangeChecked) {
  BreathStyle bad = loadBreathStyle("calm");
  bad.driveDecayFraction = 0.0;
  EXPECT_THROW(validateBreathStyle(bad), Error);
  bad.driveDecayFraction = 1.5;
  EXPECT_THROW(validateBreathStyle(bad), Error);
  bad = loadBreathStyle("calm");
  bad.internalIntercostalAlpha = -0.1;
  EXPECT_THROW(validateBreathStyle(bad), Error);
  bad = loadBreathStyle("calm");  // 4 s cycle: the lead may be at most half of it
  bad.intercostalLead = 2.5;
  EXPECT_THROW(validateBreathStyle(bad), Error);
  bad.intercostalLead = -0.1;
  EXPECT_THROW(validateBreathStyle(bad), Error);
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
  // the rib-cage signal 2.5 sin(wt) - 1.0 sin(wt + 20 deg) has phase atan2(-sin 20, 2.5 - cos 20) = -13.3
  // degrees
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
