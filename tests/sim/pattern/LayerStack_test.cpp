#include "pneuma/sim/pattern/LayerStack.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <sstream>
#include <vector>

#include "pneuma/sim/Checkpoint.h"
#include "pneuma/sim/Error.h"

using namespace pneuma::sim;
using namespace pneuma::sim::pattern;

namespace {

Layer layer(const char* name, double rate, double depthMax, int repetitions, double balance = 0.5) {
  Layer l;
  l.name = name;
  l.cycle.kind = CycleKind::Spline;
  l.cycle.rate = rate;
  l.cycle.depthMin = 0.05;
  l.cycle.depthMax = depthMax;
  l.cycle.balance = balance;
  l.repetitions = repetitions;
  return l;
}

// largest |v(t+dt) - v(t)| over [t0, t1]
double largestStep(LayerStack& s, double t0, double t1, double dt) {
  double prev = s.sample(t0), worst = 0.0;
  for (double t = t0 + dt; t <= t1; t += dt) {
    const double v = s.sample(t);
    worst = std::max(worst, std::abs(v - prev));
    prev = v;
  }
  return worst;
}

}  // namespace

TEST(LayerStack, TopLayerPopsAfterItsRepetitions) {
  // 3 breaths at 30 b/m (2 s each) on top of infinite 15 b/m breathing
  LayerStack s;
  s.push({layer("fast", 30, 0.4, 3), layer("base", 15, 0.25, kInfinite)}, SwitchMode::Immediate);
  s.sample(0.0);
  EXPECT_EQ(s.depth(), 2);
  EXPECT_EQ(s.currentLayerName(), "fast");
  s.sample(5.999);
  EXPECT_EQ(s.currentLayerName(), "fast");
  s.sample(6.001);
  EXPECT_EQ(s.currentLayerName(), "base");
  EXPECT_EQ(s.depth(), 1);
  // the base layer starts a fresh 4 s breath at 6 s: its peak (I:E 1:1.5) is at 6 + 1.6 s
  EXPECT_NEAR(s.sample(7.6), 0.25, 1e-9);
  s.sample(1000.0);
  EXPECT_EQ(s.currentLayerName(), "base");
}

TEST(LayerStack, FinishedStackHoldsItsLastVolume) {
  LayerStack s;
  s.push({layer("once", 20, 0.3, 1)}, SwitchMode::Immediate);
  s.sample(1.0);
  EXPECT_NEAR(s.sample(3.5), 0.05, 1e-12);
  EXPECT_EQ(s.depth(), 0);
  EXPECT_NEAR(s.sample(10.0), 0.05, 1e-12);
}

TEST(LayerStack, ImmediateSwitchBlendsWithoutAJump) {
  LayerStack s;
  s.push({layer("base", 15, 0.25, kInfinite)}, SwitchMode::Immediate);
  const double dt = 1e-3;
  s.sample(0.0);
  // switch near the peak of the base breath (0.25) into a fast breath that starts at rest (0.05)
  const double before = s.sample(1.6);
  s.push({layer("fast", 60, 0.2, kInfinite)}, SwitchMode::Immediate);
  const double after = s.sample(1.6 + dt);
  EXPECT_EQ(s.currentLayerName(), "fast");
  EXPECT_NEAR(after, before, 2e-3);
  // and it keeps moving smoothly into the new cycle: |dv/dt| < 2 /s (the smoothstep fade of a 0.2 gap
  // over 0.25 s peaks at 1.2 /s; a jump would be a step of 0.2)
  EXPECT_LT(largestStep(s, 1.6 + dt, 4.0, dt), 2.0 * dt);
  // after the cross-fade the new cycle plays unmodified: period 1 s starting at 1.6 s
  EXPECT_NEAR(s.sample(4.6), 0.05, 1e-9);
}

TEST(LayerStack, EndOfCycleSwitchWaitsForTheBreathToEnd) {
  LayerStack s;
  s.push({layer("base", 15, 0.25, kInfinite)}, SwitchMode::Immediate);
  s.sample(1.0);
  s.push({layer("deep", 10, 0.5, 1)}, SwitchMode::EndOfCycle);
  s.sample(3.99);
  EXPECT_EQ(s.currentLayerName(), "base");
  s.sample(4.01);
  EXPECT_EQ(s.currentLayerName(), "deep");
  // the 6 s deep breath ends at 10 s and pops back to base
  s.sample(10.01);
  EXPECT_EQ(s.currentLayerName(), "base");
}

