#include "LungCavity.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "Anchors.h"
#include "pneuma/meshing/MeshTools.h"
#include "pneuma/meshing/Sweep.h"
#include "pneuma/sim/Error.h"

namespace pneuma::meshing {

namespace {

constexpr double kHullSample = 0.012;  // [m] spacing of hull points along each rib
constexpr double kGrid = 1e-9;         // [m] coordinate rounding of the cavity surface (determinism)
/// [m] rib and sternum points closer than this to the gut are left out of the cavity's hull. The dome slides
/// along the lower rib cage in every breath (the zone of apposition), so a wall vertex just above the seam
/// where the wall meets the dome would let the short wall face there fold under the dome as soon as the dome
/// rises a few millimetres relative to the ribs. Measured on the default model (crossing pairs summed over
/// every style and affect, tests/validation/Surfaces_test.cpp): 6920 with no clearance, 5441 at 8 mm, 4206
/// at 20 mm (the cavity's own: 953, 618, 290); the count is not monotonic in the clearance (12 mm: 6527).
/// The breathing figures change by under 1 %.
constexpr double kDomeClearance = 0.02;
/// [m] a wall face of the cavity that a floor (dome) vertex other than its neighbours comes closer to than
/// this grazes the dome: the dome meets the wall at a shallow angle there, so a millimetre of relative motion
/// makes the dome pass through the face. The cavity is built again without the face's bone point nearest that
/// vertex until no face grazes (two rounds on the default model, 11 of 456 hull points dropped, cavity 19 mL
/// smaller). Crossing pairs summed over every style and affect (tests/validation/Surfaces_test.cpp): 4206
/// without the rule; 1560 at 4 mm; 3 mm: calm + deep 277 against 126 at 4 mm; 5 mm: 145; 6 and 8 mm do not
/// converge (each round drops new points and the cavity shrinks by 10-25 %).
constexpr double kFaceClearance = 0.004;
constexpr int kMaxClearanceRounds = 8;  ///< rounds of the rule above before the cavity is taken as it is
/// [-] cosine of the angle above which a cavity triangle's corner makes it a sliver that flipSlivers() turns
/// over: 150 degrees. Crossing pairs, breath styles / affects (tests/validation/Surfaces_test.cpp), default
/// (male) model and female preset: 6 / 79 and 56 / 262 without the flips; at 140, 145, 150, 155, 160 degrees
/// 27 / 170 and 2 / 55, 0 / 68 and 2 / 46, 0 / 76 and 10 / 58, 0 / 57 and 13 / 92, 10 / 70 and 12 / 119.
/// Flipping only edges with a bone-bound corner (150 degrees): 0 / 63 and 46 / 189.
const double kSliverCos = std::cos(150.0 * M_PI / 180.0);
/// [-] two cavity triangles are flipped only when the cosine of the angle between their normals is at least
/// this (18 degrees): the flip moves the surface by at most a sliver's thickness times sin(18 deg). 0.9 gave
/// the same counts, 0.98 left the deep breaths' 6 crossing pairs.
constexpr double kFlipCoplanarity = 0.95;

std::array<long long, 3> gridKey(const Eigen::Vector3d& p) {
  return {std::llround(p.x() / kGrid), std::llround(p.y() / kGrid), std::llround(p.z() / kGrid)};
}

/// Barycentric coordinates of the point of triangle (a, b, c) closest to p, and its distance [m].
Eigen::Vector3d closestBarycentric(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                   const Eigen::Vector3d& b, const Eigen::Vector3d& c, double& distance) {
  // project onto the plane, then clamp to the triangle by checking the edges (Ericson 2005, 5.1.5)
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  Eigen::Vector3d w;
  const Eigen::Vector3d bp = p - b, cp = p - c;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp), d5 = ab.dot(cp), d6 = ac.dot(cp);
  const double va = d3 * d6 - d5 * d4, vb = d5 * d2 - d1 * d6, vc = d1 * d4 - d3 * d2;
  if (d1 <= 0 && d2 <= 0) {
    w = {1, 0, 0};
  } else if (d3 >= 0 && d4 <= d3) {
    w = {0, 1, 0};
  } else if (d6 >= 0 && d5 <= d6) {
    w = {0, 0, 1};
  } else if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    w = {1 - v, v, 0};
  } else if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double v = d2 / (d2 - d6);
    w = {1 - v, 0, v};
  } else if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double v = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    w = {0, 1 - v, v};
  } else {
    const double denom = 1.0 / (va + vb + vc);
    w = {va * denom, vb * denom, vc * denom};
  }
  distance = (w(0) * a + w(1) * b + w(2) * c - p).norm();
  return w;
}

// ---- the two lungs: the cavity minus the mediastinum, split at the midline

