// The teaching presets (resources/scenarios/teaching/) on the default model, each against calm upright
// breathing (resources/scenarios/calm.json): every preset changes the figure its description names, in the
// direction the physiology it cites gives (sim::teachingChecks(), the rows of validate's Teaching section).
// Skips when the default model has not been built.
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "DefaultModel.h"
#include "pneuma/sim/Experiments.h"

namespace pneuma::sim {
namespace {

using test::defaultModel;

// one finished run of a shipped scenario, shared by the tests
const TeachingRun& run(const std::string& file) {
  static std::map<std::string, TeachingRun> cache;
  if (const auto it = cache.find(file); it != cache.end()) return it->second;
  TeachingRun r = runTeachingScenario(defaultModel(), file, PNEUMA_RESOURCE_DIR);
  ::testing::Test::RecordProperty(
      file + ".dome_mm_per_L_left_right",
      std::to_string(r.domeRisePerLitre[0]) + " " + std::to_string(r.domeRisePerLitre[1]));
  return cache[file] = std::move(r);
}

// the checks of one preset against calm: every one passes, and there are `expected` of them
void expectPresetChecks(const std::string& preset, std::size_t expected) {
  const std::string file = preset == "calm" ? "calm.json" : "teaching/" + preset + ".json";
  std::vector<TeachingRun> runs{run("calm.json")};
  if (preset != "calm") runs.push_back(run(file));
  std::size_t count = 0;
  for (const Check& c : teachingChecks(runs)) {
    if (c.id.rfind("teaching." + preset + ".", 0) != 0) continue;
    ++count;
    EXPECT_TRUE(c.isPassed()) << c.id << ": " << c.what << " = " << c.measured << " " << c.unit
                              << ", expected " << c.target;
  }
  EXPECT_EQ(count, expected) << preset;
}

// the normal reference: both hemidiaphragms descend on inspiration
TEST(Teaching, CalmBothHemidiaphragmsDescend) {
  REQUIRE_DEFAULT_MODEL();
  expectPresetChecks("calm", 2);
}

// a paralysed hemidiaphragm: a smaller tidal volume (Laroche et al. 1988), and the paralysed dome is drawn
// up on inspiration while the other descends (Alexander 1966, the sniff test)
TEST(Teaching, ParalysedHemidiaphragmLowersTidalVolumeAndMovesParadoxically) {
  REQUIRE_DEFAULT_MODEL();
  expectPresetChecks("paralysed-left-hemidiaphragm", 3);
  expectPresetChecks("paralysed-right-hemidiaphragm", 3);
}

// weak intercostals: breathing turns abdominal and shallower (De Troyer & Estenne 1984; Urmey et al. 1986)
TEST(Teaching, WeakIntercostalsLowerTheRibCageShare) {
  REQUIRE_DEFAULT_MODEL();
  expectPresetChecks("weak-intercostals", 2);
}

// stiff rib joints (ankylosing spondylitis): the rib cage barely moves, the abdomen takes over, the tidal
// volume falls (Romagnoli et al. 2004)
TEST(Teaching, StiffChestWallShiftsBreathingToTheAbdomen) {
  REQUIRE_DEFAULT_MODEL();
  expectPresetChecks("stiff-chest-wall", 4);
}

// abdominal binding: breathing shifts to the rib cage (Hussain et al. 1985; Konno & Mead 1967)
TEST(Teaching, AbdominalBindingRaisesTheRibCageShare) {
  REQUIRE_DEFAULT_MODEL();
  expectPresetChecks("abdominal-binding", 2);
}

// supine against upright: a lower rib-cage share (Sharp et al. 1975) and a lower end-expiratory volume
// (Yamada et al. 2020)
TEST(Teaching, SupineLowersTheRibCageShareAndTheRestingVolume) {
  REQUIRE_DEFAULT_MODEL();
  expectPresetChecks("supine", 2);
}

// the checks' own logic on made-up runs: a preset that does not move its figure fails, and the shipped list
// starts with the calm reference
TEST(Teaching, ChecksFailWhenAPresetChangesNothing) {
  EXPECT_EQ(teachingScenarios().front(), "calm.json");
  TeachingRun calm;
  calm.scenario = "calm.json";
  calm.summary.tidalVolume = 500e-6;
  calm.summary.endExpiratoryVolume = 3e-3;
  calm.summary.motion.lowerRibExpansion = 5e-3;
  calm.summary.motion.umbilicusAnterior = 2e-3;
  calm.domeRisePerLitre = {-20.0, -20.0};
  std::vector<TeachingRun> runs{calm};
  for (const std::string& file : teachingScenarios()) {
    if (file == "calm.json") continue;
    TeachingRun same = calm;
    same.scenario = file;
    runs.push_back(same);
  }
  const std::vector<Check> checks = teachingChecks(runs);
  int failed = 0;
  for (const Check& c : checks)
    if (c.id.rfind("teaching.calm.", 0) != 0) failed += !c.isPassed();
  EXPECT_EQ(checks.size(), 18u);
  // all but the two "the working dome descends" checks, which calm's motion meets
  EXPECT_EQ(failed, 14) << "every preset's change fails when the preset behaves like calm";
}

}  // namespace
}  // namespace pneuma::sim
