#include "Skin.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <queue>
#include <sstream>
#include <unordered_map>
#include <vector>

#include "SkinSource.h"
#include "pneuma/meshing/MeshTools.h"
#include "pneuma/meshing/ModelSummary.h"
#include "pneuma/meshing/Tetrahedralizer.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/Ties.h"

namespace pneuma::meshing {

namespace {

// soft-tissue depth from a bone landmark out to the skin [m] (adult, lean to average; CT soft-tissue depths
// over the sternum, iliac spines and acromion are 5-20 mm, the abdominal wall 20-30 mm over the peritoneum)
constexpr double kDepthSternum = 0.012;
constexpr double kDepthAbdomen = 0.025;
constexpr double kDepthRibLateral = 0.020;
constexpr double kDepthAsis = 0.015;
constexpr double kDepthAcromion = 0.015;
constexpr double kDepthSpine = 0.012;
constexpr double kDepthScalp = 0.008;     // [m] scalp over the vertex of the skull
constexpr double kDepthClavicle = 0.012;  // [m] skin and platysma over the clavicle's shaft
constexpr double kBoneClearance = 0.006;  // [m] least distance from skin to bone after registration
constexpr double kGutClearance = 0.010;   // [m] least distance from skin to the gut surface
// [m] least distance from skin to a volume body's surface (pectorals, shoulders): the skin and the thin
// subcutaneous fat over the muscle
constexpr double kTissueClearance = 0.004;
// the skin over the muscles from the neck to the shoulder girdle (liftOverNeckMuscles()): the least distance
// from skin to a muscle's line [m] (the skin and fat of the neck, and room for the shoulders' rise: at 4 mm
// the C4-acromion line was 8.5 mm outside at a deep breath's end), how far from a vertex's normal a line may
// pass to lift it [m], how far out along the normal it may lie [m], and the passes that spread the lifts over
// the neighbours
constexpr double kNeckMuscleClearance = 0.008;
constexpr double kNeckMuscleRadius = 0.012;
constexpr double kNeckMuscleReach = 0.03;
constexpr int kNeckLiftPasses = 6;
// [-] the share of a muscle's line from the neck beyond which it lifts nothing: its lateral end runs into the
// shoulder under the deltoid volume body, which the skin already covers
constexpr double kNeckMuscleLateralEnd = 0.8;
constexpr double kThighCut = 0.10;       // [m] legs cut this far below the crotch
constexpr double kPerineumDepth = 0.07;  // [m] crotch (perineum) below the pelvic floor
constexpr double kThighCutSlack = 0.03;  // [m] a surface ending less than this below the cut is not cut again
constexpr double kAnchorSpacing = 0.012;  // [m] one bone-surface anchor per cell of this size
// [m] a skin vertex takes all of its anchors' motion within kFollowNear of them through the tissue, none
// beyond kFollowFar (linear between): the soft tissue over the chest and belly (10-60 mm) moves with them, a
// head or a hand with no bone of its own stays still instead of being dragged by a rib it hangs near
constexpr double kFollowNear = 0.06;
constexpr double kFollowFar = 0.12;
constexpr double kAcromionToRib8 = 1.4;  // [-] acromion half-breadth / rib-8 lateral half-breadth
// smoothing of the skin's binding weights over the surface (each pass averages a vertex with its ring): 60
// passes spread a seam between vertices bound to different structures (ribs, sternum, dome, wall, the still
// spine) over about sqrt(60 / 2) = 5.5 rings (5-6 cm), so that neighbouring triangles do not turn against
// each other when the view magnifies the motion 5x (tests/sim/SkinCreases_test.cpp: a calm breath at 5x, 99th
// percentile of the fold-angle change 27 deg and 16 self-crossings, against 48 deg and 66 with 10 passes)
constexpr int kBindingSmoothingPasses = 60;
// the upper trapezius carries the skin of the shoulders' top and the upper back: its fibres run from the neck
// and the upper thoracic spinous processes (still) to the clavicle's lateral third, the acromion and the
// scapular spine (moving with the girdle), so a point of it moves with the girdle by its share of the way
// from the neck to the acromion (trapeziusShare()). Bound to the girdle as a whole, the skin over the
// shoulders' top rose with it by the acromion's full lift up to the neck's side: a deep breath's shrug added
// 330 mL to the body's volume (the skin's enclosed volume 1.24 times the lungs' change, male; 1.21 female;
// the tissue is incompressible: 1). Measured (tests/validation/Skin_test.cpp on the girdle models): 1.03 with
// the values below (male and female); 1.07 with the lower edge 6 cm below the acromion instead of 12
constexpr double kTrapeziusNeck = 0.3;  // [-] share of the way from the neck's axis to the acromion where the
                                        // fibres leave the neck (its side: about 55 of 185 mm)
constexpr double kTrapeziusReach =
    0.66;  // [-] the region's lower edge below the acromion, of its half-breadth
           // (12 cm male: about T4, where the transverse fibres end)
constexpr double kTrapeziusBlend = 0.03;  // [m] the lower edge's blend upward into the region
constexpr int kSlabs = 240;               // horizontal sections of the source mesh

using Points = std::vector<Eigen::Vector3d>;

[[noreturn]] void fail(const std::string& file, const std::string& what) {
  throw sim::Error(file + ": " + what);
}

// ---------------------------------------------------------------------------------------------
// sections of the source mesh

/// The central piece of one horizontal section of the surface: the section's segments whose x-intervals join
/// up (gaps below `gap`) into the interval round the midline x0 (the torso and head; the arms are apart).
struct Section {
  bool isMidlineEmpty = true;  // the midline falls between pieces (between the legs) or the plane misses
  double xMin = 0, xMax = 0;
  Points points;  // segment ends of the central piece
};

Section centralPiece(const std::vector<std::array<Eigen::Vector3d, 2>>& segments, double x0, double gap) {
  Section s;
  if (segments.empty()) return s;
  // merge the segments' x-intervals
  std::vector<std::pair<double, double>> iv;
  for (const auto& g : segments) iv.emplace_back(std::min(g[0].x(), g[1].x()), std::max(g[0].x(), g[1].x()));
  std::sort(iv.begin(), iv.end());
  std::vector<std::pair<double, double>> merged{iv.front()};
  for (const auto& i : iv) {
    if (i.first <= merged.back().second + gap)
      merged.back().second = std::max(merged.back().second, i.second);
    else
      merged.push_back(i);
  }
  // the interval holding the midline, else the nearest one
  std::size_t best = 0;
  auto distance = [&](const std::pair<double, double>& i) {
    return x0 < i.first ? i.first - x0 : x0 > i.second ? x0 - i.second : 0.0;
  };
  for (std::size_t k = 0; k < merged.size(); ++k)
    if (distance(merged[k]) < distance(merged[best])) best = k;
  s.xMin = merged[best].first;
  s.xMax = merged[best].second;
  s.isMidlineEmpty = distance(merged[best]) > 0.0;
  for (const auto& g : segments)
    for (const auto& p : g)
      if (p.x() >= s.xMin - 1e-12 && p.x() <= s.xMax + 1e-12) s.points.push_back(p);
  return s;
}

// ---------------------------------------------------------------------------------------------
// thin-plate spline in 3-D: f(x) = A x + b + sum_i w_i |x - c_i|

struct ThinPlateSpline {
  Points centre;
  Eigen::MatrixXd w;  // (n + 4) x 3: kernel weights, then the affine part (1, x, y, z)

