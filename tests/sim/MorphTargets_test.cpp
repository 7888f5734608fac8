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
  m.targets = {{"breathing", Eigen::Matrix3Xd::Random(3, 50) * 0.01, 0.5, {}},
               {"chest", Eigen::Matrix3Xd::Random(3, 50) * 0.01, 0.9, {}},
               {"belly", Eigen::Matrix3Xd::Random(3, 50) * 0.01, 0.2, {}}};
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

// a recruited target (the shoulders) takes max(0, V - V_s) / (V_t - V_s) whatever the balance, and the
// breathing targets share the amplitude as before
TEST(PatternWeights, RecruitedTargetRampsFromItsOnsetToTheBreathingTargetsVolume) {
  MorphTargets m = randomTargets();
  MorphTarget shoulders{"shoulders", Eigen::Matrix3Xd::Random(3, 50) * 0.01, 0.5, {}};
  shoulders.onsetVolume = 3.5e-3;  // [m^3] half a litre below the breathing target's 4 L
  m.targets.push_back(shoulders);
  const MorphTargets plain = randomTargets();
  for (double v : {0.1, 0.25, 0.45, 0.65, 1.0})
    for (double b : {0.0, 0.5, 0.9}) {
      const double volume = m.restVolume + (v - 0.05) * m.volumePerFraction;  // [m^3]
      const Eigen::VectorXd w = patternWeights(m, v, b);
      ASSERT_EQ(w.size(), 4);
      EXPECT_NEAR(w(3), std::max(0.0, volume - 3.5e-3) / 0.5e-3, 1e-12) << v << " " << b;
      EXPECT_LT((w.head(3) - patternWeights(plain, v, b)).norm(), 1e-12) << v << " " << b;
    }
  // at the breathing target's volume the ramp is 1
  const double v = 0.05 + (m.targetVolume - m.restVolume) / m.volumePerFraction;
  EXPECT_NEAR(patternWeights(m, v, 0.5)(3), 1.0, 1e-12);
}

