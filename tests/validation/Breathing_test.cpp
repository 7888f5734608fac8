// Breathing on the default model against the targets of Zordan et al. 2004 (Section 8.1, Table 2,
// Figures 4-6) and physiology. Skips when the default model has not been built
// (PNEUMA_DEFAULT_MODEL_DIR, built by 'pneuma-cli model build').
#include "pneuma/sim/BreathStyleController.h"
#include "pneuma/sim/ModelIO.h"
#include "pneuma/sim/Simulation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>

namespace pneuma::sim {
namespace {

std::shared_ptr<const Model> defaultModel() {
  static const std::shared_ptr<const Model> model = []() -> std::shared_ptr<const Model> {
    const char* env = std::getenv("PNEUMA_DEFAULT_MODEL_DIR");
    const std::string dir = env != nullptr ? env : PNEUMA_DEFAULT_MODEL_DIR;
    if (!std::filesystem::exists(dir + "/model.json")) return nullptr;
    return std::make_shared<const Model>(loadModel(dir));
  }();
  return model;
}

#define REQUIRE_DEFAULT_MODEL()                                                  \
  if (!defaultModel()) GTEST_SKIP() << "default model not built (PNEUMA_DEFAULT_MODEL_DIR)"

// one finished run of a breath style, cached per (style, friction scale)
struct StyleRun {
  Summary summary;
  Trace trace;
  double settleTime = 0.0;
  std::vector<Eigen::Vector3d> spineTop;  // [m] com of the highest moving thoracic body, per frame
};

const StyleRun& run(const std::string& style, double duration, double frictionScale = 1.0) {
  static std::map<std::pair<std::string, double>, StyleRun> cache;
  const auto key = std::make_pair(style, frictionScale);
  if (const auto it = cache.find(key); it != cache.end()) return it->second;
  const Model& model = *defaultModel();
  int spine = -1;
  for (int b = 0; b < model.bodies.size(); ++b) {
    if (model.bodies.isFixed[static_cast<std::size_t>(b)] || model.bodies.name[static_cast<std::size_t>(b)].rfind("thoracic", 0) != 0) continue;
    if (spine < 0 || model.bodies.com(2, b) > model.bodies.com(2, spine)) spine = b;
  }
  SimulationOptions o;
  o.step.jointFrictionScale = frictionScale;
  o.outputRate = 30.0;
  Simulation sim(defaultModel(), std::make_unique<BreathStyleController>(loadBreathStyle(style)), o);
  StyleRun r;
  r.settleTime = o.settleTime;
  sim.advance(o.settleTime + duration, [&](const Simulation& s) {
    r.spineTop.push_back(spine >= 0 ? Eigen::Vector3d(s.state().bodyPosition.col(spine)) : Eigen::Vector3d::Zero());
    return true;
  });
  r.summary = sim.summary();
  r.trace = sim.trace();
  r.spineTop.insert(r.spineTop.begin(), r.spineTop.empty() ? Eigen::Vector3d::Zero() : r.spineTop.front());
  return cache[key] = r;
}

constexpr double kMl = 1e-6;  // [m^3] per mL

// Section 6.2 / Figure 4: "a tolerable error less than 2 percent during our results for breathing"
TEST(Breathing, GutVolumeErrorBelowTwoPercentForEveryStyle) {
  REQUIRE_DEFAULT_MODEL();
  for (const char* style : {"calm", "deep", "panting"}) EXPECT_LT(run(style, 12.0).summary.maxGutVolumeError, 0.02) << style;
  EXPECT_LT(run("forced-exhale", 8.0).summary.maxGutVolumeError, 0.02);
}

// Figure 6: calm tidal volume "almost perfectly on the 500 mL average"; Table 2: 15 b/m
TEST(Breathing, CalmTidalVolumeAndRate) {
  REQUIRE_DEFAULT_MODEL();
  const Summary& s = run("calm", 12.0).summary;
  EXPECT_NEAR(s.tidalVolume / kMl, 500.0, 50.0);
  EXPECT_NEAR(s.breathsPerMinute, 15.0, 0.5);
}

// Table 2 slow/deep: 12 b/m; tidal volume above calm and within 1-3 L, the range of deep breaths of
// healthy adults (inspiratory capacity about 3 L; West, Respiratory Physiology, ch. 2)
TEST(Breathing, DeepLargerThanCalmWithinHumanRange) {
  REQUIRE_DEFAULT_MODEL();
  const Summary& deep = run("deep", 12.0).summary;
  EXPECT_GT(deep.tidalVolume, run("calm", 12.0).summary.tidalVolume);
  EXPECT_GE(deep.tidalVolume / kMl, 1000.0);
  EXPECT_LE(deep.tidalVolume / kMl, 3000.0);
  EXPECT_NEAR(deep.breathsPerMinute, 12.0, 0.5);
}

// Section 8.1 panting: 60 b/m, "small rapid inhales and exhales where most of the motion is seen in the
// chest": smaller tidal volume than calm, and a larger chest-to-abdomen excursion ratio than calm
TEST(Breathing, PantingFastSmallAndChestDominant) {
  REQUIRE_DEFAULT_MODEL();
  const Summary& pant = run("panting", 12.0).summary;
  const Summary& calm = run("calm", 12.0).summary;
  EXPECT_NEAR(pant.breathsPerMinute, 60.0, 1.0);
  EXPECT_LT(pant.tidalVolume, calm.tidalVolume);
  const double pantRatio = pant.xiphoidExcursion / pant.umbilicusExcursion;
  const double calmRatio = calm.xiphoidExcursion / calm.umbilicusExcursion;
  EXPECT_GT(pantRatio, calmRatio);
}

// Section 8.1 / Figure 5 forced exhale: the volume falls below calm end-expiration, the rectus pulls
// the abdomen in (umbilicus posterior by >= 1 cm) and the lower ribcage down (xiphoid moves down)
TEST(Breathing, ForcedExhale) {
  REQUIRE_DEFAULT_MODEL();
  const StyleRun& forced = run("forced-exhale", 8.0);
  const Model& model = *defaultModel();
  const int umb = model.landmarks.find("umbilicus"), xiph = model.landmarks.find("xiphoid");
  const Trace& t = forced.trace;
  // reference: the last frame of the settling phase
  std::size_t ref = 0;
  while (ref + 1 < t.size() && t.time[ref + 1] <= forced.settleTime) ++ref;
  double minVolume = t.lungVolume[ref], minUmbY = 0.0, minXiphZ = 0.0;
  for (std::size_t i = ref; i < t.size(); ++i) {
    minVolume = std::min(minVolume, t.lungVolume[i]);
    minUmbY = std::min(minUmbY, t.landmarks[i](1, umb) - t.landmarks[ref](1, umb));
    minXiphZ = std::min(minXiphZ, t.landmarks[i](2, xiph) - t.landmarks[ref](2, xiph));
  }
  EXPECT_LT(minVolume, run("calm", 12.0).summary.endExpiratoryVolume);
  EXPECT_LE(minUmbY, -0.01);
  EXPECT_LT(minXiphZ, -0.001);
}

// Section 5: with rib-joint friction (Eq. 3) "during a deep inhale, as the ribs are pulled upward, the
// spine moves backward"; without friction it moves clearly less
TEST(Breathing, SpineSwaysBackwardOnDeepInhaleOnlyWithFriction) {
  REQUIRE_DEFAULT_MODEL();
  // backward sway: spine-top y at the end of inspiration minus at the end of expiration, per cycle
  auto sway = [](const StyleRun& r) {
    const Trace& t = r.trace;
    std::size_t lo = 0, hi = 0;
    for (std::size_t i = 0; i < t.size(); ++i) {
      if (t.time[i] < r.settleTime) continue;
      if (lo == 0 || t.lungVolume[i] < t.lungVolume[lo]) lo = i;
      if (hi == 0 || t.lungVolume[i] > t.lungVolume[hi]) hi = i;
    }
    return r.spineTop[hi].y() - r.spineTop[lo].y();  // [m] < 0: backward on inhale
  };
  const double withFriction = sway(run("deep", 12.0, 1.0));
  const double frictionless = sway(run("deep", 12.0, 0.0));
  EXPECT_LT(withFriction, -1e-4) << "spine should move backward (-y) on inhale";
  EXPECT_LT(std::abs(frictionless), 0.5 * std::abs(withFriction));
}

// Figure 4: "Gut deformation after a heavy impact ... volume error less than 0.5 percent". The relaxed
// torso settles, then the anterior wall within 6 cm of the umbilicus is struck at 2 m/s posteriorly.
TEST(Breathing, HeavyImpactKeepsGutVolumeErrorBelowHalfPercent) {
  REQUIRE_DEFAULT_MODEL();
  const Model& model = *defaultModel();
  struct Relaxed : Controller {
    Activations activations(double, const Metrics&) override { return relaxedActivations(); }
    std::string describe() const override { return "relaxed"; }
    std::unique_ptr<Controller> clone() const override { return std::make_unique<Relaxed>(*this); }
  };
  SimulationOptions o;
  o.settleTime = 0.0;
  Simulation sim(defaultModel(), std::make_unique<Relaxed>(), o);
  sim.advance(2.0);
  State s = sim.state();
  const Eigen::Vector3d umb = sim.latestMetrics().landmarks.col(model.landmarks.find("umbilicus"));
  int struck = 0;
  for (int n = 0; n < model.nodes.size(); ++n) {
    if (model.nodes.isFixed(n) || model.nodes.region[static_cast<std::size_t>(n)] != NodeRegion::Wall) continue;
    if ((s.nodePosition.col(n) - umb).norm() > 0.06) continue;
    s.nodeVelocity.col(n) += Eigen::Vector3d(0.0, -2.0, 0.0);
    ++struck;
  }
  ASSERT_GT(struck, 3);
  StepWork w = makeStepWork(model);
  Metrics m;
  double maxError = 0.0, maxDent = 0.0;
  const double dt = sim.dt();
  for (double t = 0.0; t < 1.5; t += dt) {
    step(model, s, dt, relaxedActivations(), o.step, w);
    computeMetrics(model, s, relaxedActivations(), o.step, w, m);
    maxError = std::max(maxError, std::abs(m.gutVolumeError));
    maxDent = std::max(maxDent, umb.y() - m.landmarks(1, model.landmarks.find("umbilicus")));
  }
  EXPECT_LT(maxError, 0.005);
  EXPECT_GT(maxDent, 0.005) << "the impact should visibly dent the wall (> 5 mm)";
}

}  // namespace
}  // namespace pneuma::sim
