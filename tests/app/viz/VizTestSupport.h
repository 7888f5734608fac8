#pragma once
// A posed toy torso for the viz tests: every body moved and turned by its own rotation, every node moved, far
// from the rest pose, so a part drawn or written at rest (or with a transposed rotation) is found out.
#include <random>

#include "../../sim/ToyTorso.h"
#include "pneuma/sim/Metrics.h"
#include "pneuma/sim/State.h"

namespace pneuma::test {

inline sim::State posedState(const sim::Model& m, unsigned seed) {
  sim::State s = sim::makeInitialState(m);
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int b = 0; b < m.bodies.size(); ++b) {
    const Eigen::Vector3d axis = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
    s.bodyOrientation[static_cast<std::size_t>(b)] =
        Eigen::Quaterniond(Eigen::AngleAxisd(0.3 + 0.1 * n(rng), axis));
    s.bodyPosition.col(b) += 0.05 * Eigen::Vector3d(n(rng), n(rng), n(rng));  // [m]
  }
  for (int i = 0; i < m.nodes.size(); ++i)
    s.nodePosition.col(i) += 0.05 * Eigen::Vector3d(n(rng), n(rng), n(rng));
  s.time = 0.25 * seed;  // [s]
  return s;
}

inline sim::Metrics someMetrics(const sim::Model& m, const sim::State& s, unsigned seed) {
  sim::Metrics out;
  out.time = s.time;
  out.gutPressure = 100.0 * seed;                                                // [Pa]
  out.lungVolume = 1e-3 * seed;                                                  // [m^3]
  out.elementForce = -Eigen::VectorXd::LinSpaced(m.elements.size(), 0.0, 10.0);  // [N] tension
  out.isSlack.assign(static_cast<std::size_t>(m.elements.size()), 0);
  return out;
}

}  // namespace pneuma::test