  ThinPlateSpline(const Points& from, const Points& to) : centre(from) {
    const int n = static_cast<int>(from.size());
    Eigen::MatrixXd L = Eigen::MatrixXd::Zero(n + 4, n + 4);
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n + 4, 3);
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j)
        L(i, j) = (from[static_cast<std::size_t>(i)] - from[static_cast<std::size_t>(j)]).norm();
      L(i, n) = L(n, i) = 1.0;
      for (int k = 0; k < 3; ++k) L(i, n + 1 + k) = L(n + 1 + k, i) = from[static_cast<std::size_t>(i)][k];
      rhs.row(i) = to[static_cast<std::size_t>(i)].transpose();
    }
    w = L.fullPivLu().solve(rhs);
  }
  Eigen::Vector3d operator()(const Eigen::Vector3d& x) const {
    const int n = static_cast<int>(centre.size());
    Eigen::Vector3d y = w.row(n).transpose() + w.block(n + 1, 0, 3, 3).transpose() * x;
    for (int i = 0; i < n; ++i) y += w.row(i).transpose() * (x - centre[static_cast<std::size_t>(i)]).norm();
    return y;
  }
};

// ---------------------------------------------------------------------------------------------
// nearest point among many: a uniform grid

class PointGrid {
 public:
  PointGrid(const Points& p, double cell) : m_points(p), m_cell(cell) {
    for (std::size_t i = 0; i < p.size(); ++i) m_cells[key(p[i])].push_back(static_cast<int>(i));
  }
  /// Index of the nearest point within `radius`, or -1.
  int nearest(const Eigen::Vector3d& x, double radius) const {
    const int r = static_cast<int>(std::ceil(radius / m_cell));
    const auto c = cellOf(x);
    int best = -1;
    double bestD = radius * radius;
    for (int i = -r; i <= r; ++i)
      for (int j = -r; j <= r; ++j)
        for (int k = -r; k <= r; ++k) {
          auto it = m_cells.find(pack(c[0] + i, c[1] + j, c[2] + k));
          if (it == m_cells.end()) continue;
          for (int q : it->second) {
            const double d = (m_points[static_cast<std::size_t>(q)] - x).squaredNorm();
            if (d < bestD) {
              bestD = d;
              best = q;
            }
          }
        }
    return best;
  }

 private:
  std::array<long long, 3> cellOf(const Eigen::Vector3d& x) const {
    return {static_cast<long long>(std::floor(x.x() / m_cell)),
            static_cast<long long>(std::floor(x.y() / m_cell)),
            static_cast<long long>(std::floor(x.z() / m_cell))};
  }
  static long long pack(long long i, long long j, long long k) {
    return ((i + (1 << 20)) << 42) | ((j + (1 << 20)) << 21) | (k + (1 << 20));
  }
  long long key(const Eigen::Vector3d& x) const {
    const auto c = cellOf(x);
    return pack(c[0], c[1], c[2]);
  }
  Points m_points;
  double m_cell;
  std::unordered_map<long long, std::vector<int>> m_cells;
};

/// Distance from p to the triangle (a, b, c) [m] (Ericson 2005, "Real-Time Collision Detection", 5.1.5).
double pointTriangleDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                             const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return ap.norm();
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return bp.norm();
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return (p - (a + d1 / (d1 - d3) * ab)).norm();
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return cp.norm();
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return (p - (a + d2 / (d2 - d6) * ac)).norm();
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return (p - (b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b))).norm();
  const double denom = 1.0 / (va + vb + vc);
  return (p - (a + ab * (vb * denom) + ac * (vc * denom))).norm();
}

/// Area-weighted vertex normals of a closed outward mesh.
Eigen::Matrix3Xd vertexNormals(const Eigen::Matrix3Xd& v, const Eigen::Matrix3Xi& t) {
  Eigen::Matrix3Xd n = Eigen::Matrix3Xd::Zero(3, v.cols());
  for (int f = 0; f < t.cols(); ++f) {
    const Eigen::Vector3d a = (v.col(t(1, f)) - v.col(t(0, f))).cross(v.col(t(2, f)) - v.col(t(0, f)));
    for (int k = 0; k < 3; ++k) n.col(t(k, f)) += a;
  }
  for (int i = 0; i < n.cols(); ++i) n.col(i).normalize();
  return n;
}

/// Neighbour lists of the vertices of a triangle mesh.
std::vector<std::vector<int>> neighbours(int nV, const Eigen::Matrix3Xi& t) {
  std::vector<std::vector<int>> nb(static_cast<std::size_t>(nV));
  for (int f = 0; f < t.cols(); ++f)
    for (int k = 0; k < 3; ++k) {
      nb[static_cast<std::size_t>(t(k, f))].push_back(t((k + 1) % 3, f));
      nb[static_cast<std::size_t>(t(k, f))].push_back(t((k + 2) % 3, f));
    }
  for (auto& n : nb) {
    std::sort(n.begin(), n.end());
    n.erase(std::unique(n.begin(), n.end()), n.end());
  }
  return nb;
}

// ---------------------------------------------------------------------------------------------
// the model's landmarks for the skin (world, rest) [m]

struct Landmark {
  std::string name;
  Eigen::Vector3d bone;  // on the skeleton or the gut
  Eigen::Vector3d skin;  // bone + soft-tissue depth outward
};

