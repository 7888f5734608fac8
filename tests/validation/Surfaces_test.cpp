// No surface passes through another (issue 13): the lung cavity, the two lungs and the gut, posed at
// end-expiration and end-inspiration (the frames of smallest and largest lung volume after settling) of every
// shipped breath style (resources/presets/*.json) and every affect preset (resources/presets/affect/),
// checked with the triangle-triangle crossing test of SurfaceCrossings.h: each surface against itself, and
// the pairs that must not cross (each lung with the gut, with the cavity and with the other lung). Short
// runs: two seconds of settling and one breath or a few seconds of each style. Skips when the default model
// is absent. ctest runs the rest and breath-style checks on the female preset's model as well
// (FemalePreset.Surfaces).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
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

// the lung's self-crossings that involve a face on the mediastinum (a vertex embedded between the cavity
// points above and below it, 6 cavity slots): the embedding's own, as opposed to those it inherits from the
// cavity's walls
int medialCrossings(const LungSurface& l, const Eigen::Matrix3Xd& x) {
  std::vector<std::pair<int, int>> pairs;
  pneuma::test::countSelfCrossings(x, l.triangles, pneuma::test::kCrossingTolerance, &pairs);
  auto isMedial = [&](int f) {
    for (int k = 0; k < 3; ++k)
      if (l.cavityVertex(3, l.triangles(k, f)) >= 0) return true;
    return false;
  };
  int n = 0;
  for (const auto& [a, b] : pairs) n += isMedial(a) && isMedial(b);
  return n;
}

// The surfaces still cross (issue 13). Fixing the dome's posterior (crural) rim to the spine, laying the dome
// on the front of the vertebral bodies like the ribs' zone of apposition, and keeping the cavity's wall 20 mm
// clear of the dome (resources/anatomy/README.md) removed the calm cavity's folds at end-expiration and cut
// the crossing pairs summed over every style and affect from 8172 to 4206 (the cavity's own: 1201 to 290;
// the gut's: 359 to 9). Building the cavity again without the hull points of wall faces that graze the dome
// (meshing/src/LungCavity.cpp, kFaceClearance) cut them to 1560 (the cavity's own: 8). What remains,
// measured, is the lungs' (R 120, L 159 self; with the cavity 748, with the gut 516): the cut leaves
// mediastinal lung faces that stand on the dome where it wraps the front of the vertebral bodies and rises
// steeply beyond the mediastinum's side, so the face's foot lies against the gut across the plane and passes
// into it when the dome moves a millimetre against the walls the face's corners are bound to (depths up to
// 4-10 mm). Splitting the mediastinal faces to 12 mm edges that follow the floor and ceiling (total 3867),
// and a posterior mediastinum as wide as the vertebral bodies (relief 166 -> 265-345) made it worse. Until
// they are gone those pairs are reported and the test is skipped naming them; set this to true to enforce
// them.
constexpr bool kEnforceWallCrossings = false;
// Until then their sum may not grow: crossing pairs summed over both phases of the breath styles and of the
// affects. Measured: 264 and 1294 before the Delaunay flips of the lungs' mediastinal faces
// (meshing/src/LungCavity.cpp, flipMediastinalFaces), 130 and 747 after (in total 1558 -> 877: the left
// lung's own 159 -> 42, the right lung's 122 -> 117, the lungs with the cavity 748 -> 438, with the gut 516
// -> 267); 130 and 539 with the affect drive's continuous demand and softer feedback (docs/patterns.md,
// "Feedback"); 35 and 142 with points inside the mediastinal faces, each bound between the walls above and
// below it (meshing/src/LungCavity.cpp, addFacePoints: in total 669 -> 177, the lungs with the gut 211 -> 40,
// with the cavity 338 -> 93, the lungs' own 116 -> 40); 35 and 140 with the muscle and posture work of
// session 17; 19 and 92 with the dome's cap triangulated Delaunay (meshing/src/GutSurface.cpp: in total 175
// -> 111; the gut's and the cavity's own 2 -> 0, the lungs with the cavity 93 -> 66, with the gut 40 -> 11; a
// sliver beside the apex turned over at calm end-inspiration, and a fifth of the lung crossings were with the
// cavity's floor triangles on it); 16 and 127 with the rib necks' lock at 300 N m/rad, the driven scalenes
// and the stiff first costal cartilage (resources/anatomy/README.md, "Rib motion"): the upper ribs now rise,
// and at joy's deep end-inspiration the left lung's own crossings went 6 -> 14, the lungs' with the cavity 17
// -> 38; 6 and 79 with a point in each fan of the mediastinal faces that spans the strip beside the vertebral
// bodies (meshing/src/LungCavity.cpp, addBoundaryFanPoints); 0 and 76 with the cavity's slivers turned over
// (meshing/src/LungCavity.cpp, flipSlivers: a 10 mm floor sliver beside the spine twisted under the back
// wall's 235 mm face at the deep breaths' end-inspiration and the right lung's mediastinal face crossed that
// face, 3 pairs each in deep and forced-exhale; the female preset's 56 and 262 went to 10 and 58); 0 and 33
// with joy's laugh inhaling with the rib cage as well (resources/presets/affect/joy.json,
// inspiratory_balance: its 59 pairs, where the dome alone drew 1.25 L, went to 13); 0 and 19 with the
// mediastinal faces' points bound along the chord that meets a wall soonest (meshing/src/LungCavity.cpp,
// kChordDirections: the 4 pairs each of anger, excitement, pain and startle at end-expiration, a face point
// beside the dome's posterior notch, are gone); 0 and 18 with the fan points at 0.6 times the face points'
// spacing (meshing/src/LungCavity.cpp, kFanEdge; the female preset's styles 8 -> 0, so ctest
// FemalePreset.Surfaces checks them too); 0 and 16 with relaxation's and sadness's balance at 0.45
// (resources/presets/affect/, docs/patterns.md: at 0.2 and 0.35 the dome alone drew their inspirations and
// the rib cage was drawn in; relaxation's 2 pairs, and the female preset's 6 pairs of the gut with itself in
// the two, are gone: her affects 45 -> 39); 0 and 4 with the dome's rim held on the ribs as the rest of the
// zone of apposition is (meshing/src/MuscleNetwork.cpp, addApposition(): at joy's laugh the untied rim rode
// up past the first ring on its insertions on the rising lower ribs; the female preset's 39 -> 14). The
// budget leaves about 10 % for the run-to-run spread of other changes.
constexpr int kAffectCrossingBudget = 5;

