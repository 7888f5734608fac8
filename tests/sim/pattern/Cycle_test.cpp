#include "pneuma/sim/pattern/Cycle.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "pneuma/sim/Error.h"

using namespace pneuma::sim;
using namespace pneuma::sim::pattern;

namespace {

CycleSpec spline(std::vector<Keyframe> k, bool isRelative = true) {
  CycleSpec c;
  c.kind = CycleKind::Spline;
  c.isRelative = isRelative;
  c.keyframes = std::move(k);
  return c;
}

// message of the Error thrown by validateCycle, or "" when it passes
std::string validationError(const CycleSpec& c) {
  try {
    validateCycle(c);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Cycle, LinearIsTheIETriangle) {
  // 20 b/m, I:E 1:2 -> 3 s breath, 1 s up, 2 s down, between depth 0.1 and 0.5
  CycleSpec c;
  c.rate = 20.0;
  c.ieRatio = 0.5;
  c.depthMin = 0.1;
  c.depthMax = 0.5;
  const Cycle cycle(c);
  EXPECT_DOUBLE_EQ(cycle.duration(), 3.0);
  EXPECT_DOUBLE_EQ(cycle.volume(0.0), 0.1);
  EXPECT_NEAR(cycle.volume(0.5), 0.3, 1e-12);
  EXPECT_NEAR(cycle.volume(1.0), 0.5, 1e-12);
  EXPECT_NEAR(cycle.volume(2.0), 0.3, 1e-12);
  EXPECT_NEAR(cycle.volume(3.0), 0.1, 1e-12);
}

TEST(Cycle, EveryKindIsContinuousInRangeAndPeriodic) {
  CycleSpec linear;
  CycleSpec keyframe = spline({{0, 0.0}, {0.3, 1.0}, {0.5, 0.6}, {0.6, 0.7}, {1.0, 0.0}});
  keyframe.kind = CycleKind::Keyframe;
  CycleSpec smooth = spline({{0, 0.0}, {0.4, 1.0}, {1.0, 0.0}});
  CycleSpec absolute = spline({{0, 0.0}, {0.5, 0.9}, {0.7, 1.0}, {2.0, 0.0}}, false);
  absolute.postInspiratoryPause = 0.5;
  absolute.postExpiratoryPause = 0.25;
  for (CycleSpec c : {linear, keyframe, smooth, absolute}) {
    c.depthMin = 0.05;
    c.depthMax = 0.4;
    const Cycle cycle(c);
    const double d = cycle.duration();
    const double dt = d / 20000.0;
    double largestStep = 0.0, lo = 1.0, hi = 0.0;
    for (int i = 0; i <= 20000; ++i) {
      const double v = cycle.volume(i * dt);
      lo = std::min(lo, v);
      hi = std::max(hi, v);
      if (i > 0) largestStep = std::max(largestStep, std::abs(v - cycle.volume((i - 1) * dt)));
    }
    SCOPED_TRACE(cycleKindName(c.kind));
    // range: the shape spans exactly [depthMin, depthMax]
    EXPECT_NEAR(lo, c.depthMin, 1e-9);
    EXPECT_NEAR(hi, c.depthMax, 1e-4);
    // continuity: no step larger than the steepest keyframe slope allows (here < 5e-3 per 1/20000)
    EXPECT_LT(largestStep, 5e-3);
    // periodicity: the breath ends where it starts
    EXPECT_NEAR(cycle.volume(0.0), cycle.volume(d), 1e-12);
  }
}

TEST(Cycle, SplineDoesNotOvershootSharpKeyframes) {
  // a plateau and a cliff: a natural cubic spline would overshoot above 1 and below 0 here
  const Cycle cycle(spline({{0, 0.0}, {0.05, 1.0}, {0.5, 1.0}, {0.55, 0.0}, {1.0, 0.0}}));
  for (int i = 0; i <= 10000; ++i) {
    const double s = cycle.shape(i / 10000.0);
    ASSERT_GE(s, 0.0);
    ASSERT_LE(s, 1.0);
  }
  // flat between equal keyframes (monotone interpolation keeps plateaus flat)
  EXPECT_DOUBLE_EQ(cycle.shape(0.3), 1.0);
  EXPECT_DOUBLE_EQ(cycle.shape(0.8), 0.0);
}

TEST(Cycle, RelativeTimeIsWarpedToTheRateAbsoluteTimeIsNot) {
  CycleSpec c = spline({{0, 0.0}, {0.25, 1.0}, {1.0, 0.0}});
  c.rate = 12.0;
  EXPECT_DOUBLE_EQ(Cycle(c).duration(), 5.0);
  c.rate = 30.0;
  const Cycle fast(c);
  EXPECT_DOUBLE_EQ(fast.duration(), 2.0);
  EXPECT_NEAR(fast.volume(0.5), c.depthMax, 1e-12);  // peak at a quarter of the breath
  const Cycle absolute(spline({{0, 0.0}, {0.8, 1.0}, {3.2, 0.0}}, false));
  EXPECT_DOUBLE_EQ(absolute.duration(), 3.2);
  EXPECT_NEAR(absolute.volume(0.8), absolute.spec().depthMax, 1e-12);
}

TEST(Cycle, PausesHoldTheVolumeAndKeepTheRate) {
  CycleSpec c;
  c.rate = 15.0;  // 4 s per breath
  c.ieRatio = 1.0;
  c.postInspiratoryPause = 1.0;
  c.postExpiratoryPause = 0.6;
  const Cycle cycle(c);
  EXPECT_DOUBLE_EQ(cycle.duration(), 4.0);
  // moving part 2.4 s: up 1.2 s, hold 1 s at the peak, down 1.2 s, hold 0.6 s at rest
  for (double t = 1.2; t <= 2.2; t += 0.05) EXPECT_NEAR(cycle.volume(t), c.depthMax, 1e-12) << t;
  for (double t = 3.4; t <= 4.0; t += 0.05) EXPECT_NEAR(cycle.volume(t), c.depthMin, 1e-12) << t;
  EXPECT_LT(cycle.volume(2.8), c.depthMax - 0.05);
}

TEST(Cycle, VariationScalesDurationAndDepth) {
  CycleSpec c;
  c.postInspiratoryPause = 0.5;
  const Cycle cycle(c);
  const BreathVariation v{1.2, 0.5};
  EXPECT_NEAR(cycle.duration(v), 0.5 + 1.2 * 3.5, 1e-12);
  double hi = 0.0;
  for (int i = 0; i <= 1000; ++i) hi = std::max(hi, cycle.volume(cycle.duration(v) * i / 1000.0, v));
  EXPECT_NEAR(hi, c.depthMin + 0.5 * (c.depthMax - c.depthMin), 1e-9);
}

// the inspiratory balance holds from the breath's start to the shape's peak (the first keyframe with the
// largest value, moved by the duration variation), the balance from there on, the post-inspiratory pause
// included
TEST(Cycle, InspiratoryBalanceHoldsUntilThePeak) {
  CycleSpec c = spline({{0, 0.0}, {0.8, 1.0}, {1.2, 0.5}, {1.3, 1.0}, {2.6, 0.0}}, false);
  c.balance = 0.15;
  c.postInspiratoryPause = 0.5;
  EXPECT_DOUBLE_EQ(Cycle(c).balance(0.79), 0.15);  // unset: the balance throughout
  c.inspiratoryBalance = 0.9;
  const Cycle cycle(c);
  EXPECT_DOUBLE_EQ(cycle.balance(0.0), 0.9);
  EXPECT_DOUBLE_EQ(cycle.balance(0.79), 0.9);
  EXPECT_DOUBLE_EQ(cycle.balance(0.81), 0.15);
  EXPECT_DOUBLE_EQ(cycle.balance(1.25), 0.15);  // in the pause
  EXPECT_DOUBLE_EQ(cycle.balance(1.8), 0.15);   // rising again after the peak: still expiration
  const BreathVariation slower{1.5, 1.0};
  EXPECT_DOUBLE_EQ(cycle.balance(1.15, slower), 0.9);  // the peak at 1.2 s
  EXPECT_DOUBLE_EQ(cycle.balance(1.25, slower), 0.15);
}

TEST(Cycle, InvalidSpecsNameTheField) {
  CycleSpec c;
  c.depthMin = 0.4;
  c.depthMax = 0.2;
  EXPECT_NE(validationError(c).find("depth: min 0.4 > max 0.2"), std::string::npos) << validationError(c);

  c = CycleSpec();
  c.rate = -3.0;
  EXPECT_EQ(validationError(c).rfind("rate_bpm:", 0), 0u) << validationError(c);

  c = spline({{0, 0.0}, {0.6, 1.0}, {0.4, 0.5}, {1.0, 0.0}});
  EXPECT_EQ(validationError(c).rfind("keyframes[2].time:", 0), 0u) << validationError(c);

  c = spline({{0, 0.0}, {0.6, 1.0}, {1.0, 0.3}});
  EXPECT_EQ(validationError(c).rfind("keyframes[2].volume:", 0), 0u) << validationError(c);

  c = CycleSpec();
  c.rate = 60.0;
  c.postInspiratoryPause = 1.0;  // a 1 s breath cannot hold 1 s
  EXPECT_EQ(validationError(c).rfind("rate_bpm:", 0), 0u) << validationError(c);

  c = CycleSpec();
  c.balance = 1.5;
  EXPECT_EQ(validationError(c).rfind("balance:", 0), 0u) << validationError(c);

  c = CycleSpec();
  c.inspiratoryBalance = std::nan("");
  EXPECT_EQ(validationError(c).rfind("inspiratory_balance:", 0), 0u) << validationError(c);

  EXPECT_EQ(validationError(CycleSpec()), "");
}
