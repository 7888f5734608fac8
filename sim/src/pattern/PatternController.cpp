#include "pneuma/sim/pattern/PatternController.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "pneuma/sim/Checkpoint.h"
#include "pneuma/sim/Error.h"

namespace pneuma::sim::pattern {

namespace {

std::size_t idx(ElementGroup g) { return static_cast<std::size_t>(g); }

constexpr ElementGroup kDrivenGroups[] = {ElementGroup::IntercostalExternal,
                                          ElementGroup::IntercostalInternal, ElementGroup::Diaphragm,
                                          ElementGroup::Rectus, ElementGroup::TransversusObliques};

// the useful part of a response curve in direction `sign` (+1 raises, -1 lowers the volume), made
// monotone: reach[k] = max over j <= k of max(sign R[j], 0); reach.back() is the group's capacity
GroupResponse reach(const GroupResponse& response, double sign) {
  GroupResponse r{};
  for (std::size_t k = 1; k < r.size(); ++k) r[k] = std::max(r[k - 1], sign * response[k]);
  return r;
}

// the activation whose reach is `demand` (linear between levels; 0 for no demand; beyond the capacity the
// lowest level that reaches it: a group whose answer falls again at high activation is not driven past its
// peak)
double invert(const GroupResponse& reach, double demand) {
  if (demand <= 0.0) return 0.0;
  std::size_t peak = 0;
  for (std::size_t k = 1; k < reach.size(); ++k) {
    if (reach[k] <= reach[k - 1]) continue;
    if (reach[k] >= demand)
      return kCalibrationAlphas[k - 1] + (demand - reach[k - 1]) / (reach[k] - reach[k - 1]) *
                                             (kCalibrationAlphas[k] - kCalibrationAlphas[k - 1]);
    peak = k;
  }
  return kCalibrationAlphas[peak];
}

// one lever: the useful reach curve of its muscle group(s) and their time constant
struct Lever {
  GroupResponse reach{};  // [-] monotone useful fraction change at each of kCalibrationAlphas
  double tau = 0.0;       // [s] lag of the lung volume behind the lever's activation
  double capacity() const { return reach.back(); }
};
// a channel of the drive (chest or belly): the lever that raises the volume and the one that lowers it
struct Channel {
  Lever in, out;
  // [-] the capacity in the direction of a signed demand (0 for none)
  double capacity(double demand) const {
    return demand > 0.0 ? in.capacity() : demand < 0.0 ? out.capacity() : 0.0;
  }
};
// the drive's two channels: chest (external / internal intercostals) and belly (diaphragm / abdominal
// wall: rectus and transversus/obliques at one activation, their useful reaches added)
struct Levers {
  Channel chest, belly;
};
// the levers of calibration `c`; `internalLag` [s] (PatternControllerOptions::internalIntercostalLag) is
// added to the internal intercostals' lag
Levers levers(const DriveCalibration& c, double internalLag = 0.0) {
  auto lever = [&c, internalLag](ElementGroup g, double sign) {
    const double lag = g == ElementGroup::IntercostalInternal ? internalLag : 0.0;
    return Lever{reach(c.response[idx(g)], sign), c.timeConstant[idx(g)] + lag};
  };
  Levers l;
  l.chest = {lever(ElementGroup::IntercostalExternal, 1.0), lever(ElementGroup::IntercostalInternal, -1.0)};
  l.belly.in = lever(ElementGroup::Diaphragm, 1.0);
  const Lever rectus = lever(ElementGroup::Rectus, -1.0),
              obliques = lever(ElementGroup::TransversusObliques, -1.0);
  for (std::size_t k = 0; k < l.belly.out.reach.size(); ++k)
    l.belly.out.reach[k] = rectus.reach[k] + obliques.reach[k];
  const double wall = rectus.capacity() + obliques.capacity();
  l.belly.out.tau =
      wall > 0.0 ? (rectus.capacity() * rectus.tau + obliques.capacity() * obliques.tau) / wall : 0.0;
  return l;
}

// [-] of the volume fraction (15 mL at the default 2.5 L per unit): the width of the hand-over between a
// channel's two levers in channelDemand(). With plain max(x, 0) the chest's demand kept its value but not its
// slope where the external intercostals' lag term (tau_in about 0.19 s) switched on; the chest, quasi-static
// at 10 ms, follows its activation within one step, so the flow jumped for one step and echoed through the
// feedback (focus: the internal alpha fell 0.048 in one step against 0.016 before, the lung volume rose 7.5
// mL in that step and 3 mL in the steps around it: 45 % of peak flow at 10 ms; 8 % with the rounded
// hand-over)
constexpr double kHandOverWidth = 0.006;

// max(x, 0) with its corner rounded over [-w/2, w/2] by the parabola (x + w/2)^2 / (2 w): equal to it outside
// that band, continuous with its slope everywhere, and rampUp(x) - rampUp(-x) = x
double rampUp(double x, double w) {
  if (x >= 0.5 * w) return x;
  if (x <= -0.5 * w) return 0.0;
  return (x + 0.5 * w) * (x + 0.5 * w) / (2.0 * w);
}

// a channel's whole demand (as if it took all of the target): the static demand plus the inverse of its
// lag, tau times the target's rate, each lever with its own tau: the raising lever's positive part plus the
// lowering lever's negative part, each rounded over kHandOverWidth (rampUp). Continuous in the demand and the
// rate, and so is its slope (picking one lever by the sign of d + tau_in r jumped from 0 to d + tau_out r
// where the two lags differ, each time the rate changed sign); with equal lags it is d + tau r exactly
double channelDemand(double demand, double rate, const Channel& ch) {
  return rampUp(demand + ch.in.tau * rate, kHandOverWidth) -
         rampUp(-(demand + ch.out.tau * rate), kHandOverWidth);
}

// the share of the target the chest takes: the balance b, lowered (raised) until the chest's (belly's)
// part of its whole demand fits its capacity when both pull the same way; the other channel takes over
// that part of the target and compensates its own lag for it
double chestShare(double balance, double chestWhole, double bellyWhole, const Levers& l) {
  if (chestWhole * bellyWhole < 0.0) return balance;  // opposite directions: each is clipped on its own
  double b = balance;
  if (std::abs(b * chestWhole) > l.chest.capacity(chestWhole))
    b = l.chest.capacity(chestWhole) / std::abs(chestWhole);
  if (std::abs((1.0 - b) * bellyWhole) > l.belly.capacity(bellyWhole))
    b = std::max(b, 1.0 - l.belly.capacity(bellyWhole) / std::abs(bellyWhole));
  return b;
}

// calibration run of one group: it rests for kRest, then steps through the non-zero levels of
// kCalibrationAlphas, kLevel at each (r fixed), while every other group stays relaxed; control time t
constexpr double kRest = 0.6;                                                    // [s]
constexpr double kLevel = 0.8;                                                   // [s]
constexpr double kGroupTime = kRest + kLevel * (kCalibrationAlphas.size() - 1);  // [s] per group
class StaircaseController : public Controller {
 public:
  StaircaseController(ElementGroup group, double r) : m_group(group), m_r(r) {}
  Activations activations(double t, const Metrics&) override {
    Activations a = relaxedActivations();
    if (t >= kRest) {
      const auto level =
          std::min(1 + static_cast<std::size_t>((t - kRest) / kLevel), kCalibrationAlphas.size() - 1);
      a[idx(m_group)] = {m_r, kCalibrationAlphas[level]};
    }
    return a;
  }
  std::string describe() const override { return "drive calibration staircase"; }
  std::unique_ptr<Controller> clone() const override { return std::make_unique<StaircaseController>(*this); }
  double maxTimeStep() const override { return kDriveTimeStep; }