// runs `controller` for settle + duration and checks the frames of smallest and largest lung volume after
// settling: the two lungs never cross each other nor does a mediastinal face cross anything; the other
// crossings are added to `wall` (see kEnforceWallCrossings)
void expectNoCrossings(const std::string& name, std::unique_ptr<Controller> controller, double duration,
                       std::ostringstream& wall, int& sum) {
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
    const PosedGeometry p = pose(*model, *state);
    const int medial =
        medialCrossings(model->lungs.right, p.lungRight) + medialCrossings(model->lungs.left, p.lungLeft);
    EXPECT_EQ(c.at("right-left"), 0) << name << " at " << phase;
    EXPECT_EQ(medial, 0) << name << " at " << phase << ": mediastinal faces cross";
    int total = 0;
    for (const auto& [pair, n] : c) total += n;
    testing::Test::RecordProperty(name + "." + phase, describe(c));
    if (kEnforceWallCrossings) {
      EXPECT_EQ(total, 0) << name << " at " << phase << ": " << describe(c);
    }
    sum += total;
    if (total > 0) wall << "\n  " << name << " at " << phase << ": " << describe(c);
  }
}

// the known crossings where the dome folds, reported as a skip until kEnforceWallCrossings; their sum over
// the runs may not grow past `budget`
void reportWallCrossings(const std::ostringstream& wall, int sum, int budget) {
  testing::Test::RecordProperty("crossings", sum);
  EXPECT_LE(sum, budget) << "crossing pairs summed over the runs:" << wall.str();
  if (!wall.str().empty())
    GTEST_SKIP() << "surfaces cross where the dome folds (kEnforceWallCrossings):" << wall.str();
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
  std::ostringstream wall;
  int sum = 0;
  for (const char* style : {"calm", "deep", "panting", "forced-exhale"}) {
    const BreathStyle s = loadBreathStyle(style);
    // one breath of the periodic styles (at least 4 s), the forced exhale's whole manoeuvre
    const double duration = s.cycles > 0 ? 7.0 : std::max(4.0, 60.0 / s.breathsPerMinute);
    expectNoCrossings(style, std::make_unique<BreathStyleController>(s), duration, wall, sum);
  }
  // the styles cross nowhere since flipSlivers (above): enforced at both phases of every style
  testing::Test::RecordProperty("crossings", sum);
  EXPECT_EQ(sum, 0) << "crossing pairs summed over the breath styles:" << wall.str();
}

TEST(Surfaces, NoCrossingsInAnyAffect) {
  REQUIRE_DEFAULT_MODEL();
  const pattern::DriveCalibration calibration = pattern::calibrateDrive(defaultModel());
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(fs::path(PNEUMA_RESOURCE_DIR) / "presets" / "affect"))
    if (e.path().extension() == ".json") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  ASSERT_GE(names.size(), 10u);
  std::ostringstream wall;
  int sum = 0;
  for (const std::string& name : names)
    expectNoCrossings("affect " + name,
                      pattern::makeAffectController(name, PNEUMA_RESOURCE_DIR, 1, calibration), 4.0, wall,
                      sum);
  reportWallCrossings(wall, sum, kAffectCrossingBudget);
}

}  // namespace
}  // namespace pneuma::sim
