#include "pneuma/sim/Recorder.h"

#include <algorithm>
#include <cmath>

namespace pneuma::sim {

void Recorder::record(const State& state, const Metrics& metrics) {
  RecordedFrame f;
  f.time = state.time;
  const Eigen::Index nb = state.bodyPosition.cols();
  f.bodyPose.resize(static_cast<std::size_t>(7 * nb));
  for (Eigen::Index b = 0; b < nb; ++b) {
    const Eigen::Quaterniond& q = state.bodyOrientation[static_cast<std::size_t>(b)];
    float* p = f.bodyPose.data() + 7 * b;
    for (int k = 0; k < 3; ++k) p[k] = static_cast<float>(state.bodyPosition(k, b));
    p[3] = static_cast<float>(q.w());
    p[4] = static_cast<float>(q.x());
    p[5] = static_cast<float>(q.y());
    p[6] = static_cast<float>(q.z());
  }
  f.nodePosition.assign(state.nodePosition.data(), state.nodePosition.data() + state.nodePosition.size());
  f.elementForce.assign(metrics.elementForce.data(),
                        metrics.elementForce.data() + metrics.elementForce.size());
  f.lungVolume = metrics.lungVolume;
  f.gutVolumeError = metrics.gutVolumeError;
  f.gutPressure = metrics.gutPressure;
  f.activations = metrics.activations;
  m_frames.push_back(std::move(f));
  if (m_capacity > 0 && m_frames.size() > m_capacity) m_frames.pop_front();
}

void Recorder::setCapacity(std::size_t capacity) {
  m_capacity = capacity;
  while (m_capacity > 0 && m_frames.size() > m_capacity) m_frames.pop_front();
}

std::size_t Recorder::indexAt(double time) const {
  if (m_frames.empty()) return 0;
  const auto it = std::lower_bound(m_frames.begin(), m_frames.end(), time,
                                   [](const RecordedFrame& f, double t) { return f.time < t; });
  if (it == m_frames.end()) return m_frames.size() - 1;
  const std::size_t i = static_cast<std::size_t>(it - m_frames.begin());
  if (i > 0 && std::abs(m_frames[i - 1].time - time) <= std::abs(it->time - time)) return i - 1;
  return i;
}

void Recorder::restore(std::size_t i, State& state) const {
  const RecordedFrame& f = m_frames.at(i);
  const Eigen::Index nb = static_cast<Eigen::Index>(f.bodyPose.size() / 7);
  const Eigen::Index nn = static_cast<Eigen::Index>(f.nodePosition.size() / 3);
  state.time = f.time;
  state.bodyPosition.resize(3, nb);
  state.bodyOrientation.resize(static_cast<std::size_t>(nb));
  for (Eigen::Index b = 0; b < nb; ++b) {
    const float* p = f.bodyPose.data() + 7 * b;
    state.bodyPosition.col(b) = Eigen::Vector3d(p[0], p[1], p[2]);
    state.bodyOrientation[static_cast<std::size_t>(b)] =
        Eigen::Quaterniond(p[3], p[4], p[5], p[6]).normalized();
  }
  state.nodePosition = Eigen::Map<const Eigen::Matrix3Xf>(f.nodePosition.data(), 3, nn).cast<double>();
  state.bodyVelocity = Eigen::Matrix3Xd::Zero(3, nb);
  state.bodyAngularVelocity = Eigen::Matrix3Xd::Zero(3, nb);
  state.nodeVelocity = Eigen::Matrix3Xd::Zero(3, nn);
}

void Recorder::restore(std::size_t i, State& state, Metrics& metrics) const {
  restore(i, state);
  const RecordedFrame& f = m_frames.at(i);
  metrics.time = f.time;
  metrics.lungVolume = f.lungVolume;
  metrics.gutVolumeError = f.gutVolumeError;
  metrics.gutPressure = f.gutPressure;
  metrics.activations = f.activations;
  metrics.elementForce = Eigen::Map<const Eigen::VectorXf>(f.elementForce.data(),
                                                           static_cast<Eigen::Index>(f.elementForce.size()))
                             .cast<double>();
  metrics.isSlack.clear();
}

}  // namespace pneuma::sim
