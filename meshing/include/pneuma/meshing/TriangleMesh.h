#pragma once
/// @file TriangleMesh.h
/// An indexed triangle mesh and the integral properties of the solid it bounds.

#include <Eigen/Core>
#include <vector>

namespace pneuma::meshing {

/// Indexed triangle mesh; closed meshes are oriented counter-clockwise seen from outside.
struct TriangleMesh {
  Eigen::Matrix3Xd vertices;   ///< [m] positions (3 x #V)
  Eigen::Matrix3Xi triangles;  ///< vertex indices (3 x #F)

  int vertexCount() const { return static_cast<int>(vertices.cols()); }
  int triangleCount() const { return static_cast<int>(triangles.cols()); }
  /// Appends `other` as a separate component.
  void append(const TriangleMesh& other);
  /// The mirror image through the plane x = 0 (orientation kept outward).
  TriangleMesh mirroredX() const;
  /// The mesh translated by `t` [m].
  TriangleMesh translated(const Eigen::Vector3d& t) const;
  /// The same surface in a canonical form that does not depend on how it was produced: vertex
  /// coordinates rounded to multiples of `grid` [m], vertices sorted lexicographically, each triangle
  /// rotated to start at its smallest index (orientation kept) and triangles sorted.
  TriangleMesh canonical(double grid) const;
};

/// Mass properties of a homogeneous solid.
struct MassProperties {
  double volume = 0.0;                                ///< [m^3]
  double mass = 0.0;                                  ///< [kg]
  Eigen::Vector3d com{0, 0, 0};                       ///< [m] centre of mass
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  ///< [kg m^2] inertia tensor about the com, mesh axes
};

/// Volume enclosed by a closed outward mesh, V = 1/6 sum_f a . (b x c) (divergence theorem) [m^3].
double enclosedVolume(const Eigen::Matrix3Xd& vertices, const Eigen::Matrix3Xi& triangles);

/// Mass, centre of mass and inertia of the solid bounded by a closed outward mesh at uniform `density`
/// [kg/m^3]: exact integrals over the signed tetrahedra (origin, a, b, c) of every face, using the
/// canonical tetrahedron covariance det(A) A C0 A^T with C0 = [2 1 1; 1 2 1; 1 1 2] / 120
/// (Tonon 2004, "Explicit exact formulas for the 3-D tetrahedron inertia tensor").
MassProperties massProperties(const TriangleMesh& mesh, double density);

/// Quality of a triangle, q = 4 sqrt(3) area / (sum of squared edge lengths): 1 equilateral, 0 degenerate.
double triangleQuality(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c);

/// Delaunay edge flips (Lawson 1977, "Software for C1 surface interpolation") of the part of a consistently
/// oriented triangle mesh that `isFlippable` marks (one flag per triangle), in the plane coordinates `planar`
/// (2 x #V) [m] of its vertices: an edge shared by two marked triangles is flipped while the opposite corner
/// of the other triangle lies strictly inside the circumcircle of the first and the two form a strictly
/// convex quadrilateral (tolerances scaled by the quadrilateral's size). This ends with the Delaunay
/// triangulation of the same points, which maximises the smallest angle; no vertex is added or moved,
/// orientation is kept, and marked triangles stay marked. Cocircular quadrilaterals (ties, as in
/// mirror-symmetric meshes) are left as they are, so the result does not depend on the order of the scan.
/// Returns the number of flips.
int delaunayFlips(Eigen::Matrix3Xi& triangles, const Eigen::Matrix2Xd& planar,
                  const std::vector<char>& isFlippable);

}  // namespace pneuma::meshing
