#include "pneuma/sim/pattern/LayerStack.h"

#include <algorithm>
#include <cmath>

#include "pneuma/sim/Checkpoint.h"
#include "pneuma/sim/Error.h"

namespace pneuma::sim::pattern {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMaxBlend = 0.4;     // [s] longest cross-fade
constexpr double kSameVolume = 1e-9;  // [-] start volumes closer than this need no cross-fade
}  // namespace

const char* switchModeName(SwitchMode m) { return m == SwitchMode::Immediate ? "immediate" : "end_of_cycle"; }

bool switchModeFromName(const std::string& name, SwitchMode& out) {
  if (name == "immediate")
    out = SwitchMode::Immediate;
  else if (name == "end_of_cycle")
    out = SwitchMode::EndOfCycle;
  else
    return false;
  return true;
}

LayerStack::LayerStack(std::uint64_t seed) : m_random(seed) {}

double LayerStack::blendDuration(const Cycle& cycle) { return std::min(kMaxBlend, 0.25 * cycle.duration()); }

void LayerStack::push(const std::vector<Layer>& playOrder, SwitchMode mode, double atTime) {
  // validate every layer up front so that a bad push changes nothing
  if (playOrder.empty()) throw Error("layers: must not be empty");
  if (std::isnan(atTime)) throw Error("time_s: must not be NaN");
  Pending p{atTime, mode, {}};
  for (std::size_t i = 0; i < playOrder.size(); ++i) {
    const Layer& l = playOrder[i];
    const std::string field = "layers[" + std::to_string(i) + "]";
    if (l.repetitions != kInfinite && l.repetitions < 1)
      throw Error(field + ".repeat: must be >= 1 or infinite, got " + std::to_string(l.repetitions));
    try {
      p.layers.push_back(Active{l.name, Cycle(l.cycle), l.repetitions});
    } catch (const Error& e) {
      throw Error(field + ".cycle." + e.what());
    }
  }

  // keep the schedule sorted by time, pushes at equal times in call order
  auto pos = std::upper_bound(m_scheduled.begin(), m_scheduled.end(), atTime,
                              [](double t, const Pending& q) { return t < q.time; });
  m_scheduled.insert(pos, std::move(p));
}

double LayerStack::sample(double t) {
  if (!std::isfinite(t) || t < m_time)
    throw Error("sample: time must be finite and not decrease, got " + std::to_string(t) + " after " +
                std::to_string(m_time));

  // process the events up to t in time order: due pushes, then ends of breaths
  double now = m_time;
  for (;;) {
    if (m_layers.empty() && !m_atCycleEnd.empty()) {
      // nothing plays: an end-of-cycle push applies at once
      for (const Pending& p : m_atCycleEnd) pushNow(p.layers);
      m_atCycleEnd.clear();
      startBreath(now, m_hold);
      continue;
    }
    const double dueTime = m_scheduled.empty() ? kInf : std::max(m_scheduled.front().time, now);
    const double endTime =
        m_layers.empty() ? kInf : m_breathStart + m_layers.back().cycle.duration(m_variation);
    if (dueTime <= t && dueTime <= endTime) {
      Pending p = std::move(m_scheduled.front());
      m_scheduled.erase(m_scheduled.begin());
      now = dueTime;
      if (p.mode == SwitchMode::Immediate) {
        const double v = evaluate(now);
        pushNow(p.layers);
        startBreath(now, v);
      } else {
        m_atCycleEnd.push_back(std::move(p));
      }
    } else if (endTime <= t) {
      now = endTime;
      endBreath(now);
    } else {
      break;
    }
  }

  m_time = t;
  m_volume = evaluate(t);
  return m_volume;
}

double LayerStack::evaluate(double t) const {
  if (m_layers.empty()) return m_hold;
  double v = m_layers.back().cycle.volume(t - m_breathStart, m_variation);

  // cross-fade from the held switch volume (smoothstep weight)
  if (m_blendDuration > 0.0 && t < m_blendStart + m_blendDuration) {
    const double x = (t - m_blendStart) / m_blendDuration;
    const double w = 1.0 - x * x * (3.0 - 2.0 * x);
    v = w * m_blendFrom + (1.0 - w) * v;
  }
  return v;
}

