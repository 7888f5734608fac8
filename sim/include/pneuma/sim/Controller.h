#pragma once
/// @file Controller.h
/// Muscle activation control (Zordan et al. 2004, Section 7): every muscle group gets a contraction
/// ratio r(t) and an activation alpha(t) that enter the muscle law, Eq. 2:
///   F = min[-alpha kac (l - r l0) - kpe (l - l0) - b dl/dt, 0].

#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "pneuma/sim/Activation.h"
#include "pneuma/sim/Metrics.h"

namespace pneuma::sim {

class CheckpointWriter;
class CheckpointReader;

/// A source of muscle activations. Simulation calls activations() once per step with the control
/// time and the most recent output-frame metrics (feedback controllers read `latest.lungVolume`).
/// Implementations must be deterministic: the same call sequence gives the same outputs.
class Controller {
 public:
  virtual ~Controller() = default;
  /// Activations at control time `t` [s] (0 = first instant after the settling phase).
  /// @param latest metrics of the latest output frame (lungVolume [m^3] etc.); zeros before the first frame.
  virtual Activations activations(double t, const Metrics& latest) = 0;
  /// One-line human-readable description, e.g. "breath style 'calm' (15 b/m)".
  virtual std::string describe() const = 0;
  /// A deep copy with the same parameters and internal state.
  virtual std::unique_ptr<Controller> clone() const = 0;
  /// [s] The largest time step this controller is made for; a run whose dt is left unset steps at
  /// min(defaultTimeStep(integrator), maxTimeStep()) (resolveOptions(), Simulation.h). Infinity (the
  /// default) when any step will do; a feedback controller tuned against the plant at a given step says so.
  virtual double maxTimeStep() const { return std::numeric_limits<double>::infinity(); }

  /// What every tracking controller (one that drives the lung volume toward a target curve: an affect, a
  /// pattern, a measured trace) reports, in its volume-fraction units v = v_rest + (V - V_rest) / S
  /// (PatternController.h); NaN for a controller without a volume target (a breath style).
  /// [-] target fraction v_T at the last control time.
  virtual double targetFraction() const { return std::numeric_limits<double>::quiet_NaN(); }
  /// [-] fraction of the last measured lung volume v_M.
  virtual double measuredFraction() const { return std::numeric_limits<double>::quiet_NaN(); }
  /// [%] RMS of v_T - v_M over the frames compared, as a percentage of the target's peak-to-peak.
  virtual double trackingRmsPercent() const { return std::numeric_limits<double>::quiet_NaN(); }
  /// Whether this controller has a volume target (targetFraction() is then a number once control starts).
  bool tracksVolume() const { return !std::isnan(trackingRmsPercent()); }

  /// Writes what activations() depends on besides the construction parameters (clocks, integrals, random
  /// streams, learned values, pushed layers), for an exact restart from a file (Simulation::save(),
  /// Checkpoint.h). A controller whose outputs depend on its call history must override both this and
  /// loadState(); the defaults, for controllers that are functions of (t, latest) alone, write and read
  /// nothing.
  virtual void saveState(CheckpointWriter& out) const { (void)out; }
  /// Reads what saveState() wrote into a controller made with the same parameters; afterwards it continues
  /// exactly as the one that was saved. @throws Error when the data does not fit this controller.
  virtual void loadState(CheckpointReader& in) { (void)in; }
};

}  // namespace pneuma::sim
