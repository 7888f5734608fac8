// The silhouette of shapes whose outline is known: boxes (rectangles, exact), a sphere (a circle, within the
// tessellation's error), a frame (an outline with a hole) and two boxes apart (two outlines).
#include "pneuma/sim/Silhouette.h"

#include <gtest/gtest.h>

#include <cmath>

namespace pneuma::sim {
namespace {

struct Mesh {
  Eigen::Matrix3Xd x;
  Eigen::Matrix3Xi t;
};

// appends the closed box [lo, hi] (12 outward triangles)
void addBox(Mesh& m, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  const Eigen::Index base = m.x.cols();
  m.x.conservativeResize(3, base + 8);
  for (int i = 0; i < 8; ++i)
    m.x.col(base + i) << (i & 1 ? hi.x() : lo.x()), (i & 2 ? hi.y() : lo.y()), (i & 4 ? hi.z() : lo.z());
  const int faces[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                            {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  const Eigen::Index t0 = m.t.cols();
  m.t.conservativeResize(3, t0 + 12);
  for (int f = 0; f < 12; ++f)
    for (int k = 0; k < 3; ++k) m.t(k, t0 + f) = static_cast<int>(base) + faces[f][k];
}

// a UV sphere of radius r at the origin: `rings` latitude bands, `segments` meridians
Mesh sphere(double r, int rings, int segments) {
  Mesh m;
  m.x.resize(3, 2 + (rings - 1) * segments);
  m.x.col(0) << 0, 0, -r;
  m.x.col(1) << 0, 0, r;
  for (int i = 1; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const double th = M_PI * i / rings - M_PI / 2, ph = 2 * M_PI * j / segments;
      m.x.col(2 + (i - 1) * segments + j) << r * std::cos(th) * std::cos(ph), r * std::cos(th) * std::sin(ph),
          r * std::sin(th);
    }
  std::vector<Eigen::Vector3i> tris;
  const auto v = [&](int i, int j) { return 2 + (i - 1) * segments + (j % segments); };
  for (int j = 0; j < segments; ++j) {
    tris.emplace_back(0, v(1, j + 1), v(1, j));
    tris.emplace_back(1, v(rings - 1, j), v(rings - 1, j + 1));
    for (int i = 1; i + 1 < rings; ++i) {
      tris.emplace_back(v(i, j), v(i, j + 1), v(i + 1, j + 1));
      tris.emplace_back(v(i, j), v(i + 1, j + 1), v(i + 1, j));
    }
  }
  m.t.resize(3, static_cast<Eigen::Index>(tris.size()));
  for (std::size_t f = 0; f < tris.size(); ++f) m.t.col(static_cast<Eigen::Index>(f)) = tris[f];
  return m;
}

// [m^2] signed area of a closed loop (shoelace)
double area(const Eigen::Matrix2Xd& p) {
  double a = 0.0;
  for (Eigen::Index i = 0; i < p.cols(); ++i) {
    const Eigen::Index j = (i + 1) % p.cols();
    a += p(0, i) * p(1, j) - p(0, j) * p(1, i);
  }
  return 0.5 * a;
}

TEST(Silhouette, BoxSpansAreExactAndItsOutlineIsItsRectangle) {
  Mesh box;
  addBox(box, {-0.10, -0.07, 0.20}, {0.15, 0.05, 0.63});
  // seen from the side u = y, from the front u = x, at any height inside; nothing above or below
  for (double z : {0.2 + 1e-9, 0.31, 0.45, 0.63 - 1e-9}) {
    const auto lateral = silhouetteSpans(box.x, box.t, SilhouetteView::Lateral, z);
    ASSERT_EQ(lateral.size(), 1u) << z;
    EXPECT_NEAR(lateral[0].first, -0.07, 1e-15);
    EXPECT_NEAR(lateral[0].second, 0.05, 1e-15);
    EXPECT_NEAR(silhouetteWidth(box.x, box.t, SilhouetteView::Frontal, z), 0.25, 1e-15);
  }
  EXPECT_TRUE(silhouetteSpans(box.x, box.t, SilhouetteView::Lateral, 0.64).empty());
  EXPECT_EQ(silhouetteWidth(box.x, box.t, SilhouetteView::Lateral, 0.19), 0.0);

  const double h = 0.004;
  const SilhouetteOutline o = silhouetteOutline(box.x, box.t, SilhouetteView::Lateral, h);
  ASSERT_EQ(o.loops.size(), 1u);
  const Eigen::Matrix2Xd& p = o.loops[0];
  // the sides are exact (outline points on rows sit at span ends); the top and bottom within half a cell
  EXPECT_NEAR(p.row(0).minCoeff(), -0.07, 1e-12);
  EXPECT_NEAR(p.row(0).maxCoeff(), 0.05, 1e-12);
  for (Eigen::Index i = 0; i < p.cols(); ++i) {
    const double du = std::min(std::abs(p(0, i) + 0.07), std::abs(p(0, i) - 0.05));
    const double dz = std::min(std::abs(p(1, i) - 0.20), std::abs(p(1, i) - 0.63));
    EXPECT_LE(std::min(du, dz), 0.5 * h + 1e-12) << "point " << i << " off the rectangle";
  }
  EXPECT_NEAR(std::abs(area(p)), 0.12 * 0.43, 0.12 * h + 0.43 * 1e-12);
}

TEST(Silhouette, SphereOutlineIsACircle) {
  const double r = 0.15;
  const int rings = 64, segments = 128;
  const Mesh s = sphere(r, rings, segments);
  // the polyhedron lies between the inscribed radius r cos(pi / segments) cos(pi / 2 rings) and r
  const double inner = r * std::cos(M_PI / segments) * std::cos(M_PI / (2 * rings));
  for (double z : {-0.12, -0.05, 0.0, 0.07, 0.13}) {
    const double w = silhouetteWidth(s.x, s.t, SilhouetteView::Lateral, z);
    EXPECT_LE(w, 2 * std::sqrt(r * r - z * z) + 1e-12) << z;
    EXPECT_GE(w, 2 * std::sqrt(std::max(inner * inner - z * z, 0.0)) - 1e-12) << z;
  }
  const double h = 0.002;
  for (SilhouetteView view : {SilhouetteView::Lateral, SilhouetteView::Frontal}) {
    const SilhouetteOutline o = silhouetteOutline(s.x, s.t, view, h);
    ASSERT_EQ(o.loops.size(), 1u) << silhouetteViewName(view);
    const Eigen::Matrix2Xd& p = o.loops[0];
    EXPECT_GT(p.cols(), 300);
    // points on rows are exact span ends (inside the sphere); points between rows lie within half a cell in z
    for (Eigen::Index i = 0; i < p.cols(); ++i) {
      const double radius = p.col(i).norm();
      const bool isOnRow = std::abs(std::remainder(p(1, i) - s.x.row(2).minCoeff(), h)) < 1e-9;
      EXPECT_LE(radius, r + (isOnRow ? 1e-9 : 0.5 * h));
      EXPECT_GE(radius, inner - 0.5 * h);
    }
    EXPECT_NEAR(std::abs(area(p)), M_PI * r * r, 0.01 * M_PI * r * r);
  }
}

TEST(Silhouette, FrameHasAHoleAndSeparateBoxesHaveSeparateOutlines) {
  // a square frame in the coronal plane: four bars, 0.3 m outside, 0.2 m inside
  Mesh frame;
  addBox(frame, {-0.15, -0.02, 0.00}, {0.15, 0.02, 0.05});
  addBox(frame, {-0.15, -0.02, 0.25}, {0.15, 0.02, 0.30});
  addBox(frame, {-0.15, -0.02, 0.04}, {-0.10, 0.02, 0.26});
  addBox(frame, {0.10, -0.02, 0.04}, {0.15, 0.02, 0.26});
  const SilhouetteOutline front = silhouetteOutline(frame.x, frame.t, SilhouetteView::Frontal, 0.005);
  ASSERT_EQ(front.loops.size(), 2u) << "outer and inner outline";
  std::vector<double> areas;
  for (const Eigen::Matrix2Xd& p : front.loops) areas.push_back(std::abs(area(p)));
  std::sort(areas.begin(), areas.end());
  EXPECT_NEAR(areas[0], 0.2 * 0.2, 0.8 * 0.005);
  EXPECT_NEAR(areas[1], 0.3 * 0.3, 1.2 * 0.005);
  const auto spans = silhouetteSpans(frame.x, frame.t, SilhouetteView::Frontal, 0.15);
  ASSERT_EQ(spans.size(), 2u);
  EXPECT_NEAR(spans[0].second, -0.10, 1e-15);
  EXPECT_NEAR(spans[1].first, 0.10, 1e-15);
  // seen from the side the bars cover one another: one outline, no hole
  EXPECT_EQ(silhouetteOutline(frame.x, frame.t, SilhouetteView::Lateral, 0.005).loops.size(), 1u);

  Mesh two;
  addBox(two, {-0.3, 0.0, 0.0}, {-0.1, 0.1, 0.5});
  addBox(two, {0.1, 0.0, 0.0}, {0.3, 0.1, 0.4});
  EXPECT_EQ(silhouetteOutline(two.x, two.t, SilhouetteView::Frontal, 0.01).loops.size(), 2u);
  EXPECT_EQ(silhouetteOutline(two.x, two.t, SilhouetteView::Lateral, 0.01).loops.size(), 1u);
}

TEST(Silhouette, MovesWithTheMesh) {
  Mesh s = sphere(0.1, 24, 48);
  const Eigen::Vector4d before = silhouetteOutline(s.x, s.t, SilhouetteView::Lateral, 0.003).bounds();
  s.x.colwise() += Eigen::Vector3d(0.4, 0.023, -0.31);
  const Eigen::Vector4d after = silhouetteOutline(s.x, s.t, SilhouetteView::Lateral, 0.003).bounds();
  // u = y moves by 0.023 exactly (row ends are exact); z within a cell (the grid moves with the mesh's
  // bottom)
  EXPECT_NEAR(after(0) - before(0), 0.023, 1e-3);
  EXPECT_NEAR(after(2) - before(2), 0.023, 1e-3);
  EXPECT_NEAR(after(1) - before(1), -0.31, 0.003);
  EXPECT_NEAR(after(3) - before(3), -0.31, 0.003);
  EXPECT_NEAR(silhouetteWidth(s.x, s.t, SilhouetteView::Lateral, -0.31), 0.2 * std::cos(M_PI / 48), 2e-3);
}

}  // namespace
}  // namespace pneuma::sim
