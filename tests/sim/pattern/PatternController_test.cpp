// The pattern controller's feedback law on a first-order lung plant (no physics model needed).
#include "pneuma/sim/pattern/PatternController.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>

#include "pneuma/sim/Error.h"

using namespace pneuma::sim;
using namespace pneuma::sim::pattern;

namespace {

const std::string kResources = PNEUMA_RESOURCE_DIR;
std::size_t idx(ElementGroup g) { return static_cast<std::size_t>(g); }

// a calibration with concave (saturating) responses, as muscles have: R_g(alpha) = g (1 - e^(-3 alpha)) / (1
// - e^(-3))
DriveCalibration plantCalibration() {
  std::array<double, kElementGroupCount> gain{};
  gain[idx(ElementGroup::IntercostalExternal)] = 0.3;
  gain[idx(ElementGroup::Diaphragm)] = 0.6;
  gain[idx(ElementGroup::IntercostalInternal)] = -0.1;
  gain[idx(ElementGroup::Rectus)] = -0.05;
  gain[idx(ElementGroup::TransversusObliques)] = -0.05;
  DriveCalibration c;
  c.restVolume = 2.4e-3;  // [m^3]
  for (std::size_t g = 0; g < gain.size(); ++g)
    for (std::size_t k = 0; k < kCalibrationAlphas.size(); ++k)
      c.response[g][k] = gain[g] * (1.0 - std::exp(-3.0 * kCalibrationAlphas[k])) / (1.0 - std::exp(-3.0));
  return c;
}

// a lung whose volume relaxes with time constant tau [s] towards the static response of the activations
// (the calibrated curves, additive over groups), whose true responses are `gainError` times the calibrated
// ones; frames at 60 Hz as in Simulation. On the default model the intercostals lag their activation by
// about 0.2 s (rib friction) and the diaphragm by about 0.07 s.
struct Plant {
  double tau = 0.06, gainError = 0.8, volume = 2.4e-3, time = 0.0, nextFrame = 0.0;
  double maxInternalStep = 0.0;  // [-] largest change of the internal intercostals' alpha in one control step
  Metrics latest;
  Activations last{};

  double staticVolume(const Activations& a, const DriveCalibration& c) const {
    double f = 0.0;
    for (int g = 0; g < kElementGroupCount; ++g)
      f += groupResponse(c, static_cast<ElementGroup>(g), a[static_cast<std::size_t>(g)].alpha);
    return c.restVolume + gainError * f * c.volumePerFraction;
  }
  // runs `seconds` of control (after a 1 s settle) and returns the controller's tracking
  void run(PatternController& ctl, double seconds, const DriveCalibration& c) {
    const double dt = 1e-3, settle = 1.0;
    while (time < settle + seconds) {
      const double before = last[idx(ElementGroup::IntercostalInternal)].alpha;
      last = ctl.activations(std::max(time - settle, 0.0), latest);
      validateActivations(last);
      maxInternalStep =
          std::max(maxInternalStep, std::abs(last[idx(ElementGroup::IntercostalInternal)].alpha - before));
      volume += dt / tau * (staticVolume(last, c) - volume);
      time += dt;
      if (time >= nextFrame) {
        latest.time = time;
        latest.lungVolume = volume;
        nextFrame += 1.0 / 60.0;
      }
    }
  }
};

}  // namespace

TEST(PatternController, TracksSustainedPresetsOnALaggingMiscalibratedPlant) {
  for (const char* affect : {"neutral", "excitement", "relaxation", "focus", "panic", "sadness"}) {
    SCOPED_TRACE(affect);
    const DriveCalibration c = plantCalibration();
    auto ctl = makeAffectController(affect, kResources, 1, c);
    Plant plant;
    plant.run(*ctl, 30.0, c);
    EXPECT_GT(ctl->tracking().frames, 1700);
    EXPECT_LT(ctl->tracking().rmsPercentOfPeakToPeak(), 10.0);
    RecordProperty(std::string("rms_pct_") + affect,
                   std::to_string(ctl->tracking().rmsPercentOfPeakToPeak()));
    EXPECT_NEAR(ctl->measuredFraction(), ctl->targetFraction(), 0.05);
  }
}

TEST(PatternController, GroupResponseInterpolatesTheCalibratedCurve) {
  const DriveCalibration c = plantCalibration();
  const GroupResponse& r = c.response[idx(ElementGroup::Diaphragm)];
  EXPECT_DOUBLE_EQ(groupResponse(c, ElementGroup::Diaphragm, 0.0), 0.0);
  EXPECT_DOUBLE_EQ(groupResponse(c, ElementGroup::Diaphragm, 0.2), r[4]);
  EXPECT_DOUBLE_EQ(groupResponse(c, ElementGroup::Diaphragm, 1.0), r.back());
  EXPECT_NEAR(groupResponse(c, ElementGroup::Diaphragm, 0.6), 0.6 * r[6] + 0.4 * r[7],
              1e-15);  // 0.6 = 0.5 + 0.4 * 0.25
  EXPECT_DOUBLE_EQ(groupResponse(c, ElementGroup::Diaphragm, 2.0), r.back());
}

