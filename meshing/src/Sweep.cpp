#include "pneuma/meshing/Sweep.h"

#include <Eigen/Geometry>
#include <cmath>

#include "pneuma/sim/Error.h"

namespace pneuma::meshing {

TriangleMesh sweepTube(const std::vector<SweepStation>& stations, int around, bool isLoop) {
  const int n = static_cast<int>(stations.size());
  if (n < (isLoop ? 3 : 2) || around < 3) throw sim::Error("sweepTube: too few stations or points around");
  const int rings = n;
  const int caps = isLoop ? 0 : 2;
  TriangleMesh m;
  m.vertices.resize(3, rings * around + caps);

  // ring vertices: ellipse in the plane normal to the centreline tangent
  for (int i = 0; i < n; ++i) {
    const SweepStation& s = stations[static_cast<std::size_t>(i)];
    const int prev = isLoop ? (i + n - 1) % n : std::max(i - 1, 0);
    const int next = isLoop ? (i + 1) % n : std::min(i + 1, n - 1);
    const Eigen::Vector3d t =
        (stations[static_cast<std::size_t>(next)].centre - stations[static_cast<std::size_t>(prev)].centre)
            .normalized();
    const Eigen::Vector3d u = (s.up - s.up.dot(t) * t).normalized();
    const Eigen::Vector3d w = t.cross(u);
    for (int k = 0; k < around; ++k) {
      const double a = 2.0 * M_PI * k / around;
      m.vertices.col(i * around + k) =
          s.centre + s.halfHeight * std::cos(a) * u + s.halfWidth * std::sin(a) * w;
    }
  }

  // side quads, split into two triangles
  const int segments = isLoop ? n : n - 1;
  m.triangles.resize(3, 2 * segments * around + caps * around);
  int f = 0;
  for (int i = 0; i < segments; ++i) {
    const int i1 = (i + 1) % n;
    for (int k = 0; k < around; ++k) {
      const int k1 = (k + 1) % around;
      const int a = i * around + k, b = i * around + k1, c = i1 * around + k1, d = i1 * around + k;
      m.triangles.col(f++) = Eigen::Vector3i(a, b, c);
      m.triangles.col(f++) = Eigen::Vector3i(a, c, d);
    }
  }

  // end caps: fans around the first and last centreline points
  if (!isLoop) {
    const int c0 = rings * around;
    const int c1 = c0 + 1;
    m.vertices.col(c0) = stations.front().centre;
    m.vertices.col(c1) = stations.back().centre;
    const int last = (n - 1) * around;
    for (int k = 0; k < around; ++k) {
      const int k1 = (k + 1) % around;
      m.triangles.col(f++) = Eigen::Vector3i(c0, k1, k);
      m.triangles.col(f++) = Eigen::Vector3i(c1, last + k, last + k1);
    }
  }

  // orient outward
  if (enclosedVolume(m.vertices, m.triangles) < 0.0) m.triangles.row(1).swap(m.triangles.row(2));
  return m;
}

}  // namespace pneuma::meshing
