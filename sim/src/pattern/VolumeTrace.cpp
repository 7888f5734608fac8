#include "pneuma/sim/pattern/VolumeTrace.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "pneuma/sim/Error.h"
#include "pneuma/sim/JsonReader.h"
#include "pneuma/sim/Limits.h"
#include "pneuma/sim/pattern/PatternController.h"

namespace pneuma::sim::pattern {

namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

std::vector<std::string> splitFields(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream in(line);
  std::string f;
  while (std::getline(in, f, ',')) fields.push_back(trim(f));
  if (!line.empty() && line.back() == ',') fields.push_back("");
  return fields;
}

// one located column: its index and, for the volume, the factor to m^3
struct Column {
  int index = -1;
  std::string header;
  double toSi = 1.0;
};

// value at x[0] of the least-squares parabola through x[0 .. m-1] (unit spacing): the trace's edge with its
// noise averaged out and its slope and curvature kept (a Savitzky-Golay end-point estimate)
double edgeValue(const std::vector<double>& x, std::ptrdiff_t m) {
  m = std::min<std::ptrdiff_t>(m, static_cast<std::ptrdiff_t>(x.size()));
  if (m < 3) return x.front();
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (std::ptrdiff_t i = 0; i < m; ++i) {
    const double s = static_cast<double>(i);
    const Eigen::Vector3d basis(1.0, s, s * s);
    normal += basis * basis.transpose(), rhs += basis * x[static_cast<std::size_t>(i)];
  }
  return normal.ldlt().solve(rhs)(0);
}

// zero-phase second-order Butterworth low-pass (bilinear transform), run forwards then backwards over the
// trace padded at each end by its odd reflection about the edge value (2 e - x[k], k = 1 .. pad): a padded
// trace continues with the edge's value and slope, so the filter's start-up transient falls in the padding
// and the trace's ends are not pulled toward a mean (scipy.signal.filtfilt's 'odd' padding, with the edge
// value taken from a parabola over one cut-off period instead of the one edge sample, so that sensor noise
// on that sample is not mirrored into the whole padding)
void filtfilt(std::vector<double>& x, double timeStep, double cutoff) {
  const auto n = static_cast<std::ptrdiff_t>(x.size());
  const auto period = static_cast<std::ptrdiff_t>(std::round(1.0 / (cutoff * timeStep)));
  const std::ptrdiff_t pad = std::min<std::ptrdiff_t>(2 * period, n - 1);
  const double front = edgeValue(x, period);
  const double back = edgeValue(std::vector<double>(x.rbegin(), x.rend()), period);
  std::vector<double> padded;
  padded.reserve(static_cast<std::size_t>(n + 2 * pad));
  for (std::ptrdiff_t i = pad; i >= 1; --i) padded.push_back(2.0 * front - x[static_cast<std::size_t>(i)]);
  padded.insert(padded.end(), x.begin(), x.end());
  for (std::ptrdiff_t i = 1; i <= pad; ++i)
    padded.push_back(2.0 * back - x[static_cast<std::size_t>(n - 1 - i)]);

  const double k = std::tan(M_PI * cutoff * timeStep), norm = 1.0 / (1.0 + std::sqrt(2.0) * k + k * k);
  const double b0 = k * k * norm, b1 = 2.0 * b0, b2 = b0;
  const double a1 = 2.0 * (k * k - 1.0) * norm, a2 = (1.0 - std::sqrt(2.0) * k + k * k) * norm;
  // each pass starts steady at its first (padding) sample
  const auto pass = [&](auto begin, auto end) {
    double x1 = *begin, x2 = *begin, y1 = *begin, y2 = *begin;
    for (auto it = begin; it != end; ++it) {
      const double y = b0 * *it + b1 * x1 + b2 * x2 - a1 * y1 - a2 * y2;
      x2 = x1, x1 = *it, y2 = y1, y1 = y;
      *it = y;
    }
  };
  pass(padded.begin(), padded.end());
  pass(padded.rbegin(), padded.rend());
  std::copy(padded.begin() + pad, padded.begin() + pad + n, x.begin());
}

}  // namespace

double VolumeTrace::sample(double t) const {
  if (volume.empty()) return 0.0;
  const double s = t / timeStep;
  if (!(s > 0.0)) return volume.front();
  const std::size_t k = static_cast<std::size_t>(s);
  if (k + 1 >= volume.size()) return volume.back();
  const double w = s - static_cast<double>(k);
  return (1.0 - w) * volume[k] + w * volume[k + 1];
}

double VolumeTrace::duration() const {
  return volume.empty() ? 0.0 : timeStep * static_cast<double>(volume.size() - 1);
}

