#include "pneuma/sim/Metrics.h"

#include <algorithm>
#include <cmath>

namespace pneuma::sim {

void Trace::append(const Metrics& m) {
  time.push_back(m.time);
  lungVolume.push_back(m.lungVolume);
  gutVolumeError.push_back(m.gutVolumeError);
  landmarks.push_back(m.landmarks);
}

void Trace::clear() {
  time.clear();
  lungVolume.clear();
  gutVolumeError.clear();
  landmarks.clear();
}

namespace {
// first frame index with time >= from
std::size_t firstIndex(const Trace& t, double from) {
  return static_cast<std::size_t>(std::lower_bound(t.time.begin(), t.time.end(), from) - t.time.begin());
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

double landmarkExcursion(const Trace& trace, int index, double from) {
  return landmarkRange(trace, index, from).maxCoeff();
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
  }

  // landmark excursions
  auto excursion = [&](const char* name) {
    const auto it = std::find(landmarkNames.begin(), landmarkNames.end(), name);
    return it == landmarkNames.end() ? 0.0
                                     : landmarkExcursion(trace, static_cast<int>(it - landmarkNames.begin()), from);
  };
  s.diaphragmApexExcursion = excursion("diaphragm_apex");
  s.xiphoidExcursion = excursion("xiphoid");
  s.umbilicusExcursion = excursion("umbilicus");
  return s;
}

}  // namespace pneuma::sim
