#pragma once
/// @file PatternController.h
/// Drives the physical torso so that its lung-cavity volume follows a respiration pattern (de Melo et al.
/// 2010 patterns on the Zordan et al. 2004 model; docs/patterns.md).
///
/// Volume mapping (target fraction v <-> lung-cavity volume V [m^3]):
///   V(v) = V_rest + (v - v_rest) * S,
/// with V_rest the settled lung volume of the relaxed torso (end of the settling phase), v_rest = 0.05
/// (the rest level of every preset: neutral breathing is 5-25 %) and S [m^3] the volume per unit fraction,
/// 2.5 L by default, so that neutral breathing has a 0.5 L tidal volume and v = 1 lies 2.4 L above rest.
///
/// Control law, every step, in volume-fraction units:
///   u = (v_T - v_rest) + T_lead dv_T/dt      feed-forward: the static inverse plus a lead for the lag
///     + K_p e + K_i integral(e dt),           feedback on e = v_T - v_M, v_M the measured fraction
/// u > 0 is inspiratory drive, split by the thoraco-abdominal balance b between the external intercostals
/// (share b) and the diaphragm (share 1 - b); u < 0 is expiratory drive, split between the internal
/// intercostals (b) and rectus + transversus/obliques (1 - b), which therefore work in forced expirations
/// only. Each group's activation is alpha_g = share * |u| / |g_g|, where g_g [-] is the group's calibrated
/// static gain (volume fraction per unit alpha, see calibrateDrive()); a group that saturates at alpha = 1,
/// or that moves the volume the wrong way on this model, hands its share to its partner. Unlike Zordan's binary alpha with a varying r, alpha is
/// graded and r fixed (contractionR): force then grows with the command and an idle antagonist adds
/// no stiffness, which a feedback loop needs.

