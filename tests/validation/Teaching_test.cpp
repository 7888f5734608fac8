// The teaching presets (resources/scenarios/teaching/) on the default model, each against calm upright
// breathing (resources/scenarios/calm.json): every preset changes the figure its description names, in the
// direction the physiology it cites gives. Skips when the default model has not been built.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "DefaultModel.h"
#include "pneuma/sim/Scenario.h"
#include "pneuma/sim/Simulation.h"

namespace pneuma::sim {
namespace {

using test::defaultModel;

constexpr double kMl = 1e6;  // [mL/m^3]

// what a preset run gives
struct TeachingRun {
  Summary summary;
  /// [mm/L] height of each hemidiaphragm against the lung volume over the breaths (least-squares slope),
  /// {left, right}: < 0 when the half descends on inspiration, > 0 when it rises (paradoxical)
  std::array<double, 2> domeRisePerLitre{};
};

// [m] mean height of the gut nodes that hold a diaphragm element of one side (share 0: left, 1: right)
std::array<std::vector<int>, 2> hemidiaphragmNodes(const Model& m, const StepWork& w) {
  std::array<std::vector<int>, 2> out;
  std::vector<char> seen(static_cast<std::size_t>(m.nodes.size()) * 2, 0);
  for (int e = 0; e < m.elements.size(); ++e) {
    if (m.elements.group[static_cast<std::size_t>(e)] != ElementGroup::Diaphragm) continue;
    const double s = w.constants.elementRightShare(e);
    if (s != 0.0 && s != 1.0) continue;  // midline strands belong to both halves
    const int side = s == 1.0 ? 1 : 0;
    for (const AnchorSet* a : {&m.elements.endA, &m.elements.endB})
      for (int k = 0; k < 3; ++k) {
        const int n = a->nodes(k, e);
        if (a->body[static_cast<std::size_t>(e)] >= 0 || n < 0 || m.nodes.isFixed(n)) continue;
        char& mark = seen[static_cast<std::size_t>(2 * n + side)];
        if (!mark) out[static_cast<std::size_t>(side)].push_back(n);
        mark = 1;
      }
  }
  return out;
}

// least-squares slope of y against x
double slope(const std::vector<double>& x, const std::vector<double>& y) {
  double mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) mx += x[i], my += y[i];
  mx /= static_cast<double>(x.size());
  my /= static_cast<double>(y.size());
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i)
    sxy += (x[i] - mx) * (y[i] - my), sxx += (x[i] - mx) * (x[i] - mx);
  return sxy / sxx;
}

// one finished run of a shipped scenario ("calm.json", "teaching/supine.json", ...): 12 s after settling at
// 30 frames/s, shared by the tests
const TeachingRun& run(const std::string& file) {
  static std::map<std::string, TeachingRun> cache;
  if (const auto it = cache.find(file); it != cache.end()) return it->second;
  const Scenario s = loadScenario(std::string(PNEUMA_RESOURCE_DIR) + "/scenarios/" + file);
  SimulationOptions o = s.options;
  o.outputRate = 30.0;
  o.recordSeconds = kTraceOnlyRecordSeconds;
  const auto model = defaultModel();
  Simulation sim(model, makeController(s, model, PNEUMA_RESOURCE_DIR), o);
  const auto nodes = hemidiaphragmNodes(*model, sim.stepWork());
  std::vector<double> volume;               // [L]
  std::array<std::vector<double>, 2> dome;  // [mm]
  sim.advance(o.settleTime + 12.0, [&](const Simulation& sm) {
    if (sm.state().time < o.settleTime) return true;
    volume.push_back(sm.latestMetrics().lungVolume * 1e3);
    for (std::size_t side = 0; side < 2; ++side) {
      double z = 0.0;
      for (int n : nodes[side]) z += sm.state().nodePosition(2, n);
      dome[side].push_back(z / static_cast<double>(nodes[side].size()) * 1e3);
    }
    return true;
  });
  TeachingRun r;
  r.summary = sim.summary();
  for (std::size_t side = 0; side < 2; ++side) r.domeRisePerLitre[side] = slope(volume, dome[side]);
  ::testing::Test::RecordProperty(
      file + ".dome_mm_per_L_left_right",
      std::to_string(r.domeRisePerLitre[0]) + " " + std::to_string(r.domeRisePerLitre[1]));
  return cache[file] = r;
}

