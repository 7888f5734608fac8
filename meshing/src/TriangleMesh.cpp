#include "pneuma/meshing/TriangleMesh.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <tuple>
#include <utility>
#include <vector>

namespace pneuma::meshing {

void TriangleMesh::append(const TriangleMesh& other) {
  const int offset = vertexCount();
  const Eigen::Index nv = vertices.cols();
  const Eigen::Index nf = triangles.cols();
  vertices.conservativeResize(3, nv + other.vertices.cols());
  vertices.rightCols(other.vertices.cols()) = other.vertices;
  triangles.conservativeResize(3, nf + other.triangles.cols());
  triangles.rightCols(other.triangles.cols()) = other.triangles.array() + offset;
}

TriangleMesh TriangleMesh::mirroredX() const {
  TriangleMesh m = *this;
  m.vertices.row(0) *= -1.0;
  // a reflection flips orientation: swap two corners to keep normals outward
  m.triangles.row(1).swap(m.triangles.row(2));
  return m;
}

TriangleMesh TriangleMesh::translated(const Eigen::Vector3d& t) const {
  TriangleMesh m = *this;
  m.vertices.colwise() += t;
  return m;
}

TriangleMesh TriangleMesh::canonical(double grid) const {
  // round, then order vertices by their rounded coordinates
  const int n = vertexCount();
  std::vector<std::array<long long, 3>> key(static_cast<std::size_t>(n));
  for (int v = 0; v < n; ++v) {
    for (int k = 0; k < 3; ++k)
      key[static_cast<std::size_t>(v)][static_cast<std::size_t>(k)] = std::llround(vertices(k, v) / grid);
  }
  std::vector<int> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return key[static_cast<std::size_t>(a)] < key[static_cast<std::size_t>(b)];
  });
  std::vector<int> newIndex(static_cast<std::size_t>(n));
  TriangleMesh m;
  m.vertices.resize(3, n);
  for (int i = 0; i < n; ++i) {
    const auto& k = key[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])];
    m.vertices.col(i) =
        Eigen::Vector3d(static_cast<double>(k[0]), static_cast<double>(k[1]), static_cast<double>(k[2])) *
        grid;
    newIndex[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])] = i;
  }

  // re-index, rotate each triangle to its smallest index, sort
  std::vector<std::array<int, 3>> tris;
  for (int f = 0; f < triangleCount(); ++f) {
    std::array<int, 3> t{};
    for (int k = 0; k < 3; ++k)
      t[static_cast<std::size_t>(k)] = newIndex[static_cast<std::size_t>(triangles(k, f))];
    while (t[0] > t[1] || t[0] > t[2]) t = {t[1], t[2], t[0]};
    tris.push_back(t);
  }
  std::sort(tris.begin(), tris.end());
  m.triangles.resize(3, static_cast<Eigen::Index>(tris.size()));
  for (std::size_t f = 0; f < tris.size(); ++f) {
    m.triangles.col(static_cast<Eigen::Index>(f)) = Eigen::Vector3i(tris[f][0], tris[f][1], tris[f][2]);
  }
  return m;
}

double enclosedVolume(const Eigen::Matrix3Xd& vertices, const Eigen::Matrix3Xi& triangles) {
  double v6 = 0.0;
  for (Eigen::Index f = 0; f < triangles.cols(); ++f) {
    const Eigen::Vector3d a = vertices.col(triangles(0, f));
    const Eigen::Vector3d b = vertices.col(triangles(1, f));
    const Eigen::Vector3d c = vertices.col(triangles(2, f));
    v6 += a.dot(b.cross(c));
  }
  return v6 / 6.0;
}

MassProperties massProperties(const TriangleMesh& mesh, double density) {
  Eigen::Matrix3d c0;
  c0 << 2, 1, 1, 1, 2, 1, 1, 1, 2;
  c0 /= 120.0;

  // accumulate volume, first moment and covariance about the origin
  double volume = 0.0;
  Eigen::Vector3d first = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (int f = 0; f < mesh.triangleCount(); ++f) {
    Eigen::Matrix3d a;
    for (int k = 0; k < 3; ++k) a.col(k) = mesh.vertices.col(mesh.triangles(k, f));
    const double det = a.determinant();
    volume += det / 6.0;
    first += det / 24.0 * a.rowwise().sum();
    cov += det * a * c0 * a.transpose();
  }

  // shift the covariance to the centre of mass and convert it to an inertia tensor
  MassProperties p;
  p.volume = volume;
  p.mass = density * volume;
  p.com = first / volume;
  const Eigen::Matrix3d covCom = cov - volume * p.com * p.com.transpose();
  p.inertia = density * (covCom.trace() * Eigen::Matrix3d::Identity() - covCom);
  return p;
}

