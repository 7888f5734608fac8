// Run limits (Limits.h): inputs that would never finish are refused by every loader and by the Simulation,
// each with the same rule and message naming the field and the value (issue 15, class 5).
#include "pneuma/sim/Limits.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "ToyTorso.h"
#include "pneuma/sim/BreathStyleController.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/Scenario.h"
#include "pneuma/sim/Simulation.h"
#include "pneuma/sim/pattern/Pattern.h"

namespace pneuma::sim {
namespace {

const std::string kResources = PNEUMA_RESOURCE_DIR;

// the Error message of `f`, or "" when it throws none
template <typename F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

std::string patternWithCycle(const std::string& cycle) {
  return R"({"format": "pneuma-pattern", "version": 1, "name": "t", "layers": [
    {"name": "only", "repeat": "infinite", "cycle": )" +
         cycle + "}]}";
}

std::string patternError(const std::string& cycle) {
  return errorOf([&] { pattern::parsePattern(patternWithCycle(cycle), "p.json", kResources); });
}

std::string scenarioWith(const std::string& members) {
  return R"({"format": "pneuma-scenario", "version": 1, "controller": {"style": "calm"}, )" + members + "}";
}

std::string scenarioError(const std::string& members) {
  return errorOf([&] { parseScenario(scenarioWith(members), "s.json", "/base"); });
}

TEST(Limits, RangeNamesFieldBoundsUnitAndValue) {
  EXPECT_TRUE(kTimeStepRange.contains(0.01));
  EXPECT_FALSE(kTimeStepRange.contains(1e-300));
  EXPECT_FALSE(kTimeStepRange.contains(std::nan("")));
  EXPECT_EQ(errorOf([] { kTimeStepRange.check("--dt", 1e-300); }),
            "--dt: must be in [1e-06, 0.05] s, got 1e-300");
  EXPECT_EQ(errorOf([] { kTimeStepRange.check("--dt", 0.01); }), "");
}

TEST(Limits, PatternRatesAndKeyframesThatWouldNeverFinishAreRefused) {
  // 1e12 breaths a minute: the breath scheduler would step through 1e12 breaths in each simulated minute
  EXPECT_EQ(patternError(R"({"kind": "linear", "rate_bpm": 1e12, "depth": [0.05, 0.25]})"),
            "p.json: layers[0].cycle.rate_bpm: must be in [0.5, 200] breaths/min, got 1e+12");
  // absolute keyframes 1e-300 s apart: a breath of 2e-300 s, which adds nothing to the clock
  const std::string tiny = patternError(
      R"({"kind": "keyframe", "time": "absolute", "depth": [0.05, 0.25], "keyframes": [[0, 0], [1e-300, 1], [2e-300, 0]]})");
  EXPECT_NE(tiny.find("layers[0].cycle.keyframes[2].time"), std::string::npos) << tiny;
  EXPECT_NE(tiny.find("must be in [0.3, 120] s, got 2e-300"), std::string::npos) << tiny;
  // a long enough breath whose keyframes are 1e-300 s apart (a step in the volume)
  const std::string close = patternError(
      R"({"kind": "keyframe", "time": "absolute", "depth": [0.05, 0.25], "keyframes": [[0, 0], [1e-300, 1], [4, 0]]})");
  EXPECT_NE(close.find("keyframes[1].time: 1e-300 s after keyframes[0]"), std::string::npos) << close;
  // relative keyframes: apart in seconds once scaled to the breath
  const std::string relative = patternError(
      R"({"kind": "keyframe", "rate_bpm": 15, "depth": [0.05, 0.25], "keyframes": [[0, 0], [0.00001, 1], [1, 0]]})");
  EXPECT_NE(relative.find("keyframes[1].time: 4e-05 s after keyframes[0]"), std::string::npos) << relative;
  // what people write is still accepted
  EXPECT_EQ(patternError(R"({"kind": "linear", "rate_bpm": 60, "depth": [0.05, 0.25]})"), "");
  EXPECT_EQ(
      patternError(
          R"({"kind": "keyframe", "time": "absolute", "depth": [0.05, 0.25], "keyframes": [[0, 0], [1.5, 1], [4, 0]]})"),
      "");
}

TEST(Limits, BreathStyleRateSharesThePatternsRule) {
  BreathStyle s = loadBreathStyle("calm");
  s.breathsPerMinute = 1e12;
  EXPECT_EQ(errorOf([&] { validateBreathStyle(s); }),
            "breath style 'calm': breaths_per_minute: must be in [0.5, 200] breaths/min, got 1e+12");
}

TEST(Limits, ScenarioTimesUseTheSameRulesAsTheCommandLine) {
  EXPECT_EQ(scenarioError(R"("duration_s": 1e308)"),
            "s.json: duration_s: must be in [0.001, 86400] s, got 1e+308");
  EXPECT_EQ(scenarioError(R"("duration_s": 5, "overrides": {"dt_s": 1e-300})"),
            "s.json: overrides.dt_s: must be in [1e-06, 0.05] s, got 1e-300");
  EXPECT_EQ(scenarioError(R"("duration_s": 5, "overrides": {"settle_time_s": 1e9})"),
            "s.json: overrides.settle_time_s: must be in [0, 600] s, got 1e+09");
  EXPECT_EQ(scenarioError(R"("duration_s": 5, "outputs": {"output_rate_hz": 1e12})"),
            "s.json: outputs.output_rate_hz: must be in [0.01, 10000] Hz, got 1e+12");
  EXPECT_EQ(scenarioError(R"("duration_s": 5, "overrides": {"dt_s": 0.01, "settle_time_s": 1})"), "");
}

TEST(Limits, SimulationRefusesOptionsAndRunsThatWouldNeverFinish) {
  const auto model = std::make_shared<const Model>(test::makeToyTorso(1));
  auto calm = [] { return std::make_unique<BreathStyleController>(loadBreathStyle("calm")); };
  SimulationOptions o;
  o.dt = 1e-300;
  EXPECT_EQ(errorOf([&] { Simulation(model, calm(), o); }), "dt: must be in [1e-06, 0.05] s, got 1e-300");
  o = {};
  o.settleTime = 1e9;
  EXPECT_EQ(errorOf([&] { Simulation(model, calm(), o); }), "settleTime: must be in [0, 600] s, got 1e+09");
  o = {};
  o.dt = 0.01;
  Simulation sim(model, calm(), o);
  const std::string e = errorOf([&] { sim.advance(1e308); });
  EXPECT_EQ(e, "duration: 1e+308 s at dt 0.01 s needs more than the 1e+09 steps a run may take");
  EXPECT_EQ(sim.state().steps, 0);  // refused before stepping
}

}  // namespace
}  // namespace pneuma::sim