std::vector<Landmark> modelLandmarks(const AnatomyParams& a, const BuiltModel& built, double& crotchZ) {
  const sim::Model& m = built.model;
  const Eigen::Matrix3Xd lm = restPoints(m.landmarks.points, m);
  auto at = [&](const char* n) { return Eigen::Vector3d(lm.col(m.landmarks.find(n))); };
  std::vector<Landmark> out;
  auto add = [&](const std::string& n, const Eigen::Vector3d& p, const Eigen::Vector3d& depth) {
    out.push_back({n, p, p + depth});
  };
  const Eigen::Vector3d jugular = at("jugular_notch"), r8r = at("rib8_lateral_right"),
                        r8l = at("rib8_lateral_left");
  add("jugular_notch", jugular, {0, kDepthSternum, 0});
  add("xiphoid", at("xiphoid"), {0, kDepthSternum, 0});
  add("umbilicus", at("umbilicus"), {0, kDepthAbdomen, 0});
  add("rib8_lateral_right", r8r, {kDepthRibLateral, 0, 0});
  add("rib8_lateral_left", r8l, {-kDepthRibLateral, 0, 0});

  // bone surfaces in world
  auto worldMesh = [&](int b) {
    return Eigen::Matrix3Xd(built.bodyMeshes[static_cast<std::size_t>(b)].vertices.colwise() +
                            m.bodies.com.col(b));
  };
  auto bodyNamed = [&](const std::string& n) {
    for (int b = 0; b < m.bodies.size(); ++b)
      if (m.bodies.name[static_cast<std::size_t>(b)] == n) return b;
    return -1;
  };
  // anterior superior iliac spines: the pelvis's most anterior point on each side
  const int pelvis = bodyNamed("pelvis");
  if (pelvis < 0) throw sim::Error("skin: the model has no body 'pelvis'");
  const Eigen::Matrix3Xd pv = worldMesh(pelvis);
  for (int side : {1, -1}) {
    int best = -1;
    for (int i = 0; i < pv.cols(); ++i)
      if (side * pv(0, i) > 0.02 && pv(2, i) > a.abdomen.floorLevel + 0.04 &&
          (best < 0 || pv(1, i) > pv(1, best)))
        best = i;
    add(side > 0 ? "asis_right" : "asis_left", pv.col(best), {0, kDepthAsis, 0});
  }
  // acromions: a scapula's most superolateral point when the model has one, else set out from rib 8
  for (int side : {1, -1}) {
    const int scapula = bodyNamed(side > 0 ? "scapula_right" : "scapula_left");
    Eigen::Vector3d p;
    if (scapula >= 0) {
      const Eigen::Matrix3Xd sv = worldMesh(scapula);
      int best = 0;
      for (int i = 0; i < sv.cols(); ++i)
        if (side * sv(0, i) + sv(2, i) > side * sv(0, best) + sv(2, best)) best = i;
      p = sv.col(best);
    } else {
      p = Eigen::Vector3d(kAcromionToRib8 * (side > 0 ? r8r.x() : r8l.x()), jugular.y() - 0.05,
                          jugular.z() + 0.01);
    }
    add(side > 0 ? "acromion_right" : "acromion_left", p, {0, 0, kDepthAcromion});
  }
  // spine: the most posterior bone point on the midline at the xiphoid's and the umbilicus's levels (and the
  // jugular notch's, under the shoulder girdle)
  std::vector<const char*> levels = {"xiphoid", "umbilicus"};
  if (bodyNamed("clavicle_right") >= 0) levels.push_back("jugular_notch");
  for (const char* level : levels) {
    const double z = at(level).z();
    Eigen::Vector3d best(0, 1e9, 0);
    for (int b = 0; b < m.bodies.size(); ++b) {
      const Eigen::Matrix3Xd bv = worldMesh(b);
      for (int i = 0; i < bv.cols(); ++i)
        if (std::abs(bv(0, i)) < 0.02 && std::abs(bv(2, i) - z) < 0.015 && bv(1, i) < best.y())
          best = bv.col(i);
    }
    if (best.y() > 1e8) throw sim::Error(std::string("skin: no spine behind the ") + level);
    add(std::string("spine_at_") + level, best, {0, -kDepthSpine, 0});
  }
  // the arms (a model with a shoulder girdle): elbow and wrist joint centres and the fingertips, matched with
  // the centreline of the source's arms; the top of the head
  for (int side : {1, -1}) {
    const std::string n = side > 0 ? "_right" : "_left";
    const int forearm = bodyNamed("forearm" + n);
    int elbowJoint = -1;
    for (int j = 0; j < m.joints.size(); ++j)
      if (m.joints.name[static_cast<std::size_t>(j)] == "elbow" + n) elbowJoint = j;
    if (forearm < 0 || elbowJoint < 0) continue;
    const Eigen::Vector3d elbow = m.joints.anchor.col(elbowJoint);
    const Eigen::Matrix3Xd fv = worldMesh(forearm);
    Eigen::Index tip = 0;
    (fv.colwise() - elbow).colwise().squaredNorm().maxCoeff(&tip);
    const Eigen::Vector3d along = (fv.col(tip) - elbow).normalized();
    add("elbow" + n, elbow, Eigen::Vector3d::Zero());
    add("wrist" + n, elbow + a.girdle.forearmLength * along, Eigen::Vector3d::Zero());
    add("fingertip" + n, elbow + (a.girdle.forearmLength + a.girdle.handLength) * along,
        Eigen::Vector3d::Zero());
  }
  // the clavicles' middles, under the skin of the upper chest
  for (int side : {1, -1}) {
    const int clavicle = bodyNamed(side > 0 ? "clavicle_right" : "clavicle_left");
    if (clavicle < 0) continue;
    add(side > 0 ? "clavicle_right" : "clavicle_left", m.bodies.com.col(clavicle),
        {0, kDepthClavicle, 0.004});
  }
  if (const int head = bodyNamed("head"); head >= 0) {
    const Eigen::Matrix3Xd hv = worldMesh(head);
    Eigen::Index top = 0;
    hv.row(2).maxCoeff(&top);
    add("head_top", hv.col(top), {0, 0, kDepthScalp});
  }
  crotchZ = a.abdomen.floorLevel - kPerineumDepth;  // perineum, below the pelvic floor
  return out;
}

/// The elbow, wrist and fingertip of the source's arm on `side` (+1 right, -1 left): the arm is the part of
/// the surface lateral of the acromion, its fingertip the most lateral vertex; the vertices binned by their
/// distance from the fingertip over the surface give the arm's centreline (the bins' centroids), the elbow is
/// the centreline point farthest from the line between its ends, the wrist lies between the elbow and the
/// fingertip at the forearm's share of the forearm and hand.
std::array<Eigen::Vector3d, 3> sourceArm(const TriangleMesh& s, const Eigen::Vector3d& acromion, int side,
                                         double forearmShare, const std::string& file) {
  const Eigen::Matrix3Xd& v = s.vertices;
  const int nV = s.vertexCount();
  const double height = v.row(2).maxCoeff() - v.row(2).minCoeff();
  Eigen::Index tip = 0;
  (side * v.row(0)).maxCoeff(&tip);
  auto isArm = [&](int i) { return side * (v(0, i) - acromion.x()) > 0.0; };
  // distances over the arm's edges from the fingertip (Dijkstra)
  const auto nb = neighbours(nV, s.triangles);
  std::vector<double> d(static_cast<std::size_t>(nV), std::numeric_limits<double>::infinity());
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  d[static_cast<std::size_t>(tip)] = 0.0;
  queue.push({0.0, static_cast<int>(tip)});
  while (!queue.empty()) {
    const auto [di, i] = queue.top();
    queue.pop();
    if (di > d[static_cast<std::size_t>(i)]) continue;
    for (int j : nb[static_cast<std::size_t>(i)]) {
      if (!isArm(j)) continue;
      const double dj = di + (v.col(j) - v.col(i)).norm();
      if (dj < d[static_cast<std::size_t>(j)]) {
        d[static_cast<std::size_t>(j)] = dj;
        queue.push({dj, j});
      }
    }
  }
  const double bin = 0.006 * height;
  std::vector<Eigen::Vector3d> sum;
  std::vector<int> count;
  for (int i = 0; i < nV; ++i) {
    if (!std::isfinite(d[static_cast<std::size_t>(i)])) continue;
    const std::size_t k = static_cast<std::size_t>(d[static_cast<std::size_t>(i)] / bin);
    if (k >= sum.size()) {
      sum.resize(k + 1, Eigen::Vector3d::Zero());
      count.resize(k + 1, 0);
    }
    sum[k] += v.col(i);
    ++count[k];
  }
  Points centre;
  for (std::size_t k = 0; k < sum.size(); ++k)
    if (count[k] > 0) centre.push_back(sum[k] / count[k]);
  if (centre.size() < 10) fail(file, "cannot find the arms (no surface lateral of the acromions)");
  // the elbow: farthest from the chord between the centreline's ends
  const Eigen::Vector3d a = centre.front(), chord = (centre.back() - a).normalized();
  std::size_t elbow = 0;
  double far = -1.0;
  for (std::size_t k = 0; k < centre.size(); ++k) {
    const Eigen::Vector3d r = centre[k] - a;
    const double off = (r - r.dot(chord) * chord).norm();
    if (off > far) {
      far = off;
      elbow = k;
    }
  }
  // the wrist: along the centreline from the elbow toward the fingertip
  std::vector<double> arc(elbow + 1, 0.0);  // arc length from the elbow
  for (std::size_t k = elbow; k-- > 0;) arc[k] = arc[k + 1] + (centre[k + 1] - centre[k]).norm();
  std::size_t wrist = elbow;
  while (wrist > 0 && arc[wrist] < forearmShare * arc.front()) --wrist;
  return {centre[elbow], centre[wrist], v.col(tip)};
}