#include "pneuma/sim/Controller.h"
#include "pneuma/sim/Simulation.h"
#include "pneuma/sim/pattern/Pattern.h"

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace pneuma::sim::pattern {

/// Static response of a model to each muscle group, and the volume mapping.
struct DriveCalibration {
  double restVolume = 0.0;        ///< [m^3] V_rest; 0 = take the settled volume when control starts
  double volumePerFraction = 2.5e-3;  ///< [m^3] S, lung volume per unit volume fraction
  double restFraction = 0.05;     ///< [-] v_rest, the fraction the relaxed torso represents
  /// [-] volume-fraction change per unit alpha of each group alone (at r = contractionR), indexed by
  /// ElementGroup, positive when the group raises the volume. Inspiratory groups (external intercostals,
  /// diaphragm) should be positive, expiratory ones negative; a group acting the other way is not used.
  std::array<double, kElementGroupCount> gain{};
  double contractionR = 0.6;      ///< [-] r of every driven group (Eq. 2)
};

/// Feedback settings.
struct PatternControllerOptions {
  double kp = 2.0;                ///< [-] proportional gain on the fraction error
  double ki = 4.0;                ///< [1/s] integral gain
  double integralLimit = 0.2;     ///< [-] clamp of ki * integral (anti-windup), in fraction units
  double lead = 0.1;              ///< [s] T_lead, feed-forward on the target's rate of change
  double balanceTimeConstant = 0.3;  ///< [s] first-order smoothing of balance changes between layers
};

/// Target-versus-measured statistics over the frames seen after control started.
struct TrackingStats {
  long long frames = 0;           ///< [-] frames compared
  double sumSquaredError = 0.0;   ///< [-] sum of (v_T - v_M)^2
  double targetMin = 1.0;         ///< [-]
  double targetMax = 0.0;         ///< [-]
  /// [%] RMS error as a percentage of the target's peak-to-peak (0 when nothing was compared).
  double rmsPercentOfPeakToPeak() const;
};

/// Measures each muscle group's static gain on `model`: a relaxed run gives V_rest, then each group alone
/// is held at alpha = 0.05 (r = contractionR) for 2.5 s. The small activation measures the local gain near
/// rest, where breathing happens (the muscle response is strongly non-linear: on the default model the
/// external intercostals add 0.6 L at alpha = 0.02 but only 2.2 L at alpha = 1). About 3 s of wall time.
/// @param options  simulation options (integrator, dt, settleTime) to use for the runs
DriveCalibration calibrateDrive(std::shared_ptr<const Model> model, const SimulationOptions& options = {},
                                double contractionR = 0.6);

/// A Controller that plays a LayerStack on the physical model (see the file comment).
class PatternController : public Controller {
 public:
  /// @param stack        the pattern to play (e.g. makeLayerStack(loadAffect("panic", dir), seed))
  /// @param calibration  from calibrateDrive() on the same model
  /// @throws Error when no group can raise (or lower) the volume, or an option is out of range.
  PatternController(LayerStack stack, DriveCalibration calibration, PatternControllerOptions options = {},
                    std::string description = "pattern");

  /// The pattern clock starts at the first call with t > 0 (earlier calls are the settling phase), and
  /// its first breath cross-fades from the lung volume measured then, so a controller installed mid-run
  /// (Simulation::setController()) takes over without a jump. Control time going backwards
  /// (Simulation::reset()) restarts the pattern from its initial stack.
  Activations activations(double t, const Metrics& latest) override;
  std::string describe() const override;
  std::unique_ptr<Controller> clone() const override;

  /// Pushes layers live (the app's affect selector); see LayerStack::push().
  void push(const std::vector<Layer>& playOrder, SwitchMode mode);

  /// [-] target fraction v_T at the last control time.
  double targetFraction() const { return m_target; }
  /// [-] fraction of the last measured lung volume (0 before the rest volume is known).
  double measuredFraction() const { return m_measured; }
  /// [-] fraction of a lung volume [m^3] under this controller's mapping.
  double volumeToFraction(double volume) const;
  /// [m^3] lung volume of a fraction under this controller's mapping.
  double fractionToVolume(double fraction) const;
  const TrackingStats& tracking() const { return m_tracking; }
  const LayerStack& stack() const { return m_stack; }
  const DriveCalibration& calibration() const { return m_calibration; }

 private:
  Activations distribute(double drive, double balance) const;  // drive u and balance b -> alphas
  void restart();                                               // back to the state at construction

  LayerStack m_stack;
  LayerStack m_initialStack;       // for restart()
  DriveCalibration m_calibration;
  DriveCalibration m_givenCalibration;  // as passed in (restVolume may be learned later)
  PatternControllerOptions m_options;
  std::string m_description;
  bool m_isControlling = false;   // false during settling (t = 0 calls)
  double m_restVolumeSeen = 0.0;  // [m^3] latest lung volume seen while settling
  double m_lastTime = 0.0;        // [s] control time of the last call
  double m_startTime = 0.0;       // [s] control time at which control (and the pattern clock) started
  double m_lastFrameTime = -1.0;  // [s] Metrics::time of the last frame used
  double m_lastFrameControlTime = 0.0;  // [s] control time at which that frame arrived
  double m_target = 0.0;          // [-] v_T at m_lastTime
  double m_measured = 0.0;        // [-] v_M of the last frame
  double m_error = 0.0;           // [-] e of the last frame
  double m_integral = 0.0;        // [-] ki * integral(e dt), clamped
  double m_balance = 0.5;         // [-] smoothed balance
  TrackingStats m_tracking;
};

/// A PatternController playing the affect preset NAME from `resourceDir` (resources/) on `model`.
/// @throws Error "unknown affect 'NAME' (valid: ...)" or a preset/calibration error.
std::unique_ptr<PatternController> makeAffectController(const std::string& name, const std::string& resourceDir,
                                                        std::uint64_t seed, const DriveCalibration& calibration);

/// A PatternController playing a pattern file (layers and timeline) on `model`.
std::unique_ptr<PatternController> makePatternController(const Pattern& pattern, std::uint64_t seed,
                                                         const DriveCalibration& calibration);

}  // namespace pneuma::sim::pattern