double triangleQuality(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const double area = 0.5 * (b - a).cross(c - a).norm();
  const double sq = (b - a).squaredNorm() + (c - b).squaredNorm() + (a - c).squaredNorm();
  return sq > 0.0 ? 4.0 * std::sqrt(3.0) * area / sq : 0.0;
}

int delaunayFlips(Eigen::Matrix3Xi& triangles, const Eigen::Matrix2Xd& planar,
                  const std::vector<char>& isFlippable) {
  const auto at = [](int i) { return static_cast<std::size_t>(i); };
  const int nf = static_cast<int>(triangles.cols());
  const auto xy = [&](int v) { return Eigen::Vector2d(planar.col(v)); };
  // twice the signed area of (a, b, c)
  const auto orient = [&](int a, int b, int c) {
    const Eigen::Vector2d u = xy(b) - xy(a), w = xy(c) - xy(a);
    return u.x() * w.y() - u.y() * w.x();
  };
  // > 0 when d lies inside the circumcircle of the counter-clockwise triangle (a, b, c)
  const auto inCircle = [&](int a, int b, int c, int d) {
    Eigen::Matrix3d m;
    const std::array<int, 3> abc{a, b, c};
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector2d q = xy(abc[static_cast<std::size_t>(i)]) - xy(d);
      m.row(i) << q.x(), q.y(), q.squaredNorm();
    }
    return m.determinant();
  };
  using Edge = std::pair<int, int>;
  const auto edge = [](int a, int b) { return a < b ? Edge{a, b} : Edge{b, a}; };
  std::map<Edge, std::vector<int>> faces;  // undirected edge -> the triangles that hold it
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) faces[edge(triangles(k, f), triangles((k + 1) % 3, f))].push_back(f);
  // one flip at a time, each found by a fresh scan of the edges (the map changes under the scan)
  constexpr int kMaxFlips = 100000;
  for (int flip = 0; flip < kMaxFlips; ++flip) {
    bool isFlipped = false;
    for (auto it = faces.begin(); it != faces.end(); ++it) {
      if (it->second.size() != 2 || !isFlippable[at(it->second[0])] || !isFlippable[at(it->second[1])])
        continue;
      const int f = it->second[0], g = it->second[1];
      // f = (a, b, c) with a -> b the shared edge; g = (b, a, d) in a consistently oriented mesh
      int k = 0;
      while (edge(triangles(k, f), triangles((k + 1) % 3, f)) != it->first) ++k;
      const int a = triangles(k, f), b = triangles((k + 1) % 3, f), c = triangles((k + 2) % 3, f);
      int d = -1;
      for (int j = 0; j < 3; ++j)
        if (triangles(j, g) == b && triangles((j + 1) % 3, g) == a) d = triangles((j + 2) % 3, g);
      if (d < 0 || faces.count(edge(c, d)) > 0) continue;
      // the quadrilateral's size sets the tolerances (coordinates may be rounded to a grid)
      double size = 0.0;
      for (const int v : {b, c, d}) size = std::max(size, (xy(v) - xy(a)).norm());
      const double s = orient(a, b, c) > 0.0 ? 1.0 : -1.0;
      if (s * orient(a, b, c) < 1e-9 * size * size || s * orient(b, a, d) < 1e-9 * size * size)
        continue;  // a triangle of no area, whose orientation the rounding decides
      if (s * orient(a, d, c) < 1e-6 * size * size || s * orient(b, c, d) < 1e-6 * size * size)
        continue;  // a quadrilateral that is not strictly convex
      if (s * inCircle(a, b, c, d) <= 1e-6 * std::pow(size, 4)) continue;  // Delaunay already (or cocircular)
      // flip a-b to c-d: (a, d, c) and (b, c, d), orientation kept
      triangles.col(f) << a, d, c;
      triangles.col(g) << b, c, d;
      const Edge old = it->first;
      for (const auto& [e, from, to] : {std::tuple{edge(b, c), f, g}, std::tuple{edge(a, d), g, f}})
        std::replace(faces[e].begin(), faces[e].end(), from, to);
      faces[edge(c, d)] = {f, g};
      faces.erase(old);
      isFlipped = true;
      break;
    }
    if (!isFlipped) return flip;
  }
  return kMaxFlips;
}

}  // namespace pneuma::meshing
