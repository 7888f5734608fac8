#pragma once
/// @file ModelIO.h
/// Reading, writing and validating model directories (format: docs/model-format.md).

#include <string>

#include "pneuma/sim/Model.h"

namespace pneuma::sim {

/// Current model.json format version written by saveModel(); loadModel() accepts this major version.
constexpr int kModelFormatVersion = 1;

/// Reads `<dir>/model.json`. Validates it fully (see validateModel()).
/// @throws Error naming the JSON path and the reason, e.g. "model.json: elements.rest_length[3]: must be >
/// 0".
Model loadModel(const std::string& dir);

/// Parses a model from the text of a model.json (no file access). Same validation as loadModel().
Model parseModel(const std::string& jsonText, const std::string& sourceName = "model.json");

/// Serialises a model to the text of a model.json. Deterministic: the same model gives the same bytes.
std::string serializeModel(const Model& model);

/// Writes `<dir>/model.json` (dir must exist) through a temporary file and a rename.
void saveModel(const Model& model, const std::string& dir);

/// Checks sizes, index ranges, finite values, positive masses, rest lengths and inertias, the presence of the
/// required landmarks, and the structure: the joints form a tree (one parent joint per body, no body its own
/// ancestor), the gut and the lung cavity are closed, consistently oriented surfaces enclosing a positive
/// rest volume, and at least one element with a passive gain > 0 holds them. @throws Error naming the field
/// and the reason, e.g. "gut.triangles[12]: edge 4-9 has no neighbouring triangle: the surface is open".
void validateModel(const Model& model);

}  // namespace pneuma::sim