// ---------------------------------------------------------------------------------------------
// the source mesh's landmarks

Points sourceLandmarks(const TriangleMesh& s, const std::vector<Landmark>& target, double targetCrotchZ,
                       const std::string& file, double& crotchZ) {
  const Eigen::Matrix3Xd& v = s.vertices;
  const double zLo = v.row(2).minCoeff(), zHi = v.row(2).maxCoeff();
  const double height = zHi - zLo;
  const double gap = 0.004 * height;
  const double slab = height / kSlabs;
  std::vector<double> xs(static_cast<std::size_t>(v.cols()));
  for (Eigen::Index i = 0; i < v.cols(); ++i) xs[static_cast<std::size_t>(i)] = v(0, i);
  std::nth_element(xs.begin(), xs.begin() + static_cast<std::ptrdiff_t>(xs.size() / 2), xs.end());
  const double x0 = xs[xs.size() / 2];
  // section k: the plane z = zHi - (k + 0.5) slab, cut through every triangle that spans it
  std::vector<std::vector<std::array<Eigen::Vector3d, 2>>> cuts(kSlabs);
  for (int f = 0; f < s.triangleCount(); ++f) {
    std::array<Eigen::Vector3d, 3> c{v.col(s.triangles(0, f)), v.col(s.triangles(1, f)),
                                     v.col(s.triangles(2, f))};
    const double lo = std::min({c[0].z(), c[1].z(), c[2].z()}), hi = std::max({c[0].z(), c[1].z(), c[2].z()});
    const int k0 = std::max(0, static_cast<int>(std::ceil((zHi - hi) / slab - 0.5)));
    const int k1 = std::min(kSlabs - 1, static_cast<int>(std::floor((zHi - lo) / slab - 0.5)));
    for (int k = k0; k <= k1; ++k) {
      const double z = zHi - (k + 0.5) * slab;
      std::vector<Eigen::Vector3d> ends;
      for (int e = 0; e < 3; ++e) {
        const Eigen::Vector3d& p = c[static_cast<std::size_t>(e)];
        const Eigen::Vector3d& q = c[static_cast<std::size_t>((e + 1) % 3)];
        if ((p.z() - z) * (q.z() - z) < 0.0) ends.push_back(p + (z - p.z()) / (q.z() - p.z()) * (q - p));
      }
      if (ends.size() == 2) cuts[static_cast<std::size_t>(k)].push_back({ends[0], ends[1]});
    }
  }
  std::vector<Section> sec;
  for (const auto& cut : cuts) sec.push_back(centralPiece(cut, x0, gap));
  auto width = [&](int i) {
    return sec[static_cast<std::size_t>(i)].xMax - sec[static_cast<std::size_t>(i)].xMin;
  };

  // from the top down: the head widens to its widest, narrows by a fifth (chin and neck), the neck narrows to
  // its narrowest, then the shoulders widen to twice that
  int i = 0;
  while (i < kSlabs && sec[static_cast<std::size_t>(i)].points.empty()) ++i;
  double headWidth = 0.0;
  for (; i < kSlabs && !(width(i) < 0.8 * headWidth); ++i) headWidth = std::max(headWidth, width(i));
  int neck = i, shoulders = -1;
  for (; i < kSlabs; ++i) {
    if (width(i) > 2.0 * width(neck)) {
      shoulders = i;
      break;
    }
    if (width(i) < width(neck)) neck = i;
  }
  if (shoulders < 0 || headWidth < 0.03 * height)
    fail(file, "cannot find the neck (no narrowing below the head between wider head and shoulders)");
  // the crotch: the highest section below the shoulders whose midline falls between the legs
  int crotch = -1;
  for (int k = shoulders; k < kSlabs; ++k)
    if (sec[static_cast<std::size_t>(k)].isMidlineEmpty && !cuts[static_cast<std::size_t>(k)].empty()) {
      crotch = k;
      break;
    }
  if (crotch < 0) fail(file, "cannot find the crotch (no section below the shoulders parts at the midline)");
  const double zNeck = zHi - (neck + 0.5) * slab;
  crotchZ = zHi - (crotch + 0.5) * slab;

  // the model's neck: above the jugular notch by the skin's own neck-to-notch share (a fixed proportion of
  // the neck-to-crotch span, 0.13: adult stature ratios, neck 0.87, notch 0.82, crotch 0.47)
  const double jugularT = target[0].skin.z();
  const double neckT = jugularT + 0.13 / 0.87 * (jugularT - targetCrotchZ);
  auto zOf = [&](double zt) {
    return crotchZ + (zt - targetCrotchZ) / (neckT - targetCrotchZ) * (zNeck - crotchZ);
  };
  auto slabAt = [&](double z) { return std::clamp(static_cast<int>((zHi - z) / slab), 0, kSlabs - 1); };
  // lateral scale: the rib-8 breadth
  const double r8z = zOf(0.5 * (target[3].skin.z() + target[4].skin.z()));
  const Section& r8 = sec[static_cast<std::size_t>(slabAt(r8z))];
  const double scaleX = (r8.xMax - r8.xMin) / (target[3].skin.x() - target[4].skin.x());

  Points out;
  auto targetIndex = [&](const std::string& name) {
    for (std::size_t k = 0; k < target.size(); ++k)
      if (target[k].name == name) return k;
    fail(file, "the model has no landmark " + name);
  };
  for (const Landmark& t : target) {
    // the arms, from their centrelines (the acromions are found before them), and the top of the head
    if (t.name == "head_top") {
      Eigen::Index top = 0;
      v.row(2).maxCoeff(&top);
      out.push_back(v.col(top));
      continue;
    }
    if (t.name.rfind("elbow_", 0) == 0 || t.name.rfind("wrist_", 0) == 0 ||
        t.name.rfind("fingertip_", 0) == 0) {
      const std::string n = t.name.substr(t.name.find('_'));  // "_right" or "_left"
      const Eigen::Vector3d& elbow = target[targetIndex("elbow" + n)].skin;
      const Eigen::Vector3d& wrist = target[targetIndex("wrist" + n)].skin;
      const Eigen::Vector3d& tip = target[targetIndex("fingertip" + n)].skin;
      const double share = (wrist - elbow).norm() / ((wrist - elbow).norm() + (tip - wrist).norm());
      const auto arm = sourceArm(s, out[targetIndex("acromion" + n)], n == "_right" ? 1 : -1, share, file);
      out.push_back(arm[t.name[0] == 'e' ? 0 : t.name[0] == 'w' ? 1 : 2]);
      continue;
    }
    const double z = zOf(t.skin.z());
    const double x = x0 + scaleX * t.skin.x();
    // candidate points: the central piece of the sections within 1.5 slabs of z
    Points cand;
    for (int k = slabAt(z) - 1; k <= slabAt(z) + 1; ++k)
      if (k >= 0 && k < kSlabs)
        for (const auto& p : sec[static_cast<std::size_t>(k)].points) cand.push_back(p);
    if (cand.empty()) fail(file, "cannot find the " + t.name + " (no surface at its level)");
    bool found = false;
    Eigen::Vector3d best(0, 0, 0);
    double bestScore = 0.0;
    const double band = (std::abs(t.skin.x()) < 1e-3 ? 0.006 : 0.01) * height;
    auto better = [&](const Eigen::Vector3d& q, double score) {
      if (!found || score > bestScore) {
        best = q;
        bestScore = score;
        found = true;
      }
    };
    for (const Eigen::Vector3d& p : cand) {
      const Eigen::Vector3d q = p;
      if (t.name.rfind("rib8", 0) == 0) {
        better(q, (t.skin.x() > 0 ? 1 : -1) * p.x());  // most lateral
      } else if (t.name.rfind("spine", 0) == 0) {
        if (std::abs(p.x() - x0) < band) better(q, -p.y());  // most posterior on the midline
      } else if (t.name.rfind("acromion", 0) == 0) {
        continue;  // searched by column below
      } else {
        if (std::abs(p.x() - x) < band) better(q, p.y());  // most anterior at its x
      }
    }
    if (t.name.rfind("acromion", 0) == 0) {
      // the top of the shoulder: the highest vertex in the column at x near its level
      for (int q = 0; q < v.cols(); ++q)
        if (std::abs(v(0, q) - x) < band && v(2, q) < z + 0.1 * height && v(2, q) > z - 0.1 * height)
          better(v.col(q), v(2, q));
    }
    if (!found) fail(file, "cannot find the " + t.name + " on the surface");
    out.push_back(best);
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// cut the legs below `zCut` and cap the cuts: the pieces of the surface below zCut that reach down to the
// soles (within 5 cm of the lowest point), not the hands

TriangleMesh cutLegs(const TriangleMesh& s, double zCut, const std::string& file) {
  const int nV = s.vertexCount();
  const double zFloor = s.vertices.row(2).minCoeff() + 0.05;
  if (zFloor - 0.05 > zCut - kThighCutSlack) return s;  // legs already cut about here (a skin of ours)
  std::vector<char> isCut(static_cast<std::size_t>(nV), 0);
  {
    // flood the part below the cut from the vertices near the floor
    const auto nb = neighbours(nV, s.triangles);
    std::vector<int> stack;
    for (int i = 0; i < nV; ++i)
      if (s.vertices(2, i) < std::min(zFloor, zCut)) {
        isCut[static_cast<std::size_t>(i)] = 1;
        stack.push_back(i);
      }
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      for (int j : nb[static_cast<std::size_t>(i)])
        if (!isCut[static_cast<std::size_t>(j)] && s.vertices(2, j) < zCut) {
          isCut[static_cast<std::size_t>(j)] = 1;
          stack.push_back(j);
        }
    }
  }
  std::vector<Eigen::Vector3i> tris;
  for (int f = 0; f < s.triangleCount(); ++f) {
    const Eigen::Vector3i t = s.triangles.col(f);
    if (!isCut[static_cast<std::size_t>(t[0])] && !isCut[static_cast<std::size_t>(t[1])] &&
        !isCut[static_cast<std::size_t>(t[2])])
      tris.push_back(t);
  }
  // boundary loops: directed edges without their reverse, followed head to tail
  std::map<std::pair<int, int>, int> directed;
  for (const auto& t : tris)
    for (int k = 0; k < 3; ++k) directed[{t[k], t[(k + 1) % 3]}] = 1;
  std::map<int, int> next;  // boundary edge a -> b, reversed for the cap: cap edges run b -> a
  for (const auto& [e, one] : directed)
    if (!directed.count({e.second, e.first})) {
      if (next.count(e.second)) fail(file, "the leg cut leaves a boundary that is not a simple loop");
      next[e.second] = e.first;
    }
  Points verts;
  for (int i = 0; i < nV; ++i) verts.push_back(s.vertices.col(i));
  int loops = 0;
  while (!next.empty()) {
    std::vector<int> loop;
    int a = next.begin()->first;
    while (next.count(a)) {
      loop.push_back(a);
      const int b = next[a];
      next.erase(a);
      a = b;
    }
    if (a != loop.front()) fail(file, "the leg cut leaves an open boundary");
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int q : loop) c += verts[static_cast<std::size_t>(q)];
    c /= static_cast<double>(loop.size());
    const int centre = static_cast<int>(verts.size());
    verts.push_back(c);
    for (std::size_t k = 0; k < loop.size(); ++k)
      tris.emplace_back(loop[k], loop[(k + 1) % loop.size()], centre);
    ++loops;
  }
  if (loops != 0 && loops != 2) fail(file, "the leg cut gives " + std::to_string(loops) + " cuts, not 2");
  // drop unused vertices
  std::vector<int> index(verts.size(), -1);
  int n = 0;
  for (const auto& t : tris)
    for (int k = 0; k < 3; ++k)
      if (index[static_cast<std::size_t>(t[k])] < 0) index[static_cast<std::size_t>(t[k])] = n++;
  TriangleMesh out;
  out.vertices.resize(3, n);
  for (std::size_t i = 0; i < verts.size(); ++i)
    if (index[i] >= 0) out.vertices.col(index[i]) = verts[i];
  out.triangles.resize(3, static_cast<Eigen::Index>(tris.size()));
  for (std::size_t f = 0; f < tris.size(); ++f)
    for (int k = 0; k < 3; ++k)
      out.triangles(k, static_cast<Eigen::Index>(f)) = index[static_cast<std::size_t>(tris[f][k])];
  return out;
}