/// Proportions of the mediastinum, as fractions of the cavity's rest extent (W lateral, D anteroposterior,
/// H craniocaudal). The central block (trachea, oesophagus, great vessels, the vertebral bodies' bulge) runs
/// the cavity's full depth and height; the heart is an ellipsoid that sits on the diaphragm's central tendon,
/// left of the block's centre and anterior (adult heart about 12 x 8.5 x 6 cm). The whole mediastinum's
/// lateral offset from the cavity's midline is solved for the right/left split.
constexpr double kBlockHalfWidth = 0.075;  // [-] of W: a 3.5-4.5 cm wide central mediastinum
constexpr double kHeartHalfWidth = 0.23;   // [-] of W (lateral semi-axis, about 6 cm)
constexpr double kHeartHalfDepth = 0.24;   // [-] of D (anteroposterior semi-axis, about 4.5 cm)
constexpr double kHeartHalfHeight = 0.24;  // [-] of H (craniocaudal semi-axis, about 5.5 cm)
constexpr double kHeartCentreX = -0.08;    // [-] of W from the block's centre: to the left
constexpr double kHeartCentreY = 0.58;     // [-] of D from the back: anterior of the middle
constexpr double kHeartSink = 0.05;        // [-] of the vertical semi-axis below the floor under its centre
/// Right lung's share of the two lungs' volume: 53.5 % (upright and supine CT, Yamada et al. 2020,
/// Respiration 99:598, Table 3: standing 53.3 +/- 1.3 %, supine 53.6 +/- 1.5 %).
constexpr double kRightShare = 0.535;
constexpr double kOnSurface = 1e-7;
// // [m] a lung vertex this close to a cavity triangle lies on it

TriangleMesh box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  TriangleMesh m;
  m.vertices.resize(3, 8);
  for (int i = 0; i < 8; ++i)
    m.vertices.col(i) =
        Eigen::Vector3d((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(), (i & 4) ? hi.z() : lo.z());
  m.triangles.resize(3, 12);
  m.triangles << 0, 0, 4, 4, 0, 0, 2, 2, 0, 0, 1, 1,  //
      2, 3, 5, 7, 1, 5, 6, 7, 4, 6, 3, 7,             //
      3, 1, 7, 6, 5, 4, 7, 3, 6, 2, 7, 5;
  return m;
}

/// Ellipsoid of semi-axes `r` [m] about `c` (axes along x, y, z), as a capped sweep along z.
TriangleMesh ellipsoid(const Eigen::Vector3d& c, const Eigen::Vector3d& r) {
  std::vector<SweepStation> st;
  constexpr int kStations = 15;
  for (int i = 0; i < kStations; ++i) {
    const double u = -0.97 + 1.94 * i / (kStations - 1);
    const double f = std::sqrt(1.0 - u * u);
    st.push_back({c + Eigen::Vector3d(0, 0, u * r.z()), Eigen::Vector3d::UnitY(), f * r.y(), f * r.x()});
  }
  return sweepTube(st, 24, false);
}

/// The first point of the cavity surface hit by the ray p + t d, t > 0: its triangle, barycentric weights and
/// t [m per unit d]; false when the ray misses (Moller & Trumbore 1997).
bool rayHit(const TriangleMesh& cavity, const Eigen::Vector3d& p, const Eigen::Vector3d& d, int& face,
            Eigen::Vector3d& w, double& t) {
  t = std::numeric_limits<double>::infinity();
  for (int f = 0; f < cavity.triangleCount(); ++f) {
    const Eigen::Vector3d a = cavity.vertices.col(cavity.triangles(0, f));
    const Eigen::Vector3d e1 = cavity.vertices.col(cavity.triangles(1, f)) - a;
    const Eigen::Vector3d e2 = cavity.vertices.col(cavity.triangles(2, f)) - a;
    const Eigen::Vector3d q = d.cross(e2);
    const double det = e1.dot(q);
    if (std::abs(det) < 1e-14) continue;
    const Eigen::Vector3d s = p - a;
    const double u = s.dot(q) / det;
    const Eigen::Vector3d r = s.cross(e1);
    const double v = d.dot(r) / det;
    if (u < 0.0 || v < 0.0 || u + v > 1.0) continue;
    const double th = e2.dot(r) / det;
    if (th <= 0.0 || th >= t) continue;
    t = th;
    face = f;
    w = {1.0 - u - v, u, v};
  }
  return std::isfinite(t);
}

/// Lines through a point of the mediastinal face, in the face's plane (y-z), 180/24 = 7.5 degrees apart,
/// among which embed() picks the one whose nearer end on the cavity's walls is nearest, and binds the point
/// between its two ends: a point beside a steep wall follows that wall. Bound instead straight between the
/// walls above and below, a point in the face beside the dome's posterior notch (in front of T11-T12, the
/// floor 70 mm lower under it than 10 mm to its side) followed the lung's apex and the notch's bottom, 315 mm
/// apart, and the face crossed the notch's wall at end-expiration in four affects (16 crossing pairs; summed
/// over the affects 33 -> 19 on the default model, the female preset's unchanged). 12, 36 or 48 lines give
/// the same counts.
constexpr int kChordDirections = 24;