TEST(PatternController, InvertsTheMusclesNonLinearityWithoutFeedback) {
  // feed-forward alone on a fast plant that responds exactly as calibrated (concave curves): the volume
  // follows the target, which a single linear gain per muscle could not do
  for (const char* affect : {"neutral", "excitement", "relaxation"}) {
    SCOPED_TRACE(affect);
    const DriveCalibration c = plantCalibration();
    PatternControllerOptions open;
    open.kp = open.ki = 0.0;
    PatternController ctl(makeLayerStack(loadAffect(affect, kResources), 1), c, open);
    Plant plant;
    plant.tau = 0.002;
    plant.gainError = 1.0;
    plant.run(ctl, 20.0, c);
    EXPECT_LT(ctl.tracking().rmsPercentOfPeakToPeak(), 2.0);
  }
}

TEST(PatternController, LagFeedForwardInvertsAFirstOrderPlant) {
  // feed-forward alone on a plant that lags its activations by tau = 0.2 s (the recalibrated ribcage):
  // panic's 1 Hz panting lags by atan(2 pi 0.2) = 51 degrees without the tau * dv_T/dt term, and is
  // followed to within the one-step backward difference with it (the plant is the exact first-order lag)
  auto openLoopRms = [](double calibratedTau) {
    DriveCalibration c = plantCalibration();
    c.timeConstant.fill(calibratedTau);
    PatternControllerOptions open;
    open.kp = open.ki = 0.0;
    open.internalIntercostalLag = 0.0;  // the plant's lag only
    PatternController ctl(makeLayerStack(loadAffect("panic", kResources), 1), c, open);
    Plant plant;
    plant.tau = 0.2;
    plant.gainError = 1.0;
    plant.run(ctl, 20.0, c);
    return ctl.tracking().rmsPercentOfPeakToPeak();
  };
  const double without = openLoopRms(0.0), with = openLoopRms(0.2);
  RecordProperty("rms_pct_without", std::to_string(without));
  RecordProperty("rms_pct_with", std::to_string(with));
  EXPECT_GT(without, 20.0);  // 25 %
  EXPECT_LT(with, 3.0);
}

// the internal intercostals follow their drive through the first-order lag (internalIntercostalLag): in one
// 1 ms control step their activation moves at most 1 - e^(-dt / lag) of the way to the drive's, 0.01 at 0.1
// s; without the lag panic's drive moves it several times that in one step. The feed-forward adds the lag to
// their lever's, so panic is still followed on the lagging, miscalibrated plant
TEST(PatternController, InternalIntercostalsFollowTheirDriveThroughTheLag) {
  auto run = [](double lag, double& rms) {
    const DriveCalibration c = plantCalibration();
    PatternControllerOptions o;
    o.internalIntercostalLag = lag;
    PatternController ctl(makeLayerStack(loadAffect("panic", kResources), 1), c, o);
    Plant plant;
    plant.run(ctl, 20.0, c);
    rms = ctl.tracking().rmsPercentOfPeakToPeak();
    return plant.maxInternalStep;
  };
  double rmsLagged = 0.0, rmsDirect = 0.0;
  const double lagged = run(0.1, rmsLagged), direct = run(0.0, rmsDirect);
  RecordProperty("max_step_lagged", std::to_string(lagged));
  RecordProperty("max_step_direct", std::to_string(direct));
  EXPECT_LE(lagged, 1.0 - std::exp(-1e-3 / 0.1) + 1e-12);
  EXPECT_GT(direct, 3.0 * lagged);
  EXPECT_LT(rmsLagged, 10.0);
}

TEST(PatternController, RejectsANegativeTimeConstant) {
  DriveCalibration c = plantCalibration();
  c.timeConstant[idx(ElementGroup::IntercostalInternal)] = -0.1;
  try {
    makeAffectController("neutral", kResources, 1, c);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("calibration.timeConstant.intercostal_internal"), std::string::npos)
        << e.what();
  }
}