// two bones: the second turns 10 degrees about z and moves 4 mm in the breathing target, and back 6 degrees
// about x in the chest target; the blend follows the weights linearly in translation and, by nlerp, in angle
TEST(BlendBones, TranslationsBlendLinearlyAndRotationsByNormalisedLerp) {
  MorphTargets m = randomTargets();
  m.bones = {"fixed", "rib1_left"};
  const Eigen::Quaterniond q0(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()));
  m.boneBase = {Eigen::Matrix3Xd::Zero(3, 2), Eigen::Matrix4Xd(4, 2)};
  m.boneBase.rotation << Eigen::Vector4d(0, 0, 0, 1), q0.coeffs();
  const double ten = 10.0 * M_PI / 180.0, six = 6.0 * M_PI / 180.0;  // [rad]
  auto displacement = [&](const Eigen::Vector3d& move, const Eigen::AngleAxisd& turn) {
    BonePoses d{Eigen::Matrix3Xd::Zero(3, 2), Eigen::Matrix4Xd::Zero(4, 2)};
    d.translation.col(1) = move;
    d.rotation.col(1) = (Eigen::Quaterniond(turn) * q0).coeffs() - q0.coeffs();
    return d;
  };
  m.targets[0].boneDisplacement =
      displacement({0.0, 0.004, 0.0}, Eigen::AngleAxisd(ten, Eigen::Vector3d::UnitZ()));
  m.targets[1].boneDisplacement =
      displacement({0.0, 0.0, -0.002}, Eigen::AngleAxisd(six, Eigen::Vector3d::UnitX()));
  m.targets[2].boneDisplacement = {Eigen::Matrix3Xd::Zero(3, 2), Eigen::Matrix4Xd::Zero(4, 2)};

  // the angle of bone 1 from its base, and its translation
  auto turned = [&](const Eigen::VectorXd& w) {
    const std::vector<Eigen::Isometry3d> p = blendBones(m, w);
    EXPECT_EQ(p.size(), 2u);
    EXPECT_TRUE(p[0].isApprox(Eigen::Isometry3d::Identity()));
    return std::make_pair(Eigen::AngleAxisd(p[1].linear() * q0.toRotationMatrix().transpose()),
                          p[1].translation());
  };
  const auto [rest, x0] = turned(Eigen::Vector3d::Zero());
  EXPECT_LT(rest.angle(), 1e-12);
  const auto [full, x1] = turned(Eigen::Vector3d(1, 0, 0));
  EXPECT_NEAR(full.angle(), ten, 1e-12);
  EXPECT_NEAR(std::abs(full.axis().z()), 1.0, 1e-12);
  EXPECT_LT((x1 - Eigen::Vector3d(0, 0.004, 0)).norm(), 1e-15);
  // half the weight: nlerp between two rotations is exactly half the angle
  const auto [half, xHalf] = turned(Eigen::Vector3d(0.5, 0, 0));
  EXPECT_NEAR(half.angle(), 0.5 * ten, 1e-12);
  EXPECT_LT((xHalf - Eigen::Vector3d(0, 0.002, 0)).norm(), 1e-15);
  // two targets: translations add, the rotation is a unit quaternion between both turns
  const auto [both, x2] = turned(Eigen::Vector3d(1, 1, 0));
  EXPECT_LT((x2 - Eigen::Vector3d(0, 0.004, -0.002)).norm(), 1e-15);
  EXPECT_GT(both.angle(), ten);
  EXPECT_LT(both.angle(), ten + six);

  // targets without bones pose none
  m.bones.clear();
  EXPECT_TRUE(blendBones(m, Eigen::Vector3d(1, 0, 0)).empty());
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
  // breathing, chest, belly, and the shoulders of a model with a shoulder girdle (supported bodies)
  ASSERT_EQ(m.targets.size(), model->bodies.anySupported() ? 4u : 3u);
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

  // the bones were baked with the skin: at the breathing target's weight 1 every rib's anterior end (its tip)
  // is forward of and above where it is at the base: the pump-handle motion of inspiration
  ASSERT_EQ(m.bones, model->bodies.name);
  const Eigen::Matrix3Xd tips = boneTips(*model);
  const std::vector<Eigen::Isometry3d> base = blendBones(m, Eigen::Vector3d(0, 0, 0));
  const std::vector<Eigen::Isometry3d> in = blendBones(m, Eigen::Vector3d(1, 0, 0));
  int ribs = 0;
  double forward = 0.0;  // [m] mean anterior motion of the rib tips
  for (int b = 0; b < model->bodies.size(); ++b) {
    const auto i = static_cast<std::size_t>(b);
    if (model->bodies.name[i].rfind("rib", 0) != 0) continue;
    // the tip is the rib's anterior end: in front of the rib's centre of mass
    EXPECT_GT(tips(1, b), 0.0) << model->bodies.name[i];
    forward += (in[i] * tips.col(b) - base[i] * tips.col(b)).y();
    ++ribs;
  }
  ASSERT_GT(ribs, 10);
  EXPECT_GT(forward / ribs, 1e-3) << "the rib tips move forward by more than 1 mm in a deep breath";
  // the bones of a weight-0 blend are the base's, and a blend's error against itself is zero
  const BoneBlendError none = boneBlendError(*model, tips, in, in);
  EXPECT_EQ(none.tipMax, 0.0);
  EXPECT_LT(none.angleMax, 1e-7);
  const BoneBlendError deep = boneBlendError(*model, tips, in, base);
  EXPECT_GT(deep.tipMax, 1e-3);
  EXPECT_GT(deep.angleMax, deep.angleRms);

  // the shape grows linearly with the volume: the calibrated slope puts the deep breath's peak at weight ~1
  EXPECT_NEAR(m.weightPerVolume * (m.targetVolume - m.baseVolume), 1.0, 0.1);
  EXPECT_GT(m.restVolume, m.baseVolume - 0.5e-3);
}

}  // namespace
}  // namespace pneuma::sim
