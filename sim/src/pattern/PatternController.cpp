#include "pneuma/sim/pattern/PatternController.h"

#include "pneuma/sim/Error.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace pneuma::sim::pattern {

namespace {

std::size_t idx(ElementGroup g) { return static_cast<std::size_t>(g); }

constexpr ElementGroup kDrivenGroups[] = {ElementGroup::IntercostalExternal, ElementGroup::IntercostalInternal,
                                          ElementGroup::Diaphragm, ElementGroup::Rectus,
                                          ElementGroup::TransversusObliques};

// split a volume-fraction demand >= 0 between two muscles with useful gains gA, gB >= 0 (0: the muscle
// cannot help): A takes `shareA` of it, and a muscle saturating at alpha = 1 (or unable to help) hands its
// remainder to the other one
std::pair<double, double> splitDemand(double demand, double shareA, double gA, double gB) {
  if (gA <= 0.0) shareA = 0.0;
  if (gB <= 0.0) shareA = 1.0;
  double a = gA > 0.0 ? demand * shareA / gA : 0.0, b = gB > 0.0 ? demand * (1.0 - shareA) / gB : 0.0;
  if (a > 1.0 && gB > 0.0) b += (a - 1.0) * gA / gB, a = 1.0;
  if (b > 1.0 && gA > 0.0) a += (b - 1.0) * gB / gA, b = 1.0;
  return {std::min(a, 1.0), std::min(b, 1.0)};
}

// useful gains: how much each group raises (inspiratory) or lowers (expiratory) the volume fraction per
// unit alpha; a group acting the other way on this model gets 0 and is not used
double raises(const DriveCalibration& c, ElementGroup g) { return std::max(c.gain[idx(g)], 0.0); }
double lowers(const DriveCalibration& c, ElementGroup g) { return std::max(-c.gain[idx(g)], 0.0); }

// holds one group at a constant activation during [start, end) of control time, relaxed otherwise
class StepController : public Controller {
 public:
  StepController(ElementGroup group, double alpha, double r, double start, double end)
      : m_group(group), m_alpha(alpha), m_r(r), m_start(start), m_end(end) {}
  Activations activations(double t, const Metrics&) override {
    Activations a = relaxedActivations();
    if (t >= m_start && t < m_end) a[idx(m_group)] = {m_r, m_alpha};
    return a;
  }
  std::string describe() const override { return std::string("calibration step of ") + groupName(m_group); }
  std::unique_ptr<Controller> clone() const override { return std::make_unique<StepController>(*this); }

 private:
  ElementGroup m_group;
  double m_alpha, m_r, m_start, m_end;
};

// mean lung volume [m^3] of the trace frames with time in [from, to)
double meanVolume(const Trace& trace, double from, double to) {
  double sum = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < trace.size(); ++i)
    if (trace.time[i] >= from && trace.time[i] < to) sum += trace.lungVolume[i], ++n;
  if (n == 0) throw Error("calibrateDrive: no output frames in [" + std::to_string(from) + ", " + std::to_string(to) + ") s");
  return sum / n;
}

}  // namespace