// ---------------------------------------------------------------------------------------------
// obstacles: bone surfaces and the gut, as points with outward normals and the clearance they need

struct Obstacles {
  Points point;
  Points normal;
  std::vector<double> clearance;  // [m]
  std::vector<int> body;          // body index, -1 for a node
  std::vector<int> node;          // node index (a gut node or a volume body's superficial node), else -1
};

Obstacles obstaclesOf(const BuiltModel& built) {
  const sim::Model& m = built.model;
  Obstacles o;
  for (int b = 0; b < m.bodies.size(); ++b) {
    const TriangleMesh& mesh = built.bodyMeshes[static_cast<std::size_t>(b)];
    const Eigen::Matrix3Xd n = vertexNormals(mesh.vertices, mesh.triangles);
    for (int i = 0; i < mesh.vertexCount(); ++i) {
      o.point.push_back(mesh.vertices.col(i) + m.bodies.com.col(b));
      o.normal.push_back(n.col(i));
      o.clearance.push_back(kBoneClearance);
      o.body.push_back(b);
      o.node.push_back(-1);
    }
  }
  // the nodes: the gut's, and the volume bodies' superficial ones (the skin lies over the pectorals and
  // shoulders; bind() takes no anchor from them); their deep nodes, tied to a bone (a spring from the node to
  // a body), lie under them
  Eigen::Matrix3Xi surfaces = m.gut.triangles;
  for (const Eigen::Matrix3Xi& t : m.volumes.triangles) {
    surfaces.conservativeResize(3, surfaces.cols() + t.cols());
    surfaces.rightCols(t.cols()) = t;
  }
  const Eigen::Matrix3Xd n = vertexNormals(m.nodes.rest, surfaces);
  const std::vector<char> isTied = sim::tiedNodes(m);
  for (int i = 0; i < m.nodes.size(); ++i) {
    const bool isTissue = m.nodes.region[static_cast<std::size_t>(i)] == sim::NodeRegion::Tissue;
    if (isTissue && isTied[static_cast<std::size_t>(i)]) continue;
    o.point.push_back(m.nodes.rest.col(i));
    o.normal.push_back(n.col(i));
    o.clearance.push_back(isTissue ? kTissueClearance : kGutClearance);
    o.body.push_back(-1);
    o.node.push_back(i);
  }
  return o;
}

