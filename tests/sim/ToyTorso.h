#pragma once
// A small synthetic torso for sim tests and benchmarks: a fixed lumbar body, three thoracic segments
// on ball joints with passive stiffness, five ribs per side on costovertebral ball joints with
// friction (Eq. 3), a sternum held by cartilage springs, external and internal intercostals, and an
// ellipsoidal gut (icosphere) with a fixed back and bottom, a diaphragm dome, rectus and transversus
// strands. It has every part the default model has, at a tenth of the size, so tests can run the
// whole pipeline without the meshing layer. Gains are plausible SI values, not calibrated ones.

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <utility>
#include <vector>

#include "pneuma/sim/Elements.h"
#include "pneuma/sim/Model.h"
#include "pneuma/sim/State.h"
#include "pneuma/sim/Step.h"

namespace pneuma::sim::test {

// unit icosphere: `subdivisions` loop subdivisions of an icosahedron, outward counter-clockwise faces
inline void icosphere(int subdivisions, Eigen::Matrix3Xd& vertices, Eigen::Matrix3Xi& faces) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                    {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                    {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : v) p.normalize();
  std::vector<Eigen::Vector3i> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                    {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                    {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                    {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[static_cast<std::size_t>(a)] + v[static_cast<std::size_t>(b)]).normalized());
      const int i = static_cast<int>(v.size()) - 1;
      mid[key] = i;
      return i;
    };
    std::vector<Eigen::Vector3i> g;
    for (const auto& tri : f) {
      const int a = midpoint(tri[0], tri[1]), b = midpoint(tri[1], tri[2]), c = midpoint(tri[2], tri[0]);
      g.push_back({tri[0], a, c});
      g.push_back({tri[1], b, a});
      g.push_back({tri[2], c, b});
      g.push_back({a, b, c});
    }
    f = g;
  }
  vertices.resize(3, static_cast<Eigen::Index>(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i) vertices.col(static_cast<Eigen::Index>(i)) = v[i];
  faces.resize(3, static_cast<Eigen::Index>(f.size()));
  for (std::size_t i = 0; i < f.size(); ++i) faces.col(static_cast<Eigen::Index>(i)) = f[i];
}

// inertia [kg m^2] about the centroid of equal point masses at `points`, plus a small isotropic term
inline Eigen::Matrix3d pointCloudInertia(const std::vector<Eigen::Vector3d>& points, double mass,
                                         const Eigen::Vector3d& com, double radius) {
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Identity() * (0.4 * mass * radius * radius);
  const double m = mass / static_cast<double>(points.size());
  for (const auto& p : points) {
    const Eigen::Vector3d r = p - com;
    inertia += m * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
  }
  return inertia;
}

inline int addBody(Model& m, const std::string& name, bool fixed, double mass, const Eigen::Vector3d& com,
                   const Eigen::Matrix3d& inertia) {
  const int i = m.bodies.size();
  m.bodies.name.push_back(name);
  m.bodies.isFixed.push_back(fixed ? 1 : 0);
  m.bodies.mass.conservativeResize(i + 1);
  m.bodies.mass(i) = mass;
  m.bodies.com.conservativeResize(3, i + 1);
  m.bodies.com.col(i) = com;
  m.bodies.inertia.push_back(inertia);
  m.bodies.mesh.emplace_back();
  return i;
}

inline void addJoint(Model& m, const std::string& name, int parent, int child, const Eigen::Vector3d& anchor,
                     double friction, double stiffness,
                     const Eigen::Vector3d& axis = Eigen::Vector3d::UnitX(), double lockStiffness = 0.0) {
  const int i = m.joints.size();
  m.joints.name.push_back(name);
  m.joints.parent.push_back(parent);
  m.joints.child.push_back(child);
  m.joints.anchor.conservativeResize(3, i + 1);
  m.joints.anchor.col(i) = anchor;
  m.joints.friction.conservativeResize(i + 1);
  m.joints.friction(i) = friction;
  m.joints.stiffness.conservativeResize(i + 1);
  m.joints.stiffness(i) = stiffness;
  m.joints.axis.conservativeResize(3, i + 1);
  m.joints.axis.col(i) = axis;
  m.joints.lockStiffness.conservativeResize(i + 1);
  m.joints.lockStiffness(i) = lockStiffness;
}

// one endpoint: a body point (world position p) or a node
struct End {
  int body = -1;
  int node = -1;
  Eigen::Vector3d world = Eigen::Vector3d::Zero();
};

inline void addEnd(const Model& m, AnchorSet& set, const End& e) {
  if (e.body >= 0)
    set.addBodyPoint(e.body, e.world - m.bodies.com.col(e.body));
  else
    set.addNodePoint(Eigen::Vector3i(e.node, -1, -1), Eigen::Vector3d(1, 0, 0));
}

inline Eigen::Vector3d endPosition(const Model& m, const End& e) {
  return e.body >= 0 ? e.world : Eigen::Vector3d(m.nodes.rest.col(e.node));
}

inline void addElement(Model& m, ElementGroup g, const End& a, const End& b, double kac, double kpe,
                       double damping) {
  const int i = m.elements.size();
  m.elements.group.push_back(g);
  addEnd(m, m.elements.endA, a);
  addEnd(m, m.elements.endB, b);
  m.elements.restLength.conservativeResize(i + 1);
  m.elements.restLength(i) = (endPosition(m, b) - endPosition(m, a)).norm();
  for (auto* v : {&m.elements.kac, &m.elements.kpe, &m.elements.damping}) v->conservativeResize(i + 1);
  m.elements.kac(i) = kac;
  m.elements.kpe(i) = kpe;
  m.elements.damping(i) = damping;
}

// the toy torso; `gutSubdivisions` sets the gut resolution (2: 162 nodes, 3: 642, 4: 2562)
inline Model makeToyTorso(int gutSubdivisions = 2) {
  using Eigen::Vector3d;
  constexpr double kPi = 3.14159265358979323846;
  Model m;
  m.name = "toy_torso";
  m.anatomy = "synthetic";

  // spine: fixed lumbar, three thoracic segments chained by stiff ball joints
  const int lumbar =
      addBody(m, "lumbar", true, 2.0, Vector3d(0, -0.08, 0.20), Eigen::Matrix3d::Identity() * 1e-3);
  std::vector<int> thoracic;
  int parent = lumbar;
  for (int s = 0; s < 3; ++s) {
    const double z = 0.32 + 0.1 * s;
    const int b = addBody(m, "thoracic_" + std::to_string(s + 1), false, 0.5, Vector3d(0, -0.08, z),
                          Eigen::Matrix3d::Identity() * (0.4 * 0.5 * 0.03 * 0.03));
    addJoint(m, "intervertebral_" + std::to_string(s + 1), parent, b, Vector3d(0, -0.08, z - 0.05), 0.05,
             40.0);
    thoracic.push_back(b);
    parent = b;
  }

  // sternum
  const Vector3d sternumCom(0, 0.085, 0.38);
  const int sternum = addBody(m, "sternum", false, 0.15, sternumCom, Eigen::Matrix3d::Identity() * 2e-4);

  // ribs: arcs from the spine around to the front, dropping toward the sternum
  constexpr int kLevels = 5, kSamples = 9;
  auto ribPoint = [&](int level, int side, double theta) {
    const double z = 0.30 + 0.045 * level;
    return Vector3d(side * (0.02 + 0.12 * std::sin(theta)), -0.08 * std::cos(theta),
                    z - 0.03 * (1.0 - std::cos(theta)));
  };
  std::map<std::pair<int, int>, int> rib;  // (level, side) -> body
  for (int level = 0; level < kLevels; ++level) {
    for (int side : {-1, 1}) {
      std::vector<Vector3d> pts;
      for (int k = 0; k < kSamples; ++k) pts.push_back(ribPoint(level, side, kPi * k / (kSamples - 1)));
      Vector3d com = Vector3d::Zero();
      for (const auto& p : pts) com += p;
      com /= kSamples;
      const std::string name = "rib" + std::to_string(kLevels - level) + (side < 0 ? "_left" : "_right");
      const int b = addBody(m, name, false, 0.1, com, pointCloudInertia(pts, 0.1, com, 0.01));
      const int seg = thoracic[static_cast<std::size_t>(std::min(2, level * 3 / kLevels))];
      addJoint(m, "costovertebral_" + name, seg, b, ribPoint(level, side, 0.0), 0.02, 3.0);
      rib[{level, side}] = b;
      // cartilage: two springs from the rib front to the sternum
      for (double th : {kPi, 0.9 * kPi}) {
        const Vector3d p = ribPoint(level, side, th);
        addElement(m, ElementGroup::Cartilage, End{b, -1, p},
                   End{sternum, -1, Vector3d(0.0, 0.085, p.z() + 0.01)}, 0.0, 2000.0, 2.0);
      }
    }
  }

  // intercostals between neighbouring ribs: external down and forward, internal down and backward
  for (int level = 1; level < kLevels; ++level) {
    for (int side : {-1, 1}) {
      const int upper = rib[{level, side}], lower = rib[{level - 1, side}];
      for (int k = 1; k < kSamples - 2; ++k) {
        const double th = kPi * k / (kSamples - 1), dth = 0.08 * kPi;
        addElement(m, ElementGroup::IntercostalExternal, End{upper, -1, ribPoint(level, side, th)},
                   End{lower, -1, ribPoint(level - 1, side, th + dth)}, 400.0, 0.0, 1.0);
        addElement(m, ElementGroup::IntercostalInternal, End{upper, -1, ribPoint(level, side, th + dth)},
                   End{lower, -1, ribPoint(level - 1, side, th)}, 400.0, 0.0, 1.0);
      }
    }
  }

  // gut: ellipsoid with a fixed back and bottom, a diaphragm dome and a moving wall
  Eigen::Matrix3Xd unit;
  icosphere(gutSubdivisions, unit, m.gut.triangles);
  const Vector3d centre(0, 0.0, 0.17), radii(0.11, 0.085, 0.12);
  m.nodes.rest = (radii.asDiagonal() * unit).colwise() + centre;
  const int nn = m.nodes.size();
  m.nodes.region.resize(static_cast<std::size_t>(nn));
  int moving = 0;
  for (int i = 0; i < nn; ++i) {
    const Vector3d p = m.nodes.rest.col(i);
    NodeRegion r = NodeRegion::Wall;
    if (p.y() < -0.03 || p.z() < 0.09)
      r = NodeRegion::Fixed;
    else if (p.z() > 0.23)
      r = NodeRegion::Diaphragm;
    m.nodes.region[static_cast<std::size_t>(i)] = r;
    if (r != NodeRegion::Fixed) ++moving;
  }
  m.nodes.mass = Eigen::VectorXd::Zero(nn);
  for (int i = 0; i < nn; ++i)
    m.nodes.mass(i) = m.nodes.isFixed(i) ? 0.0 : 8.0 / moving;  // 8 kg wall (Section 6.1)
  m.gut.kappa = 2e5;

  // surface strands along mesh edges: diaphragm dome, rectus (front, vertical), transversus (the rest)
  std::map<std::pair<int, int>, bool> edges;
  for (Eigen::Index f = 0; f < m.gut.triangles.cols(); ++f)
    for (int k = 0; k < 3; ++k)
      edges[std::minmax(m.gut.triangles(k, f), m.gut.triangles((k + 1) % 3, f))] = true;
  std::vector<int> rim;
  for (const auto& [e, unused] : edges) {
    (void)unused;
    const int a = e.first, b = e.second;
    if (m.nodes.isFixed(a) && m.nodes.isFixed(b)) continue;
    const auto ra = m.nodes.region[static_cast<std::size_t>(a)],
               rb = m.nodes.region[static_cast<std::size_t>(b)];
    const Vector3d d = (m.nodes.rest.col(b) - m.nodes.rest.col(a)).normalized();
    const Vector3d mid = 0.5 * (m.nodes.rest.col(a) + m.nodes.rest.col(b));
    if (ra == NodeRegion::Diaphragm && rb == NodeRegion::Diaphragm)
      addElement(m, ElementGroup::Diaphragm, End{-1, a, {}}, End{-1, b, {}}, 300.0, 30.0, 0.5);
    else if (mid.y() > 0.05 && std::abs(d.z()) > 0.7)
      addElement(m, ElementGroup::Rectus, End{-1, a, {}}, End{-1, b, {}}, 300.0, 60.0, 0.5);
    else
      addElement(m, ElementGroup::TransversusObliques, End{-1, a, {}}, End{-1, b, {}}, 0.0, 60.0, 0.5);
    if ((ra == NodeRegion::Diaphragm) != (rb == NodeRegion::Diaphragm))
      rim.push_back(ra == NodeRegion::Diaphragm ? a : b);
  }
  // diaphragm rim strands up to the lowest ribs (costal margin)
  std::sort(rim.begin(), rim.end());
  rim.erase(std::unique(rim.begin(), rim.end()), rim.end());
  for (int n : rim) {
    const Vector3d p = m.nodes.rest.col(n);
    const int side = p.x() < 0 ? -1 : 1;
    const double th = std::atan2(std::abs(p.x()), -p.y());
    addElement(m, ElementGroup::Diaphragm, End{-1, n, {}}, End{rib[{0, side}], -1, ribPoint(0, side, th)},
               300.0, 30.0, 0.5);
  }

  // lung cavity: one ring per rib level, capped at the top (thoracic segment) and the bottom (diaphragm apex)
  int apex = 0;
  for (int i = 1; i < nn; ++i)
    if (m.nodes.rest(2, i) > m.nodes.rest(2, apex)) apex = i;
  const int ringSize = 2 * (kSamples - 1);
  for (int level = 0; level < kLevels; ++level) {
    for (int k = 0; k < kSamples - 1; ++k)
      m.cavity.vertices.addBodyPoint(
          rib[{level, 1}], ribPoint(level, 1, kPi * k / (kSamples - 1)) - m.bodies.com.col(rib[{level, 1}]));
    for (int k = kSamples - 1; k > 0; --k)
      m.cavity.vertices.addBodyPoint(rib[{level, -1}], ribPoint(level, -1, kPi * k / (kSamples - 1)) -
                                                           m.bodies.com.col(rib[{level, -1}]));
  }
  const int top = m.cavity.vertices.size();
  m.cavity.vertices.addBodyPoint(thoracic[2], Vector3d(0, 0.08, 0.51) - m.bodies.com.col(thoracic[2]));
  const int bottom = m.cavity.vertices.size();
  m.cavity.vertices.addNodePoint(Eigen::Vector3i(apex, -1, -1), Vector3d(1, 0, 0));
  std::vector<Eigen::Vector3i> tris;
  for (int level = 0; level + 1 < kLevels; ++level) {
    for (int k = 0; k < ringSize; ++k) {
      const int a = level * ringSize + k, b = level * ringSize + (k + 1) % ringSize;
      tris.push_back({a, b, a + ringSize});
      tris.push_back({b, b + ringSize, a + ringSize});
    }
  }
  for (int k = 0; k < ringSize; ++k) {
    tris.push_back({(kLevels - 1) * ringSize + k, (kLevels - 1) * ringSize + (k + 1) % ringSize, top});
    tris.push_back({(k + 1) % ringSize, k, bottom});
  }
  m.cavity.triangles.resize(3, static_cast<Eigen::Index>(tris.size()));
  for (std::size_t i = 0; i < tris.size(); ++i)
    m.cavity.triangles.col(static_cast<Eigen::Index>(i)) = tris[i];
  Eigen::Matrix3Xd cavityRest(3, m.cavity.vertices.size());
  for (int i = 0; i < m.cavity.vertices.size(); ++i) {
    const int b = m.cavity.vertices.body[static_cast<std::size_t>(i)];
    cavityRest.col(i) = b >= 0 ? Vector3d(m.bodies.com.col(b) + m.cavity.vertices.local.col(i))
                               : Vector3d(m.nodes.rest.col(apex));
  }
  if (enclosedVolume(cavityRest, m.cavity.triangles) < 0.0)
    m.cavity.triangles.row(1).swap(m.cavity.triangles.row(2));

  // landmarks
  int umbilicus = 0;
  for (int i = 1; i < nn; ++i)
    if ((m.nodes.rest.col(i) - Vector3d(0, 0.09, 0.14)).norm() <
        (m.nodes.rest.col(umbilicus) - Vector3d(0, 0.09, 0.14)).norm())
      umbilicus = i;
  m.landmarks.name = {"xiphoid", "umbilicus", "diaphragm_apex", "rib8_lateral_left", "rib8_lateral_right"};
  m.landmarks.points.addBodyPoint(sternum, Vector3d(0, 0.085, 0.30) - sternumCom);
  m.landmarks.points.addNodePoint(Eigen::Vector3i(umbilicus, -1, -1), Vector3d(1, 0, 0));
  m.landmarks.points.addNodePoint(Eigen::Vector3i(apex, -1, -1), Vector3d(1, 0, 0));
  for (int side : {-1, 1})
    m.landmarks.points.addBodyPoint(rib[{0, side}],
                                    ribPoint(0, side, 0.5 * kPi) - m.bodies.com.col(rib[{0, side}]));
  return m;
}

/// Appends a soft-tissue volume body (VolumeBodies) to a toy torso: a flattened icosphere lens (one
/// subdivision: 42 Tissue nodes, 0.2 kg) over rib 3 right's front, its faces' edges two-sided Cartilage
/// springs, and each node on its deep face (toward the rib) tied to the rib by three Cartilage springs along
/// the world axes (zero-length-spring stiffness k I for small motions, Zordan et al. 2004, Section 7).
/// `kappa` [Pa] is its bulk modulus; returns the index of its outermost node (the lens's apex).
inline int addToyTissueBody(Model& m, double kappa = 2e4) {
  using Eigen::Vector3d;
  int rib = -1;
  for (int b = 0; b < m.bodies.size(); ++b)
    if (m.bodies.name[static_cast<std::size_t>(b)] == "rib3_right") rib = b;
  const Vector3d normal = Vector3d(0.75, 0.66, 0.0).normalized();  // [-] outward, anterolateral
  const Vector3d centre(0.115, 0.075, 0.34);                       // [m] just outside the rib's front
  const Vector3d side = Vector3d::UnitZ().cross(normal);
  Eigen::Matrix3Xd unit;
  Eigen::Matrix3Xi faces;
  icosphere(1, unit, faces);
  const int first = m.nodes.size(), n = static_cast<int>(unit.cols());
  m.nodes.rest.conservativeResize(3, first + n);
  m.nodes.mass.conservativeResize(first + n);
  int apex = first;
  for (int i = 0; i < n; ++i) {
    const Vector3d u = unit.col(i);
    m.nodes.rest.col(first + i) = centre + 0.035 * u.x() * side + 0.03 * u.z() * Vector3d::UnitZ() +
                                  0.012 * u.y() * normal;  // [m] a lens 70 x 60 x 24 mm
    m.nodes.mass(first + i) = 0.2 / n;                     // [kg]
    m.nodes.region.push_back(NodeRegion::Tissue);
    if (u.y() > unit.col(apex - first).y()) apex = first + i;
  }
  faces.array() += first;
  // the map above may mirror the icosphere: outward normals again
  if (enclosedVolume(m.nodes.rest, faces) < 0.0) faces.row(1).swap(faces.row(2));
  m.volumes.name.push_back("toy_tissue_" + std::to_string(m.volumes.size()));
  m.volumes.triangles.push_back(faces);
  m.volumes.kappa.conservativeResize(m.volumes.size());
  m.volumes.kappa(m.volumes.size() - 1) = kappa;
  std::map<std::pair<int, int>, bool> edges;
  for (Eigen::Index f = 0; f < faces.cols(); ++f)
    for (int k = 0; k < 3; ++k) edges[std::minmax(faces(k, f), faces((k + 1) % 3, f))] = true;
  for (const auto& [e, unused] : edges) {
    (void)unused;
    addElement(m, ElementGroup::Cartilage, End{-1, e.first, {}}, End{-1, e.second, {}}, 0.0, 200.0, 0.2);
  }
  for (int i = first; i < first + n; ++i) {
    if ((m.nodes.rest.col(i) - centre).dot(normal) > 0.0) continue;
    for (int k = 0; k < 3; ++k)
      addElement(m, ElementGroup::Cartilage,
                 End{rib, -1, Vector3d(m.nodes.rest.col(i)) + 0.02 * Vector3d::Unit(k)}, End{-1, i, {}}, 0.0,
                 500.0, 0.5);
  }
  return apex;
}

/// The rest state with random velocities: N(0, nodeSpeed^2) [m/s] per moving node axis and N(0, spin^2)
/// [rad/s] per moving body axis, from a fixed seed (the energy tests' initial condition).
inline State randomVelocityState(const Model& m, double nodeSpeed, double spin, unsigned seed = 3) {
  State s = makeInitialState(m);
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  // the spins first: they do not change with the model's node count
  for (int b = 0; b < m.bodies.size(); ++b)
    if (!m.bodies.isFixed[static_cast<std::size_t>(b)])
      s.bodyAngularVelocity.col(b) = spin * Eigen::Vector3d(n(rng), n(rng), n(rng));
  for (int i = 0; i < m.nodes.size(); ++i)
    if (!m.nodes.isFixed(i)) s.nodeVelocity.col(i) = nodeSpeed * Eigen::Vector3d(n(rng), n(rng), n(rng));
  return s;
}

/// Sets the linear velocity of every jointed body to what its parent's motion and its own spin imply, so that
/// the joint anchors move together: v_c = v_p + w_p x (a - x_p) - w_c x (a - x_c), a the anchor, parents
/// first.
inline void jointConsistentVelocities(const Model& m, State& s) {
  std::vector<char> done(static_cast<std::size_t>(m.bodies.size()), 0);
  for (int b = 0; b < m.bodies.size(); ++b)
    done[static_cast<std::size_t>(b)] =
        std::find(m.joints.child.begin(), m.joints.child.end(), b) == m.joints.child.end();
  for (int pass = 0; pass < m.joints.size(); ++pass) {
    for (int j = 0; j < m.joints.size(); ++j) {
      const int p = m.joints.parent[static_cast<std::size_t>(j)],
                c = m.joints.child[static_cast<std::size_t>(j)];
      if (!done[static_cast<std::size_t>(p)] || done[static_cast<std::size_t>(c)]) continue;
      const Eigen::Vector3d a = s.bodyPosition.col(p) + s.bodyOrientation[static_cast<std::size_t>(p)] *
                                                            (m.joints.anchor.col(j) - m.bodies.com.col(p));
      s.bodyVelocity.col(c) = s.bodyVelocity.col(p) +
                              s.bodyAngularVelocity.col(p).cross(a - s.bodyPosition.col(p)) -
                              s.bodyAngularVelocity.col(c).cross(a - s.bodyPosition.col(c));
      done[static_cast<std::size_t>(c)] = 1;
    }
  }
}

/// The energy tests' run: `model` from `state` with every muscle relaxed, stepped by step() and measured
/// by computeMetrics() after each step. energy() [J] is kinetic plus elastic energy of the latest metrics.
class RelaxedRun {
 public:
  RelaxedRun(const Model& model, const StepOptions& options, State state)
      : m_model(model), m_options(options), m_state(std::move(state)), m_work(makeStepWork(model)) {
    computeMetrics(m_model, m_state, m_relaxed, m_options, m_work, m_metrics);
  }
  /// Advances by `dt` [s] and measures.
  void step(double dt) {
    sim::step(m_model, m_state, dt, m_relaxed, m_options, m_work);
    computeMetrics(m_model, m_state, m_relaxed, m_options, m_work, m_metrics);
  }
  double energy() const { return m_metrics.kineticEnergy + m_metrics.elasticEnergy; }
  const Metrics& metrics() const { return m_metrics; }
  const State& state() const { return m_state; }
  double time() const { return m_state.time; }

 private:
  const Model& m_model;
  StepOptions m_options;
  State m_state;
  StepWork m_work;
  Activations m_relaxed = relaxedActivations();
  Metrics m_metrics;
};

/// [s] time step of the integrator tests on the toy models: its bodies are heavier than the default model's
/// ribs, so the explicit scheme runs at 0.25 ms here (the default model needs defaultTimeStep(): 10 us).
inline double toyTimeStep(IntegratorKind k) {
  return k == IntegratorKind::SymplecticEuler ? 2.5e-4 : defaultTimeStep(k);
}

/// A name usable as a gtest parameter name: "implicit-euler-joints" -> "implicit_euler_joints".
inline std::string gtestName(std::string name) {
  for (char& c : name)
    if (c == '-') c = '_';
  return name;
}

}  // namespace pneuma::sim::test
