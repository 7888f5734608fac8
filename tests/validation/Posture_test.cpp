// Posture (StepOptions::posture) on the default model: calm breathing upright and lying on the back, against
// the direction the physiology gives. The checks live in sim/Experiments.h (postureChecks()), beside the
// papers'. Skips when the default model has not been built.
#include <gtest/gtest.h>

#include <map>

#include "DefaultModel.h"
#include "pneuma/sim/Experiments.h"

namespace pneuma::sim {
namespace {

using test::defaultModel;

// one finished calm run per posture, shared by the tests
const StyleRun& calm(Posture posture) {
  static std::map<Posture, StyleRun> cache;
  if (const auto it = cache.find(posture); it != cache.end()) return it->second;
  ExperimentSettings settings;
  settings.simulation.step.posture = posture;
  return cache[posture] = runBreathStyle(defaultModel(), loadBreathStyle("calm"), settings);
}

// the check `id` of postureChecks() on the calm runs, with its figures recorded in the test's XML
Check postureCheck(const std::string& id) {
  for (const Check& c : postureChecks(calm(Posture::Upright), calm(Posture::Supine)))
    if (c.id == id) {
      ::testing::Test::RecordProperty(id, std::to_string(c.measured) + " " + c.unit);
      return c;
    }
  ADD_FAILURE() << "no check " << id;
  return {};
}

void expectPassed(const Check& c) {
  EXPECT_TRUE(c.isPassed()) << c.id << ": " << c.what << " = " << c.measured << " " << c.unit << ", target "
                            << c.target << " (" << c.source << ")";
}

// lying on the back the weight of the viscera no longer pulls the dome caudally: it rests higher and the
// end-expiratory lung volume falls (lung volumes 5.3-14.7 % larger upright, Yamada et al. 2020)
TEST(Posture, SupineEndExpiratoryVolumeBelowUpright) {
  REQUIRE_DEFAULT_MODEL();
  expectPassed(postureCheck("posture.end_expiratory_volume"));
  const int apex = defaultModel()->landmarks.find("diaphragm_apex");
  ASSERT_GE(apex, 0);
  const auto restingApex =
      [&](const StyleRun& r) {  // [m] height of the central tendon when the settling ends
        std::size_t k = 0;
        while (k + 1 < r.trace.size() && r.trace.time[k + 1] <= r.settleTime) ++k;
        return r.trace.landmarks[k](2, apex);
      };
  EXPECT_GT(restingApex(calm(Posture::Supine)), restingApex(calm(Posture::Upright)));
}

// lying down, the viscera shift and the dome rises while the relaxed torso settles: the lung volume has
// stopped moving when the controller starts (the drift in the last 0.5 s is 7 mL after the default 2 s)
TEST(Posture, SettlingConvergesLyingDown) {
  REQUIRE_DEFAULT_MODEL();
  expectPassed(postureCheck("posture.settled_supine"));
}

// people breathe more with the abdomen supine and more with the rib cage upright (Sharp et al. 1975; Konno &
// Mead 1967): the rib cage's share of the calm tidal volume is smaller supine
TEST(Posture, SupineRibCageShareBelowUpright) {
  REQUIRE_DEFAULT_MODEL();
  expectPassed(postureCheck("posture.rib_cage_share"));
}

}  // namespace
}  // namespace pneuma::sim
