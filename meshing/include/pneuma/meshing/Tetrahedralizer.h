#pragma once
/// @file Tetrahedralizer.h
/// The TetGen side of meshing (all TetGen code lives in Tetrahedralizer.cpp).

#include <string>

#include "pneuma/meshing/TriangleMesh.h"

namespace pneuma::meshing {

/// A tetrahedral mesh of the volume a closed surface bounds.
struct TetMesh {
  Eigen::Matrix3Xd vertices;  ///< [m] (3 x #V): the surface vertices first, then interior Steiner points
  Eigen::Matrix4Xi tets;      ///< vertex indices (4 x #T)
  double volume = 0.0;        ///< [m^3] sum of the tetrahedra volumes
  int boundaryTriangles = 0;  ///< triangles on the boundary (equals the input's: the surface is kept)
};

/// Quality tetrahedralisation of the volume bounded by a closed outward `surface` with TetGen
/// (switches "pq1.5YQ": piecewise-linear complex, radius-edge ratio <= 1.5, boundary kept unsplit).
/// @throws sim::Error naming `part` when TetGen rejects the surface, or before TetGen runs when a triangle is
///         degenerate (quality < 0.01: TetGen 1.5 would crash on it).
TetMesh tetrahedralize(const TriangleMesh& surface, const std::string& part);

/// Tetrahedralisation of the volume bounded by a closed outward `surface` with the `interior` points (3 x #P)
/// [m] as further vertices, with TetGen (switches "pYQ": piecewise-linear complex, boundary kept unsplit, no
/// quality refinement). TetMesh::vertices holds the surface vertices, then the interior points in their
/// order (a point outside the surface is in no tetrahedron), then any Steiner points.
/// @throws sim::Error naming `part` as tetrahedralize().
TetMesh tetrahedralizeAround(const TriangleMesh& surface, const Eigen::Matrix3Xd& interior,
                             const std::string& part);

}  // namespace pneuma::meshing