void LayerStack::pushNow(const std::vector<Active>& layers) {
  for (auto it = layers.rbegin(); it != layers.rend(); ++it) m_layers.push_back(*it);
}

void LayerStack::startBreath(double t, double fromVolume) {
  // draw this breath's variation (always two draws, so the stream does not depend on the presets)
  const CycleSpec& c = m_layers.back().cycle.spec();
  m_breathStart = t;
  m_variation.durationScale = 1.0 + c.rateIrregularity * m_random.symmetric();
  m_variation.depthScale = 1.0 + c.depthIrregularity * m_random.symmetric();

  // cross-fade when the new breath does not start where the volume is (not for the very first breath)
  m_blendDuration = 0.0;
  const bool hadVolume = m_hasVolume;
  m_hasVolume = true;
  if (hadVolume && std::abs(m_layers.back().cycle.volume(0.0, m_variation) - fromVolume) > kSameVolume) {
    m_blendFrom = fromVolume;
    m_blendStart = t;
    m_blendDuration = blendDuration(m_layers.back().cycle);
  }
}

void LayerStack::endBreath(double t) {
  const double v = evaluate(t);

  // count the breath; a finished layer pops
  Active& top = m_layers.back();
  ++top.done;
  if (top.repetitions != kInfinite && top.done >= top.repetitions) m_layers.pop_back();

  // pushes waiting for this cycle end go on top
  for (const Pending& p : m_atCycleEnd) pushNow(p.layers);
  m_atCycleEnd.clear();

  if (m_layers.empty()) {
    m_hold = v;
    return;
  }
  startBreath(t, v);
}

void LayerStack::setStartVolume(double v) {
  m_hold = std::clamp(v, 0.0, 1.0);
  m_volume = m_hold;
  m_hasVolume = true;
}

double LayerStack::balance() const {
  return m_layers.empty() ? 0.5 : m_layers.back().cycle.balance(m_time - m_breathStart, m_variation);
}

std::string LayerStack::currentLayerName() const {
  return m_layers.empty() ? std::string() : m_layers.back().name;
}

namespace {

void writeCycle(CheckpointWriter& out, const std::string& key, const CycleSpec& c) {
  out.write(key + ".kind", static_cast<int>(c.kind));
  out.write(key + ".isRelative", c.isRelative);
  // an unset inspiratory balance is written as -1
  Eigen::Matrix<double, 10, 1> v;
  v << c.rate, c.depthMin, c.depthMax, c.ieRatio, c.postInspiratoryPause, c.postExpiratoryPause,
      c.rateIrregularity, c.depthIrregularity, c.balance, c.inspiratoryBalance.value_or(-1.0);
  out.write(key + ".values", v);
  Eigen::Matrix2Xd k(2, static_cast<Eigen::Index>(c.keyframes.size()));
  for (std::size_t i = 0; i < c.keyframes.size(); ++i)
    k.col(static_cast<Eigen::Index>(i)) << c.keyframes[i].time, c.keyframes[i].volume;
  out.write(key + ".keyframes", k);
}

CycleSpec readCycle(CheckpointReader& in, const std::string& key) {
  CycleSpec c;
  const long long kind = in.readInt(key + ".kind");
  if (kind < 0 || kind > static_cast<int>(CycleKind::Spline)) in.fail(key + ".kind", "unknown cycle kind");
  c.kind = static_cast<CycleKind>(kind);
  c.isRelative = in.readBool(key + ".isRelative");
  Eigen::Matrix<double, 10, 1> v;
  in.read(key + ".values", v);
  c.rate = v(0);
  c.depthMin = v(1);
  c.depthMax = v(2);
  c.ieRatio = v(3);
  c.postInspiratoryPause = v(4);
  c.postExpiratoryPause = v(5);
  c.rateIrregularity = v(6);
  c.depthIrregularity = v(7);
  c.balance = v(8);
  if (v(9) >= 0.0) c.inspiratoryBalance = v(9);
  Eigen::Matrix2Xd k;
  in.read(key + ".keyframes", k);
  for (Eigen::Index i = 0; i < k.cols(); ++i) c.keyframes.push_back({k(0, i), k(1, i)});
  return c;
}

}  // namespace