 private:
  ElementGroup m_group;
  double m_r;
};

// mean lung volume [m^3] of the trace frames with time in [from, to)
double meanVolume(const Trace& trace, double from, double to) {
  double sum = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < trace.size(); ++i)
    if (trace.time[i] >= from && trace.time[i] < to) sum += trace.lungVolume[i], ++n;
  if (n == 0)
    throw Error("calibrateDrive: no output frames in [" + std::to_string(from) + ", " + std::to_string(to) +
                ") s");
  return sum / n;
}

// integral [m^3 s] of (final - V(t)) over the trace frames with time in [from, to) (rectangle rule on
// the frame times): for a first-order response to a step settling at `final` it is tau times the step
double settlingArea(const Trace& trace, double from, double to, double final) {
  double area = 0.0;
  for (std::size_t i = 1; i < trace.size(); ++i)
    if (trace.time[i] > from && trace.time[i] <= to)
      area += (final - trace.lungVolume[i - 1]) * (trace.time[i] - trace.time[i - 1]);
  return area;
}

}  // namespace

double groupResponse(const DriveCalibration& c, ElementGroup g, double alpha) {
  const GroupResponse& r = c.response[idx(g)];
  alpha = std::clamp(alpha, 0.0, 1.0);
  std::size_t k = 1;
  while (k + 1 < r.size() && kCalibrationAlphas[k] < alpha) ++k;
  const double w = (alpha - kCalibrationAlphas[k - 1]) / (kCalibrationAlphas[k] - kCalibrationAlphas[k - 1]);
  return r[k - 1] + w * (r[k] - r[k - 1]);
}

