// No surface passes through another (issue 13): the lung cavity, the two lungs and the gut, posed at
// end-expiration and end-inspiration (the frames of smallest and largest lung volume after settling) of every
// shipped breath style (resources/presets/*.json) and every affect preset (resources/presets/affect/),
// checked with the triangle-triangle crossing test of SurfaceCrossings.h: each surface against itself, and
// the pairs that must not cross (each lung with the gut, with the cavity and with the other lung). Short
// runs: two seconds of settling and one breath or a few seconds of each style. Skips when the default model
// is absent. ctest runs the same checks on the female preset's model (FemalePreset.Surfaces).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <sstream>

#include "DefaultModel.h"
#include "SurfaceCrossings.h"
#include "pneuma/sim/BreathStyleController.h"
#include "pneuma/sim/PosedGeometry.h"
#include "pneuma/sim/Simulation.h"
#include "pneuma/sim/pattern/PatternController.h"

namespace pneuma::sim {
namespace {

namespace fs = std::filesystem;
using test::defaultModel;

// the posed surfaces of one frame (the one posing function)
PosedGeometry pose(const Model& m, const State& s) {
  PosedGeometry p;
  poseGeometry(m, s, p);
  return p;
}

// crossings per pair, e.g. {"cavity": 0, "right-gut": 3, ...}
std::map<std::string, int> crossings(const Model& m, const State& s) {
  using pneuma::test::countCrossings;
  using pneuma::test::countSelfCrossings;
  const PosedGeometry p = pose(m, s);
  const Eigen::Matrix3Xi &tc = m.cavity.triangles, &tr = m.lungs.right.triangles,
                         &tl = m.lungs.left.triangles, &tg = m.gut.triangles;
  return {{"cavity", countSelfCrossings(p.cavity, tc)},
          {"gut", countSelfCrossings(p.gut, tg)},
          {"right", countSelfCrossings(p.lungRight, tr)},
          {"left", countSelfCrossings(p.lungLeft, tl)},
          {"right-left", countCrossings(p.lungRight, tr, p.lungLeft, tl)},
          {"right-gut", countCrossings(p.lungRight, tr, p.gut, tg)},
          {"left-gut", countCrossings(p.lungLeft, tl, p.gut, tg)},
          {"right-cavity", countCrossings(p.lungRight, tr, p.cavity, tc)},
          {"left-cavity", countCrossings(p.lungLeft, tl, p.cavity, tc)}};
}

std::string describe(const std::map<std::string, int>& c) {
  std::ostringstream s;
  for (const auto& [pair, n] : c) s << pair << " " << n << "; ";
  return s.str();
}

// runs `controller` for settle + duration and expects no crossing at the frames of smallest and largest lung
// volume after settling
void expectNoCrossings(const std::string& name, std::unique_ptr<Controller> controller, double duration) {
  const auto model = defaultModel();
  SimulationOptions o;
  o.settleTime = 2.0;
  o.outputRate = 30.0;
  o.recordSeconds = kTraceOnlyRecordSeconds;
  Simulation sim(model, std::move(controller), o);
  State lo, hi;
  double vMin = 1e9, vMax = -1e9;
  sim.advance(o.settleTime + duration, [&](const Simulation& s) {
    if (s.state().time < o.settleTime) return true;
    const double v = s.latestMetrics().lungVolume;
    if (v < vMin) vMin = v, lo = s.state();
    if (v > vMax) vMax = v, hi = s.state();
    return true;
  });
  ASSERT_GT(vMax, vMin) << name;
  for (const auto& [phase, state] :
       {std::pair<const char*, const State*>{"end-expiration", &lo}, {"end-inspiration", &hi}}) {
    const std::map<std::string, int> c = crossings(*model, *state);
    int total = 0;
    for (const auto& [pair, n] : c) total += n;
    testing::Test::RecordProperty(name + "." + phase, describe(c));
    EXPECT_EQ(total, 0) << name << " at " << phase << ": " << describe(c);
  }
}

TEST(Surfaces, DefaultModelAtRestHasNoCrossings) {
  REQUIRE_DEFAULT_MODEL();
  const Model& m = *defaultModel();
  ASSERT_GT(m.lungs.right.vertexCount(), 0);
  const std::map<std::string, int> c = crossings(m, makeInitialState(m));
  for (const auto& [pair, n] : c) EXPECT_EQ(n, 0) << pair;
}

TEST(Surfaces, NoCrossingsInAnyBreathStyle) {
  REQUIRE_DEFAULT_MODEL();
  for (const char* style : {"calm", "deep", "panting", "forced-exhale"}) {
    const BreathStyle s = loadBreathStyle(style);
    // one breath of the periodic styles (at least 4 s), the forced exhale's whole manoeuvre
    const double duration = s.cycles > 0 ? 7.0 : std::max(4.0, 60.0 / s.breathsPerMinute);
    expectNoCrossings(style, std::make_unique<BreathStyleController>(s), duration);
  }
}

// four seconds of each affect: the sigh's, the yawn's and the laugh's peaks are the deepest inspirations of
// any preset
TEST(Surfaces, NoCrossingsInAnyAffect) {
  REQUIRE_DEFAULT_MODEL();
  const pattern::DriveCalibration calibration = pattern::calibrateDrive(defaultModel());
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(fs::path(PNEUMA_RESOURCE_DIR) / "presets" / "affect"))
    if (e.path().extension() == ".json") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  ASSERT_GE(names.size(), 10u);
  for (const std::string& name : names)
    expectNoCrossings("affect " + name,
                      pattern::makeAffectController(name, PNEUMA_RESOURCE_DIR, 1, calibration), 4.0);
}

}  // namespace
}  // namespace pneuma::sim
