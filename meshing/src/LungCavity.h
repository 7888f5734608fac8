#pragma once
/// @file LungCavity.h
/// The closed lung-cavity surface (Zordan et al. 2004, Figure 6).

#include "GutSurface.h"
#include "Skeleton.h"
#include "pneuma/meshing/TriangleMesh.h"
#include "pneuma/sim/Model.h"

namespace pneuma::meshing {

/// Builds `model.cavity`: the convex hull (CGAL) of points on the inner faces of ribs 1-10 and the
/// sternum, minus the gut volume (CGAL corefinement), so that the diaphragm dome is its floor. Hull
/// vertices are bound to their bone, vertices on the gut surface barycentrically to the gut triangle
/// they lie on. `model.bodies` must hold the centres of mass. @return the cavity volume [m^3].
/// Also builds `model.lungs` from it (buildLungs()).
double buildCavity(const Skeleton& sk, const GutSurface& gut, sim::Model& model);

/// Builds `model.lungs` from the cavity surface `cavity` (rest positions [m], vertex i = model.cavity vertex
/// i): the cavity minus the mediastinum (a central block the cavity's full depth and height, and the heart,
/// an ellipsoid resting on the diaphragm left of the midline, CGAL corefinement), split into the right (x >
/// 0) and left lungs. The heart's lateral offset is solved so that the right lung holds 53.5 % of the two
/// (Yamada et al. 2020). Each lung vertex is embedded in the cavity (sim::LungSurface); mediastinumVolume is
/// the rest volume the lungs leave. @throws sim::Error when the cut does not leave two lungs inside the
/// cavity.
void buildLungs(const TriangleMesh& cavity, sim::Model& model);

}  // namespace pneuma::meshing
