#include "LungCavity.h"

#include "Anchors.h"

#include "pneuma/meshing/MeshTools.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

namespace pneuma::meshing {

namespace {

constexpr double kHullSample = 0.012;  // [m] spacing of hull points along each rib
constexpr double kGrid = 1e-9;         // [m] coordinate rounding of the cavity surface (determinism)

std::array<long long, 3> gridKey(const Eigen::Vector3d& p) {
  return {std::llround(p.x() / kGrid), std::llround(p.y() / kGrid), std::llround(p.z() / kGrid)};
}

/// Barycentric coordinates of the point of triangle (a, b, c) closest to p, and its distance [m].
Eigen::Vector3d closestBarycentric(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                   const Eigen::Vector3d& c, double& distance) {
  // project onto the plane, then clamp to the triangle by checking the edges (Ericson 2005, 5.1.5)
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  Eigen::Vector3d w;
  const Eigen::Vector3d bp = p - b, cp = p - c;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp), d5 = ab.dot(cp), d6 = ac.dot(cp);
  const double va = d3 * d6 - d5 * d4, vb = d5 * d2 - d1 * d6, vc = d1 * d4 - d3 * d2;
  if (d1 <= 0 && d2 <= 0) {
    w = {1, 0, 0};
  } else if (d3 >= 0 && d4 <= d3) {
    w = {0, 1, 0};
  } else if (d6 >= 0 && d5 <= d6) {
    w = {0, 0, 1};
  } else if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    w = {1 - v, v, 0};
  } else if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double v = d2 / (d2 - d6);
    w = {1 - v, 0, v};
  } else if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double v = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    w = {0, 1 - v, v};
  } else {
    const double denom = 1.0 / (va + vb + vc);
    w = {va * denom, vb * denom, vc * denom};
  }
  distance = (w(0) * a + w(1) * b + w(2) * c - p).norm();
  return w;
}

}  // namespace

double buildCavity(const Skeleton& sk, const GutSurface& gut, sim::Model& model) {
  // hull points on the inner faces of the moving ribs and on the back of the sternum
  std::vector<Endpoint> pts;
  for (int level = 1; level <= 10; ++level) {
    for (int side : {kRight, kLeft}) {
      const RibCurve& r = sk.ribCurve[static_cast<std::size_t>(level - 1)][static_cast<std::size_t>(side)];
      const int b = sk.rib[static_cast<std::size_t>(level - 1)][static_cast<std::size_t>(side)];
      for (double s = 0.0; s <= r.length(); s += kHullSample) {
        pts.push_back(Endpoint::onBody(b, r.at(s, 0.5 * r.thickness)));
      }
      pts.push_back(Endpoint::onBody(b, r.at(r.length(), 0.5 * r.thickness)));
    }
  }
  for (const Eigen::Vector3d& p : sk.sternumInner) pts.push_back(Endpoint::onBody(sk.sternum, p));
  Eigen::Matrix3Xd hullInput(3, static_cast<Eigen::Index>(pts.size()));
  for (std::size_t i = 0; i < pts.size(); ++i) hullInput.col(static_cast<Eigen::Index>(i)) = pts[i].world;

  // hull minus gut: the diaphragm dome becomes the floor
  std::vector<int> source;
  const TriangleMesh hull = convexHull(hullInput, source);
  std::map<std::array<long long, 3>, int> hullVertex;
  for (int v = 0; v < hull.vertexCount(); ++v) hullVertex.emplace(gridKey(hull.vertices.col(v)), source[static_cast<std::size_t>(v)]);
  TriangleMesh gutMesh;
  gutMesh.vertices = gut.rest;
  gutMesh.triangles = gut.triangles;
  const TriangleMesh cavity = subtract(hull, gutMesh, kGrid, "lung cavity");

  // bind every cavity vertex: hull corners to their bone, the rest to the gut triangle it lies on
  sim::Cavity& c = model.cavity;
  c = sim::Cavity{};
  for (int v = 0; v < cavity.vertexCount(); ++v) {
    const Eigen::Vector3d p = cavity.vertices.col(v);
    auto it = hullVertex.find(gridKey(p));
    if (it != hullVertex.end()) {
      addEndpoint(c.vertices, pts[static_cast<std::size_t>(it->second)], model.bodies);
      continue;
    }
    double best = 1e9;
    Endpoint e;
    for (int f = 0; f < gut.triangles.cols(); ++f) {
      double d = 0.0;
      const Eigen::Vector3i t = gut.triangles.col(f);
      const Eigen::Vector3d w = closestBarycentric(p, gut.rest.col(t(0)), gut.rest.col(t(1)), gut.rest.col(t(2)), d);
      if (d < best) {
        best = d;
        e = Endpoint{-1, p, t, w};
      }
    }
    addEndpoint(c.vertices, e, model.bodies);
  }
  c.triangles = cavity.triangles;
  return enclosedVolume(cavity.vertices, cavity.triangles);
}

}  // namespace pneuma::meshing
