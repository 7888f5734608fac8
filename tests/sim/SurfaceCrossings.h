#pragma once
// Triangle-triangle crossings between closed surfaces (the lung cavity, the lungs, the gut): how the tests
// find a surface that passes through another or through itself. Header-only test support (no metric uses it).
//
// Two triangles cross when an edge of one passes through the interior of the other: its end points lie
// strictly on opposite sides of the other's plane (signed distances beyond `tolerance`) and the point where
// it meets the plane lies strictly inside the triangle (Moller 1997, "A fast triangle-triangle intersection
// test", with the segment form of Ericson 2005, "Real-Time Collision Detection", 5.3.6). Two non-coplanar
// triangles that intersect along a segment of positive length always have such an edge. Touching (a vertex or
// an edge lying on the other triangle, coplanar faces shared by two surfaces bound to the same walls) is not
// a crossing. A uniform grid over the triangles' bounding boxes keeps the pairs tested near-linear in the
// mesh size.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>
#include <utility>
#include <vector>

namespace pneuma::test {

/// Default tolerance [m] of the side tests: far below any mesh feature, far above rounding at torso scale.
constexpr double kCrossingTolerance = 1e-9;

namespace detail {

// true when segment p-q passes through the interior of triangle (a, b, c)
inline bool segmentCrossesTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                                   const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                   const Eigen::Vector3d& c, double tolerance) {
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double area2 = n.norm();
  if (!(area2 > 0.0)) return false;  // degenerate triangle
  const Eigen::Vector3d u = n / area2;
  const double dp = u.dot(p - a), dq = u.dot(q - a);
  if (!((dp > tolerance && dq < -tolerance) || (dp < -tolerance && dq > tolerance))) return false;
  const Eigen::Vector3d x = p + (dp / (dp - dq)) * (q - p);
  // strictly inside: each sub-triangle's height over the opposite edge beyond the tolerance
  const std::array<std::array<Eigen::Vector3d, 2>, 3> edges{{{a, b}, {b, c}, {c, a}}};
  for (const auto& e : edges) {
    const Eigen::Vector3d d = e[1] - e[0];
    const double h = u.dot(d.cross(x - e[0])) / d.norm();
    if (!(h > tolerance)) return false;
  }
  return true;
}

inline bool trianglesCross(const std::array<Eigen::Vector3d, 3>& s, const std::array<Eigen::Vector3d, 3>& t,
                           double tolerance) {
  for (int k = 0; k < 3; ++k) {
    if (segmentCrossesTriangle(s[k], s[(k + 1) % 3], t[0], t[1], t[2], tolerance)) return true;
    if (segmentCrossesTriangle(t[k], t[(k + 1) % 3], s[0], s[1], s[2], tolerance)) return true;
  }
  return false;
}

inline std::array<Eigen::Vector3d, 3> corners(const Eigen::Matrix3Xd& v, const Eigen::Matrix3Xi& f, int i) {
  return {v.col(f(0, i)), v.col(f(1, i)), v.col(f(2, i))};
}

}  // namespace detail

