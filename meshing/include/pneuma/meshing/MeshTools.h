#pragma once
/// @file MeshTools.h
/// The CGAL side of meshing (all CGAL code lives in MeshTools.cpp): mesh checks, isotropic
/// remeshing, convex hulls and Boolean difference.

#include <string>
#include <vector>

#include "pneuma/meshing/TriangleMesh.h"

namespace pneuma::meshing {

/// Result of checkMesh().
struct MeshCheck {
  bool isManifold = false;         ///< every face could be added to a halfedge mesh
  bool isClosed = false;           ///< CGAL::is_closed: no border edges
  bool isSelfIntersecting = true;  ///< CGAL::Polygon_mesh_processing::does_self_intersect
  bool isOutward = false;          ///< positive enclosed volume
  bool isValid() const { return isManifold && isClosed && !isSelfIntersecting && isOutward; }
};

/// Checks a triangle mesh with CGAL.
MeshCheck checkMesh(const TriangleMesh& mesh);

/// Checks `mesh` (it must be a closed, manifold, self-intersection-free outward surface), remeshes it
/// isotropically to `targetEdge` [m] (CGAL::Polygon_mesh_processing::isotropic_remeshing, 3 iterations)
/// and checks the result again. @throws sim::Error naming `part` and the failed check.
TriangleMesh remeshIsotropic(const TriangleMesh& mesh, double targetEdge, const std::string& part);

/// Convex hull of `points` (3 x #P) [m] (CGAL::convex_hull_3), outward. `source[v]` is the index of
/// the input point that hull vertex v came from.
TriangleMesh convexHull(const Eigen::Matrix3Xd& points, std::vector<int>& source);

/// Boolean difference a \ b of two closed surfaces by corefinement
/// (CGAL::Polygon_mesh_processing::corefine_and_compute_difference). The result is canonical(`grid`)
/// so that it does not depend on CGAL's internal (address-based) ordering. @throws sim::Error naming `part`.
TriangleMesh subtract(const TriangleMesh& a, const TriangleMesh& b, double grid, const std::string& part);

}  // namespace pneuma::meshing
