// All CGAL code of pneuma::meshing (kept in one translation unit: CGAL dominates compile time).
#include "pneuma/meshing/MeshTools.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/helpers.h>
#include <CGAL/convex_hull_3.h>

#include <array>
#include <cstdint>
#include <map>

#include "pneuma/sim/Error.h"

namespace pneuma::meshing {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
namespace PMP = CGAL::Polygon_mesh_processing;

constexpr double kHullJitter = 1e-7;  // [m] span of the per-point offset that breaks coplanar ties

// copy into a halfedge mesh; false when a face breaks manifoldness
bool toSurfaceMesh(const TriangleMesh& in, SurfaceMesh& out) {
  std::vector<SurfaceMesh::Vertex_index> v;
  v.reserve(static_cast<std::size_t>(in.vertexCount()));
  for (int i = 0; i < in.vertexCount(); ++i) {
    v.push_back(out.add_vertex(Point(in.vertices(0, i), in.vertices(1, i), in.vertices(2, i))));
  }
  for (int f = 0; f < in.triangleCount(); ++f) {
    const auto face = out.add_face(v[static_cast<std::size_t>(in.triangles(0, f))],
                                   v[static_cast<std::size_t>(in.triangles(1, f))],
                                   v[static_cast<std::size_t>(in.triangles(2, f))]);
    if (face == SurfaceMesh::null_face()) return false;
  }
  return true;
}

TriangleMesh fromSurfaceMesh(SurfaceMesh m) {
  m.collect_garbage();
  TriangleMesh out;
  out.vertices.resize(3, static_cast<Eigen::Index>(m.number_of_vertices()));
  for (auto v : m.vertices()) {
    const Point& p = m.point(v);
    out.vertices.col(static_cast<Eigen::Index>(v.idx())) = Eigen::Vector3d(p.x(), p.y(), p.z());
  }
  out.triangles.resize(3, static_cast<Eigen::Index>(m.number_of_faces()));
  Eigen::Index f = 0;
  for (auto face : m.faces()) {
    int k = 0;
    for (auto v : CGAL::vertices_around_face(m.halfedge(face), m)) {
      out.triangles(k++, f) = static_cast<int>(v.idx());
    }
    ++f;
  }
  return out;
}

MeshCheck check(const SurfaceMesh& m, bool isManifold, const TriangleMesh& mesh) {
  MeshCheck c;
  c.isManifold = isManifold;
  if (!isManifold) return c;
  c.isClosed = CGAL::is_closed(m);
  c.isSelfIntersecting = PMP::does_self_intersect(m);
  c.isOutward = enclosedVolume(mesh.vertices, mesh.triangles) > 0.0;
  return c;
}

void requireValid(const MeshCheck& c, const std::string& part, const std::string& stage) {
  if (!c.isManifold) throw sim::Error(part + ": " + stage + " mesh is not manifold");
  if (!c.isClosed) throw sim::Error(part + ": " + stage + " mesh is not closed");
  if (c.isSelfIntersecting) throw sim::Error(part + ": " + stage + " mesh intersects itself");
  if (!c.isOutward) throw sim::Error(part + ": " + stage + " mesh is not oriented outward");
}

}  // namespace

MeshCheck checkMesh(const TriangleMesh& mesh) {
  SurfaceMesh m;
  const bool isManifold = toSurfaceMesh(mesh, m);
  return check(m, isManifold, mesh);
}

TriangleMesh remeshIsotropic(const TriangleMesh& mesh, double targetEdge, const std::string& part) {
  SurfaceMesh m;
  const bool isManifold = toSurfaceMesh(mesh, m);
  requireValid(check(m, isManifold, mesh), part, "input");

  PMP::isotropic_remeshing(faces(m), targetEdge, m, CGAL::parameters::number_of_iterations(3));
  TriangleMesh out = fromSurfaceMesh(m);

  SurfaceMesh again;
  const bool isStillManifold = toSurfaceMesh(out, again);
  requireValid(check(again, isStillManifold, out), part, "remeshed");
  return out;
}

TriangleMesh convexHull(const Eigen::Matrix3Xd& points, std::vector<int>& source) {
  // CGAL triangulates a flat part of the hull (four or more coplanar points: mirror-symmetric ribs give many)
  // in an order that follows heap addresses, so the same points could give another hull from one process to
  // the next. A fixed sub-micrometre offset per point puts them in general position, where the hull is
  // unique; the output keeps the exact input coordinates.
  auto jitter = [](std::uint64_t i, int k) {
    std::uint64_t z = (i * 3 + static_cast<std::uint64_t>(k) + 1) * 0x9e3779b97f4a7c15ULL;  // splitmix64
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    return kHullJitter * (static_cast<double>(z >> 11) / 9007199254740992.0 - 0.5);  // [m]
  };
  std::vector<Point> pts;
  std::map<std::array<double, 3>, int> index;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const std::uint64_t u = static_cast<std::uint64_t>(i);
    const std::array<double, 3> p{points(0, i) + jitter(u, 0), points(1, i) + jitter(u, 1),
                                  points(2, i) + jitter(u, 2)};
    pts.emplace_back(p[0], p[1], p[2]);
    index.emplace(p, static_cast<int>(i));
  }
  SurfaceMesh hull;
  CGAL::convex_hull_3(pts.begin(), pts.end(), hull);
  TriangleMesh out = fromSurfaceMesh(hull);
  source.assign(static_cast<std::size_t>(out.vertexCount()), -1);
  for (int v = 0; v < out.vertexCount(); ++v) {
    const int i = index.at(std::array<double, 3>{out.vertices(0, v), out.vertices(1, v), out.vertices(2, v)});
    source[static_cast<std::size_t>(v)] = i;
    out.vertices.col(v) = points.col(i);
  }
  return out;
}

TriangleMesh subtract(const TriangleMesh& a, const TriangleMesh& b, double grid, const std::string& part) {
  SurfaceMesh ma, mb, result;
  if (!toSurfaceMesh(a, ma) || !toSurfaceMesh(b, mb)) throw sim::Error(part + ": operand is not manifold");
  if (!PMP::corefine_and_compute_difference(ma, mb, result)) {
    throw sim::Error(part + ": Boolean difference failed (operands not closed or not bounding a volume)");
  }
  return fromSurfaceMesh(result).canonical(grid);
}

}  // namespace pneuma::meshing
