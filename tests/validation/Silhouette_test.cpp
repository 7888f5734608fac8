// The body's silhouette (issue 16) on the default model: seen from the side, the chest and the belly move as
// published chest-wall motion says, in every breath style (sim::silhouetteChecks, shared with validate's
// Silhouette section: De Groote et al. 1997, Kaneko & Horie 2012, Sharp et al. 1975, Zordan et al. 2004
// Fig. 5). Skips when the default model is absent.
#include "pneuma/sim/Silhouette.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "DefaultModel.h"
#include "pneuma/sim/Experiments.h"

namespace pneuma::sim {
namespace {

using test::defaultModel;

// one breath per style, shared by the tests
const SilhouetteBreath& breath(const std::string& style) {
  static std::map<std::string, SilhouetteBreath> cache;
  if (!cache.count(style))
    cache[style] =
        silhouetteBreath(runBreathStyle(defaultModel(), loadBreathStyle(style), ExperimentSettings{}));
  return cache.at(style);
}

TEST(Silhouette, ChestAndBellyMoveAsPublishedInEveryStyle) {
  REQUIRE_DEFAULT_MODEL();
  std::vector<SilhouetteBreath> breaths;
  for (const char* style : {"calm", "deep", "panting", "forced-exhale"}) breaths.push_back(breath(style));
  const std::vector<Check> checks = silhouetteChecks(breaths);
  ASSERT_EQ(checks.size(), 9u) << "chest and belly of four styles, and calm's chest marker";
  for (const Check& c : checks) {
    RecordProperty(c.id, std::to_string(c.measured));
    EXPECT_TRUE(c.isPassed()) << c.id << ": " << c.what << " = " << c.measured << " " << c.unit << ", target "
                              << c.target << " [" << c.lower << ", " << c.upper << "] (" << c.source << ")";
  }
}

// the chest marker is a material point on the front of the chest: on a calm inhale it moves ventrally and
// cranially, as De Groote et al. 1997's markers at the costal cartilages do ("mostly ventrally and
// cranially")
TEST(Silhouette, ChestMarkerMovesVentrallyAndCranially) {
  REQUIRE_DEFAULT_MODEL();
  const SilhouetteBreath& b = breath("calm");
  EXPECT_GT(b.chestMarker.y(), 0.001);
  EXPECT_GT(b.chestMarker.z(), 0.001);
  EXPECT_LT(std::abs(b.chestMarker.x()), 0.5 * b.chestMarker.y())
      << "a midline marker moves in the sagittal plane";
}

// the lines sit where they are defined: the chest line between the jugular notch and the xiphoid, the belly
// line below it; seen from the side the whole body is one outline whose depth at the lines is the body's
TEST(Silhouette, LinesAndOutlineAreTheBodys) {
  REQUIRE_DEFAULT_MODEL();
  const Model& m = *defaultModel();
  const SilhouetteBreath& b = breath("calm");
  EXPECT_GT(b.chestHeight, b.bellyHeight + 0.10);
  const SilhouetteOutline side =
      silhouetteOutline(b.skinExpiration, m.skin.triangles, SilhouetteView::Lateral, 0.004);
  ASSERT_FALSE(side.loops.empty());
  std::size_t largest = 0;
  for (std::size_t i = 0; i < side.loops.size(); ++i)
    if (side.loops[i].cols() > side.loops[largest].cols()) largest = i;
  const Eigen::Matrix2Xd& body = side.loops[largest];
  // from the vertex to the thighs' cut: over the vertex-to-crotch height of an adult, about 0.53 of the
  // stature (crotch height 0.47 stature, NASA-STD-3000 anthropometry), 0.9 m for 1.7 m
  EXPECT_GT(body.row(1).maxCoeff() - body.row(1).minCoeff(), 0.9) << "the body from its head to its thighs";
  // adult chest depth 15-35 cm, abdomen 15-40 cm (anthropometric ranges)
  const double chest =
      silhouetteWidth(b.skinExpiration, m.skin.triangles, SilhouetteView::Lateral, b.chestHeight);
  const double belly =
      silhouetteWidth(b.skinExpiration, m.skin.triangles, SilhouetteView::Lateral, b.bellyHeight);
  EXPECT_GT(chest, 0.15);
  EXPECT_LT(chest, 0.35);
  EXPECT_GT(belly, 0.15);
  EXPECT_LT(belly, 0.40);
}

}  // namespace
}  // namespace pneuma::sim