/// Binds each vertex of `lung` to the cavity (sim::LungSurface): a cavity vertex itself, the cavity triangle
/// it lies on, or, on the mediastinal face, the two cavity points at the ends of the chord through it that
/// meets a wall soonest (kChordDirections).
sim::LungSurface embed(const TriangleMesh& lung, const TriangleMesh& cavity, const std::string& part) {
  std::map<std::array<long long, 3>, int> cavityVertex;
  for (int v = 0; v < cavity.vertexCount(); ++v) cavityVertex.emplace(gridKey(cavity.vertices.col(v)), v);
  sim::LungSurface s;
  s.cavityVertex.setConstant(sim::kLungVertexSlots, lung.vertexCount(), -1);
  s.weights.setZero(sim::kLungVertexSlots, lung.vertexCount());
  s.triangles = lung.triangles;
  for (int v = 0; v < lung.vertexCount(); ++v) {
    const Eigen::Vector3d p = lung.vertices.col(v);
    if (auto it = cavityVertex.find(gridKey(p)); it != cavityVertex.end()) {
      s.cavityVertex(0, v) = it->second;
      s.weights(0, v) = 1.0;
      continue;
    }
    // on a cavity wall: the triangle it lies on
    double best = 1e9;
    int face = -1;
    Eigen::Vector3d w;
    for (int f = 0; f < cavity.triangleCount(); ++f) {
      double d = 0.0;
      const Eigen::Vector3i t = cavity.triangles.col(f);
      const Eigen::Vector3d wf = closestBarycentric(p, cavity.vertices.col(t(0)), cavity.vertices.col(t(1)),
                                                    cavity.vertices.col(t(2)), d);
      if (d < best) best = d, face = f, w = wf;
    }
    if (best < kOnSurface) {
      for (int k = 0; k < 3; ++k) s.cavityVertex(k, v) = cavity.triangles(k, face), s.weights(k, v) = w(k);
      continue;
    }
    // on the mediastinal face: between the two cavity points of the line through it, in the face's plane,
    // that meets a wall soonest (kChordDirections)
    int fa = -1, fb = -1;
    Eigen::Vector3d wa, wb;
    double near = std::numeric_limits<double>::infinity(), t = 0.0;
    for (int i = 0; i < kChordDirections; ++i) {
      const double phi = M_PI * i / kChordDirections;
      const Eigen::Vector3d d(0.0, std::sin(phi), std::cos(phi));
      int f0 = -1, f1 = -1;
      Eigen::Vector3d w0, w1;
      double t0 = 0.0, t1 = 0.0;
      if (!rayHit(cavity, p, d, f0, w0, t0) || !rayHit(cavity, p, -d, f1, w1, t1)) continue;
      if (std::min(t0, t1) < near - 1e-9) {
        near = std::min(t0, t1);
        fa = f0, wa = w0, fb = f1, wb = w1;
        t = t0 / (t0 + t1);  // 0 at the first point, 1 at the second
      }
    }
    if (fa < 0) throw sim::Error(part + ": vertex " + std::to_string(v) + " is not inside the lung cavity");
    for (int k = 0; k < 3; ++k) {
      s.cavityVertex(k, v) = cavity.triangles(k, fa), s.weights(k, v) = (1.0 - t) * wa(k);
      s.cavityVertex(3 + k, v) = cavity.triangles(k, fb), s.weights(3 + k, v) = t * wb(k);
    }
  }
  return s;
}

/// The connected components of `m` (triangles sharing a vertex), each as its own mesh.
std::vector<TriangleMesh> components(const TriangleMesh& m) {
  std::vector<int> parent(static_cast<std::size_t>(m.vertexCount()));
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&](int v) {
    while (parent[static_cast<std::size_t>(v)] != v)
      v = parent[static_cast<std::size_t>(v)] =
          parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(v)])];
    return v;
  };
  for (int f = 0; f < m.triangleCount(); ++f)
    for (int k = 1; k < 3; ++k)
      parent[static_cast<std::size_t>(root(m.triangles(k, f)))] = root(m.triangles(0, f));
  std::map<int, int> index;  // root -> component
  std::vector<TriangleMesh> out;
  std::vector<std::map<int, int>> local;
  for (int f = 0; f < m.triangleCount(); ++f) {
    const int r = root(m.triangles(0, f));
    auto [it, isNew] = index.emplace(r, static_cast<int>(out.size()));
    if (isNew) out.emplace_back(), local.emplace_back();
    TriangleMesh& c = out[static_cast<std::size_t>(it->second)];
    std::map<int, int>& map = local[static_cast<std::size_t>(it->second)];
    Eigen::Vector3i t;
    for (int k = 0; k < 3; ++k) {
      const int v = m.triangles(k, f);
      auto [vi, added] = map.emplace(v, static_cast<int>(map.size()));
      if (added) {
        c.vertices.conservativeResize(3, c.vertices.cols() + 1);
        c.vertices.col(c.vertices.cols() - 1) = m.vertices.col(v);
      }
      t(k) = vi->second;
    }
    c.triangles.conservativeResize(3, c.triangles.cols() + 1);
    c.triangles.col(c.triangles.cols() - 1) = t;
  }
  return out;
}

struct LungMeshes {
  TriangleMesh right, left;
  double rightFaceX = 0.0, leftFaceX = 0.0;  // [m] the central block's sides: each lung's flat medial face
};

/// True when triangle f of `lung` lies in the plane x = `faceX` [m], the lung's flat mediastinal face.
bool isOnFace(const TriangleMesh& lung, int f, double faceX) {
  for (int k = 0; k < 3; ++k)
    if (!(std::abs(lung.vertices(0, lung.triangles(k, f)) - faceX) < kOnSurface)) return false;
  return true;
}

