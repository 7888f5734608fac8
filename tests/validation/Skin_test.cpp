// The skin (issue 16) on the default model in a deep breath: closed and free of self-crossings at rest and at
// end-inspiration, and its enclosed volume changes as the lungs' does. The body's tissues are incompressible,
// so between end-expiration and end-inspiration the volume inside the skin grows by the air drawn in: the
// lung volume change (Konno & Mead 1967, J Appl Physiol 22:407, who measure the tidal volume from the chest
// and belly surface motion on exactly this principle). Skips when the default model is absent.
#include <gtest/gtest.h>

#include "DefaultModel.h"
#include "SurfaceCrossings.h"
#include "pneuma/sim/BreathStyleController.h"
#include "pneuma/sim/PosedGeometry.h"
#include "pneuma/sim/Simulation.h"

namespace pneuma::sim {
namespace {

using test::defaultModel;

// [-] |dV_skin / dV_lungs - 1| allowed. Measured on the male default model, deep breath: 1491 / 1539 mL =
// 0.97 (0.87 with 10 smoothing passes of the binding instead of 60; the tissue far from the moving bones,
// 6-12 cm through it, takes only part of their motion: Skin.cpp kFollowNear)
constexpr double kVolumeTolerance = 0.20;

double enclosed(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xi& t) {
  double v = 0.0;
  for (Eigen::Index f = 0; f < t.cols(); ++f) v += x.col(t(0, f)).dot(x.col(t(1, f)).cross(x.col(t(2, f))));
  return v / 6.0;
}

struct Breath {
  State lo, hi;  // end-expiration and end-inspiration: smallest and largest lung volume after settling
  double lungLo = 0.0, lungHi = 0.0;  // [m^3]
};

Breath deepBreath() {
  const auto model = defaultModel();
  SimulationOptions o;
  o.settleTime = 2.0;
  o.outputRate = 30.0;
  o.recordSeconds = kTraceOnlyRecordSeconds;
  Simulation sim(model, std::make_unique<BreathStyleController>(loadBreathStyle("deep")), o);
  Breath b;
  b.lungLo = 1e9;
  b.lungHi = -1e9;
  sim.advance(o.settleTime + 7.0, [&](const Simulation& s) {
    if (s.state().time < o.settleTime) return true;
    const double v = s.latestMetrics().lungVolume;
    if (v < b.lungLo) b.lungLo = v, b.lo = s.state();
    if (v > b.lungHi) b.lungHi = v, b.hi = s.state();
    return true;
  });
  return b;
}

TEST(Skin, StaysClosedAndUncrossedAndFollowsTheLungVolumeInADeepBreath) {
  REQUIRE_DEFAULT_MODEL();
  const Model& m = *defaultModel();
  ASSERT_GT(m.skin.vertexCount(), 0) << "the default model has no skin";
  const Breath b = deepBreath();
  ASSERT_GT(b.lungHi - b.lungLo, 0.5e-3) << "a deep breath moves more than 500 mL";

  PosedGeometry rest, lo, hi;
  poseGeometry(m, makeInitialState(m), rest);
  poseGeometry(m, b.lo, lo);
  poseGeometry(m, b.hi, hi);
  // closed (model validation checks the triangles) and no triangle passes through another
  EXPECT_EQ(pneuma::test::countSelfCrossings(rest.skin, m.skin.triangles), 0) << "at rest";
  EXPECT_EQ(pneuma::test::countSelfCrossings(hi.skin, m.skin.triangles), 0) << "at end-inspiration";

  // the body's volume grows by the air drawn in
  const double dSkin = enclosed(hi.skin, m.skin.triangles) - enclosed(lo.skin, m.skin.triangles);
  const double dLung = b.lungHi - b.lungLo;
  RecordProperty("skin_volume_change_mL", std::to_string(dSkin * 1e6));
  RecordProperty("lung_volume_change_mL", std::to_string(dLung * 1e6));
  EXPECT_NEAR(dSkin / dLung, 1.0, kVolumeTolerance)
      << "skin " << dSkin * 1e6 << " mL, lungs " << dLung * 1e6 << " mL";
}

}  // namespace
}  // namespace pneuma::sim