DriveCalibration calibrateDrive(std::shared_ptr<const Model> model, const SimulationOptions& options,
                                double contractionR) {
  // each group alone at a small activation: rest window, then the held window once the volume has settled
  constexpr double kAlpha = 0.05;  // [-] small: the local gain near rest, where breathing happens
  constexpr double kHold = 2.5;    // [s] activation held
  constexpr double kWindow = 0.5;  // [s] averaging window at the end of each phase
  DriveCalibration c;
  c.contractionR = contractionR;
  const double t0 = options.settleTime;
  for (ElementGroup g : kDrivenGroups) {
    Simulation sim(model, std::make_unique<StepController>(g, kAlpha, contractionR, kWindow, kWindow + kHold), options);
    sim.advance(t0 + kWindow + kHold);
    const double rest = meanVolume(sim.trace(), t0, t0 + kWindow);
    const double held = meanVolume(sim.trace(), t0 + kWindow + kHold - kWindow, t0 + kWindow + kHold);
    c.restVolume = rest;
    c.gain[idx(g)] = (held - rest) / (c.volumePerFraction * kAlpha);
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
    if (!std::isfinite(c.gain[idx(g)]))
      throw Error(std::string("calibration.gain.") + groupName(g) + ": must be finite, got " +
                  std::to_string(c.gain[idx(g)]));
  if (raises(c, ElementGroup::IntercostalExternal) + raises(c, ElementGroup::Diaphragm) <= 0.0)
    throw Error("calibration.gain: neither intercostal_external nor diaphragm raises the lung volume");
  if (lowers(c, ElementGroup::IntercostalInternal) + lowers(c, ElementGroup::Rectus) +
          lowers(c, ElementGroup::TransversusObliques) <= 0.0)
    throw Error("calibration.gain: none of intercostal_internal, rectus, transversus_obliques lowers the lung volume");
  if (!(c.volumePerFraction > 0.0)) throw Error("calibration.volumePerFraction: must be > 0");
  if (!(c.restVolume >= 0.0)) throw Error("calibration.restVolume: must be >= 0");
  if (!(c.contractionR > 0.0 && c.contractionR <= 1.5)) throw Error("calibration.contractionR: must be in (0, 1.5]");
  if (!(options.kp >= 0.0 && options.ki >= 0.0 && options.integralLimit >= 0.0 && options.lead >= 0.0 &&
        options.balanceTimeConstant > 0.0))
    throw Error("pattern controller options: gains and times must be >= 0 (balanceTimeConstant > 0)");
  m_balance = m_stack.balance();
}

double PatternController::volumeToFraction(double volume) const {
  return m_calibration.restFraction + (volume - m_calibration.restVolume) / m_calibration.volumePerFraction;
}

double PatternController::fractionToVolume(double fraction) const {
  return m_calibration.restVolume + (fraction - m_calibration.restFraction) * m_calibration.volumePerFraction;
}

void PatternController::push(const std::vector<Layer>& playOrder, SwitchMode mode) { m_stack.push(playOrder, mode); }

void PatternController::restart() {
  m_stack = m_initialStack;
  m_calibration = m_givenCalibration;
  m_isControlling = false;
  m_restVolumeSeen = 0.0;
  m_lastTime = m_lastFrameControlTime = m_startTime = 0.0;
  m_lastFrameTime = -1.0;
  m_target = m_measured = m_error = m_integral = 0.0;
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
    return distribute(0.0, m_balance);
  }

  // control starts: the pattern clock starts here, and its first breath blends from the measured volume
  if (!m_isControlling) {
    m_isControlling = true;
    if (m_calibration.restVolume == 0.0) m_calibration.restVolume = m_restVolumeSeen;
    m_startTime = t;
    m_lastTime = t;
    m_lastFrameTime = latest.time;
    m_lastFrameControlTime = t;
    m_stack.setStartVolume(m_calibration.restVolume > 0.0 && latest.lungVolume > 0.0
                               ? volumeToFraction(latest.lungVolume)
                               : m_calibration.restFraction);
  }
  const double dt = t - m_lastTime;
  m_lastTime = t;

  // target and its rate of change
  const double previous = m_target;
  m_target = m_stack.sample(t - m_startTime);
  const double targetRate = dt > 0.0 ? (m_target - previous) / dt : 0.0;  // [1/s]

  // feedback: a new frame was measured at this very control time
  if (latest.time > m_lastFrameTime && m_calibration.restVolume > 0.0) {
    m_measured = volumeToFraction(latest.lungVolume);
    m_error = m_target - m_measured;
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

  // smooth balance changes between layers
  m_balance += (m_stack.balance() - m_balance) * (1.0 - std::exp(-dt / m_options.balanceTimeConstant));

  // feed-forward plus feedback, in volume-fraction units
  const double drive = (m_target - m_calibration.restFraction) + m_options.lead * targetRate +
                       m_options.kp * m_error + m_integral;
  return distribute(drive, m_balance);
}

Activations PatternController::distribute(double drive, double balance) const {
  const DriveCalibration& c = m_calibration;
  Activations a = relaxedActivations();
  for (ElementGroup group : kDrivenGroups) a[idx(group)].r = c.contractionR;

  if (drive >= 0.0) {
    // inspiration: external intercostals (chest, share b) and diaphragm (belly, 1 - b)
    const auto [chest, belly] = splitDemand(drive, balance, raises(c, ElementGroup::IntercostalExternal),
                                            raises(c, ElementGroup::Diaphragm));
    a[idx(ElementGroup::IntercostalExternal)].alpha = chest;
    a[idx(ElementGroup::Diaphragm)].alpha = belly;
  } else {
    // expiration below rest: internal intercostals (chest) and the abdominal wall (belly), forced
    const double rectus = lowers(c, ElementGroup::Rectus), obliques = lowers(c, ElementGroup::TransversusObliques);
    const auto [chest, belly] =
        splitDemand(-drive, balance, lowers(c, ElementGroup::IntercostalInternal), rectus + obliques);
    a[idx(ElementGroup::IntercostalInternal)].alpha = chest;
    a[idx(ElementGroup::Rectus)].alpha = rectus > 0.0 ? belly : 0.0;
    a[idx(ElementGroup::TransversusObliques)].alpha = obliques > 0.0 ? belly : 0.0;
  }
  return a;
}

std::string PatternController::describe() const {
  std::ostringstream os;
  os << "pattern '" << m_description << "'";
  if (!m_stack.currentLayerName().empty()) os << " (playing '" << m_stack.currentLayerName() << "')";
  return os.str();
}

std::unique_ptr<Controller> PatternController::clone() const { return std::make_unique<PatternController>(*this); }

std::unique_ptr<PatternController> makePatternController(const Pattern& pattern, std::uint64_t seed,
                                                         const DriveCalibration& calibration) {
  return std::make_unique<PatternController>(makeLayerStack(pattern, seed), calibration, PatternControllerOptions{},
                                             pattern.name);
}

std::unique_ptr<PatternController> makeAffectController(const std::string& name, const std::string& resourceDir,
                                                        std::uint64_t seed, const DriveCalibration& calibration) {
  return makePatternController(loadAffect(name, resourceDir), seed, calibration);
}

}  // namespace pneuma::sim::pattern