/// Number of pairs (triangle of A, triangle of B) that cross (see the file comment). When `same` is true, A
/// and B are one surface: each unordered pair is counted once and pairs of triangles that share a vertex
/// index are skipped (neighbours meet along their common edge or corner).
/// @param va, vb  vertex positions [m] (3 x #V); @param fa, fb  vertex indices (3 x #F)
/// @param pairs   when not null, receives the crossing pairs (triangle of A, triangle of B)
inline int countCrossings(const Eigen::Matrix3Xd& va, const Eigen::Matrix3Xi& fa, const Eigen::Matrix3Xd& vb,
                          const Eigen::Matrix3Xi& fb, bool same = false,
                          double tolerance = kCrossingTolerance,
                          std::vector<std::pair<int, int>>* pairs = nullptr) {
  const int na = static_cast<int>(fa.cols()), nb = static_cast<int>(fb.cols());
  if (na == 0 || nb == 0) return 0;
  // bounding boxes
  auto boxes = [](const Eigen::Matrix3Xd& v, const Eigen::Matrix3Xi& f) {
    std::vector<Eigen::AlignedBox3d> out(static_cast<std::size_t>(f.cols()));
    for (int i = 0; i < f.cols(); ++i)
      for (int k = 0; k < 3; ++k) out[static_cast<std::size_t>(i)].extend(v.col(f(k, i)));
    return out;
  };
  const std::vector<Eigen::AlignedBox3d> ba = boxes(va, fa), bb = boxes(vb, fb);
  // grid of B's boxes, cells about twice the mean box size
  Eigen::AlignedBox3d all;
  double size = 0.0;
  for (const auto& b : bb) all.extend(b), size += b.sizes().maxCoeff();
  const double cell = std::max(2.0 * size / nb, 1e-6);
  auto cellOf = [&](const Eigen::Vector3d& p) {
    return Eigen::Vector3i(((p - all.min()) / cell).array().floor().cast<int>());
  };
  auto key = [](int x, int y, int z) {
    return (static_cast<long long>(x) * 73856093LL) ^ (static_cast<long long>(y) * 19349663LL) ^
           (static_cast<long long>(z) * 83492791LL);
  };
  std::unordered_map<long long, std::vector<int>> grid;
  for (int j = 0; j < nb; ++j) {
    const Eigen::Vector3i lo = cellOf(bb[static_cast<std::size_t>(j)].min()),
                          hi = cellOf(bb[static_cast<std::size_t>(j)].max());
    for (int x = lo.x(); x <= hi.x(); ++x)
      for (int y = lo.y(); y <= hi.y(); ++y)
        for (int z = lo.z(); z <= hi.z(); ++z) grid[key(x, y, z)].push_back(j);
  }
  // candidate pairs from the cells A's boxes overlap, each tested once
  int count = 0;
  std::vector<int> seen(static_cast<std::size_t>(nb), -1);
  for (int i = 0; i < na; ++i) {
    const Eigen::AlignedBox3d& box = ba[static_cast<std::size_t>(i)];
    const Eigen::Vector3i lo = cellOf(box.min()), hi = cellOf(box.max());
    for (int x = lo.x(); x <= hi.x(); ++x)
      for (int y = lo.y(); y <= hi.y(); ++y)
        for (int z = lo.z(); z <= hi.z(); ++z) {
          const auto it = grid.find(key(x, y, z));
          if (it == grid.end()) continue;
          for (int j : it->second) {
            if (seen[static_cast<std::size_t>(j)] == i) continue;
            seen[static_cast<std::size_t>(j)] = i;
            if (same && j <= i) continue;
            if (same && (fa.col(i).array() == fb(0, j) || fa.col(i).array() == fb(1, j) ||
                         fa.col(i).array() == fb(2, j))
                            .any())
              continue;
            if (!box.intersects(bb[static_cast<std::size_t>(j)])) continue;
            if (!detail::trianglesCross(detail::corners(va, fa, i), detail::corners(vb, fb, j), tolerance))
              continue;
            ++count;
            if (pairs != nullptr) pairs->emplace_back(i, j);
          }
        }
  }
  return count;
}

/// Crossings of a surface with itself (countCrossings() with same = true).
inline int countSelfCrossings(const Eigen::Matrix3Xd& v, const Eigen::Matrix3Xi& f,
                              double tolerance = kCrossingTolerance,
                              std::vector<std::pair<int, int>>* pairs = nullptr) {
  return countCrossings(v, f, v, f, true, tolerance, pairs);
}

/// True when `p` lies inside the closed mesh (v, f): a ray from p crosses it an odd number of times.
inline bool isInside(const Eigen::Vector3d& p, const Eigen::Matrix3Xd& v, const Eigen::Matrix3Xi& f) {
  const Eigen::Vector3d d = Eigen::Vector3d(0.5773, 0.5774, 0.5775).normalized();  // off every axis
  int hits = 0;
  for (Eigen::Index i = 0; i < f.cols(); ++i) {
    // Moller-Trumbore
    const Eigen::Vector3d a = v.col(f(0, i)), e1 = v.col(f(1, i)) - a, e2 = v.col(f(2, i)) - a;
    const Eigen::Vector3d h = d.cross(e2);
    const double det = e1.dot(h);
    if (std::abs(det) < 1e-18) continue;
    const Eigen::Vector3d s = p - a;
    const double u = s.dot(h) / det;
    if (u < 0.0 || u > 1.0) continue;
    const Eigen::Vector3d q = s.cross(e1);
    const double w = d.dot(q) / det;
    if (w < 0.0 || u + w > 1.0) continue;
    if (e2.dot(q) / det > 0.0) ++hits;
  }
  return hits % 2 == 1;
}

}  // namespace pneuma::test
