#include "TissueBodies.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "Anchors.h"
#include "pneuma/sim/Elements.h"
#include "pneuma/sim/Error.h"

namespace pneuma::meshing {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kBoneGap = 0.003;  // [m] deep face to the bone surface
constexpr double kTieArm = 0.02;    // [m] length of a deep node's three tie springs
// [m] a sliding deep node's tie: anchored this far inside the bone along the inward normal, so that it holds
// the node's distance to the bone and hardly a slide along it (a slide s lengthens it by about s^2 / 2 l)
constexpr double kSlideArm = 0.1;
constexpr double kProfilePower = 0.6;  // [-] fullness of the thickness profile sin^p (1: a plain sine)
constexpr int kPectoralColumns = 5;    // [-] sternal border, costochondral junction, then three along the rib
// [-] the pectoral's lateral edge: this share of the way from the costochondral junction back to the rib's
// most lateral point (about the anterior axillary line)
constexpr double kPectoralLateralShare = 0.35;
constexpr int kDeltoidRows = 5;     // [-] from above the acromion down to the deltoid tuberosity
constexpr int kDeltoidColumns = 5;  // [-] round the arm from the front to the back
// [rad] the cap's sweep round the upper arm, centred on its lateral side (front and back of the shoulder)
constexpr double kDeltoidSweep = 200.0 * kPi / 180.0;
// [-] share of the upper arm the cap covers below the glenohumeral joint (the deltoid tuberosity)
constexpr double kDeltoidReach = 0.45;
constexpr double kDeltoidDepth = 0.012;  // [m] deep face off the humerus (the rotator cuff between)

/// A lens's deep face: an R x C grid of points on the bones (row-major), the bone each is tied to, the
/// outward unit normal there, and whether the node slides on the bone (held along the normal only).
struct DeepGrid {
  int rows = 0, cols = 0;
  std::vector<Eigen::Vector3d> point;
  std::vector<int> bone;
  std::vector<Eigen::Vector3d> outward;
  std::vector<bool> slides;

