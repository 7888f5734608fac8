#pragma once
/// @file SkinSource.h
/// Reading a body-surface mesh with assimp (all assimp code lives in SkinSource.cpp).

#include <string>

#include "pneuma/meshing/TriangleMesh.h"

namespace pneuma::meshing {

/// Reads the body surface in `path` (any format assimp reads: Collada, OBJ, STL, PLY, glTF, ...) as one
/// closed outward triangle mesh in the world axes (RAS): all meshes of the scene with their node transforms
/// applied, polygons triangulated, duplicate vertices welded (positions equal to 1e-6 of the bounding-box
/// diagonal), repeated-vertex triangles dropped, and the largest connected piece kept (MakeHuman's separate
/// eyes are dropped). The file is taken to be Y-up and facing +Z (the convention of MakeHuman, Blender's glTF
/// and Collada exports): world = (-X, +Z, +Y). Lengths stay in the file's unit; registration rescales them.
/// @throws sim::Error "<path>: <problem>" when assimp cannot read the file, it holds no triangles, or the
///         kept piece is not closed (edges without a partner) or not consistently oriented.
TriangleMesh readSkinSource(const std::string& path);

}  // namespace pneuma::meshing
