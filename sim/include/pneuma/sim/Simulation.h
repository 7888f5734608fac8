#pragma once
/// @file Simulation.h
/// The Qt-free "logic layer" that both pneuma-cli and the desktop app drive (3D Slicer's Logic,
/// MuJoCo's simulate without the window): owns the model, the state, the controller and the options,
/// steps, measures at the output rate, records, and stops with an Error on a blow-up.
///
/// Time line: t in [0, settleTime) is the settling phase (gravity and passive forces find their
/// equilibrium; the controller is asked for activations(0, ...), the start-of-cycle posture). From
/// t = settleTime on, the controller runs with control time t - settleTime. Summary figures are
/// measured from settleTime on.

#include <atomic>
#include <functional>
#include <istream>
#include <limits>
#include <memory>
#include <optional>
#include <ostream>
#include <string>

#include "pneuma/sim/Controller.h"
#include "pneuma/sim/Metrics.h"
#include "pneuma/sim/Model.h"
#include "pneuma/sim/Recorder.h"
#include "pneuma/sim/State.h"
#include "pneuma/sim/Step.h"

namespace pneuma::sim {

/// Run settings (validated by validateSimulationOptions()).
struct SimulationOptions {
  StepOptions step;          ///< integrator, gravity and posture, friction scale, kappa override, gain scales
  std::optional<double> dt;  ///< [s] time step in kTimeStepRange; unset: resolveOptions() picks it
  double settleTime = 2.0;   ///< [s] settling phase before the controller starts, in kSettleTimeRange
  double outputRate = 60.0;  ///< [Hz] metrics and recording rate, in kOutputRateRange
  double recordSeconds = 300.0;  ///< [s] recorder window (older frames dropped); 0 = unlimited
};

/// What a run takes where its options leave the choice to the model, the integrator or the controller.
struct ResolvedOptions {
  double kappa =
      0.0;  ///< [Pa] gut bulk modulus of Eq. 4: effectiveKappa(), StepOptions::kappa else Model::gut.kappa
  double dt = 0.0;  ///< [s] SimulationOptions::dt, else min(defaultTimeStep(integrator), maxTimeStep)
};

/// The one place where unset options get their values: the Simulation, the CLI (simulate, bench) and the
/// app's parameter panel all call it. `maxTimeStep` [s] is the controller's Controller::maxTimeStep()
/// (infinity for an open-loop controller): a feedback controller tuned at a step caps the default one, never
/// a given dt.
ResolvedOptions resolveOptions(const Model& model, const SimulationOptions& options,
                               double maxTimeStep = std::numeric_limits<double>::infinity());

/// [-] most frames Simulation::trace() holds (9.1 min at 60 Hz, about 10 MB): beyond it the trace keeps every
/// other frame and from then on records every 2nd (4th, ...) one, so a long run's memory stays bounded and
/// the summary of a run longer than this is measured on the thinned trace.
inline constexpr std::size_t kMaxTraceFrames = std::size_t{1} << 15;

/// [s] recorder window of runs that read the trace rather than scrub the timeline (the CLI, the validation
/// experiments, the benchmarks): filling a long fresh window costs page faults every frame (docs/cli.md,
/// "Performance").
inline constexpr double kTraceOnlyRecordSeconds = 1.0;

/// @throws Error naming the field and value: dt set and outside kTimeStepRange, settleTime outside
///         kSettleTimeRange, outputRate outside kOutputRateRange (Limits.h), recordSeconds < 0, bad step
///         options.
void validateSimulationOptions(const SimulationOptions& o);

/// Everything a run continues from besides the model, the options and the controller's parameters. A run
/// restored from it steps bit-identically to the run it was taken from: in the same process
/// (Simulation::checkpoint(), restore()) and through a file (Simulation::save(), load()).
struct SimulationCheckpoint {
  State state;          ///< positions, velocities, time and step count
  SolverMemory solver;  ///< the implicit solver's memory (Step.h): factorization, its age, last CG count
  StepOutputs outputs;  ///< the last step's by-products (element forces, joint error)
  Metrics latest;       ///< the latest output frame, which the controller reads next
  Activations activations{};                     ///< applied in the last step
  double nextFrameTime = 0.0;                    ///< [s] when the next output frame falls due
  std::shared_ptr<const Controller> controller;  ///< a copy of the controller with its internal state
};

class Simulation {
 public:
  /// Validates the model (masses, gains >= 0), the controller's first activations and the options.
  /// @throws Error naming the field and value before anything runs.
  Simulation(std::shared_ptr<const Model> model, std::unique_ptr<Controller> controller,
             SimulationOptions options = {});