DriveCalibration calibrateDrive(std::shared_ptr<const Model> model, const SimulationOptions& options,
                                double contractionR, const std::atomic<bool>* stop) {
  constexpr double kRestWindow = 0.3;   // [s] baseline: end of each rest
  constexpr double kLevelWindow = 0.4;  // [s] response: end of each level
  DriveCalibration c;
  c.contractionR = contractionR;
  const double start = options.settleTime;
  for (std::size_t n = 0; n < std::size(kDrivenGroups); ++n) {
    // one run per group from the settled torso: the ribs' slow release (rib friction) would otherwise
    // carry one group's answer into the next group's baseline
    Simulation sim(model, std::make_unique<StaircaseController>(kDrivenGroups[n], contractionR), options);
    sim.setStopFlag(stop);
    sim.advance(start + kGroupTime);
    if (sim.wasStopped())
      throw Interrupted(std::string("drive calibration stopped by request at group ") +
                        groupName(kDrivenGroups[n]));
    const double rest = meanVolume(sim.trace(), start + kRest - kRestWindow, start + kRest);
    if (n == 0) c.restVolume = rest;
    GroupResponse& r = c.response[idx(kDrivenGroups[n])];
    double area = 0.0, change = 0.0;  // [m^3 s], [m^3] summed over the steps
    for (std::size_t k = 1; k < r.size(); ++k) {
      const double end = start + kRest + k * kLevel;
      r[k] = (meanVolume(sim.trace(), end - kLevelWindow, end) - rest) / c.volumePerFraction;
      const double from = rest + r[k - 1] * c.volumePerFraction, to = rest + r[k] * c.volumePerFraction;
      // steps that take the group further from rest (a group past its peak answers the other way)
      if ((to - from) * r[k] > 0.0) {
        area += settlingArea(sim.trace(), end - kLevel, end, to);
        change += to - from;
      }
    }
    // method of moments over the whole staircase: tau = sum of areas / sum of changes
    c.timeConstant[idx(kDrivenGroups[n])] = std::abs(change) > 0.0 ? std::max(area / change, 0.0) : 0.0;
  }
  return c;
}

double TrackingStats::rmsPercentOfPeakToPeak() const {
  if (frames == 0 || targetMax <= targetMin) return 0.0;
  return 100.0 * std::sqrt(sumSquaredError / static_cast<double>(frames)) / (targetMax - targetMin);
}

