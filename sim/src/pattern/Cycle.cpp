#include "pneuma/sim/pattern/Cycle.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "pneuma/sim/Error.h"
#include "pneuma/sim/Limits.h"

namespace pneuma::sim::pattern {

namespace {

std::string num(double x) {
  std::ostringstream os;
  os << x;
  return os.str();
}

[[noreturn]] void fail(const std::string& field, const std::string& why) { throw Error(field + ": " + why); }

void requireRange(const std::string& field, double x, double lo, double hi) {
  if (!std::isfinite(x) || x < lo || x > hi)
    fail(field, "must be in [" + num(lo) + ", " + num(hi) + "], got " + num(x));
}

// monotone (PCHIP / Fritsch-Butland) slope at a keyframe between secants d0 (width h0) and d1 (width h1):
// zero at local extrema, a weighted harmonic mean otherwise, so the cubic never overshoots.
double monotoneSlope(double d0, double h0, double d1, double h1) {
  if (d0 * d1 <= 0.0) return 0.0;
  return 3.0 * (h0 + h1) / ((2.0 * h1 + h0) / d0 + (h1 + 2.0 * h0) / d1);
}

}  // namespace

const char* cycleKindName(CycleKind k) {
  switch (k) {
    case CycleKind::Linear:
      return "linear";
    case CycleKind::Keyframe:
      return "keyframe";
    case CycleKind::Spline:
      return "spline";
  }
  return "linear";
}

void validateCycle(const CycleSpec& c) {
  // scalar ranges
  requireRange("depth[0]", c.depthMin, 0.0, 1.0);
  requireRange("depth[1]", c.depthMax, 0.0, 1.0);
  if (c.depthMin > c.depthMax) fail("depth", "min " + num(c.depthMin) + " > max " + num(c.depthMax));
  if (!std::isfinite(c.ieRatio) || c.ieRatio <= 0.0) fail("ie_ratio", "must be > 0, got " + num(c.ieRatio));
  requireRange("post_inspiratory_pause_s", c.postInspiratoryPause, 0.0, 60.0);
  requireRange("post_expiratory_pause_s", c.postExpiratoryPause, 0.0, 60.0);
  requireRange("irregularity.rate", c.rateIrregularity, 0.0, 0.5);
  requireRange("irregularity.depth", c.depthIrregularity, 0.0, 0.5);
  requireRange("balance", c.balance, 0.0, 1.0);
  if (c.inspiratoryBalance) requireRange("inspiratory_balance", *c.inspiratoryBalance, 0.0, 1.0);

  // keyframes: which kinds need them
  const auto& k = c.keyframes;
  if (c.kind == CycleKind::Linear && !k.empty()) fail("keyframes", "not allowed for kind linear");
  if (c.kind == CycleKind::Keyframe && k.size() < 2)
    fail("keyframes", "kind keyframe needs at least 2 keyframes, got " + num(static_cast<double>(k.size())));
  if (c.kind == CycleKind::Spline && k.size() == 1) fail("keyframes", "needs at least 2 keyframes or none");
  if (!c.isRelative && k.empty()) fail("time", "absolute time needs keyframes (kind keyframe or spline)");

  // keyframes: order and range
  for (std::size_t i = 0; i < k.size(); ++i) {
    const std::string f = "keyframes[" + std::to_string(i) + "]";
    if (!std::isfinite(k[i].time)) fail(f + ".time", "must be finite");
    requireRange(f + ".volume", k[i].volume, 0.0, 1.0);
    if (i == 0 && k[i].time != 0.0)
      fail(f + ".time", "the first keyframe must be at time 0, got " + num(k[i].time));
    if (i > 0 && !(k[i].time > k[i - 1].time))
      fail(f + ".time", num(k[i].time) + " is not after keyframes[" + std::to_string(i - 1) + "].time " +
                            num(k[i - 1].time) + " (keyframes out of order)");
  }
  if (!k.empty()) {
    const std::string last = "keyframes[" + std::to_string(k.size() - 1) + "]";
    if (c.isRelative && k.back().time != 1.0)
      fail(last + ".time",
           "the last keyframe of a relative cycle must be at time 1, got " + num(k.back().time));
    if (k.back().volume != k.front().volume)
      fail(last + ".volume", "must equal keyframes[0].volume " + num(k.front().volume) +
                                 " so that the cycle repeats continuously, got " + num(k.back().volume));
  }

  // relative timing: the pauses must leave time to move
  const double pauses = c.postInspiratoryPause + c.postExpiratoryPause;
  if (c.isRelative) {
    kBreathRateRange.check("rate_bpm", c.rate);
    const double period = 60.0 / c.rate;
    if (period <= pauses)
      fail("rate_bpm", "period 60/" + num(c.rate) + " = " + num(period) +
                           " s leaves no time to breathe after " + num(pauses) + " s of pauses");
  }

  // a breath of bounded length (the breath scheduler steps from breath to breath), keyframes apart in time
  const double moving = c.isRelative ? 60.0 / c.rate - pauses : k.back().time;
  if (!c.isRelative) {
    const std::string last = "keyframes[" + std::to_string(k.size() - 1) + "].time";
    if (!kBreathPeriodRange.contains(moving + pauses))
      fail(last, "the breath (" + num(moving) + " s of keyframes + " + num(pauses) + " s of pauses) " +
                     kBreathPeriodRange.problem(moving + pauses));
  }
  const double timeScale =
      c.isRelative && !k.empty() ? moving / k.back().time : 1.0;  // [s] per keyframe time
  for (std::size_t i = 1; i < k.size(); ++i) {
    const double gap = (k[i].time - k[i - 1].time) * timeScale;  // [s]
    if (!(gap >= kMinKeyframeGap))
      fail("keyframes[" + std::to_string(i) + "].time",
           num(gap) + " s after keyframes[" + std::to_string(i - 1) + "]: keyframes must be at least " +
               num(kMinKeyframeGap) + " s apart");
  }
}

Cycle::Cycle(const CycleSpec& spec) : m_spec(spec) {
  validateCycle(spec);

  // normalised keyframes: explicit, or the I:E triangle rest -> peak -> rest
  if (spec.keyframes.empty()) {
    const double inspiration = spec.ieRatio / (1.0 + spec.ieRatio);
    m_u = {0.0, inspiration, 1.0};
    m_s = {0.0, 1.0, 0.0};
  } else {
    const double span = spec.keyframes.back().time;
    for (const Keyframe& k : spec.keyframes) {
      m_u.push_back(k.time / span);
      m_s.push_back(k.volume);
    }
  }
  m_peak = static_cast<int>(std::max_element(m_s.begin(), m_s.end()) - m_s.begin());
  m_moving = spec.isRelative ? 60.0 / spec.rate - spec.postInspiratoryPause - spec.postExpiratoryPause
                             : spec.keyframes.back().time;

  // periodic monotone slopes (the wrap-around secant is the last one)
  if (spec.kind == CycleKind::Spline) {
    const std::size_t n = m_u.size();
    m_slope.assign(n, 0.0);
    auto secant = [&](std::size_t i) { return (m_s[i + 1] - m_s[i]) / (m_u[i + 1] - m_u[i]); };
    for (std::size_t i = 1; i + 1 < n; ++i)
      m_slope[i] = monotoneSlope(secant(i - 1), m_u[i] - m_u[i - 1], secant(i), m_u[i + 1] - m_u[i]);
    m_slope[0] = monotoneSlope(secant(n - 2), m_u[n - 1] - m_u[n - 2], secant(0), m_u[1] - m_u[0]);
    m_slope[n - 1] = m_slope[0];
  }
}

double Cycle::duration(const BreathVariation& variation) const {
  return m_spec.postInspiratoryPause + m_spec.postExpiratoryPause + m_moving * variation.durationScale;
}

double Cycle::shape(double u) const {
  u = std::clamp(u, 0.0, 1.0);
  const std::size_t i = std::min<std::size_t>(
      static_cast<std::size_t>(std::upper_bound(m_u.begin(), m_u.end(), u) - m_u.begin()), m_u.size() - 1);
  const std::size_t a = i - 1;
  const double h = m_u[i] - m_u[a];
  const double t = (u - m_u[a]) / h;
  if (m_slope.empty()) return m_s[a] + t * (m_s[i] - m_s[a]);

  // cubic Hermite on [u_a, u_i]
  const double t2 = t * t, t3 = t2 * t;
  const double s = (2 * t3 - 3 * t2 + 1) * m_s[a] + (t3 - 2 * t2 + t) * h * m_slope[a] +
                   (-2 * t3 + 3 * t2) * m_s[i] + (t3 - t2) * h * m_slope[i];
  return std::clamp(s, 0.0, 1.0);
}

double Cycle::peakTime(const BreathVariation& variation) const {
  return m_u[static_cast<std::size_t>(m_peak)] * (m_moving * variation.durationScale);
}

double Cycle::balance(double tau, const BreathVariation& variation) const {
  return m_spec.inspiratoryBalance && tau < peakTime(variation) ? *m_spec.inspiratoryBalance : m_spec.balance;
}

double Cycle::volume(double tau, const BreathVariation& variation) const {
  // map breath time to shape time, holding during the pauses
  const double moving = m_moving * variation.durationScale;
  const double peak = peakTime(variation);
  const double pauseIn = m_spec.postInspiratoryPause;
  double u;
  if (tau <= peak)
    u = tau / moving;
  else if (tau <= peak + pauseIn)
    u = m_u[static_cast<std::size_t>(m_peak)];
  else
    u = (tau - pauseIn) / moving;

  // shape to volume fraction inside the (varied) depth range
  const double amplitude = (m_spec.depthMax - m_spec.depthMin) * variation.depthScale;
  return std::clamp(m_spec.depthMin + shape(u) * amplitude, 0.0, 1.0);
}

}  // namespace pneuma::sim::pattern