VolumeTrace parseVolumeTrace(const std::string& text, const std::string& sourceName, double timeStep,
                             double cutoff) {
  if (!(timeStep > 0.0) || !(cutoff > 0.0 && cutoff < 0.5 / timeStep))
    throw Error(sourceName + ": trace step or cut-off out of range");
  std::stringstream in(text);
  std::string line;
  int lineNo = 0;
  Column time, vol;
  bool hasHeader = false;
  std::vector<double> t, v;  // [s], [m^3] as read
  std::vector<int> rowLine;  // file line of each row
  const auto where = [&](int ln, const Column& c) {
    return sourceName + ":" + std::to_string(ln) + ": column " + std::to_string(c.index + 1) + " '" +
           excerptOf(c.header) + "': ";
  };
  while (std::getline(in, line)) {
    ++lineNo;
    const std::string trimmed = trim(line);
    if (trimmed.empty() || trimmed[0] == '#') continue;
    const std::vector<std::string> fields = splitFields(trimmed);
    if (!hasHeader) {
      hasHeader = true;
      for (int c = 0; c < static_cast<int>(fields.size()); ++c) {
        const std::string& h = fields[c];
        const auto open = h.find('[');
        const std::string name = trim(h.substr(0, open));
        const bool isTime = name == "time", isVolume = name == "volume" || name == "lung_volume";
        if (!isTime && !isVolume) continue;
        Column& col = isTime ? time : vol;
        if (col.index >= 0) continue;  // the first of two candidate columns is used
        col.index = c, col.header = h;
        const auto close = h.find(']', open == std::string::npos ? 0 : open);
        if (open == std::string::npos || close == std::string::npos)
          throw Error(where(lineNo, col) + "missing unit (write '" + name +
                      (isTime ? " [s]'" : " [L]' or '" + name + " [mL]'") + ")");
        const std::string unit = trim(h.substr(open + 1, close - open - 1));
        if (isTime && unit == "s") continue;
        if (isVolume && unit == "L") {
          col.toSi = 1e-3;
          continue;
        }
        if (isVolume && unit == "mL") {
          col.toSi = 1e-6;
          continue;
        }
        throw Error(where(lineNo, col) + "unknown unit '" + excerptOf(unit) + "' (use " +
                    (isTime ? "s" : "L or mL") + ")");
      }
      if (time.index < 0 || vol.index < 0)
        throw Error(sourceName + ":" + std::to_string(lineNo) +
                    ": header needs a 'time [s]' and a 'volume [L]' (or [mL]) column, got '" +
                    excerptOf(trimmed) + "'");
      continue;
    }
    double value[2];
    const Column* cols[2] = {&time, &vol};
    for (int i = 0; i < 2; ++i) {
      const Column& c = *cols[i];
      if (c.index >= static_cast<int>(fields.size())) throw Error(where(lineNo, c) + "missing value");
      const std::string& f = fields[c.index];
      char* end = nullptr;
      errno = 0;
      value[i] = std::strtod(f.c_str(), &end);
      if (f.empty() || end != f.c_str() + f.size() || !std::isfinite(value[i]))
        throw Error(where(lineNo, c) + "not a finite number: '" + excerptOf(f) + "'");
      value[i] *= c.toSi;
    }
    if (!t.empty() && !(value[0] > t.back()))
      throw Error(where(lineNo, time) + "time must increase, got " + fields[time.index] + " after line " +
                  std::to_string(rowLine.back()));
    if (value[1] < 0.0) throw Error(where(lineNo, vol) + "negative volume " + fields[vol.index]);
    t.push_back(value[0]), v.push_back(value[1]), rowLine.push_back(lineNo);
  }
  if (t.size() < 2) throw Error(sourceName + ": a trace needs a header and at least two rows");
  kDurationRange.check(sourceName + ": duration", t.back() - t.front());
  // an impossible swing is reported at the row that takes it beyond the limit
  double lo = v[0], hi = v[0];
  for (std::size_t i = 0; i < v.size(); ++i) {
    lo = std::min(lo, v[i]), hi = std::max(hi, v[i]);
    if (hi - lo > kMaxTraceSwing)
      throw Error(where(rowLine[i], vol) + "volume swing " + std::to_string((hi - lo) * 1e3) +
                  " L exceeds the " + std::to_string(kMaxTraceSwing * 1e3).substr(0, 3) +
                  " L a lung can hold");
  }

  // 1. resample: the mean of the rows' piecewise-linear curve over each step's window [s - h/2, s + h/2]
  // (held beyond the ends), through its running integral C(x) = integral from t_0 to x of V
  std::vector<double> area(t.size(), 0.0);  // [m^3 s] C(t_i)
  for (std::size_t i = 1; i < t.size(); ++i)
    area[i] = area[i - 1] + 0.5 * (v[i] + v[i - 1]) * (t[i] - t[i - 1]);
  const auto integral = [&](double x) {
    if (x <= t.front()) return (x - t.front()) * v.front();
    if (x >= t.back()) return area.back() + (x - t.back()) * v.back();
    const std::size_t i = static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), x) - t.begin()) - 1;
    const double vx = v[i] + (v[i + 1] - v[i]) * (x - t[i]) / (t[i + 1] - t[i]);
    return area[i] + 0.5 * (v[i] + vx) * (x - t[i]);
  };
  VolumeTrace out;
  out.timeStep = timeStep;
  const double t0 = t.front();
  const std::size_t n = static_cast<std::size_t>(std::floor((t.back() - t0) / timeStep + 1e-9)) + 1;
  out.volume.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double s = t0 + timeStep * static_cast<double>(k);
    out.volume[k] = (integral(s + 0.5 * timeStep) - integral(s - 0.5 * timeStep)) / timeStep;
  }
  // 2. zero-phase low-pass, 3. offset to the minimum
  filtfilt(out.volume, timeStep, cutoff);
  const double minimum = *std::min_element(out.volume.begin(), out.volume.end());
  for (double& x : out.volume) x -= minimum;
  return out;
}

VolumeTrace loadVolumeTrace(const std::string& path) {
  VolumeTrace trace = parseVolumeTrace(readInputFile(path), path, kDriveTimeStep);
  trace.name = path.substr(path.find_last_of('/') + 1);
  return trace;
}

}  // namespace pneuma::sim::pattern