PatternController::PatternController(LayerStack stack, DriveCalibration calibration,
                                     PatternControllerOptions options, std::string description)
    : m_stack(stack),
      m_initialStack(std::move(stack)),
      m_calibration(calibration),
      m_givenCalibration(calibration),
      m_options(options),
      m_description(std::move(description)) {
  const DriveCalibration& c = m_calibration;
  for (ElementGroup g : kDrivenGroups)
    for (std::size_t k = 0; k < kCalibrationAlphas.size(); ++k)
      if (!std::isfinite(c.response[idx(g)][k]))
        throw Error(std::string("calibration.response.") + groupName(g) + "[" + std::to_string(k) +
                    "]: must be finite, got " + std::to_string(c.response[idx(g)][k]));
  for (ElementGroup g : kDrivenGroups)
    if (!(c.timeConstant[idx(g)] >= 0.0 && c.timeConstant[idx(g)] < 10.0))
      throw Error(std::string("calibration.timeConstant.") + groupName(g) + ": must be in [0, 10) s, got " +
                  std::to_string(c.timeConstant[idx(g)]));
  const Levers l = levers(c);
  if (l.chest.in.capacity() + l.belly.in.capacity() <= 0.0)
    throw Error("calibration.response: neither intercostal_external nor diaphragm raises the lung volume");
  if (l.chest.out.capacity() + l.belly.out.capacity() <= 0.0)
    throw Error(
        "calibration.response: none of intercostal_internal, rectus, transversus_obliques lowers the lung "
        "volume");
  if (!(c.volumePerFraction > 0.0)) throw Error("calibration.volumePerFraction: must be > 0");
  if (!(c.restVolume >= 0.0)) throw Error("calibration.restVolume: must be >= 0");
  if (!(c.contractionR > 0.0 && c.contractionR <= 1.5))
    throw Error("calibration.contractionR: must be in (0, 1.5]");
  if (!(options.kp >= 0.0 && options.ki >= 0.0 && options.integralLimit >= 0.0 &&
        options.balanceTimeConstant > 0.0 && options.internalIntercostalLag >= 0.0))
    throw Error("pattern controller options: gains and times must be >= 0 (balanceTimeConstant > 0)");
  m_balance = m_stack.balance();
}

PatternController::PatternController(VolumeTrace trace, DriveCalibration calibration,
                                     PatternControllerOptions options)
    : PatternController(LayerStack(), calibration, options, trace.name) {
  if (trace.volume.empty()) throw Error("trace '" + trace.name + "': no samples");
  m_trace = std::make_shared<const VolumeTrace>(std::move(trace));
}

double PatternController::sampleTarget(double tau) {
  if (!m_trace) return m_stack.sample(tau);
  const double v = m_calibration.restFraction + m_trace->sample(tau) / m_calibration.volumePerFraction;
  const double s = std::clamp(tau / kTraceBlend, 0.0, 1.0), w = 1.0 - s * s * (3.0 - 2.0 * s);  // smoothstep
  return w * m_traceStart + (1.0 - w) * v;
}

double PatternController::volumeToFraction(double volume) const {
  return m_calibration.restFraction + (volume - m_calibration.restVolume) / m_calibration.volumePerFraction;
}

double PatternController::fractionToVolume(double fraction) const {
  return m_calibration.restVolume + (fraction - m_calibration.restFraction) * m_calibration.volumePerFraction;
}

void PatternController::push(const std::vector<Layer>& playOrder, SwitchMode mode) {
  m_stack.push(playOrder, mode);
}

void PatternController::restart() {
  m_stack = m_initialStack;
  m_calibration = m_givenCalibration;
  m_isControlling = false;
  m_restVolumeSeen = 0.0;
  m_lastTime = m_lastFrameControlTime = m_startTime = 0.0;
  m_lastFrameTime = -1.0;
  m_target = m_targetRate = m_measured = m_error = m_integral = m_traceStart = m_internalAlpha = 0.0;
  m_balance = m_stack.balance();
  m_tracking = TrackingStats();
}

