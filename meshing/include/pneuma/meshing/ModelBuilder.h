#pragma once
/// @file ModelBuilder.h
/// Builds the simulation model of a torso (Zordan et al. 2004, Sections 4-6) from an anatomy preset,
/// and writes it as a model directory (model.json plus body render meshes).

#include <string>
#include <vector>

#include "pneuma/meshing/AnatomyParams.h"
#include "pneuma/meshing/ModelSummary.h"
#include "pneuma/meshing/TriangleMesh.h"
#include "pneuma/sim/Model.h"

namespace pneuma::meshing {

/// Numbers measured while building (beyond the model's own summary).
struct BuildReport {
  ModelSummary summary;               ///< counts, volumes and masses of the built model
  int tetrahedra = 0;                 ///< TetGen tetrahedra of the gut volume
  double tetVolume = 0.0;             ///< [m^3] TetGen volume of the gut
  double gutQualityMin = 0.0;         ///< [-] smallest pressure-surface triangle quality (1 = equilateral)
  double gutQualityMean = 0.0;        ///< [-] mean pressure-surface triangle quality
  int boneTriangles = 0;              ///< triangles of all remeshed bones
  int skinTetrahedra = 0;             ///< TetGen tetrahedra of the soft tissue inside the skin (0: no skin)
  double skinLandmarkResidual = 0.0;  ///< [m] largest distance from a surface landmark's target to the skin
  double skinBoneClearance = 0.0;     ///< [m] least distance from a skin vertex to a bone surface
};

/// The body surface a model is built with by default: MakeHuman's base mesh as Debian's assimp-testmodels
/// package installs it (source and licence: resources/anatomy/README.md).
constexpr const char* kDefaultSkinFile = "/usr/share/assimp/models/Collada/human.zae";

/// A built model with its render meshes.
struct BuiltModel {
  sim::Model model;
  std::vector<TriangleMesh> bodyMeshes;  ///< per body, body frame [m] (written as meshes/<body>.vtp)
  BuildReport report;
};

/// Builds bones (closed, checked and remeshed with CGAL; mass properties at the preset's bone density),
/// joints, the gut (its volume checked against TetGen to 0.1 %), the elements, the lung cavity and the
/// landmarks, the skin from `skinFile` (any mesh assimp reads; Skin.h; empty: no skin), then validates the
/// model. Deterministic. @throws sim::Error naming the failing part (or the skin file).
BuiltModel buildModel(const AnatomyParams& anatomy, const std::string& skinFile = kDefaultSkinFile);

/// Writes `built` to `dir` (model.json and meshes/*.vtp) through a temporary sibling directory of its own
/// ("<dir>.tmp-<pid>-<n>") that is renamed into place, so `dir` is either left untouched or holds the whole
/// model. Only a missing or empty `dir` or an earlier model (one holding model.json) is replaced; nothing
/// else beside it is touched. A trailing slash is allowed.
/// @throws sim::Error when `dir` is not empty and not a model directory, or cannot be written.
void writeModelDirectory(const BuiltModel& built, const std::string& dir);

}  // namespace pneuma::meshing