/// Lifts the skin over the muscles from the neck to the shoulder girdle (every element from the cervical
/// spine to a clavicle or scapula: upper trapezius, levator scapulae, rhomboid). A straight muscle from the
/// neck to the shoulder cuts the concave neck-shoulder line of the registered mesh (the upper trapezius from
/// C2 and C4 by up to 12 mm), where the real muscle wraps the neck and makes that line. A vertex x with
/// normal n whose normal line x + t n passes within kNeckMuscleRadius of a muscle's line (between 5 % of the
/// way from its neck end and kNeckMuscleLateralEnd), at -kNeckMuscleClearance < t < kNeckMuscleReach, is
/// lifted by t + kNeckMuscleClearance along n; kNeckLiftPasses passes give each vertex the larger of its lift
/// and 0.8 of its neighbours' mean, so that the skin takes the muscle's contour without a fold.
void liftOverNeckMuscles(TriangleMesh& s, const sim::Model& m) {
  const auto isGirdleBone = [&](int b) {
    if (b < 0) return false;
    const std::string& name = m.bodies.name[static_cast<std::size_t>(b)];
    return name.rfind("clavicle", 0) == 0 || name.rfind("scapula", 0) == 0;
  };
  const auto isNeck = [&](int b) {
    return b >= 0 && m.bodies.name[static_cast<std::size_t>(b)] == "cervical_spine";
  };
  // each muscle's line from its neck end to its girdle end [m]
  const Eigen::Matrix3Xd endA = restPoints(m.elements.endA, m), endB = restPoints(m.elements.endB, m);
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> lines;
  for (int e = 0; e < m.elements.size(); ++e) {
    const int p = m.elements.endA.body[static_cast<std::size_t>(e)],
              q = m.elements.endB.body[static_cast<std::size_t>(e)];
    if (isNeck(p) && isGirdleBone(q)) lines.emplace_back(endA.col(e), endB.col(e));
    if (isNeck(q) && isGirdleBone(p)) lines.emplace_back(endB.col(e), endA.col(e));
  }
  if (lines.empty()) return;
  const Eigen::Matrix3Xd normal = vertexNormals(s.vertices, s.triangles);
  Eigen::VectorXd lift = Eigen::VectorXd::Zero(s.vertexCount());
  for (int i = 0; i < s.vertexCount(); ++i) {
    const Eigen::Vector3d x = s.vertices.col(i), n = normal.col(i);
    for (const auto& [a, b] : lines) {
      // the closest points of the normal line x + t n and the muscle's line a + u d, u in [0.05, 0.8]
      const Eigen::Vector3d d = b - a, w = x - a;
      const double nd = n.dot(d), dd = d.dot(d), det = dd - nd * nd;
      if (det < 1e-12 * dd) continue;
      const double u = std::clamp((d.dot(w) - nd * n.dot(w)) / det, 0.05, kNeckMuscleLateralEnd);
      const Eigen::Vector3d q = a + u * d;
      const double t = n.dot(q - x);
      if (t <= -kNeckMuscleClearance || t >= kNeckMuscleReach || (x + t * n - q).norm() > kNeckMuscleRadius)
        continue;
      lift(i) = std::max(lift(i), t + kNeckMuscleClearance);
    }
  }
  const auto nb = neighbours(s.vertexCount(), s.triangles);
  for (int pass = 0; pass < kNeckLiftPasses; ++pass) {
    Eigen::VectorXd spread = lift;
    for (int i = 0; i < s.vertexCount(); ++i) {
      const auto& ring = nb[static_cast<std::size_t>(i)];
      if (ring.empty()) continue;
      double mean = 0.0;
      for (int j : ring) mean += lift(j);
      spread(i) = std::max(lift(i), 0.8 * mean / static_cast<double>(ring.size()));
    }
    lift = spread;
  }
  for (int i = 0; i < s.vertexCount(); ++i) s.vertices.col(i) += lift(i) * normal.col(i);
}

/// Pushes skin vertices out of the obstacles; returns the least remaining clearance to a bone [m].
double pushOut(TriangleMesh& s, const Obstacles& o) {
  const PointGrid grid(o.point, 0.02);
  const auto nb = neighbours(s.vertexCount(), s.triangles);
  const double reach = 0.04;
  double least = 1e9;
  for (int iter = 0; iter < 30; ++iter) {
    const Eigen::Matrix3Xd normal = vertexNormals(s.vertices, s.triangles);
    Eigen::Matrix3Xd push = Eigen::Matrix3Xd::Zero(3, s.vertexCount());
    int violations = 0;
    least = 1e9;
    for (int i = 0; i < s.vertexCount(); ++i) {
      const Eigen::Vector3d p = s.vertices.col(i);
      const int q = grid.nearest(p, reach);
      if (q < 0) continue;
      const double d = (p - o.point[static_cast<std::size_t>(q)]).dot(o.normal[static_cast<std::size_t>(q)]);
      if (o.body[static_cast<std::size_t>(q)] >= 0) least = std::min(least, d);
      const double need = o.clearance[static_cast<std::size_t>(q)] - d;
      if (need > 0) {
        // along the skin's own normal, by as much as moves it `need` off the obstacle
        const double cosine = std::max(0.3, normal.col(i).dot(o.normal[static_cast<std::size_t>(q)]));
        push.col(i) = (need + 0.001) / cosine * normal.col(i);
        ++violations;
      }
    }
    if (violations == 0) break;
    // spread each push over the neighbours so the surface stays smooth
    for (int pass = 0; pass < 2; ++pass) {
      Eigen::Matrix3Xd spread = push;
      for (int i = 0; i < s.vertexCount(); ++i) {
        for (int j : nb[static_cast<std::size_t>(i)])
          if (push.col(j).squaredNorm() > spread.col(i).squaredNorm())
            spread.col(i) = 0.5 * (spread.col(i) + push.col(j));
      }
      push = spread;
    }
    s.vertices += push;
  }
  return least;
}

// ---------------------------------------------------------------------------------------------
// binding through the soft tissue

constexpr int kK = sim::kSkinVertexSlots - 1;  // nearest anchors per vertex; the last slot for the still body

/// The share of the shoulder girdle's motion the tissue at `p` takes through the upper trapezius
/// (kTrapezius*): on the side of acromion `a` [m] (world, rest), medial of it and above its height less
/// kTrapeziusReach of its half-breadth, f = clamp((t - t0) / (1 - t0), 0, 1) with t the share of the way from
/// the neck's axis n = (0, a_y, a_z) to the acromion, t = (p - n).(a - n) / |a - n|^2, and t0 =
/// kTrapeziusNeck; blended to 1 (all of it) over kTrapeziusBlend below the region.
double trapeziusShare(const Eigen::Vector3d& p, const Eigen::Vector3d& a) {
  if (p.x() * a.x() <= 0.0 || std::abs(p.x()) > std::abs(a.x())) return 1.0;
  const Eigen::Vector3d n(0.0, a.y(), a.z());
  const double t = std::clamp((p - n).dot(a - n) / (a - n).squaredNorm(), 0.0, 1.0);
  const double f = std::clamp((t - kTrapeziusNeck) / (1.0 - kTrapeziusNeck), 0.0, 1.0);
  const double lower = a.z() - kTrapeziusReach * std::abs(a.x());
  const double inside = std::clamp((p.z() - lower) / kTrapeziusBlend, 0.0, 1.0);
  return 1.0 - inside * (1.0 - f);
}