/// Delaunay edge flips (Lawson 1977, "Software for C1 surface interpolation") of the triangles of `lung` that
/// lie in the plane x = `faceX` [m], the lung's flat face on the central mediastinal block. The corefinement
/// leaves that face as long slivers fanning across it between the points where the block's side meets the
/// cavity's walls, so a sliver's corners follow walls (ribs, sternum, dome) a hand's breadth apart and, as
/// they move, the sliver folds through its neighbours, the walls and the gut. An interior edge of the face is
/// flipped while the opposite corner of its other triangle lies strictly inside its triangle's circumcircle
/// (in the face's y-z coordinates) and the two triangles form a strictly convex quadrilateral; this ends with
/// the Delaunay triangulation of the same points, which maximises the smallest angle. No point is added or
/// moved and the face stays flat, so every volume is unchanged. Measured on the default model (crossing pairs
/// summed over every style and affect, tests/validation/Surfaces_test.cpp): 1558 before, 877 after.
void flipMediastinalFaces(TriangleMesh& lung, double faceX) {
  std::vector<char> isFlat(static_cast<std::size_t>(lung.triangleCount()), 0);
  for (int f = 0; f < lung.triangleCount(); ++f)
    isFlat[static_cast<std::size_t>(f)] = isOnFace(lung, f, faceX);
  delaunayFlips(lung.triangles, lung.vertices.bottomRows<2>(), isFlat);  // the face's y-z coordinates
}

/// The flat mediastinal face of a lung (the plane x = faceX): its triangles and its boundary edges (the
/// edges of one face triangle).
struct MediastinalFace {
  std::vector<int> flat;
  std::vector<std::pair<int, int>> boundary;
};

MediastinalFace mediastinalFace(const TriangleMesh& lung, double faceX) {
  MediastinalFace face;
  for (int f = 0; f < lung.triangleCount(); ++f)
    if (isOnFace(lung, f, faceX)) face.flat.push_back(f);
  std::map<std::pair<int, int>, int> edgeCount;
  for (const int f : face.flat)
    for (int k = 0; k < 3; ++k) {
      const int u = lung.triangles(k, f), v = lung.triangles((k + 1) % 3, f);
      ++edgeCount[{std::min(u, v), std::max(u, v)}];
    }
  for (const auto& [e, n] : edgeCount)
    if (n == 1) face.boundary.push_back(e);
  return face;
}

/// [m] distance in the face's plane (y-z) from q to the boundary of `face`.
double boundaryDistance(const TriangleMesh& lung, const MediastinalFace& face, const Eigen::Vector2d& q) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& [u, v] : face.boundary) {
    const Eigen::Vector2d p0 = lung.vertices.col(u).tail<2>(), d = lung.vertices.col(v).tail<2>() - p0;
    const double s = std::clamp((q - p0).dot(d) / d.squaredNorm(), 0.0, 1.0);
    best = std::min(best, (p0 + s * d - q).norm());
  }
  return best;
}

/// [m] spacing of the points added inside each lung's mediastinal face (addFacePoints()). Measured on the
/// default model (crossing pairs summed over every style and affect, tests/validation/Surfaces_test.cpp):
/// 669 without them; at 7, 10, 12, 15, 18, 20, 22, 25, 28, 30, 35 mm: 847, 594, 436, 227, 196, 285, 201, 177,
/// 174, 402, 257. The count depends on where the grid's points fall against the dome's slopes, so the value
/// is taken from the middle of the 22-28 mm run of low counts.
constexpr double kFacePointSpacing = 0.025;