Activations PatternController::activations(double t, const Metrics& latest) {
  // control time going backwards means the simulation was reset: start the pattern over
  if (t < m_lastTime) restart();

  // settling (t = 0): hold the rest posture and learn the rest volume unless it was given
  if (!m_isControlling && t <= 0.0) {
    if (latest.lungVolume > 0.0 && m_calibration.restVolume == 0.0) m_restVolumeSeen = latest.lungVolume;
    m_target = m_calibration.restFraction;
    return distribute(0.0, 0.0, m_balance);
  }

  // control starts: the pattern clock starts here, and its first breath blends from the measured volume
  if (!m_isControlling) {
    m_isControlling = true;
    if (m_calibration.restVolume == 0.0) m_calibration.restVolume = m_restVolumeSeen;
    m_startTime = t;
    m_lastTime = t;
    m_lastFrameTime = latest.time;
    m_lastFrameControlTime = t;
    m_traceStart = m_calibration.restVolume > 0.0 && latest.lungVolume > 0.0
                       ? volumeToFraction(latest.lungVolume)
                       : m_calibration.restFraction;
    m_stack.setStartVolume(m_traceStart);
  }
  const double dt = t - m_lastTime;
  m_lastTime = t;

  // target, and the feed-forward demand: its distance from rest, and its rate (backward difference)
  const double previousTarget = m_target;
  m_target = sampleTarget(t - m_startTime);
  const double feedForward = m_target - m_calibration.restFraction;
  m_targetRate = dt > 0.0 ? (m_target - previousTarget) / dt : 0.0;

  // feedback: a new frame was measured at this very control time
  if (latest.time > m_lastFrameTime && m_calibration.restVolume > 0.0) {
    m_measured = volumeToFraction(latest.lungVolume);
    m_error = m_target - m_measured;
    // anti-windup: integrate only while the muscles can still give what the error asks for
    const double demand = feedForward + m_options.kp * m_error + m_integral;
    const Levers l = levers(m_calibration, m_options.internalIntercostalLag);
    const bool isSaturated = m_error > 0.0 ? demand >= l.chest.in.capacity() + l.belly.in.capacity()
                                           : -demand >= l.chest.out.capacity() + l.belly.out.capacity();
    if (!isSaturated)
      m_integral = std::clamp(m_integral + m_options.ki * m_error * (t - m_lastFrameControlTime),
                              -m_options.integralLimit, m_options.integralLimit);
    m_lastFrameTime = latest.time;
    m_lastFrameControlTime = t;
    // statistics
    m_tracking.frames += 1;
    m_tracking.sumSquaredError += m_error * m_error;
    m_tracking.targetMin = std::min(m_tracking.targetMin, m_target);
    m_tracking.targetMax = std::max(m_tracking.targetMax, m_target);
  }

  // smooth balance changes (between layers, and at the peak of a cycle with an inspiratory balance)
  m_balance += (m_stack.balance() - m_balance) * (1.0 - std::exp(-dt / m_options.balanceTimeConstant));

  // feed-forward plus PI feedback, in volume-fraction units
  Activations a = distribute(feedForward + m_options.kp * m_error + m_integral, m_targetRate, m_balance);
  // the internal intercostals follow their drive with a first-order lag (internalIntercostalLag)
  double& internal = a[idx(ElementGroup::IntercostalInternal)].alpha;
  const double lag = m_options.internalIntercostalLag;
  m_internalAlpha =
      lag > 0.0 ? m_internalAlpha + (internal - m_internalAlpha) * (1.0 - std::exp(-dt / lag)) : internal;
  internal = m_internalAlpha;
  return a;
}

