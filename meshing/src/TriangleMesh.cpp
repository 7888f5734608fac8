#include "pneuma/meshing/TriangleMesh.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
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

}  // namespace pneuma::meshing
