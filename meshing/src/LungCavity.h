#pragma once
/// @file LungCavity.h
/// The closed lung-cavity surface (Zordan et al. 2004, Figure 6).

#include "GutSurface.h"
#include "Skeleton.h"

#include "pneuma/sim/Model.h"

namespace pneuma::meshing {

/// Builds `model.cavity`: the convex hull (CGAL) of points on the inner faces of ribs 1-10 and the
/// sternum, minus the gut volume (CGAL corefinement), so that the diaphragm dome is its floor. Hull
/// vertices are bound to their bone, vertices on the gut surface barycentrically to the gut triangle
/// they lie on. `model.bodies` must hold the centres of mass. @return the cavity volume [m^3].
double buildCavity(const Skeleton& sk, const GutSurface& gut, sim::Model& model);

}  // namespace pneuma::meshing
