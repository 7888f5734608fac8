// The crossing test of SurfaceCrossings.h on analytic cases: two triangles that cross, touch, share a plane
// or stay apart, and a closed sphere mesh with one vertex pushed through the opposite side.
#include "SurfaceCrossings.h"

#include <gtest/gtest.h>

#include <cmath>

namespace pneuma::test {
namespace {

Eigen::Matrix3Xi oneTriangle() { return Eigen::Matrix3Xi(Eigen::Vector3i(0, 1, 2)); }

Eigen::Matrix3Xd triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  Eigen::Matrix3Xd v(3, 3);
  v << a, b, c;
  return v;
}

int crossings(const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b) {
  return countCrossings(a, oneTriangle(), b, oneTriangle());
}

// a unit-radius latitude-longitude sphere, outward, poles at +-z (vertex 0 north, vertex 1 south)
void sphere(int rings, int segments, Eigen::Matrix3Xd& v, Eigen::Matrix3Xi& f) {
  const double pi = std::acos(-1.0);
  v.resize(3, 2 + (rings - 1) * segments);
  v.col(0) = Eigen::Vector3d(0, 0, 1);
  v.col(1) = Eigen::Vector3d(0, 0, -1);
  auto at = [&](int r, int s) { return 2 + (r - 1) * segments + (s % segments); };  // r in 1..rings-1
  for (int r = 1; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const double th = pi * r / rings, ph = 2 * pi * s / segments;
      v.col(at(r, s)) =
          Eigen::Vector3d(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
    }
  std::vector<Eigen::Vector3i> t;
  for (int s = 0; s < segments; ++s) {
    t.emplace_back(0, at(1, s), at(1, s + 1));
    t.emplace_back(1, at(rings - 1, s + 1), at(rings - 1, s));
    for (int r = 1; r < rings - 1; ++r) {
      t.emplace_back(at(r, s), at(r + 1, s), at(r + 1, s + 1));
      t.emplace_back(at(r, s), at(r + 1, s + 1), at(r, s + 1));
    }
  }
  f.resize(3, static_cast<Eigen::Index>(t.size()));
  for (std::size_t i = 0; i < t.size(); ++i) f.col(static_cast<Eigen::Index>(i)) = t[i];
}

const Eigen::Matrix3Xd kFloor = triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0});

TEST(SurfaceCrossings, TriangleThroughAnotherCrosses) {
  // a vertical triangle whose lower edge runs 0.1 below the floor, through its interior
  EXPECT_EQ(crossings(kFloor, triangle({0.2, 0.2, -0.1}, {0.3, 0.2, -0.1}, {0.25, 0.2, 0.5})), 1);
  // a pointed triangle: only its two slanted edges pierce the floor
  EXPECT_EQ(crossings(kFloor, triangle({0.2, 0.2, -0.1}, {0.4, 0.1, 0.3}, {0.1, 0.4, 0.3})), 1);
}

TEST(SurfaceCrossings, TouchingIsNotCrossing) {
  // a vertex resting on the floor's interior, an edge lying on it, a corner shared
  EXPECT_EQ(crossings(kFloor, triangle({0.2, 0.2, 0.0}, {0.3, 0.2, 0.4}, {0.25, 0.3, 0.5})), 0);
  EXPECT_EQ(crossings(kFloor, triangle({0.1, 0.1, 0.0}, {0.3, 0.1, 0.0}, {0.2, 0.1, 0.5})), 0);
  EXPECT_EQ(crossings(kFloor, triangle({0, 0, 0}, {-1, 0, 0.5}, {0, -1, 0.5})), 0);
  // coplanar and overlapping (a face shared by two surfaces bound to the same wall)
  EXPECT_EQ(crossings(kFloor, triangle({0.1, 0.1, 0}, {0.6, 0.1, 0}, {0.1, 0.6, 0})), 0);
  // in the plane x = y, one edge standing on the floor's hypotenuse: the floor's edge meets it at a point of
  // both
  EXPECT_EQ(crossings(kFloor, triangle({0.5, 0.5, -0.1}, {0.5, 0.5, 0.4}, {0.9, 0.9, 0.2})), 0);
  // a piercing edge that passes the floor just outside its hypotenuse
  EXPECT_EQ(crossings(kFloor, triangle({0.6, 0.6, -0.1}, {0.7, 0.6, -0.1}, {0.65, 0.6, 0.5})), 0);
}

TEST(SurfaceCrossings, DisjointDoNotCross) {
  EXPECT_EQ(crossings(kFloor, triangle({0.2, 0.2, 0.1}, {0.3, 0.2, 0.1}, {0.25, 0.2, 0.5})), 0);
  EXPECT_EQ(crossings(kFloor, triangle({2, 2, -1}, {3, 2, -1}, {2.5, 2, 1})), 0);
}

TEST(SurfaceCrossings, ClosedMeshWithOneVertexPushedThrough) {
  Eigen::Matrix3Xd v;
  Eigen::Matrix3Xi f;
  sphere(12, 16, v, f);
  EXPECT_EQ(countSelfCrossings(v, f), 0);
  // a copy far away does not cross; one shifted by half a radius does, along a closed curve
  const Eigen::Matrix3Xd apart = v.colwise() + Eigen::Vector3d(3, 0, 0);
  const Eigen::Matrix3Xd shifted = v.colwise() + Eigen::Vector3d(0.5, 0, 0);
  EXPECT_EQ(countCrossings(v, f, apart, f), 0);
  EXPECT_GT(countCrossings(v, f, shifted, f), 16);
  // the north pole pushed down through the south cap: its fan of 16 triangles pierces the far side
  v.col(0) = Eigen::Vector3d(0.01, 0.02, -1.3);
  EXPECT_GE(countSelfCrossings(v, f), 16);
  // pushed only inward (a dent) it crosses nothing
  v.col(0) = Eigen::Vector3d(0.0, 0.0, 0.2);
  EXPECT_EQ(countSelfCrossings(v, f), 0);
}

}  // namespace
}  // namespace pneuma::test
