#include "GutSurface.h"

#include <algorithm>
#include <cmath>

#include "pneuma/meshing/TriangleMesh.h"

namespace pneuma::meshing {

namespace {

constexpr double kSquareness = 2.4;  // superellipse exponent of the cavity cross-section
constexpr double kBackHalfAngle =
    55.0 * M_PI / 180.0;                      // fixed back: within this angle of the posterior midline
constexpr double kSpineNotchWidth = 0.40;     // [rad] angular width of the indentation around the spine
constexpr double kNotchDepthFraction = 0.35;  // [-] the spine notch reaches at most this far into the section
constexpr int kFloorCapRings = 2;             // rings of the fixed floor cap between its centre and the wall
constexpr double kStarMargin = 0.04;  // [m] cap and dome centres lie this far in front of the spine notch

double superPow(double u) { return std::copysign(std::pow(std::abs(u), 2.0 / kSquareness), u); }

/// Semi-axes of a cavity cross-section [m].
struct Section {
  double lateral = 0.0;
  double anterior = 0.0;
  double posterior = 0.0;
};

Section lerp(const Section& a, const Section& b, double f) {
  return {a.lateral + f * (b.lateral - a.lateral), a.anterior + f * (b.anterior - a.anterior),
          a.posterior + f * (b.posterior - a.posterior)};
}

/// The cavity's shape: sections at the floor, the umbilicus and the costal margin, and the margin's height.
class GutShape {
 public:
  GutShape(const AnatomyParams& a, const Skeleton& sk) : m_a(a.abdomen) {
    const double halfW = 0.5 * m_a.width;
    m_floor = {0.45 * halfW, 0.45 * m_a.anteriorDepth, 0.5 * m_a.posteriorDepth};
    m_navel = {halfW, m_a.anteriorDepth, m_a.posteriorDepth};
    m_rim = {halfW, sk.xiphoidTip.y() - 0.012, m_a.posteriorDepth};
    m_rimFront = sk.xiphoidTip.z() - 0.005;
    m_rimBack = sk.lumbarFront.front().z();
    m_rimSide = std::max(m_rimBack, sk.ribCurve[9][kRight].centre.back().z());
    m_spineFront = sk.lumbarFront.front().y() + 0.006;
  }

  /// height of the costal margin (diaphragm rim) at angle phi: high at the xiphoid, at the tip of rib 10
  /// laterally, low at the crura
  double rimZ(double phi) const {
    const double c = std::cos(phi);
    return m_rimSide + ((c > 0 ? m_rimFront : m_rimBack) - m_rimSide) * std::pow(std::abs(c), 1.5);
  }
  double floorZ() const { return m_a.floorLevel; }

  /// wall point at angle phi and height fraction t (0 floor, 1 costal margin)
  Eigen::Vector3d wall(double phi, double t) const {
    const double zr = rimZ(phi);
    const double z = floorZ() + t * (zr - floorZ());
    const double tNavel = std::clamp((m_a.umbilicusLevel - floorZ()) / (zr - floorZ()), 0.05, 0.95);
    // rounded below the navel, straight toward the margin above it
    const Section s = t < tNavel ? lerp(m_floor, m_navel, std::sin(0.5 * M_PI * t / tNavel))
                                 : lerp(m_navel, m_rim, (t - tNavel) / (1.0 - tNavel));
    return section(s, phi, z);
  }

 private:
  Eigen::Vector3d section(const Section& s, double phi, double z) const {
    const double c = std::cos(phi);
    double y = (c > 0 ? s.anterior : s.posterior) * superPow(c);
    // the lumbar spine bulges into the cavity on the posterior midline (at most a third of the depth)
    const double notchY =
        std::min(m_spineFront, -s.posterior + kNotchDepthFraction * (s.anterior + s.posterior));
    const double d = std::remainder(phi - M_PI, 2.0 * M_PI);
    y += (notchY + s.posterior) * std::exp(-d * d / (kSpineNotchWidth * kSpineNotchWidth));
    return {s.lateral * superPow(std::sin(phi)), y, z};
  }