TEST(LayerStack, EndOfCycleSwitchIsContinuous) {
  LayerStack s;
  s.push({layer("base", 15, 0.25, kInfinite)}, SwitchMode::Immediate);
  s.push({layer("deep", 10, 0.5, 2)}, SwitchMode::EndOfCycle, 2.0);
  EXPECT_LT(largestStep(s, 0.0, 30.0, 1e-3), 1e-3);
}

TEST(LayerStack, ScheduledPushHappensAtItsTime) {
  LayerStack s;
  s.push({layer("base", 15, 0.25, kInfinite)}, SwitchMode::Immediate, 0.0);
  s.push({layer("event", 30, 0.5, 2)}, SwitchMode::Immediate, 10.0);
  s.sample(9.999);
  EXPECT_EQ(s.currentLayerName(), "base");
  // a single large step still processes the event at 10 s: the event breaths end at 14 s
  s.sample(13.9);
  EXPECT_EQ(s.currentLayerName(), "event");
  s.sample(14.1);
  EXPECT_EQ(s.currentLayerName(), "base");
}

TEST(LayerStack, SameSeedGivesTheSameIrregularBreathing) {
  Layer irregular = layer("irregular", 20, 0.4, kInfinite);
  irregular.cycle.rateIrregularity = 0.2;
  irregular.cycle.depthIrregularity = 0.3;
  auto run = [&](std::uint64_t seed) {
    LayerStack s(seed);
    s.push({irregular}, SwitchMode::Immediate);
    std::vector<double> v;
    for (int i = 0; i < 60000; ++i) v.push_back(s.sample(i * 1e-3));
    return v;
  };
  const std::vector<double> a = run(42), b = run(42), c = run(43);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(0, std::memcmp(a.data(), b.data(), a.size() * sizeof(double)));  // bit-identical
  EXPECT_NE(a, c);
  // the variation is real: breath peaks differ
  double lo = 1.0, hi = 0.0;
  for (double x : a) hi = std::max(hi, x), lo = std::min(lo, x);
  EXPECT_GT(hi, 0.4);  // some breaths deeper than nominal
}

TEST(LayerStack, RejectsBadPushesAndTimeTravel) {
  LayerStack s;
  EXPECT_THROW(s.push({}, SwitchMode::Immediate), Error);
  Layer bad = layer("bad", 15, 0.25, 0);
  try {
    s.push({layer("ok", 15, 0.25, 1), bad}, SwitchMode::Immediate);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("layers[1].repeat"), std::string::npos) << e.what();
  }
  bad = layer("bad", 15, 0.25, 1);
  bad.cycle.depthMin = 0.6;
  try {
    s.push({bad}, SwitchMode::Immediate);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("layers[0].cycle.depth"), std::string::npos) << e.what();
  }
  s.sample(2.0);
  EXPECT_THROW(s.sample(1.0), Error);
}

// the playing layer's balance follows its breath: the inspiratory balance while it rises, the balance after
// its peak; a stack read back from a checkpoint plays on with the same balances and volumes
TEST(LayerStack, BalanceFollowsTheBreathAndSurvivesACheckpoint) {
  Layer l = layer("laugh", 15.0, 0.55, kInfinite, 0.15);  // 4 s breaths, peak at 1.6 s (I:E 1:1.5)
  l.cycle.inspiratoryBalance = 0.9;
  LayerStack s(3);
  s.push({l}, SwitchMode::Immediate, 0.0);
  s.sample(0.0);
  s.sample(1.0);
  EXPECT_DOUBLE_EQ(s.balance(), 0.9);
  std::stringstream file;
  CheckpointWriter out(file);
  s.saveState(out, "stack");
  LayerStack read(0);
  CheckpointReader in(file, "stack.ckpt");
  read.loadState(in, "stack");
  EXPECT_DOUBLE_EQ(read.balance(), 0.9);
  for (double t : {1.5, 2.0, 4.9}) {
    EXPECT_EQ(read.sample(t), s.sample(t)) << t;
    EXPECT_EQ(read.balance(), s.balance()) << t;
  }
  EXPECT_DOUBLE_EQ(s.balance(), 0.9);  // 0.9 s into the second breath
  s.sample(5.8);                       // 1.8 s into it, past the peak
  EXPECT_DOUBLE_EQ(s.balance(), 0.15);
}
