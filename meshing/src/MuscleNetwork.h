#pragma once
/// @file MuscleNetwork.h
/// Spring-muscle elements (Zordan et al. 2004, Sections 4-6, Table 1) and the costal cartilage springs.

#include "GutSurface.h"
#include "Skeleton.h"
#include "pneuma/sim/Model.h"

namespace pneuma::meshing {

/// Fills `model.elements` from the skeleton and gut; `model.bodies` must already hold the centres of mass.
/// Gains: k = group gain * referenceLength / restLength (see Gains).
void buildElements(const AnatomyParams& a, const Skeleton& sk, const GutSurface& gut, sim::Model& model);

}  // namespace pneuma::meshing
