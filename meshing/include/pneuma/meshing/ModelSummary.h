#pragma once
/// @file ModelSummary.h
/// The headline numbers of a model, as `pneuma-cli model build` and `model info` print them.

#include <array>
#include <string>

#include "pneuma/sim/Model.h"

namespace pneuma::meshing {

/// Counts, volumes and masses of a model at rest.
struct ModelSummary {
  int bodies = 0;
  int movingBodies = 0;
  int joints = 0;
  int nodes = 0;
  int fixedNodes = 0;
  std::array<int, sim::kElementGroupCount> elements{};  ///< per sim::ElementGroup
  double gutVolume = 0.0;                               ///< [m^3] enclosed by the gut surface at rest
  double cavityVolume = 0.0;                            ///< [m^3] enclosed by the lung-cavity surface at rest
  double gutWallMass = 0.0;   ///< [kg] mass of the moving abdominal-wall nodes (region Wall)
  double boneMass = 0.0;      ///< [kg] mass of all bodies
  int skinVertices = 0;       ///< vertices of the skin (0: the model has none)
  int skinTriangles = 0;      ///< triangles of the skin
  int skinTetrahedra = 0;     ///< TetGen tetrahedra of the soft tissue the skin is bound through
  double skinVolume = 0.0;    ///< [m^3] enclosed by the skin at rest
  int tissueBodies = 0;       ///< soft-tissue volume bodies (sim::VolumeBodies: pectorals, shoulders)
  int tissueNodes = 0;        ///< their nodes (region Tissue)
  double tissueVolume = 0.0;  ///< [m^3] the volume they enclose at rest, together
  double tissueMass = 0.0;    ///< [kg] the mass of their nodes
};

/// World rest positions of the points of `set` (3 x #P) [m]: body points at com + local (body axes are
/// world-parallel at rest), node points as the weighted sum of their nodes' rest positions.
Eigen::Matrix3Xd restPoints(const sim::AnchorSet& set, const sim::Model& model);

/// Summarises `model` at its rest pose.
ModelSummary summarizeModel(const sim::Model& model);

/// The summary as a JSON object with the keys of `model info --json` (volumes in mL, masses in kg).
std::string summaryJson(const ModelSummary& s);

/// The summary as human-readable lines.
std::string summaryText(const ModelSummary& s);

}  // namespace pneuma::meshing