/// Adds points on a square grid of kFacePointSpacing [m] inside the flat mediastinal face of `lung` (the
/// plane x = `faceX` [m]), each splitting the face triangle it falls in; points closer than half a spacing to
/// the face's boundary are left out. flipMediastinalFaces() then makes the face Delaunay again, and embed()
/// binds each point between the cavity's walls (kChordDirections). Without them the face is a fan of
/// slivers between points where the plane cuts walls a hand's breadth apart (the ribs behind, the dome's
/// crest below), and as the dome moves against the ribs a sliver swings through the dome; with them the
/// face's inside follows the walls around each point.
void addFacePoints(TriangleMesh& lung, double faceX) {
  const auto yz = [&](int v) { return Eigen::Vector2d(lung.vertices(1, v), lung.vertices(2, v)); };
  MediastinalFace face = mediastinalFace(lung, faceX);
  std::vector<int>& flat = face.flat;
  Eigen::Vector2d lo(1e9, 1e9), hi(-1e9, -1e9);
  for (const auto& [u, v] : face.boundary) {
    lo = lo.cwiseMin(yz(u)).cwiseMin(yz(v));
    hi = hi.cwiseMax(yz(u)).cwiseMax(yz(v));
  }
  // true when q lies strictly inside face triangle f
  const auto isInside = [&](const Eigen::Vector2d& q, int f) {
    const Eigen::Vector2d a = yz(lung.triangles(0, f)), b = yz(lung.triangles(1, f)),
                          c = yz(lung.triangles(2, f));
    const double det = (b.x() - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (b.y() - a.y());
    if (std::abs(det) < 1e-14) return false;
    const double wb = ((q.x() - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (q.y() - a.y())) / det;
    const double wc = ((b.x() - a.x()) * (q.y() - a.y()) - (q.x() - a.x()) * (b.y() - a.y())) / det;
    return std::min({wb, wc, 1.0 - wb - wc}) > 1e-6;
  };
  const double h = kFacePointSpacing;
  for (double z = std::ceil(lo.y() / h) * h; z < hi.y(); z += h)
    for (double y = std::ceil(lo.x() / h) * h; y < hi.x(); y += h) {
      const Eigen::Vector2d q(y, z);
      const auto host = std::find_if(flat.begin(), flat.end(), [&](int f) { return isInside(q, f); });
      if (host == flat.end() || boundaryDistance(lung, face, q) < 0.5 * h) continue;
      // split the host triangle (a, b, c) into (a, b, n), (b, c, n), (c, a, n)
      const int n = lung.vertexCount(), f = *host, nf = lung.triangleCount();
      lung.vertices.conservativeResize(3, n + 1);
      lung.vertices.col(n) = Eigen::Vector3d(faceX, y, z);
      const Eigen::Vector3i t = lung.triangles.col(f);
      lung.triangles.conservativeResize(3, nf + 2);
      lung.triangles.col(f) << t(0), t(1), n;
      lung.triangles.col(nf) << t(1), t(2), n;
      lung.triangles.col(nf + 1) << t(2), t(0), n;
      flat.push_back(nf);
      flat.push_back(nf + 1);
    }
}

/// [m] a triangle of the mediastinal face whose three corners all lie on the face's boundary and whose
/// longest edge is longer than this gets a point at its centroid, unless a point added so is closer than half
/// this (addBoundaryFanPoints()): about the face points' spacing, the strip addFacePoints() leaves along the
/// boundary. Measured on the default model (crossing pairs summed over the breath styles / the affects,
/// tests/validation/Surfaces_test.cpp): 16 / 127 without the points; 6 / 79 at 0.6 and 0.8 times the spacing,
/// 6 / 100 at 1.0. A point in every such triangle (no spacing between them) gave 6 / 83 at 15-30 mm, and two
/// points 0.4 mm apart made the mediastinal faces cross each other; points in the short slivers along the
/// floor (4 and 10 mm: 36 / 170 and 22 / 131) sit a fraction of a millimetre above the floor and cross it as
/// the dome moves. With the face's points bound along their shortest chords (kChordDirections), default model
/// and female preset: at 0.4, 0.5, 0.55-0.7, 0.8, 1.0 times the spacing 0 / 29 and 0 / 45, 0 / 18 and 7 / 45,
/// 0 / 18-19 and 0 / 45, 0 / 19 and 8 / 53, 0 / 17 and 8 / 53; no points: 0 / 17 and 54 / 58. 0.6 is the
/// middle of the run that leaves both presets' styles uncrossed (an ear of 22 mm on the female's right face
/// behind the xiphoid turned over at the deep breaths' end-inspiration at 0.8).
constexpr double kFanEdge = 0.6 * kFacePointSpacing;

/// Splits, at its centroid, every triangle of the flat mediastinal face of `lung` (the plane x = `faceX` [m])
/// whose three corners lie on the face's boundary and whose longest edge exceeds kFanEdge, then makes the
/// face Delaunay again (flipMediastinalFaces()), until none is left (at most a few rounds). Where the face
/// meets the dome beside the vertebral bodies, a strip narrower than addFacePoints()'s margin is left as a
/// fan of slivers between points on the floor: three points on a curve that bends as the dome descends, so a
/// sliver turns over through its neighbours, the floor and the gut at deep end-inspirations. A centroid is
/// bound between the cavity's walls (embed()) and holds each half of the fan off the floor.
void addBoundaryFanPoints(TriangleMesh& lung, double faceX) {
  const int firstAdded = lung.vertexCount();
  for (int round = 0; round < 4; ++round) {
    const MediastinalFace face = mediastinalFace(lung, faceX);
    std::vector<char> onBoundary(static_cast<std::size_t>(lung.vertexCount()), 0);
    for (const auto& [u, v] : face.boundary)
      onBoundary[static_cast<std::size_t>(u)] = onBoundary[static_cast<std::size_t>(v)] = 1;
    int added = 0;
    for (const int f : face.flat) {
      const Eigen::Vector3i t = lung.triangles.col(f);
      double longest = 0.0;
      bool allBoundary = true;
      for (int k = 0; k < 3; ++k) {
        allBoundary = allBoundary && onBoundary[static_cast<std::size_t>(t(k))];
        longest = std::max(longest, (lung.vertices.col(t(k)) - lung.vertices.col(t((k + 1) % 3))).norm());
      }
      const Eigen::Vector3d c =
          (lung.vertices.col(t(0)) + lung.vertices.col(t(1)) + lung.vertices.col(t(2))) / 3.0;
      if (!allBoundary || longest <= kFanEdge) continue;
      // one point per fan: none within half a fan edge of a point added before
      bool crowded = false;
      for (int v = firstAdded; v < lung.vertexCount(); ++v)
        crowded = crowded || (lung.vertices.col(v) - c).norm() < 0.5 * kFanEdge;
      if (crowded) continue;
      const int n = lung.vertexCount(), nf = lung.triangleCount();
      lung.vertices.conservativeResize(3, n + 1);
      lung.vertices.col(n) = Eigen::Vector3d(faceX, c.y(), c.z());
      lung.triangles.conservativeResize(3, nf + 2);
      lung.triangles.col(f) << t(0), t(1), n;
      lung.triangles.col(nf) << t(1), t(2), n;
      lung.triangles.col(nf + 1) << t(2), t(0), n;
      ++added;
    }
    if (added == 0) return;
    flipMediastinalFaces(lung, faceX);
  }
}

/// The cavity minus the mediastinum shifted `shift` [m] from the cavity's midline (x > 0: right).
LungMeshes carveLungs(const TriangleMesh& cavity, double shift) {
  const Eigen::Vector3d lo = cavity.vertices.rowwise().minCoeff(), hi = cavity.vertices.rowwise().maxCoeff();
  const Eigen::Vector3d size = hi - lo,
                        pad(0.0, 0.02, 0.02);  // [m] the block overhangs front, back, top, bottom
  const double midX = 0.5 * (lo.x() + hi.x()) + shift;
  const TriangleMesh block = box(Eigen::Vector3d(midX - kBlockHalfWidth * size.x(), lo.y(), lo.z()) - pad,
                                 Eigen::Vector3d(midX + kBlockHalfWidth * size.x(), hi.y(), hi.z()) + pad);
  // the heart rests on the floor under its centre
  const Eigen::Vector3d r(kHeartHalfWidth * size.x(), kHeartHalfDepth * size.y(),
                          kHeartHalfHeight * size.z());
  Eigen::Vector3d c(midX + kHeartCentreX * size.x(), lo.y() + kHeartCentreY * size.y(), hi.z());
  int face = -1;
  Eigen::Vector3d w;
  double depth = 0.0;  // [m] from the cavity's top down to its floor under the heart's centre
  if (!rayHit(cavity, c, -Eigen::Vector3d::UnitZ(), face, w, depth))
    throw sim::Error("lungs: no cavity floor under the heart");
  c.z() += -depth + (1.0 - kHeartSink) * r.z();
  const TriangleMesh carved = subtract(subtract(cavity, block, kGrid, "lungs (central mediastinum)"),
                                       ellipsoid(c, r), kGrid, "lungs (heart)");
  // each component to the side of its centroid; the right lung lies at x > 0 (world RAS)
  LungMeshes out;
  out.rightFaceX = midX + kBlockHalfWidth * size.x();
  out.leftFaceX = midX - kBlockHalfWidth * size.x();
  for (const TriangleMesh& part : components(carved)) {
    const double v = enclosedVolume(part.vertices, part.triangles);
    if (v < 1e-6) continue;  // slivers below 1 mL the cut leaves at the block's edges
    TriangleMesh& side = part.vertices.row(0).mean() > midX ? out.right : out.left;  // the block splits them
    side.append(part);
  }
  return out;
}

/// The hull points to drop so that no wall face of `cavity` grazes the dome (kFaceClearance): for each wall
/// face (one with a bone-bound vertex) and each floor vertex closer to it than kFaceClearance that shares no
/// face with its corners, the face's bone point nearest that vertex. bonePoint[v] is cavity vertex v's hull
/// point, -1 for a floor vertex; the result is a flag per hull point (of `pointCount`).
std::vector<char> grazingPoints(const TriangleMesh& cavity, const std::vector<int>& bonePoint,
                                std::size_t pointCount) {
  const auto at = [](int i) { return static_cast<std::size_t>(i); };
  // the vertices sharing a face with each vertex
  std::vector<std::vector<int>> ring(at(cavity.vertexCount()));
  for (int f = 0; f < cavity.triangleCount(); ++f)
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 3; ++j) ring[at(cavity.triangles(k, f))].push_back(cavity.triangles(j, f));
  std::vector<char> drop(pointCount, 0);
  for (int f = 0; f < cavity.triangleCount(); ++f) {
    const Eigen::Vector3i t = cavity.triangles.col(f);
    if (bonePoint[at(t(0))] < 0 && bonePoint[at(t(1))] < 0 && bonePoint[at(t(2))] < 0) continue;
    for (int v = 0; v < cavity.vertexCount(); ++v) {
      if (bonePoint[at(v)] >= 0) continue;
      bool neighbour = false;
      for (int k = 0; k < 3; ++k)
        neighbour = neighbour || std::count(ring[at(t(k))].begin(), ring[at(t(k))].end(), v) > 0;
      if (neighbour) continue;
      double d = 0.0;
      closestBarycentric(cavity.vertices.col(v), cavity.vertices.col(t(0)), cavity.vertices.col(t(1)),
                         cavity.vertices.col(t(2)), d);
      if (d >= kFaceClearance) continue;
      int nearest = -1;
      double best = std::numeric_limits<double>::infinity();
      for (int k = 0; k < 3; ++k) {
        const double e = (cavity.vertices.col(t(k)) - cavity.vertices.col(v)).norm();
        if (bonePoint[at(t(k))] >= 0 && e < best) best = e, nearest = bonePoint[at(t(k))];
      }
      drop[at(nearest)] = 1;
    }
  }
  return drop;
}

/// Turns over the slivers of `cavity`: an edge whose two triangles are nearly coplanar (kFlipCoplanarity) and
/// whose opposite corners' angles sum to more than 180 degrees, one of them wider than the sliver angle
/// (kSliverCos), is flipped to the other diagonal of its quadrilateral when that quadrilateral is strictly
/// convex and the new edge is not already in the mesh (Lawson 1977 flips, only for slivers), until none is
/// left (at most a few rounds). The subtraction of the gut from the hull leaves slivers along the seam where
/// the wall meets the dome (a hull face cut a few millimetres from its corner) and on the floor between
/// points where hull edges cross gut triangles; their corners are bound to different gut triangles or to a
/// rib and the gut, so when the dome descends a sliver twists through its wide neighbour (the cavity's
/// adjacent faces are not checked against each other) and the lung faces embedded on it cross that neighbour.
/// On the default model a 10 mm sliver on the floor beside the spine (two seam vertices and a right rib
/// point) turned over under the 235 mm back-wall face next to it at the deep breaths' end-inspiration, and
/// the right lung's mediastinal face crossed the wall there. No vertex is added or moved; the default
/// model's cavity loses 3.4 mL of 5608 mL (the female preset's 2.4 of 4089). Returns the number of flips.
int flipSlivers(TriangleMesh& cavity) {
  const auto at = [](int i) { return static_cast<std::size_t>(i); };
  const auto angle = [](const Eigen::Vector3d& o, const Eigen::Vector3d& x, const Eigen::Vector3d& y) {
    return std::acos(std::clamp((x - o).normalized().dot((y - o).normalized()), -1.0, 1.0));
  };
  int flips = 0;
  for (int round = 0; round < 10; ++round) {
    // each edge's triangles, with the corner opposite the edge
    std::map<std::pair<int, int>, std::vector<std::pair<int, int>>> edges;
    for (int f = 0; f < cavity.triangleCount(); ++f)
      for (int k = 0; k < 3; ++k) {
        const int u = cavity.triangles(k, f), v = cavity.triangles((k + 1) % 3, f);
        edges[{std::min(u, v), std::max(u, v)}].push_back({f, (k + 2) % 3});
      }
    std::vector<char> touched(at(cavity.triangleCount()), 0);
    int n = 0;
    for (const auto& [e, faces] : edges) {
      if (faces.size() != 2) continue;
      const auto [f0, k0] = faces[0];
      const auto [f1, k1] = faces[1];
      if (touched[at(f0)] || touched[at(f1)]) continue;
      // f0 = (a, x, y), f1 = (b, y, x): the quadrilateral a, x, b, y
      const int a = cavity.triangles(k0, f0), b = cavity.triangles(k1, f1);
      const int x = cavity.triangles((k0 + 1) % 3, f0), y = cavity.triangles((k0 + 2) % 3, f0);
      const Eigen::Vector3d pa = cavity.vertices.col(a), pb = cavity.vertices.col(b),
                            px = cavity.vertices.col(x), py = cavity.vertices.col(y);
      const double alpha = angle(pa, px, py), beta = angle(pb, px, py);
      if (std::cos(std::max(alpha, beta)) > kSliverCos || alpha + beta < M_PI + 1e-3) continue;
      const Eigen::Vector3d n0 = (px - pa).cross(py - pa), n1 = (py - pb).cross(px - pb);
      if (n0.normalized().dot(n1.normalized()) < kFlipCoplanarity) continue;
      // strictly convex: both new triangles keep the old orientation
      if ((px - pa).cross(pb - pa).dot(n0) <= 0.0 || (pb - pa).cross(py - pa).dot(n0) <= 0.0) continue;
      if (edges.count({std::min(a, b), std::max(a, b)}) > 0) continue;
      cavity.triangles.col(f0) << a, x, b;
      cavity.triangles.col(f1) << a, b, y;
      edges[{std::min(a, b), std::max(a, b)}];  // the new edge, so that no other flip makes it again
      touched[at(f0)] = touched[at(f1)] = 1;
      ++n;
    }
    flips += n;
    if (n == 0) break;
  }
  return flips;
}

}  // namespace