  int at(int r, int c) const { return r * cols + c; }
  bool isRim(int r, int c) const { return r == 0 || c == 0 || r == rows - 1 || c == cols - 1; }
};

/// The outward unit normal of the deep face (the chest wall under the lens) at grid point `i`: the cross
/// product of the grid's tangents along its rows and columns (central differences, one-sided at the rim),
/// turned to the side of `g.outward`. A rib's own normal (g.outward) lies in the rib's plane, which tilts
/// about 40 deg down at the front of the lower ribs: a tie along it let the deep nodes slide into the ribs
/// below as the ribs rose.
Eigen::Vector3d wallNormal(const DeepGrid& g, std::size_t i) {
  const int r = static_cast<int>(i) / g.cols, c = static_cast<int>(i) % g.cols;
  auto p = [&](int rr, int cc) { return g.point[static_cast<std::size_t>(g.at(rr, cc))]; };
  const Eigen::Vector3d alongRow = p(r, std::min(c + 1, g.cols - 1)) - p(r, std::max(c - 1, 0));
  const Eigen::Vector3d alongColumn = p(std::min(r + 1, g.rows - 1), c) - p(std::max(r - 1, 0), c);
  const Eigen::Vector3d n = alongRow.cross(alongColumn).normalized();
  return n.dot(g.outward[i]) >= 0.0 ? n : Eigen::Vector3d(-n);
}

/// Appends the lens over `g` with largest thickness `thickness` [m] as volume body `name`: nodes, surface,
/// springs and ties (TissueBodies.h).
void addLens(const std::string& name, const DeepGrid& g, double thickness, const TissueGains& tg,
             ElementSink& sink, sim::Model& m) {
  const int first = m.nodes.size();
  std::vector<int> deep(g.point.size()), superficial(g.point.size(), -1);
  std::vector<Eigen::Vector3d> x;
  for (std::size_t i = 0; i < g.point.size(); ++i) {
    deep[i] = first + static_cast<int>(x.size());
    x.push_back(g.point[i]);
  }
  for (int r = 1; r + 1 < g.rows; ++r)
    for (int c = 1; c + 1 < g.cols; ++c) {
      const double u = static_cast<double>(r) / (g.rows - 1), v = static_cast<double>(c) / (g.cols - 1);
      const double t = thickness * std::pow(std::sin(kPi * u) * std::sin(kPi * v), kProfilePower);
      const int i = g.at(r, c);
      superficial[static_cast<std::size_t>(i)] = first + static_cast<int>(x.size());
      x.push_back(g.point[static_cast<std::size_t>(i)] + t * g.outward[static_cast<std::size_t>(i)]);
    }
  // the surface: the deep face and the superficial one (the deep rim shared), as two triangulations of the
  // grid
  auto top = [&](int r, int c) {
    const int i = g.at(r, c);
    return g.isRim(r, c) ? deep[static_cast<std::size_t>(i)] : superficial[static_cast<std::size_t>(i)];
  };
  std::vector<Eigen::Vector3i> tris;
  for (int r = 0; r + 1 < g.rows; ++r)
    for (int c = 0; c + 1 < g.cols; ++c) {
      const int a = g.at(r, c), b = g.at(r, c + 1), d = g.at(r + 1, c), e = g.at(r + 1, c + 1);
      // split along the diagonal through an interior node, so that no superficial triangle joins three rim
      // nodes (it would repeat a deep one)
      if (!g.isRim(r, c) || !g.isRim(r + 1, c + 1)) {
        tris.push_back({top(r, c), top(r + 1, c), top(r + 1, c + 1)});
        tris.push_back({top(r, c), top(r + 1, c + 1), top(r, c + 1)});
      } else {
        tris.push_back({top(r, c), top(r + 1, c), top(r, c + 1)});
        tris.push_back({top(r, c + 1), top(r + 1, c), top(r + 1, c + 1)});
      }
      tris.push_back({deep[static_cast<std::size_t>(a)], deep[static_cast<std::size_t>(e)],
                      deep[static_cast<std::size_t>(d)]});
      tris.push_back({deep[static_cast<std::size_t>(a)], deep[static_cast<std::size_t>(b)],
                      deep[static_cast<std::size_t>(e)]});
    }
  const int n = static_cast<int>(x.size());
  m.nodes.rest.conservativeResize(3, first + n);
  for (int i = 0; i < n; ++i) m.nodes.rest.col(first + i) = x[static_cast<std::size_t>(i)];
  Eigen::Matrix3Xi t(3, static_cast<Eigen::Index>(tris.size()));
  for (std::size_t i = 0; i < tris.size(); ++i) t.col(static_cast<Eigen::Index>(i)) = tris[i];
  double v0 = sim::enclosedVolume(m.nodes.rest, t);
  if (v0 < 0.0) {  // the grid's orientation decides the winding: outward normals
    t.row(1).swap(t.row(2));
    v0 = -v0;
  }
  if (!(v0 > 1e-7))
    throw sim::Error(name + ": the tissue body encloses no volume (" + std::to_string(v0) + " m^3)");
  // nodes: equal shares of the body's mass
  m.nodes.mass.conservativeResize(first + n);
  for (int i = 0; i < n; ++i) {
    m.nodes.mass(first + i) = tg.density * v0 / n;
    m.nodes.region.push_back(sim::NodeRegion::Tissue);
  }
  m.volumes.name.push_back(name);
  m.volumes.triangles.push_back(t);
  m.volumes.kappa.conservativeResize(m.volumes.size());
  m.volumes.kappa(m.volumes.size() - 1) = tg.kappa;

  // springs: along the surface edges, and through the thickness to the deep node below and its neighbours
  auto node = [&](int i) { return Endpoint::atNode(i, m.nodes.rest); };
  std::map<std::pair<int, int>, bool> edges;
  for (Eigen::Index f = 0; f < t.cols(); ++f)
    for (int k = 0; k < 3; ++k) edges[std::minmax(t(k, f), t((k + 1) % 3, f))] = true;
  for (int r = 1; r + 1 < g.rows; ++r)
    for (int c = 1; c + 1 < g.cols; ++c) {
      const int s = superficial[static_cast<std::size_t>(g.at(r, c))];
      for (const auto& [dr, dc] : {std::pair{0, 0}, {-1, 0}, {1, 0}, {0, -1}, {0, 1}})
        edges[std::minmax(s, deep[static_cast<std::size_t>(g.at(r + dr, c + dc))])] = true;
    }
  for (const auto& [e, unused] : edges) {
    (void)unused;
    sink.add(sim::ElementGroup::Cartilage, node(e.first), node(e.second), tg.surface, 0.0);
  }
  // ties: a fixed deep node to its bone by three springs along the world axes; a sliding one by one long
  // spring along the chest wall's normal (wallNormal()), as stiff along it as a tie
  for (std::size_t i = 0; i < g.point.size(); ++i) {
    if (g.slides[i]) {
      const Eigen::Vector3d wall = wallNormal(g, i);
      sink.add(sim::ElementGroup::Cartilage, Endpoint::onBody(g.bone[i], g.point[i] - kSlideArm * wall),
               node(deep[i]), tg.tie, 0.0, kSlideArm / kTieArm);
      continue;
    }
    for (int k = 0; k < 3; ++k)
      sink.add(sim::ElementGroup::Cartilage,
               Endpoint::onBody(g.bone[i], g.point[i] + kTieArm * Eigen::Vector3d::Unit(k)), node(deep[i]),
               tg.tie, 0.0);
  }
}

/// The deep face of the pectoral on `side`: a row at each of ribs 2-6, columns from the
/// sternal border (tied to the sternum) over the costochondral junction along the rib (tied to it).
DeepGrid pectoralGrid(const AnatomyParams& a, const Skeleton& sk, int side) {
  constexpr int kFirstRib = 2, kLastRib = 6;
  const int levels = kLastRib - kFirstRib + 1;
  DeepGrid g;
  g.rows = levels;
  g.cols = kPectoralColumns;
  g.point.resize(static_cast<std::size_t>(g.rows * g.cols));
  g.bone.resize(g.point.size());
  g.outward.resize(g.point.size());
  g.slides.resize(g.point.size());
  for (int r = 0; r < g.rows; ++r)
    for (int c = 0; c < g.cols; ++c) g.slides[static_cast<std::size_t>(g.at(r, c))] = r > 0 && c > 0;
  const Eigen::Vector3d front = -sk.sternumAxis.cross(Eigen::Vector3d::UnitX()).normalized();
  const double sternumHalf = 0.5 * a.sternum.thickness;  // [m]
  for (int l = 0; l < levels; ++l) {
    const int level = kFirstRib + l;  // 1-based rib level
    const RibCurve& rib = sk.ribCurve[static_cast<std::size_t>(level - 1)][static_cast<std::size_t>(side)];
    std::size_t lateral = 0;
    for (std::size_t i = 0; i < rib.centre.size(); ++i)
      if (std::abs(rib.centre[i].x()) > std::abs(rib.centre[lateral].x())) lateral = i;
    const double sEnd = rib.arc[lateral] + kPectoralLateralShare * (rib.length() - rib.arc[lateral]);
    const int r = l;
    const int i0 = g.at(r, 0);
    g.point[static_cast<std::size_t>(i0)] =
        sk.costalNotch[static_cast<std::size_t>(level - 1)][static_cast<std::size_t>(side)] +
        (sternumHalf + kBoneGap) * front;
    g.bone[static_cast<std::size_t>(i0)] = sk.sternum;
    g.outward[static_cast<std::size_t>(i0)] = front;
    for (int c = 1; c < g.cols; ++c) {
      const double s = rib.length() - (rib.length() - sEnd) * (c - 1) / (g.cols - 2);
      const int i = g.at(r, c);
      const Eigen::Vector3d inward = (rib.at(s, 1.0) - rib.at(s)).normalized();
      g.point[static_cast<std::size_t>(i)] = rib.at(s, -(0.5 * rib.thickness + kBoneGap));
      g.bone[static_cast<std::size_t>(i)] =
          sk.rib[static_cast<std::size_t>(level - 1)][static_cast<std::size_t>(side)];
      g.outward[static_cast<std::size_t>(i)] = -inward;
    }
  }
  return g;
}

/// [m] radius of the humerus (Skeleton.cpp's sweep: head, neck, shaft) at `along` [m] down its axis from the
/// glenohumeral joint; above the head, the head's
double humerusRadius(double along, double armLength) {
  const std::array<std::pair<double, double>, 5> table{
      {{-1.0, 0.022}, {0.0, 0.022}, {0.025, 0.016}, {0.07, 0.011}, {0.5 * armLength, 0.010}}};
  for (std::size_t i = 1; i < table.size(); ++i)
    if (along <= table[i].first) {
      const double f = (along - table[i - 1].first) / (table[i].first - table[i - 1].first);
      return (1.0 - f) * table[i - 1].second + f * table[i].second;
    }
  return table.back().second;
}

/// The deep face of the shoulder cap on `side`: round the upper arm's axis from the front over the lateral
/// side to the back, from above the acromion down to the deltoid tuberosity; the top row is tied to the
/// scapula (the acromion), the others to the humerus.
DeepGrid deltoidGrid(const Skeleton& sk, int side) {
  const GirdleSide& gs = sk.girdle[static_cast<std::size_t>(side)];
  const Eigen::Vector3d down = (gs.elbow - gs.glenohumeral).normalized();
  const double armLength = (gs.elbow - gs.glenohumeral).norm();
  // the lateral direction round the arm: away from the midline, square to the arm's axis
  const double sx = side == kRight ? 1.0 : -1.0;
  Eigen::Vector3d lateral = Eigen::Vector3d(sx, 0.0, 0.0);
  lateral = (lateral - lateral.dot(down) * down).normalized();
  const Eigen::Vector3d anterior = Eigen::Vector3d::UnitY();
  const Eigen::Vector3d forward = (anterior - anterior.dot(down) * down).normalized();
  DeepGrid g;
  g.rows = kDeltoidRows;
  g.cols = kDeltoidColumns;
  g.point.resize(static_cast<std::size_t>(g.rows * g.cols));
  g.bone.resize(g.point.size());
  g.outward.resize(g.point.size());
  g.slides.assign(g.point.size(), false);
  // the top row rises over the humeral head to the acromion's height
  const double top = std::max(0.0, (gs.acromion - gs.glenohumeral).dot(-down)) + kBoneGap;
  for (int r = 0; r < g.rows; ++r) {
    const double f = static_cast<double>(r) / (g.rows - 1);
    const double along = -top + f * (top + kDeltoidReach * armLength);  // [m] down the arm from the joint
    const double radius = humerusRadius(along, armLength) + kDeltoidDepth;
    for (int c = 0; c < g.cols; ++c) {
      const double phi = -0.5 * kDeltoidSweep + kDeltoidSweep * c / (g.cols - 1);
      // sweep from the front (phi < 0 toward anterior) over lateral to the back
      const Eigen::Vector3d dir = std::cos(phi) * lateral - std::sin(phi) * forward;
      const int i = g.at(r, c);
      g.point[static_cast<std::size_t>(i)] = gs.glenohumeral + along * down + radius * dir;
      g.bone[static_cast<std::size_t>(i)] = r == 0 ? gs.scapula : gs.humerus;
      g.outward[static_cast<std::size_t>(i)] = dir;
    }
  }
  return g;
}

}  // namespace

void buildTissueBodies(const AnatomyParams& a, const Skeleton& sk, sim::Model& model) {
  const TissueGains& tg = a.gains.tissue;
  if (!(tg.kappa > 0.0)) return;
  ElementSink sink(a.gains, model);
  for (int side : {kRight, kLeft})
    addLens(side == kRight ? "pectoral_right" : "pectoral_left", pectoralGrid(a, sk, side),
            tg.pectoralThickness, tg, sink, model);
  if (sk.hasGirdle)
    for (int side : {kRight, kLeft})
      addLens(side == kRight ? "deltoid_right" : "deltoid_left", deltoidGrid(sk, side), tg.deltoidThickness,
              tg, sink, model);
}

}  // namespace pneuma::meshing
