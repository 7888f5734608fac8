#include "pneuma/sim/ModelIO.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "pneuma/sim/Error.h"
#include "pneuma/sim/JsonReader.h"
#include "pneuma/sim/State.h"

namespace pneuma::sim {

using nlohmann::json;

namespace {

constexpr const char* kFormatName = "pneuma-model";
constexpr const char* kRequiredLandmarks[] = {"xiphoid", "umbilicus", "diaphragm_apex", "rib8_lateral_left",
                                              "rib8_lateral_right"};

const char* regionName(NodeRegion r) {
  switch (r) {
    case NodeRegion::Wall:
      return "wall";
    case NodeRegion::Diaphragm:
      return "diaphragm";
    case NodeRegion::Fixed:
      return "fixed";
    case NodeRegion::Tissue:
      return "tissue";
  }
  return "wall";
}

// ---------------------------------------------------------------------------------------------
// reading: every accessor carries the JSON path so that errors name the field

using Reader = JsonReader;

// anchor: {"body": i, "local": [x,y,z]} or {"nodes": [a(,b,c)], "weights": [wa(,wb,wc)]}; landmarks add
// "name"
void readAnchor(const Reader& r, AnchorSet& out, bool named = false) {
  if (r.has("body")) {
    if (named)
      r.allowKeys({"body", "local", "name"});
    else
      r.allowKeys({"body", "local"});
    out.addBodyPoint(r.at("body").integer(), r.at("local").vec3());
    return;
  }
  if (named)
    r.allowKeys({"nodes", "weights", "name"});
  else
    r.allowKeys({"nodes", "weights"});
  const Reader nodes = r.at("nodes");
  const Reader weights = r.at("weights");
  const std::size_t n = nodes.size();
  if (n < 1 || n > 3) nodes.fail("must list 1 to 3 node indices");
  if (weights.size() != n) weights.fail("must have as many entries as nodes (" + std::to_string(n) + ")");
  Eigen::Vector3i idx(-1, -1, -1);
  Eigen::Vector3d w = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < n; ++k) {
    idx[static_cast<int>(k)] = nodes[k].integer();
    w[static_cast<int>(k)] = weights[k].number();
  }
  out.addNodePoint(idx, w);
}

json writeAnchor(const AnchorSet& a, int i) {
  json j;
  if (a.body[static_cast<std::size_t>(i)] >= 0) {
    j["body"] = a.body[static_cast<std::size_t>(i)];
    j["local"] = {a.local(0, i), a.local(1, i), a.local(2, i)};
    return j;
  }
  json nodes = json::array(), weights = json::array();
  for (int k = 0; k < 3; ++k) {
    if (a.nodes(k, i) < 0) continue;
    nodes.push_back(a.nodes(k, i));
    weights.push_back(a.weights(k, i));
  }
  j["nodes"] = nodes;
  j["weights"] = weights;
  return j;
}

json vec(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

// skin: {"tetrahedra": n, "anchors": [anchor, ...], "vertices": [{"anchors": [i, ...], "weights": [w, ...],
// "offset": [x, y, z]}, ...], "triangles": [[a, b, c], ...]}
void readSkin(const Reader& r, Skin& out) {
  r.allowKeys({"tetrahedra", "anchors", "vertices", "triangles"});
  out.tetrahedra = r.at("tetrahedra").integer();
  const Reader anchors = r.at("anchors");
  for (std::size_t i = 0; i < anchors.size(); ++i) readAnchor(anchors[i], out.anchors);
  const Reader verts = r.at("vertices");
  const auto n = static_cast<Eigen::Index>(verts.size());
  out.anchor.setConstant(kSkinVertexSlots, n, -1);
  out.weights.setZero(kSkinVertexSlots, n);
  out.offset.resize(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Reader v = verts[static_cast<std::size_t>(i)];
    v.allowKeys({"anchors", "weights", "offset"});
    const Reader idx = v.at("anchors");
    const Reader w = v.at("weights");
    if (idx.size() < 1 || idx.size() > kSkinVertexSlots)
      idx.fail("must list 1 to " + std::to_string(kSkinVertexSlots) + " anchor indices");
    if (w.size() != idx.size())
      w.fail("must have as many entries as anchors (" + std::to_string(idx.size()) + ")");
    for (std::size_t k = 0; k < idx.size(); ++k) {
      out.anchor(static_cast<Eigen::Index>(k), i) = idx[k].integer();
      out.weights(static_cast<Eigen::Index>(k), i) = w[k].number();
    }
    out.offset.col(i) = v.at("offset").vec3();
  }
  const Reader tris = r.at("triangles");
  out.triangles.resize(3, static_cast<Eigen::Index>(tris.size()));
  for (std::size_t i = 0; i < tris.size(); ++i)
    out.triangles.col(static_cast<Eigen::Index>(i)) = tris[i].index3();
}

// volume bodies: [{"name": s, "kappa": k, "triangles": [[a, b, c], ...]}, ...]
void readVolumeBodies(const Reader& r, VolumeBodies& out) {
  const auto n = static_cast<Eigen::Index>(r.size());
  out.kappa.resize(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const Reader b = r[static_cast<std::size_t>(k)];
    b.allowKeys({"name", "kappa", "triangles"});
    out.name.push_back(b.at("name").string());
    out.kappa(k) = b.at("kappa").number();
    const Reader tris = b.at("triangles");
    Eigen::Matrix3Xi t(3, static_cast<Eigen::Index>(tris.size()));
    for (std::size_t i = 0; i < tris.size(); ++i) t.col(static_cast<Eigen::Index>(i)) = tris[i].index3();
    out.triangles.push_back(std::move(t));
  }
}

// lung surface: {"vertices": [{"cavity_vertices": [i, ...], "weights": [w, ...]}, ...], "triangles": [[a, b,
// c], ...]}
void readLungSurface(const Reader& r, LungSurface& out) {
  r.allowKeys({"vertices", "triangles"});
  const Reader verts = r.at("vertices");
  const auto n = static_cast<Eigen::Index>(verts.size());
  out.cavityVertex.setConstant(kLungVertexSlots, n, -1);
  out.weights.setZero(kLungVertexSlots, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Reader v = verts[static_cast<std::size_t>(i)];
    v.allowKeys({"cavity_vertices", "weights"});
    const Reader idx = v.at("cavity_vertices");
    const Reader w = v.at("weights");
    if (idx.size() < 1 || idx.size() > kLungVertexSlots)
      idx.fail("must list 1 to " + std::to_string(kLungVertexSlots) + " cavity vertex indices");
    if (w.size() != idx.size())
      w.fail("must have as many entries as cavity_vertices (" + std::to_string(idx.size()) + ")");
    for (std::size_t k = 0; k < idx.size(); ++k) {
      out.cavityVertex(static_cast<Eigen::Index>(k), i) = idx[k].integer();
      out.weights(static_cast<Eigen::Index>(k), i) = w[k].number();
    }
  }
  const Reader tris = r.at("triangles");
  out.triangles.resize(3, static_cast<Eigen::Index>(tris.size()));
  for (std::size_t i = 0; i < tris.size(); ++i)
    out.triangles.col(static_cast<Eigen::Index>(i)) = tris[i].index3();
}

json writeLungSurface(const LungSurface& s) {
  json verts = json::array();
  for (int i = 0; i < s.vertexCount(); ++i) {
    json idx = json::array(), w = json::array();
    for (int k = 0; k < kLungVertexSlots; ++k) {
      if (s.cavityVertex(k, i) < 0) continue;
      idx.push_back(s.cavityVertex(k, i));
      w.push_back(s.weights(k, i));
    }
    verts.push_back({{"cavity_vertices", std::move(idx)}, {"weights", std::move(w)}});
  }
  json tris = json::array();
  for (int i = 0; i < s.triangles.cols(); ++i)
    tris.push_back({s.triangles(0, i), s.triangles(1, i), s.triangles(2, i)});
  return {{"vertices", std::move(verts)}, {"triangles", std::move(tris)}};
}

// ---------------------------------------------------------------------------------------------
// validation helpers

[[noreturn]] void invalid(const std::string& field, const std::string& why) {
  throw Error(field + ": " + why);
}

std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

void requirePositive(double v, const std::string& field) {
  if (!std::isfinite(v) || v <= 0.0) invalid(field, "must be > 0, got " + num(v));
}
void requireNonNegative(double v, const std::string& field) {
  if (!std::isfinite(v) || v < 0.0) invalid(field, "must be >= 0, got " + num(v));
}
void requireFinite(const Eigen::Vector3d& v, const std::string& field) {
  if (!v.allFinite()) invalid(field, "must be finite");
}

void validateAnchors(const AnchorSet& a, const std::string& field, int nBodies, int nNodes) {
  const int n = a.size();
  if (a.local.cols() != n || a.nodes.cols() != n || a.weights.cols() != n)
    invalid(field, "inconsistent anchor array sizes");
  for (int i = 0; i < n; ++i) {
    const std::string f = field + "[" + std::to_string(i) + "]";
    const int b = a.body[static_cast<std::size_t>(i)];
    if (b >= 0) {
      if (b >= nBodies)
        invalid(f + ".body",
                "index " + std::to_string(b) + " out of range [0, " + std::to_string(nBodies) + ")");
      requireFinite(a.local.col(i), f + ".local");
      continue;
    }
    if (b != -1)
      invalid(f + ".body",
              "index " + std::to_string(b) + " out of range [0, " + std::to_string(nBodies) + ")");
    double sum = 0.0;
    int used = 0;
    for (int k = 0; k < 3; ++k) {
      const int node = a.nodes(k, i);
      if (node < 0) continue;
      if (node >= nNodes)
        invalid(f + ".nodes",
                "index " + std::to_string(node) + " out of range [0, " + std::to_string(nNodes) + ")");
      if (!std::isfinite(a.weights(k, i))) invalid(f + ".weights", "must be finite");
      sum += a.weights(k, i);
      ++used;
    }
    if (used == 0) invalid(f + ".nodes", "must list at least one node");
    if (std::abs(sum - 1.0) > 1e-6) invalid(f + ".weights", "must sum to 1, got " + num(sum));
  }
}

void validateTriangles(const Eigen::Matrix3Xi& t, const std::string& field, int nVertices) {
  for (int i = 0; i < t.cols(); ++i) {
    for (int k = 0; k < 3; ++k) {
      if (t(k, i) < 0 || t(k, i) >= nVertices)
        invalid(field + "[" + std::to_string(i) + "]", "vertex index " + std::to_string(t(k, i)) +
                                                           " out of range [0, " + std::to_string(nVertices) +
                                                           ")");
    }
    if (t(0, i) == t(1, i) || t(1, i) == t(2, i) || t(0, i) == t(2, i))
      invalid(field + "[" + std::to_string(i) + "]", "degenerate triangle (repeated vertex)");
  }
}

void validateLungVertices(const LungSurface& s, const std::string& field, int nCavity) {
  if (s.weights.cols() != s.cavityVertex.cols()) invalid(field, "inconsistent array sizes");
  for (int i = 0; i < s.vertexCount(); ++i) {
    const std::string f = field + "[" + std::to_string(i) + "]";
    double sum = 0.0;
    int used = 0;
    for (int k = 0; k < kLungVertexSlots; ++k) {
      const int c = s.cavityVertex(k, i);
      if (c < 0) continue;
      if (c >= nCavity)
        invalid(f + ".cavity_vertices",
                "index " + std::to_string(c) + " out of range [0, " + std::to_string(nCavity) + ")");
      const double w = s.weights(k, i);
      if (!std::isfinite(w) || w < 0.0) invalid(f + ".weights", "must be finite and >= 0, got " + num(w));
      sum += w;
      ++used;
    }
    if (used == 0) invalid(f + ".cavity_vertices", "must list at least one cavity vertex");
    if (std::abs(sum - 1.0) > 1e-6) invalid(f + ".weights", "must sum to 1, got " + num(sum));
  }
}

// signed volume enclosed by a triangle mesh (divergence theorem) [m^3]
double enclosedVolume(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xi& t) {
  double v = 0.0;
  for (int i = 0; i < t.cols(); ++i) v += x.col(t(0, i)).dot(x.col(t(1, i)).cross(x.col(t(2, i))));
  return v / 6.0;
}

// A closed, consistently oriented surface: at least a tetrahedron's 4 triangles, and every edge used exactly
// once in each direction (a flipped triangle uses an edge twice in one direction; a hole leaves an edge
// unpaired).
void validateClosedSurface(const Eigen::Matrix3Xi& t, const std::string& field) {
  if (t.cols() < 4)
    invalid(field, "must be a closed surface of at least 4 triangles, got " + std::to_string(t.cols()));
  std::map<std::pair<int, int>, int> directed;  // edge (a, b) in the order of its triangle -> triangle
  for (int i = 0; i < t.cols(); ++i) {
    for (int k = 0; k < 3; ++k) {
      const std::pair<int, int> e{t(k, i), t((k + 1) % 3, i)};
      const auto [it, isNew] = directed.emplace(e, i);
      if (!isNew)
        invalid(field + "[" + std::to_string(i) + "]",
                "edge " + std::to_string(e.first) + "-" + std::to_string(e.second) +
                    " runs the same way as in " + field + "[" + std::to_string(it->second) +
                    "]: a flipped triangle or more than two per edge");
    }
  }
  for (const auto& [e, i] : directed) {
    if (directed.count({e.second, e.first}) == 0)
      invalid(field + "[" + std::to_string(i) + "]",
              "edge " + std::to_string(e.first) + "-" + std::to_string(e.second) +
                  " has no neighbouring triangle: the surface is open");
  }
}

// rest-pose world positions of anchored points (body frames sit at the centre of mass, unrotated, at rest)
Eigen::Matrix3Xd restPoints(const AnchorSet& a, const Model& m) {
  Eigen::Matrix3Xd x(3, a.size());
  for (int i = 0; i < a.size(); ++i) {
    const int b = a.body[static_cast<std::size_t>(i)];
    if (b >= 0) {
      x.col(i) = m.bodies.com.col(b) + a.local.col(i);
      continue;
    }
    x.col(i).setZero();
    for (int k = 0; k < 3; ++k)
      if (a.nodes(k, i) >= 0) x.col(i) += a.weights(k, i) * m.nodes.rest.col(a.nodes(k, i));
  }
  return x;
}

// The joints form a forest hanging from the bodies no joint moves: one joint per child, no body its own
// ancestor.
void validateJointTree(const Model& m) {
  const int nB = m.bodies.size();
  const int nJ = m.joints.size();
  std::vector<int> parentJoint(static_cast<std::size_t>(nB), -1);  // the joint that moves each body, or -1
  for (int j = 0; j < nJ; ++j) {
    const int c = m.joints.child[static_cast<std::size_t>(j)];
    int& slot = parentJoint[static_cast<std::size_t>(c)];
    if (slot >= 0)
      invalid("joints[" + std::to_string(j) + "].child",
              "body '" + excerptOf(m.bodies.name[static_cast<std::size_t>(c)]) +
                  "' is already the child of joints[" + std::to_string(slot) +
                  "]: a body has one parent joint");
    slot = j;
  }
  for (int b = 0; b < nB; ++b) {
    int x = b;
    for (int depth = 0; parentJoint[static_cast<std::size_t>(x)] >= 0; ++depth) {
      const int j = parentJoint[static_cast<std::size_t>(x)];
      x = m.joints.parent[static_cast<std::size_t>(j)];
      if (x == b || depth > nJ)
        invalid("joints[" + std::to_string(j) + "].parent",
                "joint cycle: body '" + excerptOf(m.bodies.name[static_cast<std::size_t>(x)]) +
                    "' is its own ancestor");
    }
  }
}

}  // namespace

// =============================================================================================

void validateModel(const Model& m) {
  const int nB = m.bodies.size();
  const int nN = m.nodes.size();

  // bodies
  if (nB == 0) invalid("bodies", "must not be empty");
  if (static_cast<int>(m.bodies.isFixed.size()) != nB || m.bodies.mass.size() != nB ||
      m.bodies.com.cols() != nB || static_cast<int>(m.bodies.inertia.size()) != nB ||
      static_cast<int>(m.bodies.mesh.size()) != nB)
    invalid("bodies", "inconsistent array sizes");
  if (!m.bodies.isSupported.empty() && static_cast<int>(m.bodies.isSupported.size()) != nB)
    invalid("bodies", "inconsistent supported list");
  if (m.bodies.supportHeight.size() != 0 && m.bodies.supportHeight.size() != nB)
    invalid("bodies", "inconsistent support_height list");
  std::set<std::string> names;
  for (int i = 0; i < nB; ++i) {
    const std::string f = "bodies[" + std::to_string(i) + "]";
    const std::string& name = m.bodies.name[static_cast<std::size_t>(i)];
    if (name.empty()) invalid(f + ".name", "must not be empty");
    if (!names.insert(name).second) invalid(f + ".name", "duplicate body name '" + name + "'");
    requirePositive(m.bodies.mass[i], f + ".mass");
    requireFinite(m.bodies.com.col(i), f + ".com");
    if (const double h = m.bodies.supportHeightOf(i); h != 0.0) {
      if (!(h > 0.0 && h <= 2.0)) invalid(f + ".support_height", "must be in (0, 2] m, got " + num(h));
      if (!m.bodies.supported(i)) invalid(f + ".support_height", "needs \"supported\": true");
    }
    const Eigen::Matrix3d& I = m.bodies.inertia[static_cast<std::size_t>(i)];
    if (!I.allFinite() || (I - I.transpose()).norm() > 1e-9 * (1.0 + I.norm()))
      invalid(f + ".inertia", "must be a finite symmetric 3x3 matrix");
    const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(I).eigenvalues();
    if (ev.minCoeff() <= 0.0)
      invalid(f + ".inertia", "must be positive definite, smallest eigenvalue " + num(ev.minCoeff()));
  }
  if (m.bodies.mesh.size() != m.bodies.name.size()) invalid("bodies", "inconsistent mesh list");

  // joints
  const int nJ = m.joints.size();
  if (static_cast<int>(m.joints.name.size()) != nJ || static_cast<int>(m.joints.child.size()) != nJ ||
      m.joints.anchor.cols() != nJ || m.joints.friction.size() != nJ || m.joints.stiffness.size() != nJ ||
      m.joints.axis.cols() != nJ || m.joints.lockStiffness.size() != nJ)
    invalid("joints", "inconsistent array sizes");
  for (int i = 0; i < nJ; ++i) {
    const std::string f = "joints[" + std::to_string(i) + "]";
    const int p = m.joints.parent[static_cast<std::size_t>(i)];
    const int c = m.joints.child[static_cast<std::size_t>(i)];
    if (p < 0 || p >= nB) invalid(f + ".parent", "body index " + std::to_string(p) + " out of range");
    if (c < 0 || c >= nB) invalid(f + ".child", "body index " + std::to_string(c) + " out of range");
    if (p == c) invalid(f + ".child", "must differ from parent");
    if (m.bodies.isFixed[static_cast<std::size_t>(c)]) invalid(f + ".child", "must be a moving body");
    requireFinite(m.joints.anchor.col(i), f + ".anchor");
    requireNonNegative(m.joints.friction[i], f + ".friction");
    requireNonNegative(m.joints.stiffness[i], f + ".stiffness");
    requireNonNegative(m.joints.lockStiffness[i], f + ".lock_stiffness");
    requireFinite(m.joints.axis.col(i), f + ".axis");
    if (std::abs(m.joints.axis.col(i).norm() - 1.0) > 1e-6) invalid(f + ".axis", "must be a unit vector");
  }
  validateJointTree(m);

  // nodes and gut
  if (m.nodes.mass.size() != nN || static_cast<int>(m.nodes.region.size()) != nN)
    invalid("nodes", "inconsistent array sizes");
  for (int i = 0; i < nN; ++i) {
    const std::string f = "nodes[" + std::to_string(i) + "]";
    requireFinite(m.nodes.rest.col(i), f + ".x");
    if (m.nodes.isFixed(i))
      requireNonNegative(m.nodes.mass[i], f + ".mass");
    else
      requirePositive(m.nodes.mass[i], f + ".mass");
  }
  validateTriangles(m.gut.triangles, "gut.triangles", nN);
  requireNonNegative(m.gut.drag, "gut.drag");
  if (!(m.gut.wallToneUpright >= 0.0 && m.gut.wallToneUpright <= 0.5))
    invalid("gut.wall_tone_upright", "must be in [0, 0.5], got " + num(m.gut.wallToneUpright));
  if (m.gut.triangles.cols() > 0) {
    validateClosedSurface(m.gut.triangles, "gut.triangles");
    requirePositive(m.gut.kappa, "gut.kappa");
    const double v0 = enclosedVolume(m.nodes.rest, m.gut.triangles);
    if (v0 <= 0.0)
      invalid("gut.triangles",
              "enclosed rest volume must be > 0 (outward orientation), got " + num(v0) + " m^3");
  }

  // volume bodies: closed surfaces over tissue nodes, which the gut does not use
  const VolumeBodies& vb = m.volumes;
  if (static_cast<int>(vb.triangles.size()) != vb.size() || vb.kappa.size() != vb.size())
    invalid("volume_bodies", "inconsistent array sizes");
  std::set<std::string> bodyNames;
  for (int k = 0; k < vb.size(); ++k) {
    const std::string f = "volume_bodies[" + std::to_string(k) + "]";
    const std::string& name = vb.name[static_cast<std::size_t>(k)];
    if (name.empty()) invalid(f + ".name", "must not be empty");
    if (!bodyNames.insert(name).second) invalid(f + ".name", "duplicate name '" + name + "'");
    requirePositive(vb.kappa(k), f + ".kappa");
    const Eigen::Matrix3Xi& t = vb.triangles[static_cast<std::size_t>(k)];
    validateTriangles(t, f + ".triangles", nN);
    for (int i = 0; i < t.cols(); ++i)
      for (int c = 0; c < 3; ++c)
        if (m.nodes.region[static_cast<std::size_t>(t(c, i))] != NodeRegion::Tissue)
          invalid(f + ".triangles[" + std::to_string(i) + "]",
                  "node " + std::to_string(t(c, i)) + " is not a tissue node (region \"tissue\")");
    validateClosedSurface(t, f + ".triangles");
    const double v0 = enclosedVolume(m.nodes.rest, t);
    if (v0 <= 0.0)
      invalid(f + ".triangles",
              "enclosed rest volume must be > 0 (outward orientation), got " + num(v0) + " m^3");
  }
  for (int i = 0; i < m.gut.triangles.cols(); ++i)
    for (int c = 0; c < 3; ++c)
      if (m.nodes.region[static_cast<std::size_t>(m.gut.triangles(c, i))] == NodeRegion::Tissue)
        invalid("gut.triangles[" + std::to_string(i) + "]",
                "node " + std::to_string(m.gut.triangles(c, i)) + " is a tissue node (a volume body's)");

  // elements
  const int nE = m.elements.size();
  if (m.elements.endA.size() != nE || m.elements.endB.size() != nE || m.elements.restLength.size() != nE ||
      m.elements.kac.size() != nE || m.elements.kpe.size() != nE || m.elements.damping.size() != nE ||
      (m.elements.recruitment.size() != 0 && m.elements.recruitment.size() != nE) ||
      (!m.elements.isGliding.empty() && static_cast<int>(m.elements.isGliding.size()) != nE))
    invalid("elements", "inconsistent array sizes");
  validateAnchors(m.elements.endA, "elements.a", nB, nN);
  validateAnchors(m.elements.endB, "elements.b", nB, nN);
  if (nE == 0)
    invalid("elements", "must not be empty: no muscle or cartilage holds the rib cage and the gut");
  for (int i = 0; i < nE; ++i) {
    const std::string f = "elements[" + std::to_string(i) + "]";
    const int g = static_cast<int>(m.elements.group[static_cast<std::size_t>(i)]);
    if (g < 0 || g >= kElementGroupCount) invalid(f + ".group", "unknown group " + std::to_string(g));
    requirePositive(m.elements.restLength[i], f + ".rest_length");
    requireNonNegative(m.elements.kac[i], f + ".kac");
    requireNonNegative(m.elements.kpe[i], f + ".kpe");
    requireNonNegative(m.elements.damping[i], f + ".damping");
    const double c0 = m.elements.recruitmentOf(i);
    if (!(c0 >= 0.0 && c0 < 1.0)) invalid(f + ".recruitment", "must be in [0, 1), got " + num(c0));
    if (c0 > 0.0 && !isMuscleGroup(m.elements.group[static_cast<std::size_t>(i)]))
      invalid(f + ".recruitment", "only a muscle is recruited; a cartilage spring is passive");
    if (m.elements.glides(i) && m.elements.group[static_cast<std::size_t>(i)] != ElementGroup::Cartilage)
      invalid(f + ".gliding", "only a cartilage spring glides; a muscle pulls its two bones together");
  }
  if (m.elements.kpe.maxCoeff() <= 0.0)
    invalid("elements.kpe",
            "all " + std::to_string(nE) +
                " passive gains are 0: nothing holds the rib cage, and the lungs would turn inside out");

  // cavity
  validateAnchors(m.cavity.vertices, "cavity.vertices", nB, nN);
  validateTriangles(m.cavity.triangles, "cavity.triangles", m.cavity.vertices.size());
  validateClosedSurface(m.cavity.triangles, "cavity.triangles");
  const double cavityVolume = enclosedVolume(restPoints(m.cavity.vertices, m), m.cavity.triangles);
  if (!(cavityVolume > 0.0))
    invalid("cavity.triangles",
            "enclosed rest volume must be > 0 (outward orientation), got " + num(cavityVolume) + " m^3");
  requireNonNegative(m.cavity.recoilPressure, "cavity.recoil_pressure");
  requireNonNegative(m.cavity.compliance, "cavity.compliance");

  // lungs: embedded in the cavity, together smaller than it
  const double mediastinum = m.lungs.mediastinumVolume;
  requireNonNegative(mediastinum, "lungs.mediastinum_volume");
  if (!(mediastinum < cavityVolume))
    invalid("lungs.mediastinum_volume", "must be smaller than the cavity's rest volume " + num(cavityVolume) +
                                            " m^3, got " + num(mediastinum));
  const bool hasRight = m.lungs.right.vertexCount() > 0, hasLeft = m.lungs.left.vertexCount() > 0;
  if (hasRight != hasLeft)
    invalid(hasRight ? "lungs.left" : "lungs.right", "must be given with the other lung");
  if (hasRight) {
    const Eigen::Matrix3Xd cavityRest = restPoints(m.cavity.vertices, m);
    for (const auto& [lung, name] :
         {std::pair<const LungSurface*, std::string>{&m.lungs.right, "lungs.right"},
          {&m.lungs.left, "lungs.left"}}) {
      validateLungVertices(*lung, name + ".vertices", m.cavity.vertices.size());
      validateTriangles(lung->triangles, name + ".triangles", lung->vertexCount());
      validateClosedSurface(lung->triangles, name + ".triangles");
      Eigen::Matrix3Xd x;
      lungPositions(*lung, cavityRest, x);
      const double v = enclosedVolume(x, lung->triangles);
      if (!(v > 0.0))
        invalid(name + ".triangles",
                "enclosed rest volume must be > 0 (outward orientation), got " + num(v) + " m^3");
    }
  }

  // skin: optional; bound to anchors, each vertex a convex combination of them plus an offset
  const Skin& skin = m.skin;
  const int nV = skin.vertexCount();
  if (skin.weights.cols() != nV || skin.offset.cols() != nV) invalid("skin", "inconsistent array sizes");
  if (skin.tetrahedra < 0) invalid("skin.tetrahedra", "must be >= 0, got " + std::to_string(skin.tetrahedra));
  if (nV > 0) {
    validateAnchors(skin.anchors, "skin.anchors", nB, nN);
    for (int i = 0; i < nV; ++i) {
      const std::string f = "skin.vertices[" + std::to_string(i) + "]";
      double sum = 0.0;
      int used = 0;
      for (int k = 0; k < kSkinVertexSlots; ++k) {
        const int a = skin.anchor(k, i);
        if (a < 0) continue;
        if (a >= skin.anchors.size())
          invalid(f + ".anchors", "index " + std::to_string(a) + " out of range [0, " +
                                      std::to_string(skin.anchors.size()) + ")");
        const double w = skin.weights(k, i);
        if (!std::isfinite(w) || w < 0.0) invalid(f + ".weights", "must be finite and >= 0, got " + num(w));
        sum += w;
        ++used;
      }
      if (used == 0) invalid(f + ".anchors", "must list at least one anchor");
      if (std::abs(sum - 1.0) > 1e-6) invalid(f + ".weights", "must sum to 1, got " + num(sum));
      requireFinite(skin.offset.col(i), f + ".offset");
    }
    validateTriangles(skin.triangles, "skin.triangles", nV);
    validateClosedSurface(skin.triangles, "skin.triangles");
  } else if (skin.triangles.cols() > 0) {
    invalid("skin.triangles", "given without vertices");
  }

  // landmarks
  if (static_cast<int>(m.landmarks.name.size()) != m.landmarks.points.size())
    invalid("landmarks", "inconsistent array sizes");
  validateAnchors(m.landmarks.points, "landmarks", nB, nN);
  for (const char* required : kRequiredLandmarks) {
    if (m.landmarks.find(required) < 0)
      invalid("landmarks", std::string("missing required landmark '") + required + "'");
  }

  if (!m.gravity.allFinite()) invalid("gravity", "must be finite");
}

// =============================================================================================

Model parseModel(const std::string& jsonText, const std::string& sourceName) {
  const JsonDocument doc = JsonDocument::parse(jsonText, sourceName);
  const Reader root = doc.root();
  root.allowKeys({"format", "version", "name", "anatomy", "units", "frame", "gravity", "bodies", "joints",
                  "nodes", "gut", "volume_bodies", "elements", "cavity", "lungs", "landmarks", "skin"});

  // header
  if (root.at("format").string() != kFormatName)
    root.at("format").fail(std::string("must be \"") + kFormatName + "\"");
  const int version = root.at("version").integer();
  if (version != kModelFormatVersion)
    root.at("version").fail("unsupported version " + std::to_string(version) + " (this build reads " +
                            std::to_string(kModelFormatVersion) + ")");

  Model m;
  m.name = root.at("name").string();
  m.anatomy = root.has("anatomy") ? root.at("anatomy").string() : std::string();
  m.gravity = root.at("gravity").vec3();

  // bodies
  const Reader bodies = root.at("bodies");
  const std::size_t nB = bodies.size();
  m.bodies.mass.resize(static_cast<Eigen::Index>(nB));
  m.bodies.com.resize(3, static_cast<Eigen::Index>(nB));
  for (std::size_t i = 0; i < nB; ++i) {
    const Reader b = bodies[i];
    b.allowKeys({"name", "fixed", "mass", "com", "inertia", "mesh", "supported", "support_height"});
    m.bodies.name.push_back(b.at("name").string());
    m.bodies.isFixed.push_back(b.at("fixed").boolean() ? 1 : 0);
    m.bodies.mass[static_cast<Eigen::Index>(i)] = b.at("mass").number();
    m.bodies.com.col(static_cast<Eigen::Index>(i)) = b.at("com").vec3();
    const Reader inertia = b.at("inertia");
    if (inertia.size() != 3) inertia.fail("must be a 3x3 array");
    Eigen::Matrix3d I;
    for (std::size_t r = 0; r < 3; ++r) I.row(static_cast<Eigen::Index>(r)) = inertia[r].vec3().transpose();
    m.bodies.inertia.push_back(I);
    m.bodies.mesh.push_back(b.has("mesh") ? b.at("mesh").string() : std::string());
    // optional: no postural support when absent
    if (b.has("supported") && b.at("supported").boolean()) {
      m.bodies.isSupported.resize(nB, 0);
      m.bodies.isSupported[i] = 1;
    }
    // optional: the support acts at the centre of mass when absent
    if (b.has("support_height")) {
      if (m.bodies.supportHeight.size() == 0) m.bodies.supportHeight.setZero(static_cast<Eigen::Index>(nB));
      m.bodies.supportHeight(static_cast<Eigen::Index>(i)) = b.at("support_height").number();
    }
  }

  // joints
  const Reader joints = root.at("joints");
  const std::size_t nJ = joints.size();
  m.joints.anchor.resize(3, static_cast<Eigen::Index>(nJ));
  m.joints.friction.resize(static_cast<Eigen::Index>(nJ));
  m.joints.stiffness.resize(static_cast<Eigen::Index>(nJ));
  m.joints.axis.resize(3, static_cast<Eigen::Index>(nJ));
  m.joints.lockStiffness.resize(static_cast<Eigen::Index>(nJ));
  for (std::size_t i = 0; i < nJ; ++i) {
    const Reader j = joints[i];
    j.allowKeys({"name", "parent", "child", "anchor", "friction", "stiffness", "axis", "lock_stiffness"});
    const auto k = static_cast<Eigen::Index>(i);
    m.joints.name.push_back(j.at("name").string());
    m.joints.parent.push_back(j.at("parent").integer());
    m.joints.child.push_back(j.at("child").integer());
    m.joints.anchor.col(k) = j.at("anchor").vec3();
    m.joints.friction[k] = j.at("friction").number();
    m.joints.stiffness[k] = j.at("stiffness").number();
    // optional: models written before the rib-neck axes have ball joints (docs/model-format.md)
    m.joints.axis.col(k) = j.has("axis") ? j.at("axis").vec3() : Eigen::Vector3d::UnitX();
    m.joints.lockStiffness[k] = j.has("lock_stiffness") ? j.at("lock_stiffness").number() : 0.0;
  }

  // nodes
  const Reader nodes = root.at("nodes");
  const std::size_t nN = nodes.size();
  m.nodes.rest.resize(3, static_cast<Eigen::Index>(nN));
  m.nodes.mass.resize(static_cast<Eigen::Index>(nN));
  for (std::size_t i = 0; i < nN; ++i) {
    const Reader n = nodes[i];
    n.allowKeys({"x", "mass", "region"});
    m.nodes.rest.col(static_cast<Eigen::Index>(i)) = n.at("x").vec3();
    m.nodes.mass[static_cast<Eigen::Index>(i)] = n.at("mass").number();
    const std::string region = n.at("region").string();
    if (region == "wall")
      m.nodes.region.push_back(NodeRegion::Wall);
    else if (region == "diaphragm")
      m.nodes.region.push_back(NodeRegion::Diaphragm);
    else if (region == "fixed")
      m.nodes.region.push_back(NodeRegion::Fixed);
    else if (region == "tissue")
      m.nodes.region.push_back(NodeRegion::Tissue);
    else
      n.at("region").fail("unknown region '" + excerptOf(region) +
                          "' (expected wall, diaphragm, fixed or tissue)");
  }

  // gut
  const Reader gut = root.at("gut");
  gut.allowKeys({"kappa", "drag", "wall_tone_upright", "triangles"});
  m.gut.kappa = gut.at("kappa").number();
  if (gut.has("drag")) m.gut.drag = gut.at("drag").number();  // optional: models written before it have none
  if (gut.has("wall_tone_upright"))                           // optional likewise: no tone
    m.gut.wallToneUpright = gut.at("wall_tone_upright").numberIn(0.0, 0.5);
  const Reader gutTris = gut.at("triangles");
  m.gut.triangles.resize(3, static_cast<Eigen::Index>(gutTris.size()));
  for (std::size_t i = 0; i < gutTris.size(); ++i)
    m.gut.triangles.col(static_cast<Eigen::Index>(i)) = gutTris[i].index3();

  // volume bodies: optional; a model written before them has none (docs/model-format.md)
  if (root.has("volume_bodies")) readVolumeBodies(root.at("volume_bodies"), m.volumes);

  // elements
  const Reader elements = root.at("elements");
  const std::size_t nE = elements.size();
  for (auto* v : {&m.elements.restLength, &m.elements.kac, &m.elements.kpe, &m.elements.damping})
    v->resize(static_cast<Eigen::Index>(nE));
  for (std::size_t i = 0; i < nE; ++i) {
    const Reader e = elements[i];
    e.allowKeys({"group", "a", "b", "rest_length", "kac", "kpe", "damping", "recruitment", "gliding"});
    const auto k = static_cast<Eigen::Index>(i);
    ElementGroup g;
    const std::string group = e.at("group").string();
    if (!groupFromName(group, g)) e.at("group").fail("unknown group '" + excerptOf(group) + "'");
    m.elements.group.push_back(g);
    readAnchor(e.at("a"), m.elements.endA);
    readAnchor(e.at("b"), m.elements.endB);
    m.elements.restLength[k] = e.at("rest_length").number();
    m.elements.kac[k] = e.at("kac").number();
    m.elements.kpe[k] = e.at("kpe").number();
    m.elements.damping[k] = e.at("damping").number();
    // optional: an ordinary element (threshold 0) when absent
    if (e.has("recruitment")) {
      if (m.elements.recruitment.size() == 0) m.elements.recruitment.setZero(static_cast<Eigen::Index>(nE));
      m.elements.recruitment[k] = e.at("recruitment").number();
    }
    // optional: not a gliding spring when absent
    if (e.has("gliding") && e.at("gliding").boolean()) {
      m.elements.isGliding.resize(nE, 0);
      m.elements.isGliding[i] = 1;
    }
  }

  // cavity
  const Reader cavity = root.at("cavity");
  cavity.allowKeys({"vertices", "triangles", "recoil_pressure", "compliance"});
  // optional: models written before the pleural pressure have none (docs/model-format.md)
  if (cavity.has("recoil_pressure")) m.cavity.recoilPressure = cavity.at("recoil_pressure").number();
  if (cavity.has("compliance")) m.cavity.compliance = cavity.at("compliance").number();
  const Reader cavVerts = cavity.at("vertices");
  for (std::size_t i = 0; i < cavVerts.size(); ++i) readAnchor(cavVerts[i], m.cavity.vertices);
  const Reader cavTris = cavity.at("triangles");
  m.cavity.triangles.resize(3, static_cast<Eigen::Index>(cavTris.size()));
  for (std::size_t i = 0; i < cavTris.size(); ++i)
    m.cavity.triangles.col(static_cast<Eigen::Index>(i)) = cavTris[i].index3();

  // lungs: required; a model written before the two lungs is refused with the way to rebuild it
  if (!root.has("lungs"))
    throw Error(root.source() +
                ": lungs: missing (a model written before the two lungs; rebuild it with "
                "'pneuma-cli model build')");
  const Reader lungs = root.at("lungs");
  lungs.allowKeys({"mediastinum_volume", "right", "left"});
  m.lungs.mediastinumVolume = lungs.at("mediastinum_volume").number();
  readLungSurface(lungs.at("right"), m.lungs.right);
  readLungSurface(lungs.at("left"), m.lungs.left);

  // landmarks
  const Reader landmarks = root.at("landmarks");
  for (std::size_t i = 0; i < landmarks.size(); ++i) {
    m.landmarks.name.push_back(landmarks[i].at("name").string());
    readAnchor(landmarks[i], m.landmarks.points, true);
  }

  // skin: optional; a model written before the skin loads without one (docs/model-format.md)
  if (root.has("skin")) readSkin(root.at("skin"), m.skin);

  // semantic checks; their messages name the model field
  try {
    validateModel(m);
  } catch (const Error& e) {
    throw Error(sourceName + ": " + e.what());
  }
  return m;
}

Model loadModel(const std::string& dir) {
  const std::string path = dir + "/model.json";
  return parseModel(readInputFile(path, " (is '" + dir + "' a model directory?)"), path);
}

std::string serializeModel(const Model& m) {
  validateModel(m);
  json doc;
  doc["format"] = kFormatName;
  doc["version"] = kModelFormatVersion;
  doc["name"] = m.name;
  doc["anatomy"] = m.anatomy;
  doc["units"] = {{"length", "m"},
                  {"mass", "kg"},
                  {"time", "s"},
                  {"force", "N"},
                  {"pressure", "Pa"},
                  {"inertia", "kg m^2"},
                  {"stiffness", "N/m"},
                  {"damping", "N s/m"},
                  {"joint_friction", "N m s/rad"},
                  {"joint_stiffness", "N m/rad"},
                  {"angle", "rad"}};
  doc["frame"] =
      "RAS: +x subject's right, +y anterior, +z superior; body frames at the centre of mass, "
      "axes parallel to the world at rest";
  doc["gravity"] = vec(m.gravity);

  json bodies = json::array();
  for (int i = 0; i < m.bodies.size(); ++i) {
    const Eigen::Matrix3d& I = m.bodies.inertia[static_cast<std::size_t>(i)];
    json b;
    b["name"] = m.bodies.name[static_cast<std::size_t>(i)];
    b["fixed"] = m.bodies.isFixed[static_cast<std::size_t>(i)] != 0;
    b["mass"] = m.bodies.mass[i];
    b["com"] = vec(m.bodies.com.col(i));
    b["inertia"] = {vec(I.row(0).transpose()), vec(I.row(1).transpose()), vec(I.row(2).transpose())};
    b["mesh"] = m.bodies.mesh[static_cast<std::size_t>(i)];
    if (m.bodies.supported(i)) b["supported"] = true;
    if (m.bodies.supportHeightOf(i) != 0.0) b["support_height"] = m.bodies.supportHeightOf(i);
    bodies.push_back(std::move(b));
  }
  doc["bodies"] = std::move(bodies);

  json joints = json::array();
  for (int i = 0; i < m.joints.size(); ++i) {
    joints.push_back({{"name", m.joints.name[static_cast<std::size_t>(i)]},
                      {"parent", m.joints.parent[static_cast<std::size_t>(i)]},
                      {"child", m.joints.child[static_cast<std::size_t>(i)]},
                      {"anchor", vec(m.joints.anchor.col(i))},
                      {"friction", m.joints.friction[i]},
                      {"stiffness", m.joints.stiffness[i]},
                      {"axis", vec(m.joints.axis.col(i))},
                      {"lock_stiffness", m.joints.lockStiffness[i]}});
  }
  doc["joints"] = std::move(joints);

  json nodes = json::array();
  for (int i = 0; i < m.nodes.size(); ++i) {
    nodes.push_back({{"x", vec(m.nodes.rest.col(i))},
                     {"mass", m.nodes.mass[i]},
                     {"region", regionName(m.nodes.region[static_cast<std::size_t>(i)])}});
  }
  doc["nodes"] = std::move(nodes);

  auto triangles = [](const Eigen::Matrix3Xi& t) {
    json a = json::array();
    for (int i = 0; i < t.cols(); ++i) a.push_back({t(0, i), t(1, i), t(2, i)});
    return a;
  };
  doc["gut"] = {{"kappa", m.gut.kappa},
                {"drag", m.gut.drag},
                {"wall_tone_upright", m.gut.wallToneUpright},
                {"triangles", triangles(m.gut.triangles)}};

  if (m.volumes.size() > 0) {
    json bodies = json::array();
    for (int k = 0; k < m.volumes.size(); ++k)
      bodies.push_back({{"name", m.volumes.name[static_cast<std::size_t>(k)]},
                        {"kappa", m.volumes.kappa(k)},
                        {"triangles", triangles(m.volumes.triangles[static_cast<std::size_t>(k)])}});
    doc["volume_bodies"] = std::move(bodies);
  }

  json elements = json::array();
  for (int i = 0; i < m.elements.size(); ++i) {
    elements.push_back({{"group", groupName(m.elements.group[static_cast<std::size_t>(i)])},
                        {"a", writeAnchor(m.elements.endA, i)},
                        {"b", writeAnchor(m.elements.endB, i)},
                        {"rest_length", m.elements.restLength[i]},
                        {"kac", m.elements.kac[i]},
                        {"kpe", m.elements.kpe[i]},
                        {"damping", m.elements.damping[i]}});
    if (m.elements.recruitmentOf(i) > 0.0) elements.back()["recruitment"] = m.elements.recruitment[i];
    if (m.elements.glides(i)) elements.back()["gliding"] = true;
  }
  doc["elements"] = std::move(elements);

  json cavVerts = json::array();
  for (int i = 0; i < m.cavity.vertices.size(); ++i) cavVerts.push_back(writeAnchor(m.cavity.vertices, i));
  doc["cavity"] = {{"vertices", std::move(cavVerts)},
                   {"triangles", triangles(m.cavity.triangles)},
                   {"recoil_pressure", m.cavity.recoilPressure},
                   {"compliance", m.cavity.compliance}};

  doc["lungs"] = {{"mediastinum_volume", m.lungs.mediastinumVolume},
                  {"right", writeLungSurface(m.lungs.right)},
                  {"left", writeLungSurface(m.lungs.left)}};

  json landmarks = json::array();
  for (int i = 0; i < m.landmarks.points.size(); ++i) {
    json l = writeAnchor(m.landmarks.points, i);
    l["name"] = m.landmarks.name[static_cast<std::size_t>(i)];
    landmarks.push_back(std::move(l));
  }
  doc["landmarks"] = std::move(landmarks);

  if (m.skin.vertexCount() > 0) {
    const Skin& skin = m.skin;
    json anchors = json::array();
    for (int i = 0; i < skin.anchors.size(); ++i) anchors.push_back(writeAnchor(skin.anchors, i));
    json verts = json::array();
    for (int i = 0; i < skin.vertexCount(); ++i) {
      json idx = json::array(), w = json::array();
      for (int k = 0; k < kSkinVertexSlots; ++k) {
        if (skin.anchor(k, i) < 0) continue;
        idx.push_back(skin.anchor(k, i));
        w.push_back(skin.weights(k, i));
      }
      verts.push_back(
          {{"anchors", std::move(idx)}, {"weights", std::move(w)}, {"offset", vec(skin.offset.col(i))}});
    }
    doc["skin"] = {{"tetrahedra", skin.tetrahedra},
                   {"anchors", std::move(anchors)},
                   {"vertices", std::move(verts)},
                   {"triangles", triangles(skin.triangles)}};
  }

  return doc.dump(1) + "\n";
}

void saveModel(const Model& m, const std::string& dir) {
  const std::string text = serializeModel(m);
  const std::string path = dir + "/model.json";
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw Error(path + ": cannot write (is '" + dir + "' a writable directory?)");
    out << text;
    out.flush();
    if (!out) {
      std::remove(tmp.c_str());
      throw Error(path + ": write failed (disk full?)");
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw Error(path + ": cannot rename temporary file into place");
  }
}

}  // namespace pneuma::sim