void buildLungs(const TriangleMesh& cavity, sim::Model& model) {
  // solve the mediastinum's lateral offset for the right lung's share (secant; the share falls as it moves
  // right)
  const double width = cavity.vertices.row(0).maxCoeff() - cavity.vertices.row(0).minCoeff();
  auto share = [&](const LungMeshes& l) {
    const double r = enclosedVolume(l.right.vertices, l.right.triangles);
    return r / (r + enclosedVolume(l.left.vertices, l.left.triangles));
  };
  double x0 = 0.0, x1 = -0.04 * width;
  LungMeshes l0 = carveLungs(cavity, x0), l1 = carveLungs(cavity, x1);
  double s0 = share(l0), s1 = share(l1);
  for (int i = 0; i < 6 && std::abs(s1 - kRightShare) > 1e-3 && std::abs(s1 - s0) > 1e-9; ++i) {
    const double x2 = x1 + (kRightShare - s1) * (x1 - x0) / (s1 - s0);
    x0 = x1, s0 = s1, l0 = std::move(l1);
    x1 = std::clamp(x2, -0.15 * width, 0.15 * width);
    l1 = carveLungs(cavity, x1);
    s1 = share(l1);
  }
  if (l1.right.triangleCount() == 0 || l1.left.triangleCount() == 0)
    throw sim::Error("lungs: the mediastinum does not leave a right and a left lung");

  addFacePoints(l1.right, l1.rightFaceX);
  addFacePoints(l1.left, l1.leftFaceX);
  flipMediastinalFaces(l1.right, l1.rightFaceX);
  flipMediastinalFaces(l1.left, l1.leftFaceX);
  addBoundaryFanPoints(l1.right, l1.rightFaceX);
  addBoundaryFanPoints(l1.left, l1.leftFaceX);

  sim::Lungs& lungs = model.lungs;
  lungs.right = embed(l1.right, cavity, "lungs.right");
  lungs.left = embed(l1.left, cavity, "lungs.left");
  lungs.mediastinumVolume = enclosedVolume(cavity.vertices, cavity.triangles) -
                            enclosedVolume(l1.right.vertices, l1.right.triangles) -
                            enclosedVolume(l1.left.vertices, l1.left.triangles);
}

