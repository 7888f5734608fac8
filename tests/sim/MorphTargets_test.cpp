// Morph targets (MorphTargets.h): the least-squares fit recovers a blend exactly and measures what no blend
// can reach; de Melo's pattern-to-weight mapping follows the calibrated volume and splits by balance; and the
// targets baked on the default model move the body where their breaths do (chest or belly).
#include "pneuma/sim/MorphTargets.h"

#include <gtest/gtest.h>

#include "DefaultModel.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/PosedGeometry.h"
#include "pneuma/sim/State.h"

namespace pneuma::sim {
namespace {

// three random targets over 50 vertices, with their shares 0.2 (belly), 0.5 (breathing), 0.9 (chest)
MorphTargets randomTargets() {
  std::srand(7);
  MorphTargets m;
  m.base = Eigen::Matrix3Xd::Random(3, 50);
  m.targets = {{"breathing", Eigen::Matrix3Xd::Random(3, 50) * 0.01, 0.5},
               {"chest", Eigen::Matrix3Xd::Random(3, 50) * 0.01, 0.9},
               {"belly", Eigen::Matrix3Xd::Random(3, 50) * 0.01, 0.2}};
  m.restVolume = 3.0e-3;
  m.baseVolume = 2.9e-3;
  m.targetVolume = 4.0e-3;
  m.weightPerVolume = 1.0 / 1.1e-3;
  return m;
}

TEST(MorphFit, RecoversTheWeightsOfABlendExactly) {
  const MorphTargets m = randomTargets();
  const MorphFit fit(m);
  const Eigen::Vector3d w(0.3, -0.2, 1.1);
  const Eigen::Matrix3Xd skin = fit.blend(w);
  EXPECT_LT((fit.weights(skin) - w).norm(), 1e-10);
  const BlendError e = fit.error(skin);
  EXPECT_LT(e.rms, 1e-12);
  EXPECT_LT(e.max, 1e-12);
}

TEST(MorphFit, ErrorIsTheDistanceToTheSpanOfTheTargets) {
  // a displacement of one vertex only, orthogonal to every target: the fit cannot reach it at all
  MorphTargets m = randomTargets();
  for (MorphTarget& t : m.targets) t.displacement.col(0).setZero();
  const MorphFit fit(m);
  Eigen::Matrix3Xd skin = fit.blend(Eigen::Vector3d(0.5, 0.5, 0.0));
  skin.col(0) += Eigen::Vector3d(0.0, 0.003, 0.004);  // 5 mm
  const BlendError e = fit.error(skin);
  EXPECT_NEAR(e.max, 0.005, 1e-12);
  EXPECT_NEAR(e.rms, 0.005 / std::sqrt(50.0), 1e-12);
  EXPECT_LT((fit.weights(skin) - Eigen::Vector3d(0.5, 0.5, 0.0)).norm(), 1e-10);
}

TEST(PatternWeights, VolumeSetsTheAmplitudeAndBalanceTheSplit) {
  const MorphTargets m = randomTargets();
  // v -> V = rest + (v - 0.05) S; amplitude = k (V - V_base), none below the base
  auto amplitude = [&](double v) {
    return m.weightPerVolume * (m.restVolume + (v - 0.05) * m.volumePerFraction - m.baseVolume);
  };
  for (double v : {0.1, 0.25, 0.4, 1.0})
    for (double b : {0.0, 0.2, 0.35, 0.5, 0.7, 0.9, 1.0})
      EXPECT_NEAR(patternWeights(m, v, b).sum(), amplitude(v), 1e-12) << v << " " << b;
  EXPECT_EQ(patternWeights(m, 0.0, 0.5).sum(), 0.0);  // 0.125 L below rest is below the base: clamped

  // at a target's own share the whole amplitude goes to it; between two shares it is split linearly
  const double a = amplitude(0.3);
  EXPECT_NEAR(patternWeights(m, 0.3, 0.5)(0), a, 1e-12);
  EXPECT_NEAR(patternWeights(m, 0.3, 0.9)(1), a, 1e-12);
  EXPECT_NEAR(patternWeights(m, 0.3, 0.2)(2), a, 1e-12);
  EXPECT_NEAR(patternWeights(m, 0.3, 0.0)(2), a, 1e-12);  // beyond the belliest: all belly
  const Eigen::VectorXd w = patternWeights(m, 0.3, 0.7);  // half way from breathing (0.5) to chest (0.9)
  EXPECT_NEAR(w(0), 0.5 * a, 1e-12);
  EXPECT_NEAR(w(1), 0.5 * a, 1e-12);
  EXPECT_EQ(w(2), 0.0);
}

TEST(BakeMorphTargets, ModelWithoutSkinIsRefused) {
  REQUIRE_DEFAULT_MODEL();
  auto bare = std::make_shared<Model>(*test::defaultModel());
  bare->skin = Skin{};
  EXPECT_THROW(bakeMorphTargets(bare, PNEUMA_RESOURCE_DIR), Error);
}

// the anterior displacement [m] of a target, averaged over the front of the torso between two heights
double anteriorMotion(const MorphTargets& m, const MorphTarget& t, double zLow, double zHigh, double yFront) {
  double sum = 0.0;
  int n = 0;
  for (int v = 0; v < m.vertexCount(); ++v) {
    const Eigen::Vector3d x = m.base.col(v);
    if (x.z() < zLow || x.z() > zHigh || std::abs(x.x()) > 0.08 || x.y() < yFront) continue;
    sum += t.displacement(1, v);
    ++n;
  }
  EXPECT_GT(n, 20);
  return sum / n;
}

TEST(BakeMorphTargets, DefaultModelTargetsMoveTheChestOrTheBellyAsTheirBreaths) {
  REQUIRE_DEFAULT_MODEL();
  const std::shared_ptr<const Model> model = test::defaultModel();
  const MorphTargets m = bakeMorphTargets(model, PNEUMA_RESOURCE_DIR);
  ASSERT_EQ(m.targets.size(), 3u);
  ASSERT_EQ(m.vertexCount(), model->skin.vertexCount());

  // the chest (panting) and belly (supine deep) runs divide the breath as named
  const MorphTarget &breathing = m.targets[0], &chest = m.targets[1], &belly = m.targets[2];
  EXPECT_GT(chest.ribCageShare, 0.6);
  EXPECT_LT(belly.ribCageShare, 0.4);
  EXPECT_LT(breathing.ribCageShare, 0.5);  // the deep breath is abdominal (about 20 % rib cage)

  // heights from the rest landmarks: the chest between xiphoid and jugular notch, the belly below the xiphoid
  const State rest = makeInitialState(*model);
  PosedGeometry posed;
  poseGeometry(*model, rest, posed);
  const auto z = [&](const char* name) { return posed.landmarks(2, model->landmarks.find(name)); };
  const double yFront = posed.landmarks(1, model->landmarks.find("xiphoid"));
  const double chestLow = z("xiphoid"), chestHigh = z("jugular_notch"), bellyLow = z("umbilicus") - 0.04;
  auto ratio = [&](const MorphTarget& t) {
    return anteriorMotion(m, t, chestLow, chestHigh, yFront - 0.05) /
           anteriorMotion(m, t, bellyLow, chestLow - 0.03, yFront - 0.05);
  };
  // every inspiration moves the belly wall forward; the chest target moves the chest more, relative to the
  // belly, than the belly target does
  EXPECT_GT(anteriorMotion(m, breathing, bellyLow, chestLow - 0.03, yFront - 0.05), 0.0);
  EXPECT_GT(ratio(chest), 2.0 * ratio(belly)) << ratio(chest) << " vs " << ratio(belly);

  // the shape grows linearly with the volume: the calibrated slope puts the deep breath's peak at weight ~1
  EXPECT_NEAR(m.weightPerVolume * (m.targetVolume - m.baseVolume), 1.0, 0.1);
  EXPECT_GT(m.restVolume, m.baseVolume - 0.5e-3);
}

}  // namespace
}  // namespace pneuma::sim
