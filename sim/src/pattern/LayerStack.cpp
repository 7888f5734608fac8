#include "pneuma/sim/pattern/LayerStack.h"

#include "pneuma/sim/Error.h"

#include <algorithm>
#include <cmath>

namespace pneuma::sim::pattern {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMaxBlend = 0.4;            // [s] longest cross-fade
constexpr double kSameVolume = 1e-9;         // [-] start volumes closer than this need no cross-fade
}  // namespace

const char* switchModeName(SwitchMode m) { return m == SwitchMode::Immediate ? "immediate" : "end_of_cycle"; }

bool switchModeFromName(const std::string& name, SwitchMode& out) {
  if (name == "immediate") out = SwitchMode::Immediate;
  else if (name == "end_of_cycle") out = SwitchMode::EndOfCycle;
  else return false;
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
    const double endTime = m_layers.empty() ? kInf : m_breathStart + m_layers.back().cycle.duration(m_variation);
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

double LayerStack::balance() const { return m_layers.empty() ? 0.5 : m_layers.back().cycle.spec().balance; }

std::string LayerStack::currentLayerName() const { return m_layers.empty() ? std::string() : m_layers.back().name; }

}  // namespace pneuma::sim::pattern
