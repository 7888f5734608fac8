#pragma once
/// @file Anchors.h
/// Points bound to a rigid body or to gut nodes, as the builder collects them in world coordinates
/// before converting them to sim::AnchorSet entries.

#include <string>

#include "pneuma/meshing/AnatomyParams.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/Model.h"

namespace pneuma::meshing {

/// A world point [m] bound to body `body` (>= 0) or to up to three gut nodes with barycentric weights.
struct Endpoint {
  int body = -1;
  Eigen::Vector3d world{0, 0, 0};
  Eigen::Vector3i nodes{-1, -1, -1};
  Eigen::Vector3d weights{0, 0, 0};

  static Endpoint onBody(int b, const Eigen::Vector3d& p) { return {b, p, {-1, -1, -1}, {0, 0, 0}}; }
  static Endpoint atNode(int n, const Eigen::Matrix3Xd& rest) {
    return {-1, rest.col(n), {n, -1, -1}, {1, 0, 0}};
  }
};

/// Appends `e` to `set`; body points are stored in the body frame (world - com, axes world-parallel at rest).
inline void addEndpoint(sim::AnchorSet& set, const Endpoint& e, const sim::Bodies& bodies) {
  if (e.body >= 0) {
    set.addBodyPoint(e.body, e.world - bodies.com.col(e.body));
  } else {
    set.addNodePoint(e.nodes, e.weights);
  }
}

/// Appends elements to a model, converting endpoints and scaling the group gains by rest length.
class ElementSink {
 public:
  ElementSink(const Gains& gains, sim::Model& model) : m_gains(gains), m_model(model) {}

  /// Adds one element; `active` [-] scales kac (0: a passive element), `stiffness` [-] scales kpe and b.
  void add(sim::ElementGroup group, const Endpoint& a, const Endpoint& b, double active = 1.0,
           double stiffness = 1.0) {
    add(group, a, b, m_gains.group[static_cast<std::size_t>(group)], active, stiffness);
  }
  /// Adds one element of `group` with the gains `g` (at the reference length) instead of the group's;
  /// `recruitment` [-] is its recruitment threshold c0 (sim::Elements::recruitment; 0: an ordinary element).
  void add(sim::ElementGroup group, const Endpoint& a, const Endpoint& b, const GroupGains& g,
           double active = 1.0, double stiffness = 1.0, double recruitment = 0.0) {
    const double l0 = (a.world - b.world).norm();
    if (!(l0 > 1e-4)) throw sim::Error(std::string(sim::groupName(group)) + " element: zero rest length");
    sim::Elements& e = m_model.elements;
    e.group.push_back(group);
    addEndpoint(e.endA, a, m_model.bodies);
    addEndpoint(e.endB, b, m_model.bodies);
    const double scale = m_gains.referenceLength / l0;
    const Eigen::Index n = static_cast<Eigen::Index>(e.group.size());
    for (Eigen::VectorXd* v : {&e.restLength, &e.kac, &e.kpe, &e.damping}) v->conservativeResize(n);
    e.restLength(n - 1) = l0;
    e.kac(n - 1) = active * g.kac * scale;
    e.kpe(n - 1) = stiffness * g.kpe * scale;
    e.damping(n - 1) = stiffness * g.damping * scale;
    // the thresholds are stored once one element has one (the elements before it: 0)
    if (recruitment > 0.0 || e.recruitment.size() > 0) {
      const Eigen::Index before = e.recruitment.size();
      e.recruitment.conservativeResize(n);
      e.recruitment.tail(n - before).setZero();
      e.recruitment(n - 1) = recruitment;
    }
    if (!e.isGliding.empty()) e.isGliding.push_back(0);
  }
  /// Marks the element added last as a gliding spring (sim::Elements::isGliding).
  void markGliding() {
    sim::Elements& e = m_model.elements;
    e.isGliding.resize(e.group.size(), 0);
    e.isGliding.back() = 1;
  }

 private:
  const Gains& m_gains;
  sim::Model& m_model;
};

}  // namespace pneuma::meshing
