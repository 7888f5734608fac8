#include "pneuma/sim/Metrics.h"

#include <algorithm>
#include <cmath>
#include <complex>

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
std::complex<double> fundamental(const Trace& t, const std::vector<double>& v, std::size_t a, std::size_t b, double omega) {
  double mean = 0.0;
  for (std::size_t i = a; i < b; ++i) mean += v[i];
  mean /= static_cast<double>(b - a);
  std::complex<double> c = 0.0;
  for (std::size_t i = a; i < b; ++i) c += (v[i] - mean) * std::exp(std::complex<double>(0.0, -omega * t.time[i]));
  return c;
}

// motion in anatomical axes over the cycles delimited by the frames `up` (upward crossings of the mean volume)
Motion measureMotion(const Trace& t, const std::vector<std::string>& names, const std::vector<std::size_t>& up,
                     double period) {
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
    for (int c = 0; c < cycles; ++c) sum += f(insp[static_cast<std::size_t>(c)]) - f(exp[static_cast<std::size_t>(c)]);
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
  const int left = landmark("rib8_lateral_left"), right = landmark("rib8_lateral_right");
  if (left >= 0 && right >= 0)
    m.lowerRibExpansion = change([&](std::size_t i) { return (t.landmarks[i].col(left) - t.landmarks[i].col(right)).norm(); });

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

Eigen::Vector3d landmarkRange(const Trace& trace, int index, double from) {
  const std::size_t i0 = firstIndex(trace, from);
  if (index < 0 || i0 >= trace.size()) return Eigen::Vector3d::Zero();
  Eigen::Vector3d lo = trace.landmarks[i0].col(index), hi = lo;
  for (std::size_t i = i0; i < trace.size(); ++i) {
    lo = lo.cwiseMin(trace.landmarks[i].col(index));
    hi = hi.cwiseMax(trace.landmarks[i].col(index));
  }
  return hi - lo;
}

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
  // (so ringing smaller than a quarter of the breath is not counted as breaths)
  const auto begin = trace.lungVolume.begin() + static_cast<std::ptrdiff_t>(i0);
  const double lo = *std::min_element(begin, trace.lungVolume.end());
  const double hi = *std::max_element(begin, trace.lungVolume.end());
  double mean = 0.0;
  for (std::size_t i = i0; i < trace.size(); ++i) mean += trace.lungVolume[i];
  mean /= static_cast<double>(trace.size() - i0);
  const double hysteresis = 0.25 * (hi - lo);
  std::vector<std::size_t> up;     // frame index of each upward crossing
  std::vector<double> upTime;      // [s] interpolated crossing time
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
      const auto b = trace.lungVolume.begin() + static_cast<std::ptrdiff_t>(up[static_cast<std::size_t>(c) + 1]);
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

}  // namespace pneuma::sim
