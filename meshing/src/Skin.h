#pragma once
/// @file Skin.h
/// The body surface: a closed skin mesh registered to the anatomy and bound to the bones and the gut through
/// the soft tissue between them (sim::Skin). Method and figures: docs/model-format.md ("skin").

#include <string>

#include "pneuma/meshing/AnatomyParams.h"
#include "pneuma/meshing/ModelBuilder.h"

namespace pneuma::meshing {

/// Reads the skin mesh `file` (readSkinSource()), registers it to the built model in `out` and binds it:
///  1. landmarks on the mesh, derived from its geometry: horizontal sections of the mesh's central piece
///     (the section's points round the midline, arms excluded) give the neck (narrowest section below the
///     head) and the crotch (highest section whose midline falls between the legs); the levels of the
///     jugular notch, xiphoid, umbilicus, rib-8 laterals, ASIS and acromions follow from these two by the
///     model's own proportions (a vertical map that sends the neck-to-crotch span onto the model's); each
///     landmark is then the extreme mesh point of its section (most anterior on the midline, most lateral at
///     rib 8, most superior over the acromion, most posterior over the spine at T8 and L3);
///     A model with a shoulder girdle adds the arms and the head: on the mesh, the part lateral of each
///     acromion is the arm, its most lateral vertex the fingertip; the vertices binned by their distance from
///     it over the surface give the arm's centreline, whose point farthest from the line between its ends is
///     the elbow and whose point at the forearm's share of the elbow-to-fingertip length is the wrist; these
///     go to the model's elbow and wrist joint centres and the tip of the hand's bone, and the mesh's top to
///     the head's;
///  2. a thin-plate-spline warp (kernel |r|, Bookstein 1989) sending them onto the model's landmarks set out
///     by a soft-tissue depth (AnatomyParams-free constants in Skin.cpp);
///  3. the legs cut at the thigh, 10 cm below the crotch (placed 7 cm below the pelvic floor), and the cuts
///     capped;
///  4. vertices inside a bone or closer than 6 mm to one (or 10 mm to the gut) pushed out along the skin's
///     normal, the push spread over the neighbours;
///  5. TetGen tetrahedralises the volume inside the skin with bone-surface points and gut nodes as vertices;
///     each skin vertex takes its 3 nearest of those anchors through the tissue (Dijkstra on tetrahedron
///     edges) with inverse-square-distance weights, all of their motion within 6 cm and none beyond 12 cm
///     (the rest of the weight on a fixed body; all at any distance when the nearest is on a limb, a body
///     with a postural support), the weights averaged over the surface; a vertex bound to one
///     bone only follows it rigidly.
/// Fills out.model.skin and out.report's skin figures.
/// @throws sim::Error "<file>: <problem>" when the file cannot be read, is not closed, a landmark cannot be
///         found, or the registered surface intersects itself.
void buildSkin(const AnatomyParams& a, const std::string& file, BuiltModel& out);

}  // namespace pneuma::meshing
