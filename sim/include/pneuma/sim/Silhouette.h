#pragma once
/// @file Silhouette.h
/// The outline of a closed triangle mesh seen from the side or the front: its orthographic projection on the
/// sagittal or the coronal plane (world RAS: x right, y anterior, z superior). Used on the posed skin
/// (PosedGeometry::skin) to compare the body's silhouette at end-expiration and end-inspiration (issue 16,
/// after Zordan et al. 2004 Sec. 8.1, Fig. 5, which compare their skin's silhouette with a filmed person).
///
/// Method. The projection of a closed surface is the projection of the solid it bounds, so the region seen at
/// height z is the projection of the mesh's horizontal slice at z onto the view's horizontal axis u: the
/// union of the intervals [min u, max u] of the segments in which the triangles cut the plane z (exact, per
/// row: silhouetteSpans()). The outline curves are traced from these rows by marching squares on a grid of
/// square cells (silhouetteOutline()); along a row they cross the cell edges exactly at the span ends,
/// between rows within half a cell.

#include <Eigen/Core>
#include <limits>
#include <utility>
#include <vector>

namespace pneuma::sim {

/// The projection plane.
enum class SilhouetteView {
  Lateral,  ///< seen from the side: u = y (anterior), on the sagittal plane
  Frontal,  ///< seen from the front: u = x (right), on the coronal plane
};

/// "lateral" or "frontal".
const char* silhouetteViewName(SilhouetteView view);

constexpr double kWholeMesh = std::numeric_limits<double>::infinity();  ///< no band: the whole mesh

/// [m] The intervals [u0, u1] (u0 < u1, sorted, disjoint) that the mesh covers at height `z` in `view`: the
/// union over the triangles cut by the plane z of their cut segment's u extent. Empty where the plane misses
/// the mesh. Exact for any closed mesh.
///
/// With a finite `band`, only the part of the solid within |w| <= band counts, w the other horizontal axis (x
/// for the lateral view, y for the frontal one): seen from the side, the trunk without the arms beside it.
/// The slice is clipped to the band and its chords along the band's edges are added (the sorted crossings of
/// the edge line, paired), so the spans are those of the clipped solid.
/// @param vertices   [m] (3 x #V)
/// @param triangles  vertex indices (3 x #T)
/// @param band       [m] half-width of the band, > 0; kWholeMesh for all of it
std::vector<std::pair<double, double>> silhouetteSpans(const Eigen::Matrix3Xd& vertices,
                                                       const Eigen::Matrix3Xi& triangles, SilhouetteView view,
                                                       double z, double band = kWholeMesh);

/// The outline of a silhouette: closed polylines in the view's plane.
struct SilhouetteOutline {
  SilhouetteView view = SilhouetteView::Lateral;
  double spacing = 0.0;                 ///< [m] grid cell size it was traced on
  std::vector<Eigen::Matrix2Xd> loops;  ///< [m] each a closed loop of points (u, z), last != first (2 x #P)

  /// [m] the lowest and highest u and z of all loops: (u_min, z_min, u_max, z_max); zeros when empty.
  Eigen::Vector4d bounds() const;
};

/// Traces the outline of the mesh in `view` by marching squares over rows `spacing` apart (the rows' spans
/// from silhouetteSpans(), the columns `spacing` apart too). A point of the outline on a row lies exactly on
/// a span end; a point between rows (where the outline runs across the rows: the top of the head, the
/// shoulders) is interpolated from the rows' distances to their span ends, within half a spacing in z.
/// Features thinner than `spacing` may be lost or merged. Empty for an empty mesh.
/// @param spacing [m] > 0; the grid is capped at 4 million cells (a coarser spacing is used above that)
/// @param band    [m] as in silhouetteSpans()
SilhouetteOutline silhouetteOutline(const Eigen::Matrix3Xd& vertices, const Eigen::Matrix3Xi& triangles,
                                    SilhouetteView view, double spacing, double band = kWholeMesh);

/// [m] The silhouette's extent at height `z`: highest minus lowest u of silhouetteSpans() (for the lateral
/// view the body's anteroposterior depth, front of the chest to the back), 0 where the plane misses the mesh.
double silhouetteWidth(const Eigen::Matrix3Xd& vertices, const Eigen::Matrix3Xi& triangles,
                       SilhouetteView view, double z, double band = kWholeMesh);

}  // namespace pneuma::sim