  /// Back to the rest pose at t = 0; clears the trace and the recorder; keeps model, controller and options.
  void reset();
  /// Replaces the controller (takes effect at the next step; the controller keeps the run's clock).
  void setController(std::unique_ptr<Controller> controller);
  /// Replaces the options (validated). Changing dt or the integrator mid-run is allowed.
  void setOptions(const SimulationOptions& options);

  /// Steps until `duration` [s] more has been simulated, computing metrics and recording at the
  /// output rate. `onFrame` (optional) is called after every output frame; return false to stop early.
  /// @throws Error on NaN/Inf or blow-up, naming the time, the element/body/node and a likely cause; and
  ///         before stepping when `duration` needs more than kMaxStepsPerRun steps of dt().
  void advance(double duration, const std::function<bool(const Simulation&)>& onFrame = {});
  /// One step of dt (metrics are computed if an output frame falls due).
  void stepOnce();
  /// Makes advance() look at `*flag` before every step and return early once it is true, so that a stop
  /// request (Ctrl-C, set from a signal handler: the flag is lock-free) takes effect within one step whatever
  /// the output rate. nullptr (the default) checks nothing. The flag must outlive its use here.
  void setStopFlag(const std::atomic<bool>* flag) { m_stopFlag = flag; }
  /// True when the latest advance() returned early because the stop flag was raised.
  bool wasStopped() const { return m_wasStopped; }

  /// A copy of everything the run continues from (SimulationCheckpoint), at the current step.
  SimulationCheckpoint checkpoint() const;
  /// Continues from `checkpoint`, taken from a run on the same model: state, solver memory, last outputs,
  /// latest frame, frame clock and a copy of its controller. The options stay; the trace, the recorder and
  /// the real-time factor start over (a resumed run's summary covers the frames after the restart).
  /// @throws Error when the checkpoint's sizes are not the model's or it holds no controller.
  void restore(const SimulationCheckpoint& checkpoint);
  /// Writes checkpoint() as text (Checkpoint.h); load() on a Simulation of the same model and options, with a
  /// controller made with the same parameters, continues bit-identically.
  void save(std::ostream& out) const;
  /// Reads what save() wrote and restore()s it; the controller state is read into a copy of the current
  /// controller. @throws Error naming `source` and the field when the data is not a checkpoint of this model,
  /// dt, posture or controller.
  void load(std::istream& in, const std::string& source = "checkpoint");

  const Model& model() const { return *m_model; }
  const State& state() const { return m_state; }
  const SimulationOptions& options() const { return m_options; }
  const Controller& controller() const { return *m_controller; }
  /// Time step in use [s].
  double dt() const { return m_dt; }
  /// Metrics of the latest output frame.
  const Metrics& latestMetrics() const { return m_latest; }
  /// Activations applied in the latest step.
  const Activations& currentActivations() const { return m_activations; }
  /// The light per-frame series of the run for the summary: every output frame, up to kMaxTraceFrames; a
  /// longer run's trace is thinned evenly (every 2nd, 4th, ... frame).
  const Trace& trace() const { return m_trace; }
  const Recorder& recorder() const { return m_recorder; }
  /// Solver by-products of the latest step (CG iterations, joint error, element forces).
  const StepWork& stepWork() const { return m_work; }
  /// Summary over the run so far (see summarize()), with real-time factor, steps and dt.
  Summary summary() const;
  /// [-] simulated seconds per wall-clock second spent inside advance()/stepOnce().
  double realTimeFactor() const;

 private:
  // m_dt from the options and the controller's maxTimeStep()
  void updateTimeStep();
  // one timed step (control, physics, blow-up check); true when an output frame was emitted
  bool timedStep();
  // metrics, trace and recorder for the current state
  void emitFrame();

  std::shared_ptr<const Model> m_model;
  std::unique_ptr<Controller> m_controller;
  SimulationOptions m_options;
  double m_dt = 0.0;  // [s]
  State m_state;
  StepWork m_work;
  Activations m_activations{};
  Metrics m_latest;
  Trace m_trace;
  long long m_frameIndex = 0;   // output frames emitted since reset()
  long long m_traceStride = 1;  // the trace records frames whose index is a multiple of this
  Recorder m_recorder;
  double m_nextFrameTime = 0.0;     // [s]
  double m_wallSeconds = 0.0;       // [s] wall-clock time spent stepping, measuring and recording
  double m_simulatedSeconds = 0.0;  // [s] simulated while timed
  const std::atomic<bool>* m_stopFlag = nullptr;  // checked before every step of advance(); may be null
  bool m_wasStopped = false;
};

}  // namespace pneuma::sim