Activations PatternController::distribute(double demand, double rate, double balance) const {
  Activations a = relaxedActivations();
  for (ElementGroup group : kDrivenGroups) a[idx(group)].r = m_calibration.contractionR;
  const Levers l = levers(m_calibration, m_options.internalIntercostalLag);
  // split the target by the balance, each channel with its own lag compensation; a saturated channel
  // hands part of its share to the other
  const double chestWhole = channelDemand(demand, rate, l.chest),
               bellyWhole = channelDemand(demand, rate, l.belly);
  const double b = chestShare(balance, chestWhole, bellyWhole, l);
  const double chest = b * chestWhole, belly = (1.0 - b) * bellyWhole;
  // chest: external intercostals raise, internal intercostals lower the volume
  a[idx(ElementGroup::IntercostalExternal)].alpha = invert(l.chest.in.reach, chest);
  a[idx(ElementGroup::IntercostalInternal)].alpha = invert(l.chest.out.reach, -chest);
  // belly: the diaphragm raises it, the abdominal wall lowers it (forced expiration)
  a[idx(ElementGroup::Diaphragm)].alpha = invert(l.belly.in.reach, belly);
  const double wall = invert(l.belly.out.reach, -belly);
  for (ElementGroup g : {ElementGroup::Rectus, ElementGroup::TransversusObliques})
    a[idx(g)].alpha = reach(m_calibration.response[idx(g)], -1.0).back() > 0.0 ? wall : 0.0;
  return a;
}

std::string PatternController::describe() const {
  std::ostringstream os;
  os << (m_trace ? "volume trace '" : "pattern '") << m_description << "'";
  if (!m_stack.currentLayerName().empty()) os << " (playing '" << m_stack.currentLayerName() << "')";
  return os.str();
}

std::unique_ptr<Controller> PatternController::clone() const {
  return std::make_unique<PatternController>(*this);
}

void PatternController::saveState(CheckpointWriter& out) const {
  out.write("pattern.description", m_description);
  out.write("pattern.isControlling", m_isControlling);
  Eigen::Matrix<double, 13, 1> v;
  v << m_calibration.restVolume, m_restVolumeSeen, m_lastTime, m_startTime, m_lastFrameTime,
      m_lastFrameControlTime, m_target, m_targetRate, m_measured, m_error, m_integral, m_balance,
      m_internalAlpha;
  out.write("pattern.values", v);
  out.write("pattern.tracking.frames", m_tracking.frames);
  Eigen::Vector3d t(m_tracking.sumSquaredError, m_tracking.targetMin, m_tracking.targetMax);
  out.write("pattern.tracking.values", t);
  m_stack.saveState(out, "pattern.stack");
  if (m_trace) out.write("pattern.traceStart", m_traceStart);
}

void PatternController::loadState(CheckpointReader& in) {
  const std::string description = in.readString("pattern.description");
  if (description != m_description)
    in.fail("pattern.description", "saved for pattern '" + description.substr(0, 60) + "', not '" +
                                       m_description.substr(0, 60) + "'");
  m_isControlling = in.readBool("pattern.isControlling");
  Eigen::Matrix<double, 13, 1> v;
  in.read("pattern.values", v);
  m_calibration.restVolume = v(0);
  m_restVolumeSeen = v(1);
  m_lastTime = v(2);
  m_startTime = v(3);
  m_lastFrameTime = v(4);
  m_lastFrameControlTime = v(5);
  m_target = v(6);
  m_targetRate = v(7);
  m_measured = v(8);
  m_error = v(9);
  m_integral = v(10);
  m_balance = v(11);
  m_internalAlpha = v(12);
  m_tracking.frames = in.readInt("pattern.tracking.frames");
  Eigen::Vector3d t;
  in.read("pattern.tracking.values", t);
  m_tracking.sumSquaredError = t(0);
  m_tracking.targetMin = t(1);
  m_tracking.targetMax = t(2);
  m_stack.loadState(in, "pattern.stack");
  if (m_trace) m_traceStart = in.readDouble("pattern.traceStart");
}

std::unique_ptr<PatternController> makePatternController(const Pattern& pattern, std::uint64_t seed,
                                                         const DriveCalibration& calibration) {
  return std::make_unique<PatternController>(makeLayerStack(pattern, seed), calibration,
                                             PatternControllerOptions{}, pattern.name);
}

std::unique_ptr<PatternController> makeAffectController(const std::string& name,
                                                        const std::string& resourceDir, std::uint64_t seed,
                                                        const DriveCalibration& calibration) {
  return makePatternController(loadAffect(name, resourceDir), seed, calibration);
}

}  // namespace pneuma::sim::pattern