void bind(const TriangleMesh& skin, const BuiltModel& built, const Obstacles& o, sim::Skin& out,
          int& tetCount) {
  const sim::Model& m = built.model;
  // anchors: bone-surface points thinned to one per cell and body, and every gut node
  std::vector<int> anchorSource;  // obstacle index per interior point
  {
    std::map<std::array<long long, 4>, int> seen;
    for (std::size_t i = 0; i < o.point.size(); ++i) {
      // a volume body's node is an obstacle only: the skin slides over the pectorals and shoulders as they
      // slide over the ribs (bound to them, the skin at the inframammary fold, between the lens and the skin
      // bound to the dome, crossed itself in a deep breath)
      if (o.node[i] >= 0 && m.nodes.region[static_cast<std::size_t>(o.node[i])] == sim::NodeRegion::Tissue)
        continue;
      const Eigen::Vector3d& p = o.point[i];
      const std::array<long long, 4> key{o.body[i],
                                         static_cast<long long>(std::floor(p.x() / kAnchorSpacing)),
                                         static_cast<long long>(std::floor(p.y() / kAnchorSpacing)),
                                         static_cast<long long>(std::floor(p.z() / kAnchorSpacing))};
      if (o.body[i] < 0 || seen.emplace(key, static_cast<int>(i)).second)
        anchorSource.push_back(static_cast<int>(i));
    }
  }
  Eigen::Matrix3Xd interior(3, static_cast<Eigen::Index>(anchorSource.size()));
  for (std::size_t i = 0; i < anchorSource.size(); ++i)
    interior.col(static_cast<Eigen::Index>(i)) = o.point[static_cast<std::size_t>(anchorSource[i])];
  const TetMesh tet = tetrahedralizeAround(skin, interior, "skin");
  tetCount = static_cast<int>(tet.tets.cols());
  const int nV = skin.vertexCount();
  const int nA = static_cast<int>(anchorSource.size());
  const int nT = static_cast<int>(tet.vertices.cols());

  // tetrahedron edges
  std::vector<std::vector<int>> adj(static_cast<std::size_t>(nT));
  for (int e = 0; e < tet.tets.cols(); ++e)
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        if (i != j) adj[static_cast<std::size_t>(tet.tets(i, e))].push_back(tet.tets(j, e));
  for (auto& a : adj) {
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
  }

  // the K nearest anchors of every node through the tissue (Dijkstra from all anchors at once)
  struct Label {
    double d;
    int node, anchor;
    bool operator>(const Label& o) const { return d > o.d; }
  };
  std::priority_queue<Label, std::vector<Label>, std::greater<Label>> queue;
  for (int a = 0; a < nA; ++a) queue.push({0.0, nV + a, a});
  std::vector<std::vector<std::pair<double, int>>> found(static_cast<std::size_t>(nT));
  while (!queue.empty()) {
    const Label l = queue.top();
    queue.pop();
    auto& f = found[static_cast<std::size_t>(l.node)];
    if (static_cast<int>(f.size()) >= kK) continue;
    if (std::any_of(f.begin(), f.end(), [&](const auto& x) { return x.second == l.anchor; })) continue;
    f.emplace_back(l.d, l.anchor);
    for (int n : adj[static_cast<std::size_t>(l.node)]) {
      if (static_cast<int>(found[static_cast<std::size_t>(n)].size()) >= kK) continue;
      queue.push({l.d + (tet.vertices.col(n) - tet.vertices.col(l.node)).norm(), n, l.anchor});
    }
  }

  // the anchors as sim points (created on first use), then the vertices
  std::vector<int> simAnchor(static_cast<std::size_t>(nA), -1);
  auto useAnchor = [&](int a) {
    if (simAnchor[static_cast<std::size_t>(a)] < 0) {
      const int src = anchorSource[static_cast<std::size_t>(a)];
      const int b = o.body[static_cast<std::size_t>(src)];
      simAnchor[static_cast<std::size_t>(a)] = out.anchors.size();
      if (b >= 0)
        out.anchors.addBodyPoint(b, o.point[static_cast<std::size_t>(src)] - m.bodies.com.col(b));
      else
        out.anchors.addNodePoint({o.node[static_cast<std::size_t>(src)], -1, -1}, {1, 0, 0});
    }
    return simAnchor[static_cast<std::size_t>(a)];
  };
  out.anchor.setConstant(sim::kSkinVertexSlots, nV, -1);
  out.weights.setZero(sim::kSkinVertexSlots, nV);
  out.offset.setZero(3, nV);
  out.triangles = skin.triangles;
  // a fixed body (never moves): the still part of a vertex far from every moving structure
  int still = -1;
  for (int b = 0; b < m.bodies.size() && still < 0; ++b)
    if (m.bodies.isFixed[static_cast<std::size_t>(b)]) still = b;

  // each vertex's binding as weights over anchors (key -1: the still body): inverse-square distance through
  // the tissue, times the share of the motion it takes (all within kFollowNear of its nearest anchor, none
  // beyond kFollowFar, except all when that anchor is on a limb: a body with a postural support, the shoulder
  // girdle and arms, whose far tissue, the fingers, goes with it)
  using Binding = std::vector<std::pair<int, double>>;
  std::vector<Binding> binding(static_cast<std::size_t>(nV));
  for (int v = 0; v < nV; ++v) {
    const auto& f = found[static_cast<std::size_t>(v)];
    if (f.empty())
      throw sim::Error("skin: vertex " + std::to_string(v) +
                       " reaches no bone or gut node through the tissue");
    const int nearestBody =
        o.body[static_cast<std::size_t>(anchorSource[static_cast<std::size_t>(f.front().second)])];
    const double share =
        still < 0 || (nearestBody >= 0 && m.bodies.supported(nearestBody))
            ? 1.0
            : std::clamp((kFollowFar - f.front().first) / (kFollowFar - kFollowNear), 0.0, 1.0);
    double sum = 0.0;
    for (const auto& [d, a] : f) sum += 1.0 / std::max(d * d, 1e-6);
    Binding& b = binding[static_cast<std::size_t>(v)];
    for (const auto& [d, a] : f) b.emplace_back(a, share / std::max(d * d, 1e-6) / sum);
    if (share < 1.0) b.emplace_back(-1, 1.0 - share);
  }
  // the upper trapezius: the girdle's share of the tissue between the neck and the shoulders goes to the
  // still body (trapeziusShare())
  const Eigen::Matrix3Xd landmarks = restPoints(m.landmarks.points, m);
  for (const char* name : {"acromion_right", "acromion_left"}) {
    const int l = m.landmarks.find(name);
    if (l < 0 || still < 0) continue;
    const Eigen::Vector3d a = landmarks.col(l);
    for (int v = 0; v < nV; ++v) {
      const double keep = trapeziusShare(skin.vertices.col(v), a);
      if (keep >= 1.0) continue;
      Binding& b = binding[static_cast<std::size_t>(v)];
      double moved = 0.0;
      for (auto& [anchor, w] : b) {
        const int body =
            anchor < 0 ? -1
                       : o.body[static_cast<std::size_t>(anchorSource[static_cast<std::size_t>(anchor)])];
        if (body < 0 || !m.bodies.supported(body)) continue;
        moved += (1.0 - keep) * w;
        w *= keep;
      }
      if (moved <= 0.0) continue;
      auto stillSlot = std::find_if(b.begin(), b.end(), [](const auto& x) { return x.first < 0; });
      if (stillSlot != b.end())
        stillSlot->second += moved;
      else
        b.emplace_back(-1, moved);
    }
  }
  // smooth the bindings over the surface (neighbouring vertices move alike: no fold of the source closes
  // through itself), keeping each vertex's kK strongest anchors and its still share
  const auto nb = neighbours(nV, skin.triangles);
  auto prune = [](std::map<int, double>& w) {
    Binding b;
    double stillShare = 0.0;
    for (const auto& [a, x] : w) {
      if (a < 0)
        stillShare = x;
      else
        b.emplace_back(a, x);
    }
    stillShare = std::clamp(stillShare, 0.0, 1.0);  // rounding of the averages
    std::sort(b.begin(), b.end(), [](const auto& p, const auto& q) { return p.second > q.second; });
    if (static_cast<int>(b.size()) > kK) b.resize(static_cast<std::size_t>(kK));
    double sum = 0.0;
    for (const auto& p : b) sum += p.second;
    if (sum > 0.0)
      for (auto& p : b) p.second *= (1.0 - stillShare) / sum;
    else
      stillShare = 1.0;
    if (stillShare > 0.0) b.emplace_back(-1, stillShare);
    return b;
  };
  for (int pass = 0; pass < kBindingSmoothingPasses; ++pass) {
    std::vector<Binding> next(static_cast<std::size_t>(nV));
    for (int v = 0; v < nV; ++v) {
      std::map<int, double> w;
      for (const auto& [a, x] : binding[static_cast<std::size_t>(v)]) w[a] += 0.5 * x;
      const auto& n = nb[static_cast<std::size_t>(v)];
      for (int u : n)
        for (const auto& [a, x] : binding[static_cast<std::size_t>(u)])
          w[a] += 0.5 * x / static_cast<double>(n.size());
      next[static_cast<std::size_t>(v)] = prune(w);
    }
    binding.swap(next);
  }

  for (int v = 0; v < nV; ++v) {
    const Eigen::Vector3d x = skin.vertices.col(v);
    const Binding& b = binding[static_cast<std::size_t>(v)];
    // one bone only: the vertex follows it rigidly (a point of that bone at the vertex itself); the still
    // body only: it stays
    const int firstBody =
        b.front().first < 0
            ? still
            : o.body[static_cast<std::size_t>(anchorSource[static_cast<std::size_t>(b.front().first)])];
    bool isOneBody = firstBody >= 0;
    for (const auto& [a, w] : b)
      isOneBody =
          isOneBody &&
          (a < 0 ? still : o.body[static_cast<std::size_t>(anchorSource[static_cast<std::size_t>(a)])]) ==
              firstBody;
    if (isOneBody) {
      out.anchor(0, v) = out.anchors.size();
      out.anchors.addBodyPoint(firstBody, x - m.bodies.com.col(firstBody));
      out.weights(0, v) = 1.0;
      continue;
    }
    // the still body and each limb (a body with a postural support: the shoulder girdle and arms) carry
    // their share of the vertex rigidly, as a point of theirs at the vertex itself (linear blend skinning);
    // the torso's bones and the gut move the vertex with their anchors' displacement, so that the tissue
    // over a turning rib moves as the rib's surface does. With every anchor plus offset, a limb's skin did
    // not turn with the limb: the hand's and the elbow's small triangles folded over at the view's 5x
    Eigen::Vector3d blend = Eigen::Vector3d::Zero();
    std::map<int, int> slotOfBody;  // rigid carrier -> its slot
    int slots = 0;
    for (const auto& [a, w] : b) {
      const int body =
          a < 0 ? still : o.body[static_cast<std::size_t>(anchorSource[static_cast<std::size_t>(a)])];
      if (a < 0 || (body >= 0 && m.bodies.supported(body))) {
        auto [it, isNew] = slotOfBody.emplace(body, slots);
        if (isNew) {
          out.anchor(slots++, v) = out.anchors.size();
          out.anchors.addBodyPoint(body, x - m.bodies.com.col(body));
        }
        out.weights(it->second, v) += w;
        blend += w * x;
      } else {
        out.anchor(slots, v) = useAnchor(a);
        out.weights(slots++, v) = w;
        blend += w * o.point[static_cast<std::size_t>(anchorSource[static_cast<std::size_t>(a)])];
      }
    }
    out.offset.col(v) = x - blend;
  }
  out.tetrahedra = tetCount;
}

}  // namespace

