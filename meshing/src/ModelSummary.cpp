#include "pneuma/meshing/ModelSummary.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>

#include "pneuma/meshing/TriangleMesh.h"
#include "pneuma/sim/State.h"

namespace pneuma::meshing {

namespace {

constexpr double kMlPerM3 = 1e6;

}  // namespace

Eigen::Matrix3Xd restPoints(const sim::AnchorSet& set, const sim::Model& m) {
  Eigen::Matrix3Xd p(3, set.size());
  for (int i = 0; i < set.size(); ++i) {
    const int b = set.body[static_cast<std::size_t>(i)];
    if (b >= 0) {
      p.col(i) = m.bodies.com.col(b) + set.local.col(i);
    } else {
      p.col(i).setZero();
      for (int k = 0; k < 3; ++k) {
        if (set.nodes(k, i) >= 0) p.col(i) += set.weights(k, i) * m.nodes.rest.col(set.nodes(k, i));
      }
    }
  }
  return p;
}

ModelSummary summarizeModel(const sim::Model& m) {
  ModelSummary s;
  s.bodies = m.bodies.size();
  for (int b = 0; b < s.bodies; ++b) {
    if (!m.bodies.isFixed[static_cast<std::size_t>(b)]) ++s.movingBodies;
    s.boneMass += m.bodies.mass(b);
  }
  s.joints = m.joints.size();
  s.nodes = m.nodes.size();
  for (int i = 0; i < s.nodes; ++i) {
    if (m.nodes.isFixed(i)) ++s.fixedNodes;
    if (m.nodes.region[static_cast<std::size_t>(i)] == sim::NodeRegion::Wall)
      s.gutWallMass += m.nodes.mass(i);
    if (m.nodes.region[static_cast<std::size_t>(i)] == sim::NodeRegion::Tissue) {
      ++s.tissueNodes;
      s.tissueMass += m.nodes.mass(i);
    }
  }
  for (sim::ElementGroup g : m.elements.group) ++s.elements[static_cast<std::size_t>(g)];
  s.gutVolume = enclosedVolume(m.nodes.rest, m.gut.triangles);
  s.cavityVolume = enclosedVolume(restPoints(m.cavity.vertices, m), m.cavity.triangles);
  s.tissueBodies = m.volumes.size();
  for (const Eigen::Matrix3Xi& t : m.volumes.triangles) s.tissueVolume += enclosedVolume(m.nodes.rest, t);
  s.skinVertices = m.skin.vertexCount();
  s.skinTriangles = static_cast<int>(m.skin.triangles.cols());
  s.skinTetrahedra = m.skin.tetrahedra;
  if (s.skinVertices > 0) {
    Eigen::Matrix3Xd x;
    sim::skinPositions(m.skin, restPoints(m.skin.anchors, m), x);
    s.skinVolume = enclosedVolume(x, m.skin.triangles);
  }
  return s;
}

std::string summaryJson(const ModelSummary& s) {
  nlohmann::ordered_json j;
  j["bodies"] = s.bodies;
  j["moving_bodies"] = s.movingBodies;
  j["joints"] = s.joints;
  j["nodes"] = s.nodes;
  j["fixed_nodes"] = s.fixedNodes;
  nlohmann::ordered_json e = nlohmann::ordered_json::object();
  for (int g = 0; g < sim::kElementGroupCount; ++g) {
    e[sim::groupName(static_cast<sim::ElementGroup>(g))] = s.elements[static_cast<std::size_t>(g)];
  }
  j["elements"] = e;
  j["gut_volume_ml"] = std::round(s.gutVolume * kMlPerM3 * 10.0) / 10.0;
  j["cavity_volume_ml"] = std::round(s.cavityVolume * kMlPerM3 * 10.0) / 10.0;
  j["gut_wall_mass_kg"] = std::round(s.gutWallMass * 1e4) / 1e4;
  j["bone_mass_kg"] = std::round(s.boneMass * 1e4) / 1e4;
  j["skin"] = {{"vertices", s.skinVertices},
               {"triangles", s.skinTriangles},
               {"tetrahedra", s.skinTetrahedra},
               {"volume_ml", std::round(s.skinVolume * kMlPerM3 * 10.0) / 10.0}};
  j["volume_bodies"] = {{"bodies", s.tissueBodies},
                        {"nodes", s.tissueNodes},
                        {"volume_ml", std::round(s.tissueVolume * kMlPerM3 * 10.0) / 10.0},
                        {"mass_kg", std::round(s.tissueMass * 1e4) / 1e4}};
  return j.dump(2);
}

std::string summaryText(const ModelSummary& s) {
  std::ostringstream o;
  o << "bodies:          " << s.bodies << " (" << s.movingBodies << " moving)\n"
    << "joints:          " << s.joints << "\n"
    << "nodes:           " << s.nodes << " (" << s.fixedNodes << " fixed)\n"
    << "elements:\n";
  for (int g = 0; g < sim::kElementGroupCount; ++g) {
    o << "  " << sim::groupName(static_cast<sim::ElementGroup>(g)) << ": "
      << s.elements[static_cast<std::size_t>(g)] << "\n";
  }
  o.setf(std::ios::fixed);
  o.precision(1);
  o << "gut volume:      " << s.gutVolume * kMlPerM3 << " mL\n"
    << "cavity volume:   " << s.cavityVolume * kMlPerM3 << " mL\n";
  o.precision(3);
  o << "gut wall mass:   " << s.gutWallMass << " kg\n"
    << "bone mass:       " << s.boneMass << " kg\n";
  if (s.skinVertices > 0) {
    o.precision(1);
    o << "skin:            " << s.skinVertices << " vertices, " << s.skinTriangles << " triangles, "
      << s.skinTetrahedra << " soft-tissue tetrahedra, " << s.skinVolume * kMlPerM3 << " mL\n";
  } else {
    o << "skin:            none\n";
  }
  o.precision(1);
  if (s.tissueBodies > 0)
    o << "volume bodies:   " << s.tissueBodies << " (pectorals, shoulders), " << s.tissueNodes << " nodes, "
      << s.tissueVolume * kMlPerM3 << " mL\n";
  else
    o << "volume bodies:   none\n";
  return o.str();
}

}  // namespace pneuma::meshing