double buildCavity(const Skeleton& sk, const GutSurface& gut, sim::Model& model) {
  // hull points on the inner faces of the moving ribs and on the back of the sternum
  std::vector<Endpoint> pts;
  for (int level = 1; level <= 10; ++level) {
    for (int side : {kRight, kLeft}) {
      const RibCurve& r = sk.ribCurve[static_cast<std::size_t>(level - 1)][static_cast<std::size_t>(side)];
      const int b = sk.rib[static_cast<std::size_t>(level - 1)][static_cast<std::size_t>(side)];
      for (double s = 0.0; s <= r.length(); s += kHullSample) {
        pts.push_back(Endpoint::onBody(b, r.at(s, 0.5 * r.thickness)));
      }
      pts.push_back(Endpoint::onBody(b, r.at(r.length(), 0.5 * r.thickness)));
    }
  }
  for (const Eigen::Vector3d& p : sk.sternumInner) pts.push_back(Endpoint::onBody(sk.sternum, p));
  // keep the wall clear of the dome (kDomeClearance)
  auto gutDistance = [&](const Eigen::Vector3d& p) {
    double best = std::numeric_limits<double>::infinity();
    for (int f = 0; f < gut.triangles.cols(); ++f) {
      const Eigen::Vector3i t = gut.triangles.col(f);
      double d = 0.0;
      closestBarycentric(p, gut.rest.col(t(0)), gut.rest.col(t(1)), gut.rest.col(t(2)), d);
      best = std::min(best, d);
    }
    return best;
  };
  pts.erase(std::remove_if(pts.begin(), pts.end(),
                           [&](const Endpoint& e) { return gutDistance(e.world) < kDomeClearance; }),
            pts.end());
  TriangleMesh gutMesh;
  gutMesh.vertices = gut.rest;
  gutMesh.triangles = gut.triangles;
  // hull minus gut: the diaphragm dome becomes the floor. A wall face that a floor vertex (not its own)
  // comes within kFaceClearance of grazes the dome: drop the bone point of that face nearest the vertex and
  // build again.
  TriangleMesh cavity;
  std::vector<int> bonePoint;  // per cavity vertex: its hull point in pts, -1 for a floor vertex
  for (int round = 0;; ++round) {
    Eigen::Matrix3Xd hullInput(3, static_cast<Eigen::Index>(pts.size()));
    for (std::size_t i = 0; i < pts.size(); ++i) hullInput.col(static_cast<Eigen::Index>(i)) = pts[i].world;
    std::vector<int> source;
    const TriangleMesh hull = convexHull(hullInput, source);
    std::map<std::array<long long, 3>, int> hullVertex;
    for (int v = 0; v < hull.vertexCount(); ++v)
      hullVertex.emplace(gridKey(hull.vertices.col(v)), source[static_cast<std::size_t>(v)]);
    cavity = subtract(hull, gutMesh, kGrid, "lung cavity");
    bonePoint.assign(static_cast<std::size_t>(cavity.vertexCount()), -1);
    for (int v = 0; v < cavity.vertexCount(); ++v)
      if (auto it = hullVertex.find(gridKey(cavity.vertices.col(v))); it != hullVertex.end())
        bonePoint[static_cast<std::size_t>(v)] = it->second;
    const std::vector<char> drop = grazingPoints(cavity, bonePoint, pts.size());
    const auto dropped = std::count(drop.begin(), drop.end(), 1);
    if (dropped == 0 || round == kMaxClearanceRounds) break;
    std::vector<Endpoint> kept;
    for (std::size_t i = 0; i < pts.size(); ++i)
      if (!drop[i]) kept.push_back(pts[i]);
    pts = std::move(kept);
  }

  // turn over the slivers the subtraction leaves (the triangles only: every vertex keeps its binding)
  flipSlivers(cavity);
  // bind every cavity vertex: hull corners to their bone, the rest to the gut triangle it lies on
  sim::Cavity& c = model.cavity;
  c = sim::Cavity{};
  for (int v = 0; v < cavity.vertexCount(); ++v) {
    const Eigen::Vector3d p = cavity.vertices.col(v);
    if (const int b = bonePoint[static_cast<std::size_t>(v)]; b >= 0) {
      addEndpoint(c.vertices, pts[static_cast<std::size_t>(b)], model.bodies);
      continue;
    }
    double best = 1e9;
    Endpoint e;
    for (int f = 0; f < gut.triangles.cols(); ++f) {
      double d = 0.0;
      const Eigen::Vector3i t = gut.triangles.col(f);
      const Eigen::Vector3d w =
          closestBarycentric(p, gut.rest.col(t(0)), gut.rest.col(t(1)), gut.rest.col(t(2)), d);
      if (d < best) {
        best = d;
        e = Endpoint{-1, p, t, w};
      }
    }
    addEndpoint(c.vertices, e, model.bodies);
  }
  c.triangles = cavity.triangles;
  buildLungs(cavity, model);
  return enclosedVolume(cavity.vertices, cavity.triangles);
}

}  // namespace pneuma::meshing
