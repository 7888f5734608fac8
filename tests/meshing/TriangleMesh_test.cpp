#include "pneuma/meshing/TriangleMesh.h"

#include <gtest/gtest.h>

#include <cmath>

#include "pneuma/meshing/Sweep.h"

namespace pneuma::meshing {
namespace {

/// A torus of major radius `big` and minor radius `small` [m] around the z axis, centred at `c`.
TriangleMesh torus(double big, double small, const Eigen::Vector3d& c) {
  std::vector<SweepStation> st;
  constexpr int kStations = 256;
  for (int i = 0; i < kStations; ++i) {
    const double t = 2.0 * M_PI * i / kStations;
    st.push_back(
        {c + big * Eigen::Vector3d(std::cos(t), std::sin(t), 0), Eigen::Vector3d::UnitZ(), small, small});
  }
  return sweepTube(st, 128, true);
}

TEST(TriangleMesh, TorusMassPropertiesMatchTheFormulas) {
  // solid torus: V = 2 pi^2 R r^2, Izz = M (R^2 + 3/4 r^2), Ixx = Iyy = M (R^2 / 2 + 5/8 r^2)
  const double big = 0.1, small = 0.03, rho = 1400.0;
  const Eigen::Vector3d centre(0.3, -0.2, 0.5);
  const MassProperties p = massProperties(torus(big, small, centre), rho);
  const double mass = rho * 2.0 * M_PI * M_PI * big * small * small;
  EXPECT_NEAR(p.mass, mass, 0.01 * mass);
  EXPECT_NEAR(p.inertia(2, 2), mass * (big * big + 0.75 * small * small), 0.01 * p.inertia(2, 2));
  EXPECT_NEAR(p.inertia(0, 0), mass * (0.5 * big * big + 0.625 * small * small), 0.01 * p.inertia(0, 0));
  EXPECT_NEAR(p.inertia(1, 1), p.inertia(0, 0), 1e-6 * p.inertia(0, 0));
  // the centre of mass and the principal axes do not depend on where the torus sits
  EXPECT_LT((p.com - centre).norm(), 1e-9);
  EXPECT_LT(std::abs(p.inertia(0, 1)) + std::abs(p.inertia(0, 2)) + std::abs(p.inertia(1, 2)),
            1e-6 * p.inertia(2, 2));
}

TEST(TriangleMesh, CapsuleTubeVolumeMatchesCylinder) {
  // a straight capped tube is a cylinder: V = pi a b L (within the polygon's area deficit)
  std::vector<SweepStation> st;
  for (int i = 0; i <= 10; ++i)
    st.push_back({Eigen::Vector3d(0, 0, 0.02 * i), Eigen::Vector3d::UnitX(), 0.03, 0.01});
  const TriangleMesh m = sweepTube(st, 256, false);
  const double v = M_PI * 0.03 * 0.01 * 0.2;
  EXPECT_NEAR(enclosedVolume(m.vertices, m.triangles), v, 1e-3 * v);
}

TEST(TriangleMesh, MirrorKeepsOrientationOutward) {
  const TriangleMesh m = torus(0.1, 0.02, Eigen::Vector3d(0.2, 0, 0));
  const TriangleMesh mm = m.mirroredX();
  EXPECT_GT(enclosedVolume(mm.vertices, mm.triangles), 0.0);
  EXPECT_NEAR(massProperties(mm, 1000).com.x(), -0.2, 1e-9);
}

TEST(TriangleMesh, TriangleQualityIsOneForEquilateralAndZeroForDegenerate) {
  EXPECT_NEAR(triangleQuality({0, 0, 0}, {1, 0, 0}, {0.5, std::sqrt(3.0) / 2, 0}), 1.0, 1e-12);
  EXPECT_NEAR(triangleQuality({0, 0, 0}, {1, 0, 0}, {2, 0, 0}), 0.0, 1e-12);
}

}  // namespace
}  // namespace pneuma::meshing