void buildSkin(const AnatomyParams& a, const std::string& file, BuiltModel& out) {
  TriangleMesh source = readSkinSource(file);

  // landmarks, warp
  double targetCrotch = 0.0, sourceCrotch = 0.0;
  const std::vector<Landmark> target = modelLandmarks(a, out, targetCrotch);
  const Points from = sourceLandmarks(source, target, targetCrotch, file, sourceCrotch);
  Points to;
  for (const Landmark& l : target) to.push_back(l.skin);
  // the crotch too, on the midline, so that the warp keeps the legs below the pelvis
  Points fromAll = from, toAll = to;
  {
    double xMid = 0.0;
    for (const auto& p : from) xMid += p.x() / static_cast<double>(from.size());
    double yMid = 0.5 * (from[0].y() + from[9].y());
    fromAll.emplace_back(xMid, yMid, sourceCrotch);
    toAll.emplace_back(0.0, 0.5 * (to[0].y() + to[9].y()), targetCrotch);
  }
  const ThinPlateSpline warp(fromAll, toAll);
  for (int i = 0; i < source.vertexCount(); ++i) source.vertices.col(i) = warp(source.vertices.col(i));

  // the legs, cut at the thigh; the skin lifted over the neck's muscles and pushed out of the bones
  TriangleMesh skin = cutLegs(source, targetCrotch - kThighCut, file);
  liftOverNeckMuscles(skin, out.model);
  const Obstacles obstacles = obstaclesOf(out);
  out.report.skinBoneClearance = pushOut(skin, obstacles);

  // residuals at the surface landmarks after the push: distance from each target to the skin surface (the
  // arms' elbows, wrists and fingertips are matched on the centreline, inside the skin: no depth)
  double residual = 0.0;
  for (const Landmark& l : target) {
    if (l.skin == l.bone) continue;
    const Eigen::Vector3d& p = l.skin;
    double best = 1e9;
    for (int f = 0; f < skin.triangleCount(); ++f)
      best = std::min(best, pointTriangleDistance(p, skin.vertices.col(skin.triangles(0, f)),
                                                  skin.vertices.col(skin.triangles(1, f)),
                                                  skin.vertices.col(skin.triangles(2, f))));
    residual = std::max(residual, best);
  }
  out.report.skinLandmarkResidual = residual;

  const MeshCheck check = checkMesh(skin);
  if (!check.isValid())
    fail(file, std::string("the registered skin is not a valid closed surface: manifold ") +
                   (check.isManifold ? "yes" : "no") + ", closed " + (check.isClosed ? "yes" : "no") +
                   ", self-intersecting " + (check.isSelfIntersecting ? "yes" : "no") + ", outward " +
                   (check.isOutward ? "yes" : "no"));
  bind(skin, out, obstacles, out.model.skin, out.report.skinTetrahedra);
}

}  // namespace pneuma::meshing