TEST(PatternController, BalanceSplitsTheDriveBetweenChestAndBelly) {
  // mean alpha of intercostals vs diaphragm over the run: focus/panic chest, relaxation belly
  auto chestShare = [](const char* affect) {
    const DriveCalibration c = plantCalibration();
    auto ctl = makeAffectController(affect, kResources, 1, c);
    Plant plant;
    double chest = 0.0, belly = 0.0;
    for (int k = 0; k < 20; ++k) {
      plant.run(*ctl, 0.5 * (k + 1), c);
      chest += groupResponse(c, ElementGroup::IntercostalExternal,
                             plant.last[idx(ElementGroup::IntercostalExternal)].alpha);
      belly += groupResponse(c, ElementGroup::Diaphragm, plant.last[idx(ElementGroup::Diaphragm)].alpha);
    }
    return chest / (chest + belly);
  };
  EXPECT_GT(chestShare("panic"), 0.55);
  EXPECT_GT(chestShare("focus"), 0.55);
  EXPECT_LT(chestShare("relaxation"), 0.5);
  EXPECT_LT(chestShare("relaxation"), chestShare("focus") - 0.3);
}

TEST(PatternController, ExpiratoryMusclesWorkOnlyBelowRest) {
  // (instantaneous levers, tau = 0; with a lag the wall also helps at the end of fast expirations)
  const DriveCalibration c = plantCalibration();
  auto ctl = makeAffectController("neutral", kResources, 1, c);
  Plant plant;
  plant.run(*ctl, 10.0, c);
  // quiet breathing stays above rest: the abdominal wall stays idle (at most small corrections)
  EXPECT_LT(plant.last[idx(ElementGroup::Rectus)].alpha, 0.2);
  // a target below rest recruits rectus and obliques (forced expiration)
  Layer forced;
  forced.name = "forced";
  forced.cycle.rate = 10.0;
  forced.cycle.depthMin = 0.0;
  forced.cycle.depthMax = 0.05;
  forced.cycle.balance = 0.2;
  ctl->push({forced}, SwitchMode::Immediate);
  double maxRectus = 0.0;
  for (int k = 1; k <= 60; ++k) {
    plant.run(*ctl, 10.0 + 0.1 * k, c);
    maxRectus = std::max(maxRectus, plant.last[idx(ElementGroup::Rectus)].alpha);
  }
  EXPECT_GT(maxRectus, 0.15);  // the feed-forward alone asks 0.16 for the 0.04 belly share of -0.05
}

TEST(PatternController, AGroupActingTheWrongWayIsLeftOutAndItsPartnerTakesOver) {
  // on this model the external intercostals lower the volume: the diaphragm does all the inspiration
  DriveCalibration c = plantCalibration();
  for (double& r : c.response[idx(ElementGroup::IntercostalExternal)]) r *= -0.5;
  auto ctl = makeAffectController("panic", kResources, 1, c);
  Plant plant;
  plant.run(*ctl, 20.0, c);
  EXPECT_EQ(plant.last[idx(ElementGroup::IntercostalExternal)].alpha, 0.0);
  EXPECT_LT(ctl->tracking().rmsPercentOfPeakToPeak(), 10.0);
}

TEST(PatternController, RejectsACalibrationThatCannotInhale) {
  DriveCalibration c = plantCalibration();
  c.response[idx(ElementGroup::IntercostalExternal)] = GroupResponse{};
  for (double& r : c.response[idx(ElementGroup::Diaphragm)]) r *= -0.2;
  try {
    makeAffectController("neutral", kResources, 1, c);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("calibration.response: neither intercostal_external nor diaphragm"),
              std::string::npos)
        << e.what();
  }
}

TEST(PatternController, TakesOverMidRunWithoutAJumpAndPlaysItsEventFirst) {
  const DriveCalibration c = plantCalibration();
  auto first = makeAffectController("excitement", kResources, 1, c);
  Plant plant;
  plant.run(*first, 20.3, c);  // somewhere inside a breath
  const double before = first->measuredFraction();
  // a fresh relief controller installed at t = 20.3 s (as Simulation::setController does)
  auto second = makeAffectController("relief", kResources, 1, c);
  second->activations(0.0, plant.latest);  // the validation call of setController
  plant.run(*second, 20.31, c);
  EXPECT_NEAR(second->targetFraction(), before, 0.02);
  EXPECT_EQ(second->stack().currentLayerName(), "sigh");
  plant.run(*second, 22.0, c);
  EXPECT_EQ(second->stack().currentLayerName(), "sigh");
}

TEST(PatternController, RestartsWhenTheSimulationIsReset) {
  const DriveCalibration c = plantCalibration();
  auto ctl = makeAffectController("relief", kResources, 1, c);
  Plant plant;
  plant.run(*ctl, 12.0, c);
  EXPECT_EQ(ctl->stack().currentLayerName(), "neutral");
  Plant again;
  again.run(*ctl, 1.0, c);  // time starts over
  EXPECT_EQ(ctl->stack().currentLayerName(), "sigh");
  EXPECT_LT(ctl->tracking().frames, 70);
}