double tidalMl(const std::string& file) { return run(file).summary.tidalVolume * kMl; }
double ribCageShare(const std::string& file) { return run(file).summary.motion.ribCageShare(); }

// the normal reference: both hemidiaphragms descend on inspiration
TEST(Teaching, CalmBothHemidiaphragmsDescend) {
  REQUIRE_DEFAULT_MODEL();
  EXPECT_LT(run("calm.json").domeRisePerLitre[0], -1.0);
  EXPECT_LT(run("calm.json").domeRisePerLitre[1], -1.0);
}

// a paralysed hemidiaphragm: a smaller tidal volume (Laroche et al. 1988), and the paralysed dome is drawn
// up on inspiration while the other descends (Alexander 1966, the sniff test)
TEST(Teaching, ParalysedHemidiaphragmLowersTidalVolumeAndMovesParadoxically) {
  REQUIRE_DEFAULT_MODEL();
  for (const int paralysed : {0, 1}) {
    const std::string file = paralysed == 0 ? "teaching/paralysed-left-hemidiaphragm.json"
                                            : "teaching/paralysed-right-hemidiaphragm.json";
    SCOPED_TRACE(file);
    EXPECT_LT(tidalMl(file), 0.9 * tidalMl("calm.json"));
    const auto& rise = run(file).domeRisePerLitre;
    EXPECT_GT(rise[static_cast<std::size_t>(paralysed)], 0.0) << "the paralysed dome rises on inspiration";
    EXPECT_LT(rise[static_cast<std::size_t>(1 - paralysed)], -1.0) << "the other dome descends";
  }
}

// weak intercostals: breathing turns abdominal and shallower (De Troyer & Estenne 1984; Urmey et al. 1986)
TEST(Teaching, WeakIntercostalsLowerTheRibCageShare) {
  REQUIRE_DEFAULT_MODEL();
  const std::string file = "teaching/weak-intercostals.json";
  EXPECT_LT(ribCageShare(file), ribCageShare("calm.json") - 0.05);
  EXPECT_LT(tidalMl(file), 0.9 * tidalMl("calm.json"));
}

// stiff rib joints (ankylosing spondylitis): the rib cage barely moves, the abdomen takes over, the tidal
// volume falls (Romagnoli et al. 2004)
TEST(Teaching, StiffChestWallShiftsBreathingToTheAbdomen) {
  REQUIRE_DEFAULT_MODEL();
  const std::string file = "teaching/stiff-chest-wall.json";
  EXPECT_LT(ribCageShare(file), ribCageShare("calm.json") - 0.2);
  EXPECT_LT(run(file).summary.motion.lowerRibExpansion,
            0.5 * run("calm.json").summary.motion.lowerRibExpansion);
  EXPECT_GT(run(file).summary.motion.umbilicusAnterior, run("calm.json").summary.motion.umbilicusAnterior);
  EXPECT_LT(tidalMl(file), 0.9 * tidalMl("calm.json"));
}

// abdominal binding: breathing shifts to the rib cage (Hussain et al. 1985; Konno & Mead 1967)
TEST(Teaching, AbdominalBindingRaisesTheRibCageShare) {
  REQUIRE_DEFAULT_MODEL();
  const std::string file = "teaching/abdominal-binding.json";
  EXPECT_GT(ribCageShare(file), ribCageShare("calm.json") + 0.05);
  EXPECT_LT(tidalMl(file), tidalMl("calm.json"));
}

// supine against upright: a lower rib-cage share (Sharp et al. 1975) and a lower end-expiratory volume
// (Yamada et al. 2020)
TEST(Teaching, SupineLowersTheRibCageShareAndTheRestingVolume) {
  REQUIRE_DEFAULT_MODEL();
  const std::string file = "teaching/supine.json";
  EXPECT_LT(ribCageShare(file), ribCageShare("calm.json") - 0.05);
  EXPECT_LT(run(file).summary.endExpiratoryVolume, 0.99 * run("calm.json").summary.endExpiratoryVolume);
}

}  // namespace
}  // namespace pneuma::sim
