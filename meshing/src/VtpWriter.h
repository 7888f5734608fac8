#pragma once
/// @file VtpWriter.h
/// A minimal writer of VTK XML PolyData (.vtp, ASCII) for the render meshes of a model directory,
/// so that meshing needs no VTK. Deterministic text (fixed formatting).

#include <string>

#include "pneuma/meshing/TriangleMesh.h"

namespace pneuma::meshing {

/// Writes `mesh` as triangle polys to `path`. @throws sim::Error when the file cannot be written.
void writeVtp(const TriangleMesh& mesh, const std::string& path);

}  // namespace pneuma::meshing