  const AbdomenParams& m_a;
  Section m_floor, m_navel, m_rim;
  double m_rimFront = 0.0, m_rimBack = 0.0, m_rimSide = 0.0, m_spineFront = 0.0;
};

double ringAngle(int j, int n) { return 2.0 * M_PI * j / n; }

/// true within kBackHalfAngle of the posterior midline: the fixed back of the wall and of the dome's rim
bool isBack(double phi) { return std::abs(std::remainder(phi - M_PI, 2.0 * M_PI)) <= kBackHalfAngle + 1e-9; }

/// Triangles between two closed rings (node indices, angles 2 pi j / n), merged by angle.
void zipRings(const std::vector<int>& lower, const std::vector<int>& upper,
              std::vector<Eigen::Vector3i>& tris) {
  const long na = static_cast<long>(lower.size());
  const long nb = static_cast<long>(upper.size());
  long i = 0, j = 0;
  while (i < na || j < nb) {
    // advance on the ring whose next node comes first (exact integer comparison of (i+1)/na and (j+1)/nb)
    const bool stepLower = j == nb || (i < na && (i + 1) * nb <= (j + 1) * na);
    if (stepLower) {
      if (na > 1)
        tris.emplace_back(lower[static_cast<std::size_t>(i % na)],
                          lower[static_cast<std::size_t>((i + 1) % na)],
                          upper[static_cast<std::size_t>(j % nb)]);
      ++i;
    } else {
      if (nb > 1)
        tris.emplace_back(lower[static_cast<std::size_t>(i % na)],
                          upper[static_cast<std::size_t>((j + 1) % nb)],
                          upper[static_cast<std::size_t>(j % nb)]);
      ++j;
    }
  }
}

}  // namespace

GutSurface buildGut(const AnatomyParams& a, const Skeleton& sk) {
  const GutShape shape(a, sk);
  const Resolution& res = a.resolution;
  std::vector<Eigen::Vector3d> pts;
  GutSurface g;
  auto addNode = [&](const Eigen::Vector3d& p, sim::NodeRegion r) {
    pts.push_back(p);
    g.region.push_back(r);
    return static_cast<int>(pts.size()) - 1;
  };
  std::vector<std::vector<int>> rings;  // bottom to top, for the triangulation

  // fixed floor cap: centre and rings shrinking toward it
  Eigen::Vector3d floorCentre = Eigen::Vector3d::Zero();
  for (int j = 0; j < res.ringNodes; ++j) floorCentre += shape.wall(ringAngle(j, res.ringNodes), 0.0);
  floorCentre /= res.ringNodes;
  floorCentre.z() -= 0.015;  // a shallow bowl
  // keep the notched section star-shaped about the centre the cap rings shrink to
  floorCentre.y() = std::max(floorCentre.y(), shape.wall(M_PI, 0.0).y() + kStarMargin);
  rings.push_back({addNode(floorCentre, sim::NodeRegion::Fixed)});
  for (int c = 1; c <= kFloorCapRings; ++c) {
    const double f = static_cast<double>(c) / (kFloorCapRings + 1);
    const int n = std::max(6, static_cast<int>(std::lround(res.ringNodes * f)));
    std::vector<int> ring;
    for (int j = 0; j < n; ++j) {
      const Eigen::Vector3d w = shape.wall(ringAngle(j, n), 0.0);
      ring.push_back(addNode(floorCentre + f * (w - floorCentre) + Eigen::Vector3d(0, 0, 0.015 * f * f),
                             sim::NodeRegion::Fixed));
    }
    rings.push_back(ring);
  }

  // wall rings: the floor ring and the back are fixed, the anterior and lateral wall moves
  for (int k = 0; k < res.wallRings; ++k) {
    const double t = static_cast<double>(k) / res.wallRings;
    std::vector<int> ring;
    for (int j = 0; j < res.ringNodes; ++j) {
      const double phi = ringAngle(j, res.ringNodes);
      ring.push_back(addNode(shape.wall(phi, t),
                             k == 0 || isBack(phi) ? sim::NodeRegion::Fixed : sim::NodeRegion::Wall));
    }
    g.wallRing.push_back(ring);
    rings.push_back(ring);
  }

  // diaphragm dome: the rim on the costal margin, rings toward the apex with node spacing kept even
  std::vector<Eigen::Vector3d> rim;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double rimMeanZ = 0.0;
  for (int j = 0; j < res.domeRimNodes; ++j) {
    rim.push_back(shape.wall(ringAngle(j, res.domeRimNodes), 1.0));
    centre += rim.back();
  }
  centre /= res.domeRimNodes;
  centre.y() = std::max(centre.y(), shape.wall(M_PI, 1.0).y() + kStarMargin);
  rimMeanZ = centre.z();
  const double apexZ = rimMeanZ + a.abdomen.domeHeight;
  for (int r = 0; r < res.domeRings; ++r) {
    const double s = 1.0 - static_cast<double>(r) / res.domeRings;  // radius fraction
    const int n =
        r == 0 ? res.domeRimNodes : std::max(6, static_cast<int>(std::lround(res.domeRimNodes * s)));
    std::vector<int> ring;
    for (int j = 0; j < n; ++j) {
      const double phi = ringAngle(j, n);
      const Eigen::Vector3d w = shape.wall(phi, 1.0);
      Eigen::Vector3d p = centre + s * (w - centre);
      p.z() = apexZ + (w.z() - apexZ) * s * s;
      // the rim's posterior arc (the crura and the arcuate ligaments) is fixed to the back like the wall
      // below
      const bool isCrural = r == 0 && isBack(phi);
      ring.push_back(addNode(p, isCrural ? sim::NodeRegion::Fixed : sim::NodeRegion::Diaphragm));
    }
    g.domeRing.push_back(ring);
    g.domeRingRise.push_back(a.abdomen.domeHeight * (1.0 - s * s));
    rings.push_back(ring);
  }
  g.apex = addNode(Eigen::Vector3d(centre.x(), centre.y(), apexZ), sim::NodeRegion::Diaphragm);
  rings.push_back({g.apex});

  // triangulate ring to ring and orient outward
  std::vector<Eigen::Vector3i> tris;
  for (std::size_t r = 0; r + 1 < rings.size(); ++r) zipRings(rings[r], rings[r + 1], tris);
  g.rest.resize(3, static_cast<Eigen::Index>(pts.size()));
  for (std::size_t i = 0; i < pts.size(); ++i) g.rest.col(static_cast<Eigen::Index>(i)) = pts[i];
  g.triangles.resize(3, static_cast<Eigen::Index>(tris.size()));
  for (std::size_t f = 0; f < tris.size(); ++f) g.triangles.col(static_cast<Eigen::Index>(f)) = tris[f];
  if (enclosedVolume(g.rest, g.triangles) < 0.0) g.triangles.row(1).swap(g.triangles.row(2));

  // The dome's cap above the zone of apposition: its rings are the spine-notched outline scaled toward a
  // centre near the notch, so the inner rings are concave at the back and zipping them leaves slivers there
  // (on the default model a triangle 3.7 mm high on a 31 mm base beside the apex, which turned over at
  // calm end-inspiration: the gut's and the cavity's only self-crossings). The cap is a height field over
  // the transverse (x-y) plane, so its Delaunay triangulation there (delaunayFlips()) keeps the nodes and
  // replaces the slivers. The zone of apposition and the rim keep the ring-to-ring triangulation.
  std::vector<char> isCap(pts.size(), 0);
  isCap[static_cast<std::size_t>(g.apex)] = 1;
  for (std::size_t r = 0; r < g.domeRing.size(); ++r)
    if (g.domeRingRise[r] > a.abdomen.appositionHeight)
      for (const int v : g.domeRing[r]) isCap[static_cast<std::size_t>(v)] = 1;
  std::vector<char> onCap(static_cast<std::size_t>(g.triangles.cols()), 0);
  for (Eigen::Index f = 0; f < g.triangles.cols(); ++f)
    onCap[static_cast<std::size_t>(f)] = isCap[static_cast<std::size_t>(g.triangles(0, f))] &&
                                         isCap[static_cast<std::size_t>(g.triangles(1, f))] &&
                                         isCap[static_cast<std::size_t>(g.triangles(2, f))];
  delaunayFlips(g.triangles, g.rest.topRows<2>(), onCap);
  return g;
}

}  // namespace pneuma::meshing