void LayerStack::saveState(CheckpointWriter& out, const std::string& prefix) const {
  const auto writeLayers = [&](const std::string& key, const std::vector<Active>& layers) {
    out.write(key, static_cast<long long>(layers.size()));
    for (std::size_t i = 0; i < layers.size(); ++i) {
      const std::string k = key + "[" + std::to_string(i) + "]";
      out.write(k + ".name", layers[i].name);
      writeCycle(out, k + ".cycle", layers[i].cycle.spec());
      out.write(k + ".repetitions", layers[i].repetitions);
      out.write(k + ".done", layers[i].done);
    }
  };
  const auto writePending = [&](const std::string& key, const std::vector<Pending>& pending) {
    out.write(key, static_cast<long long>(pending.size()));
    for (std::size_t i = 0; i < pending.size(); ++i) {
      const std::string k = key + "[" + std::to_string(i) + "]";
      out.write(k + ".time", pending[i].time);
      out.write(k + ".mode", static_cast<int>(pending[i].mode));
      writeLayers(k + ".layers", pending[i].layers);
    }
  };
  out.write(prefix + ".random", m_random.state());
  writeLayers(prefix + ".layers", m_layers);
  writePending(prefix + ".scheduled", m_scheduled);
  writePending(prefix + ".atCycleEnd", m_atCycleEnd);
  Eigen::Matrix<double, 9, 1> v;
  v << m_time, m_volume, m_hold, m_breathStart, m_variation.durationScale, m_variation.depthScale,
      m_blendFrom, m_blendStart, m_blendDuration;
  out.write(prefix + ".values", v);
  out.write(prefix + ".hasVolume", m_hasVolume);
}

void LayerStack::loadState(CheckpointReader& in, const std::string& prefix) {
  const auto count = [&](const std::string& key) {
    const long long n = in.readInt(key);
    if (n < 0 || n > 100000) in.fail(key, "bad count " + std::to_string(n));
    return static_cast<std::size_t>(n);
  };
  const auto readLayers = [&](const std::string& key) {
    std::vector<Active> layers;
    const std::size_t n = count(key);
    for (std::size_t i = 0; i < n; ++i) {
      const std::string k = key + "[" + std::to_string(i) + "]";
      std::string name = in.readString(k + ".name");
      const CycleSpec spec = readCycle(in, k + ".cycle");
      const int repetitions = static_cast<int>(in.readInt(k + ".repetitions"));
      const int done = static_cast<int>(in.readInt(k + ".done"));
      try {
        layers.push_back(Active{std::move(name), Cycle(spec), repetitions, done});
      } catch (const Error& e) {
        in.fail(k + ".cycle", e.what());
      }
    }
    return layers;
  };
  const auto readPending = [&](const std::string& key) {
    std::vector<Pending> pending;
    const std::size_t n = count(key);
    for (std::size_t i = 0; i < n; ++i) {
      const std::string k = key + "[" + std::to_string(i) + "]";
      const double time = in.readDouble(k + ".time");
      const long long mode = in.readInt(k + ".mode");
      if (mode != static_cast<int>(SwitchMode::EndOfCycle) && mode != static_cast<int>(SwitchMode::Immediate))
        in.fail(k + ".mode", "unknown switch mode");
      pending.push_back(Pending{time, static_cast<SwitchMode>(mode), readLayers(k + ".layers")});
    }
    return pending;
  };
  m_random = SplitMix64(in.readUnsigned(prefix + ".random"));
  m_layers = readLayers(prefix + ".layers");
  m_scheduled = readPending(prefix + ".scheduled");
  m_atCycleEnd = readPending(prefix + ".atCycleEnd");
  Eigen::Matrix<double, 9, 1> v;
  in.read(prefix + ".values", v);
  m_time = v(0);
  m_volume = v(1);
  m_hold = v(2);
  m_breathStart = v(3);
  m_variation.durationScale = v(4);
  m_variation.depthScale = v(5);
  m_blendFrom = v(6);
  m_blendStart = v(7);
  m_blendDuration = v(8);
  m_hasVolume = in.readBool(prefix + ".hasVolume");
}

}  // namespace pneuma::sim::pattern
