#include "pneuma/sim/Simulation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "pneuma/sim/Checkpoint.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/Limits.h"
#include "pneuma/sim/ModelIO.h"

namespace pneuma::sim {

namespace {
// 2 adds simulation.posture, 3 the volume bodies, 4 the pattern drive's internal intercostal lag, 5 the
// cycles' inspiratory balance
constexpr long long kCheckpointVersion = 5;
}  // namespace

void validateSimulationOptions(const SimulationOptions& o) {
  validateStepOptions(o.step);
  if (o.dt) kTimeStepRange.check("dt", *o.dt);
  kSettleTimeRange.check("settleTime", o.settleTime);
  kOutputRateRange.check("outputRate", o.outputRate);
  if (!std::isfinite(o.recordSeconds) || o.recordSeconds < 0.0) {
    std::ostringstream os;
    os << "recordSeconds: must be >= 0 s, got " << o.recordSeconds;
    throw Error(os.str());
  }
}

ResolvedOptions resolveOptions(const Model& model, const SimulationOptions& options, double maxTimeStep) {
  ResolvedOptions r;
  r.kappa = effectiveKappa(model, options.step);
  r.dt = options.dt ? *options.dt : std::min(defaultTimeStep(options.step.integrator), maxTimeStep);
  return r;
}

Simulation::Simulation(std::shared_ptr<const Model> model, std::unique_ptr<Controller> controller,
                       SimulationOptions options)
    : m_model(std::move(model)), m_controller(std::move(controller)) {
  if (!m_model) throw Error("Simulation: no model");
  if (!m_controller) throw Error("Simulation: no controller");
  validateModel(*m_model);  // sizes, indices, masses > 0, gains >= 0, required landmarks
  setOptions(options);
  validateActivations(m_controller->activations(0.0, Metrics{}));
  reset();
}

void Simulation::setOptions(const SimulationOptions& options) {
  validateSimulationOptions(options);
  m_options = options;
  updateTimeStep();
  m_recorder.setCapacity(
      options.recordSeconds > 0.0
          ? static_cast<std::size_t>(std::ceil(options.recordSeconds * options.outputRate)) + 1
          : 0);
}

void Simulation::setController(std::unique_ptr<Controller> controller) {
  if (!controller) throw Error("Simulation::setController: no controller");
  validateActivations(controller->activations(0.0, m_latest));
  m_controller = std::move(controller);
  updateTimeStep();
}

void Simulation::updateTimeStep() {
  m_dt = resolveOptions(*m_model, m_options, m_controller->maxTimeStep()).dt;
}

void Simulation::reset() {
  m_state = makeInitialState(*m_model);
  m_work = makeStepWork(*m_model);
  m_activations = m_controller->activations(0.0, Metrics{});
  m_trace.clear();
  m_frameIndex = 0;
  m_traceStride = 1;
  m_recorder.clear();
  m_latest = Metrics{};
  m_nextFrameTime = 0.0;
  m_wallSeconds = 0.0;
  m_simulatedSeconds = 0.0;
  emitFrame();
}

void Simulation::emitFrame() {
  computeMetrics(*m_model, m_state, m_activations, m_options.step, m_work, m_latest);
  // a lung volume <= 0 means the rib cage has collapsed through itself: physically impossible, so stop
  if (!(m_latest.lungVolume > 0.0)) {
    std::ostringstream os;
    os << "simulation blew up at t = " << m_state.time << " s: lung volume " << m_latest.lungVolume * 1e6
       << " mL is not positive (the rib cage collapsed through itself; likely cause: passive gains too small "
          "to hold it, a cavity turned inside out, or dt too large)";
    throw Error(os.str());
  }
  if (m_frameIndex % m_traceStride == 0) m_trace.append(m_latest);
  if (m_trace.size() > kMaxTraceFrames) {
    m_trace.keepEveryOtherFrame();
    m_traceStride *= 2;
  }
  ++m_frameIndex;
  m_recorder.record(m_state, m_latest);
  m_nextFrameTime += 1.0 / m_options.outputRate;
}

bool Simulation::timedStep() {
  const auto start = std::chrono::steady_clock::now();

  // control: hold the cycle-start posture while settling
  const double controlTime = m_state.time - m_options.settleTime;
  m_activations = m_controller->activations(controlTime < 0.0 ? 0.0 : controlTime, m_latest);
  validateActivations(m_activations);

  // physics: forces -> integrate -> joints, then the blow-up check
  step(*m_model, m_state, m_dt, m_activations, m_options.step, m_work);
  checkState(*m_model, m_state, m_work, m_dt);

  // metrics and recording at the output rate (timed too: they are part of every run's cost)
  const bool isFrame = m_state.time >= m_nextFrameTime - 1e-9 * m_dt;
  if (isFrame) emitFrame();

  m_wallSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  m_simulatedSeconds += m_dt;
  return isFrame;
}

void Simulation::stepOnce() { timedStep(); }

void Simulation::advance(double duration, const std::function<bool(const Simulation&)>& onFrame) {
  if (!std::isfinite(duration) || duration < 0.0) {
    std::ostringstream os;
    os << "duration: must be >= 0 s, got " << duration;
    throw Error(os.str());
  }
  checkStepCount("duration", duration, m_dt);
  m_wasStopped = false;
  const double end = m_state.time + duration;
  while (m_state.time < end - 0.5 * m_dt) {
    if (m_stopFlag != nullptr && m_stopFlag->load(std::memory_order_relaxed)) {
      m_wasStopped = true;
      return;
    }
    if (timedStep() && onFrame && !onFrame(*this)) return;
  }
}

SimulationCheckpoint Simulation::checkpoint() const {
  SimulationCheckpoint c;
  c.state = m_state;
  c.solver = m_work.memory;
  c.outputs = m_work.outputs;
  c.latest = m_latest;
  c.activations = m_activations;
  c.nextFrameTime = m_nextFrameTime;
  c.controller = m_controller->clone();
  return c;
}

void Simulation::restore(const SimulationCheckpoint& c) {
  const State& s = c.state;
  const Eigen::Index nb = m_model->bodies.size(), nn = m_model->nodes.size();
  if (s.bodyPosition.cols() != nb || static_cast<Eigen::Index>(s.bodyOrientation.size()) != nb ||
      s.bodyVelocity.cols() != nb || s.bodyAngularVelocity.cols() != nb || s.nodePosition.cols() != nn ||
      s.nodeVelocity.cols() != nn || c.outputs.elementForce.size() != m_model->elements.size())
    throw Error("Simulation::restore: the checkpoint is not of this model (sizes differ)");
  if (!c.controller) throw Error("Simulation::restore: the checkpoint holds no controller");
  std::unique_ptr<Controller> controller = c.controller->clone();
  m_work.memory = c.solver;
  m_work.outputs = c.outputs;
  m_state = s;
  m_latest = c.latest;
  m_activations = c.activations;
  m_nextFrameTime = c.nextFrameTime;
  m_controller = std::move(controller);
  updateTimeStep();
  m_trace.clear();
  m_frameIndex = 0;
  m_traceStride = 1;
  m_recorder.clear();
  m_wallSeconds = 0.0;
  m_simulatedSeconds = 0.0;
}

void Simulation::save(std::ostream& out) const {
  CheckpointWriter w(out);
  w.write("pneuma.checkpoint", kCheckpointVersion);
  w.write("simulation.dt", m_dt);
  w.write("simulation.posture", postureName(m_options.step.posture));
  w.write("simulation.nextFrameTime", m_nextFrameTime);
  writeActivations(w, "simulation.activations", m_activations);
  writeState(w, m_state);
  writeSolverMemory(w, m_work.memory);
  writeStepOutputs(w, m_work.outputs);
  writeMetrics(w, m_latest);
  m_controller->saveState(w);
  w.write("end", 1);
  if (!out) throw Error("Simulation::save: the checkpoint could not be written");
}

void Simulation::load(std::istream& in, const std::string& source) {
  CheckpointReader r(in, source);
  if (const long long version = r.readInt("pneuma.checkpoint"); version != kCheckpointVersion)
    r.fail("pneuma.checkpoint", "version " + std::to_string(version) + ", this build reads version " +
                                    std::to_string(kCheckpointVersion));
  const double dt = r.readDouble("simulation.dt");
  if (dt != m_dt) {
    std::ostringstream os;
    os << "saved at dt = " << dt << " s, this run steps at " << m_dt << " s";
    r.fail("simulation.dt", os.str());
  }
  // the posture is the direction of gravity: a run continues only in the posture it was saved in
  const std::string posture = r.readString("simulation.posture");
  if (posture != postureName(m_options.step.posture))
    r.fail("simulation.posture", "saved in posture '" + posture.substr(0, 40) + "', this run is " +
                                     postureName(m_options.step.posture));
  SimulationCheckpoint c;
  c.nextFrameTime = r.readDouble("simulation.nextFrameTime");
  c.activations = readActivations(r, "simulation.activations");
  c.state = readState(r, *m_model);
  StepWork fresh = makeStepWork(*m_model);  // the memory's symbolic analysis
  c.solver = std::move(fresh.memory);
  readSolverMemory(r, c.solver);
  c.outputs = fresh.outputs;
  readStepOutputs(r, c.outputs);
  readMetrics(r, c.latest);
  std::unique_ptr<Controller> controller = m_controller->clone();
  controller->loadState(r);
  r.readInt("end");
  c.controller = std::move(controller);
  restore(c);
}

Summary Simulation::summary() const {
  std::vector<std::string> names = m_model->landmarks.name;
  Summary s = summarize(m_trace, names, m_options.settleTime);
  s.realTimeFactor = realTimeFactor();
  s.steps = m_state.steps;
  s.dt = m_dt;
  return s;
}

double Simulation::realTimeFactor() const {
  return m_wallSeconds > 0.0 ? m_simulatedSeconds / m_wallSeconds : 0.0;
}

}  // namespace pneuma::sim
