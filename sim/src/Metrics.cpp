#include "pneuma/sim/Metrics.h"

#include <algorithm>
#include <cmath>
#include <complex>

#include "StepInternal.h"

namespace pneuma::sim {

void Trace::append(const Metrics& m) {
  time.push_back(m.time);
  lungVolume.push_back(m.lungVolume);
  gutVolumeError.push_back(m.gutVolumeError);
  abdomenVolume.push_back(m.abdomenVolume);
  landmarks.push_back(m.landmarks);
}

void Trace::keepEveryOtherFrame() {
  auto thin = [](auto& series) {
    std::size_t kept = 0;
    for (std::size_t i = 0; i < series.size(); i += 2) series[kept++] = std::move(series[i]);
    series.resize(kept);
  };
  thin(time);
  thin(lungVolume);
  thin(gutVolumeError);
  thin(abdomenVolume);
  thin(landmarks);
}

void Trace::clear() {
  time.clear();
  lungVolume.clear();
  gutVolumeError.clear();
  abdomenVolume.clear();
  landmarks.clear();
}

namespace {
// first frame index with time >= from
std::size_t firstIndex(const Trace& t, double from) {
  return static_cast<std::size_t>(std::lower_bound(t.time.begin(), t.time.end(), from) - t.time.begin());
}
// the breath-frequency Fourier component of v over frames [a, b) at angular frequency omega [rad/s]
std::complex<double> fundamental(const Trace& t, const std::vector<double>& v, std::size_t a, std::size_t b,
                                 double omega) {
  double mean = 0.0;
  for (std::size_t i = a; i < b; ++i) mean += v[i];
  mean /= static_cast<double>(b - a);
  std::complex<double> c = 0.0;
  for (std::size_t i = a; i < b; ++i)
    c += (v[i] - mean) * std::exp(std::complex<double>(0.0, -omega * t.time[i]));
  return c;
}

// motion in anatomical axes over the cycles delimited by the frames `up` (upward crossings of the mean
// volume)
Motion measureMotion(const Trace& t, const std::vector<std::string>& names,
                     const std::vector<std::size_t>& up, double period) {
  Motion m;
  const int cycles = static_cast<int>(up.size()) - 1;
  if (cycles < 1) return m;
  auto landmark = [&](const char* name) {
    const auto it = std::find(names.begin(), names.end(), name);
    return it == names.end() ? -1 : static_cast<int>(it - names.begin());
  };
  // end-inspiration and end-expiration frames of each cycle
  std::vector<std::size_t> insp, exp;
  for (int c = 0; c < cycles; ++c) {
    const auto a = t.lungVolume.begin() + static_cast<std::ptrdiff_t>(up[static_cast<std::size_t>(c)]);
    const auto b = t.lungVolume.begin() + static_cast<std::ptrdiff_t>(up[static_cast<std::size_t>(c) + 1]);
    insp.push_back(static_cast<std::size_t>(std::max_element(a, b) - t.lungVolume.begin()));
    exp.push_back(static_cast<std::size_t>(std::min_element(a, b) - t.lungVolume.begin()));
  }
  // mean over cycles of f(end-inspiration frame) - f(end-expiration frame)
  auto change = [&](auto f) {
    double sum = 0.0;
    for (int c = 0; c < cycles; ++c)
      sum += f(insp[static_cast<std::size_t>(c)]) - f(exp[static_cast<std::size_t>(c)]);
    return sum / cycles;
  };
  auto axis = [&](const char* name, int k, double sign) {
    const int l = landmark(name);
    return l < 0 ? kNaN : sign * change([&](std::size_t i) { return t.landmarks[i](k, l); });
  };
  m.domeDescent = axis("diaphragm_apex", 2, -1.0);
  m.domeAnterior = axis("diaphragm_apex", 1, 1.0);
  m.sternumAnterior = axis("jugular_notch", 1, 1.0);
  m.sternumCranial = axis("jugular_notch", 2, 1.0);
  m.xiphoidAnterior = axis("xiphoid", 1, 1.0);
  m.xiphoidCranial = axis("xiphoid", 2, 1.0);
  m.umbilicusAnterior = axis("umbilicus", 1, 1.0);
  if (const int u = landmark("umbilicus"); u >= 0) {
    m.umbilicusAnteriorMin = std::numeric_limits<double>::infinity();
    for (int c = 0; c < cycles; ++c)
      m.umbilicusAnteriorMin =
          std::min(m.umbilicusAnteriorMin, t.landmarks[insp[static_cast<std::size_t>(c)]](1, u) -
                                               t.landmarks[exp[static_cast<std::size_t>(c)]](1, u));
  }
  if (landmark("acromion_left") >= 0 && landmark("acromion_right") >= 0)
    m.acromionCranial = 0.5 * (axis("acromion_left", 2, 1.0) + axis("acromion_right", 2, 1.0));
  const int left = landmark("rib8_lateral_left"), right = landmark("rib8_lateral_right");
  if (left >= 0 && right >= 0)
    m.lowerRibExpansion =
        change([&](std::size_t i) { return (t.landmarks[i].col(left) - t.landmarks[i].col(right)).norm(); });

  // Konno-Mead partition: abdomen = the wall's displaced volume, rib cage = the rest of the lung volume
  if (t.abdomenVolume.size() == t.size()) {
    std::vector<double> ribCage(t.size());
    for (std::size_t i = 0; i < t.size(); ++i) ribCage[i] = t.lungVolume[i] - t.abdomenVolume[i];
    m.abdomenTidal = change([&](std::size_t i) { return t.abdomenVolume[i]; });
    m.ribCageTidal = change([&](std::size_t i) { return ribCage[i]; });
    const double omega = 2.0 * M_PI / period;
    const double d = std::arg(fundamental(t, t.abdomenVolume, up.front(), up.back(), omega)) -
                     std::arg(fundamental(t, ribCage, up.front(), up.back(), omega));
    m.phaseAngle = std::abs(std::remainder(d, 2.0 * M_PI));
  }

  // flow dV/dt by central differences: sign changes per cycle and the largest frame-to-frame jump
  const std::size_t a = std::max<std::size_t>(up.front(), 1), b = std::min(up.back(), t.size() - 1);
  std::vector<double> flow;
  for (std::size_t i = a; i < b; ++i)
    flow.push_back((t.lungVolume[i + 1] - t.lungVolume[i - 1]) / (t.time[i + 1] - t.time[i - 1]));
  int changes = 0;
  double peak = 0.0, jump = 0.0, last = 0.0;
  for (std::size_t i = 0; i < flow.size(); ++i) {
    peak = std::max(peak, std::abs(flow[i]));
    if (i > 0) jump = std::max(jump, std::abs(flow[i] - flow[i - 1]));
    if (flow[i] != 0.0) {
      if (last != 0.0 && (flow[i] > 0.0) != (last > 0.0)) ++changes;
      last = flow[i];
    }
  }
  m.flowSignChanges = static_cast<double>(changes) / cycles;
  m.maxFlowJump = peak > 0.0 ? jump / peak : kNaN;
  return m;
}

}  // namespace

Summary summarize(const Trace& trace, const std::vector<std::string>& landmarkNames, double from) {
  Summary s;
  s.measuredFrom = from;
  const std::size_t i0 = firstIndex(trace, from);
  if (i0 >= trace.size()) return s;

  // gut volume error statistics
  double sumError = 0.0;
  for (std::size_t i = i0; i < trace.size(); ++i) {
    const double e = std::abs(trace.gutVolumeError[i]);
    s.maxGutVolumeError = std::max(s.maxGutVolumeError, e);
    sumError += e;
  }
  s.meanGutVolumeError = sumError / static_cast<double>(trace.size() - i0);

  // cycles: upward crossings of the mean volume, re-armed only after dropping 25 % of the range below it
  // (so ringing smaller than a quarter of the breath is not counted as breaths); the range is taken from the
  // first upward crossing on, so the first breath's climb from the settled volume (a style whose
  // end-expiratory volume settles higher, as panting's does) does not widen it
  double mean = 0.0;
  for (std::size_t i = i0; i < trace.size(); ++i) mean += trace.lungVolume[i];
  mean /= static_cast<double>(trace.size() - i0);
  std::size_t first = i0 + 1;
  while (first < trace.size() && !(trace.lungVolume[first - 1] < mean && trace.lungVolume[first] >= mean))
    ++first;
  const auto begin = trace.lungVolume.begin() + static_cast<std::ptrdiff_t>(i0);
  const auto from1 =
      trace.lungVolume.begin() + static_cast<std::ptrdiff_t>(std::min(first, trace.size() - 1));
  const double lo = *std::min_element(begin, trace.lungVolume.end());
  const double hi = *std::max_element(begin, trace.lungVolume.end());
  const double hysteresis = 0.25 * (*std::max_element(from1, trace.lungVolume.end()) -
                                    *std::min_element(from1, trace.lungVolume.end()));
  std::vector<std::size_t> up;  // frame index of each upward crossing
  std::vector<double> upTime;   // [s] interpolated crossing time
  bool armed = false;
  for (std::size_t i = i0 + 1; i < trace.size(); ++i) {
    const double v0 = trace.lungVolume[i - 1], v1 = trace.lungVolume[i];
    if (v1 < mean - hysteresis) armed = true;
    if (armed && v0 < mean && v1 >= mean) {
      const double f = (mean - v0) / (v1 - v0);
      up.push_back(i);
      upTime.push_back(trace.time[i - 1] + f * (trace.time[i] - trace.time[i - 1]));
      armed = false;
    }
  }

  // per-cycle peak-to-peak, minima and maxima
  s.cycles = up.size() >= 2 ? static_cast<int>(up.size()) - 1 : 0;
  if (s.cycles == 0) {
    s.tidalVolume = hi - lo;
    s.endExpiratoryVolume = lo;
    s.endInspiratoryVolume = hi;
  } else {
    double tidal = 0.0, minima = 0.0, maxima = 0.0;
    for (int c = 0; c < s.cycles; ++c) {
      const auto a = trace.lungVolume.begin() + static_cast<std::ptrdiff_t>(up[static_cast<std::size_t>(c)]);
      const auto b =
          trace.lungVolume.begin() + static_cast<std::ptrdiff_t>(up[static_cast<std::size_t>(c) + 1]);
      const double cmin = *std::min_element(a, b), cmax = *std::max_element(a, b);
      tidal += cmax - cmin;
      minima += cmin;
      maxima += cmax;
    }
    s.tidalVolume = tidal / s.cycles;
    s.endExpiratoryVolume = minima / s.cycles;
    s.endInspiratoryVolume = maxima / s.cycles;
    s.breathsPerMinute = 60.0 * s.cycles / (upTime.back() - upTime.front());
    s.motion = measureMotion(trace, landmarkNames, up, (upTime.back() - upTime.front()) / s.cycles);
  }

  return s;
}

// ---- computeMetrics() (declared in Step.h: it reads the step's outputs)

using namespace detail;

void computeMetrics(const Model& model, const State& state, const Activations& act,
                    const StepOptions& options, const StepWork& work, Metrics& out) {
  out.time = state.time;
  out.activations = act;

  // volumes: lung cavity from its bound surface, the lungs from it (Lungs), gut from the node surface
  Eigen::Matrix3Xd cavity;
  anchorPositions(model.cavity.vertices, state, cavity);
  out.thoracicCavityVolume =
      model.cavity.triangles.cols() > 0 ? enclosedVolume(cavity, model.cavity.triangles) : 0.0;
  out.lungVolume = out.thoracicCavityVolume - model.lungs.mediastinumVolume;
  out.rightLungVolume = out.leftLungVolume = kNaN;
  if (model.lungs.right.vertexCount() > 0) {
    Eigen::Matrix3Xd x;
    lungPositions(model.lungs.right, cavity, x);
    const double right = enclosedVolume(x, model.lungs.right.triangles);
    lungPositions(model.lungs.left, cavity, x);
    const double left = enclosedVolume(x, model.lungs.left.triangles);
    out.rightLungVolume = out.lungVolume * right / (right + left);
    out.leftLungVolume = out.lungVolume - out.rightLungVolume;
  }
  out.gutVolume =
      model.gut.triangles.cols() > 0 ? enclosedVolume(state.nodePosition, model.gut.triangles) : 0.0;
  out.gutVolumeError = work.constants.restGutVolume > 0.0
                           ? (out.gutVolume - work.constants.restGutVolume) / work.constants.restGutVolume
                           : 0.0;
  const double kappa = effectiveKappa(model, options);
  out.gutPressure = work.constants.restGutVolume > 0.0
                        ? gutPressure(kappa, work.constants.restGutVolume, out.gutVolume)
                        : 0.0;
  out.abdomenVolume =
      coneVolume(state.nodePosition, work.constants.wallTriangles, work.constants.restGutCentroid);
  Eigen::VectorXd bodyVolume(model.volumes.size());
  out.volumeBodyError.resize(model.volumes.size());
  for (int k = 0; k < model.volumes.size(); ++k) {
    bodyVolume(k) = enclosedVolume(state.nodePosition, model.volumes.triangles[at(k)]);
    out.volumeBodyError(k) =
        (bodyVolume(k) - work.constants.restBodyVolume(k)) / work.constants.restBodyVolume(k);
  }

  // element forces of the last step, slack state and group tensions
  const Elements& el = model.elements;
  out.elementForce = work.outputs.elementForce;
  out.isSlack.assign(at(el.size()), 0);
  out.groupMeanTension.fill(0.0);
  std::array<int, kElementGroupCount> count{};
  for (int e = 0; e < el.size(); ++e) {
    const double f = work.outputs.elementForce(e);
    if (isMuscleGroup(el.group[at(e)]) && f >= 0.0) out.isSlack[at(e)] = 1;
    out.groupMeanTension[at(static_cast<int>(el.group[at(e)]))] += std::max(-f, 0.0);
    ++count[at(static_cast<int>(el.group[at(e)]))];
  }
  for (int g = 0; g < kElementGroupCount; ++g)
    if (count[at(g)] > 0) out.groupMeanTension[at(g)] /= count[at(g)];

  // energies: kinetic, elastic (elements at the current pose, gut, joint springs), gravity
  double kinetic = 0.0, gravity = 0.0;
  const Vector3d g = postureGravity(model, options);  // zero when gravity is off
  for (int b = 0; b < model.bodies.size(); ++b) {
    if (model.bodies.isFixed[at(b)]) continue;
    const Matrix3d r = state.bodyOrientation[at(b)].toRotationMatrix();
    const Vector3d om = r.transpose() * state.bodyAngularVelocity.col(b);
    kinetic += 0.5 * model.bodies.mass(b) * state.bodyVelocity.col(b).squaredNorm() +
               0.5 * om.dot(model.bodies.inertia[at(b)] * om);
    gravity -= model.bodies.mass(b) * g.dot(state.bodyPosition.col(b) - model.bodies.com.col(b));
    // the postural support: a constant force f at the body point p (postureSupport(), postureSupportPoint())
    if (model.bodies.supported(b)) {
      const Vector3d f = postureSupport(model, b, options), p = postureSupportPoint(model, b, options);
      gravity -= f.dot(state.bodyPosition.col(b) - model.bodies.com.col(b) + r * p - p);
    }
  }
  for (int n = 0; n < model.nodes.size(); ++n) {
    if (model.nodes.isFixed(n)) continue;
    kinetic += 0.5 * model.nodes.mass(n) * state.nodeVelocity.col(n).squaredNorm();
    gravity -= model.nodes.mass(n) * g.dot(state.nodePosition.col(n) - model.nodes.rest.col(n));
  }
  double elastic = 0.0;
  for (int e = 0; e < el.size(); ++e) {
    const double l = (anchorPosition(el.endB, e, state) - anchorPosition(el.endA, e, state)).norm();
    const MuscleParams p = muscleParams(model, work.constants, e, act, options);
    elastic += isMuscleGroup(el.group[at(e)]) ? muscleEnergy(l, p) : springEnergy(l, p.restLength, p.kpe);
  }
  if (work.constants.restGutVolume > 0.0)
    elastic += gutEnergy(kappa, work.constants.restGutVolume, out.gutVolume);
  for (int k = 0; k < model.volumes.size(); ++k)
    elastic += gutEnergy(model.volumes.kappa(k), work.constants.restBodyVolume(k), bodyVolume(k));
  // lung recoil: E = P0 dV + dV^2 / (2 C) while Ppl < 0, the potential of the pleural pressure
  if (model.cavity.compliance > 0.0) {
    const double dv = out.thoracicCavityVolume - work.constants.restCavityVolume;
    const double c = model.cavity.compliance, p0 = model.cavity.recoilPressure;
    const double dvZero = -p0 * c;  // [m^3] where Ppl reaches 0
    const double d = std::max(dv, dvZero);
    elastic += p0 * (d - dvZero) + (d * d - dvZero * dvZero) / (2.0 * c);
  }
  for (int i = 0; i < model.joints.size(); ++i) {
    const int p = model.joints.parent[at(i)];
    const Vector3d th = jointRotation(state, p, model.joints.child[at(i)]);
    elastic +=
        0.5 * th.dot(jointStiffness(model.joints, i, state.bodyOrientation[at(p)].toRotationMatrix()) * th);
  }
  out.kineticEnergy = kinetic;
  out.elasticEnergy = elastic;
  out.gravityEnergy = gravity;
  out.maxJointError = work.outputs.maxJointError;

  // landmarks
  anchorPositions(model.landmarks.points, state, out.landmarks);
}

}  // namespace pneuma::sim
