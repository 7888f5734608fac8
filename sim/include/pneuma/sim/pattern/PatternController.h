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
/// Control law, every step, in volume-fraction units (a demand is a fraction change from rest):
///   d   = (v_T - v_rest) + K_p e + I,  dI/dt = K_i e     static feed-forward plus PI feedback on
///                                                      e = v_T - v_M (v_M measured at each frame)
///   D(tau_in, tau_out) = m(d + tau_in dv_T/dt) - m(-(d + tau_out dv_T/dt)),   m(x) = max(x, 0) with its
///                        corner rounded over |x| < w/2 by (x + w/2)^2 / (2 w), w = 0.006 (15 mL)
///   d_c = b D(tau_c,in, tau_c,out)                      chest channel (intercostals)
///   d_a = (1 - b) D(tau_a,in, tau_a,out)                belly channel (diaphragm, abdominal wall)
/// with b the thoraco-abdominal balance [-], dv_T/dt [1/s] the target's rate (backward difference over
/// the last step) and tau [s] the identified lags (DriveCalibration::timeConstant) of the channel's raising
/// (in) and lowering (out) lever: the tau term inverts a first-order lag (tau dV/dt + V = u  =>  u = V +
/// tau dV/dt). D is continuous in d and the rate, so the demand does not jump when the rate changes sign
/// between two levers of different lag, and so is its slope, so the flow does not jump where one lever's lag
/// term sets in: the chest follows its activation within a step (docs/patterns.md, "Control law"). The rib
/// friction
/// makes the intercostals lag their activation by about 0.2 s on the default model; without the term
/// the chest falls behind fast breathing and stays above the trough, waiting for the ribs' slow passive
/// release. d_c > 0 drives the external intercostals, d_c < 0 the internal intercostals; d_a > 0 the
/// diaphragm, d_a < 0 rectus + transversus/obliques (so the abdominal wall works below rest and at the
/// end of fast expirations). Each group's demand is turned into an activation by inverting its
/// calibrated static response curve R_g(alpha) (volume-fraction change of the group alone at activation
/// alpha, see calibrateDrive()): alpha_g = R_g^-1(d). The inversion removes the muscles' strong
/// non-linearity, so the feedback sees a near-unit static plant. When both channels pull the same way and
/// one cannot give its part (beyond the peak of its curve, or its group moves the volume the wrong way
/// on this model), the balance b is shifted until it fits: the other channel takes over that share of
/// the target and compensates its own lag for it (a fast diaphragm must not be given the slow chest's
/// lead). No group is driven past its curve's peak.
/// The integral stops while the demand is beyond what the muscles can give (anti-windup). Unlike
/// Zordan's binary alpha with a varying r, alpha is graded and r fixed (contractionR): force then grows
/// with the command and an idle antagonist adds no stiffness, which a feedback loop needs.

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pneuma/sim/Controller.h"
#include "pneuma/sim/Simulation.h"
#include "pneuma/sim/pattern/Pattern.h"
#include "pneuma/sim/pattern/VolumeTrace.h"

namespace pneuma::sim::pattern {

/// [s] The drive's time step (Controller::maxTimeStep() of PatternController and of the calibration
/// staircase): the gains, the identified lags and the hold tests belong to the plant stepped at 10 ms with
/// the feedback at the 60 Hz output frames. At the default 1/60 s the integral moves the activations by
/// K_i T = 1.7 times the error every frame, about 100 diaphragm elements near alpha 0.05 switch between
/// slack and taut from frame to frame, and the suspensions of disgust (6.8 %) and startle (5.9 %) leave the
/// 5 % bound (docs/patterns.md, "Time step").
inline constexpr double kDriveTimeStep = 0.01;

/// [-] activation levels at which calibrateDrive() measures each group's static response (0 first).
inline constexpr std::array<double, 9> kCalibrationAlphas{0.0, 0.02, 0.05, 0.1, 0.2, 0.35, 0.5, 0.75, 1.0};
/// [-] volume-fraction change of one group alone at each of kCalibrationAlphas (the first entry is 0).
using GroupResponse = std::array<double, kCalibrationAlphas.size()>;

/// Static response of a model to each muscle group, and the volume mapping.
struct DriveCalibration {
  double restVolume = 0.0;            ///< [m^3] V_rest; 0 = take the settled volume when control starts
  double volumePerFraction = 2.5e-3;  ///< [m^3] S, lung volume per unit volume fraction
  double restFraction = 0.05;         ///< [-] v_rest, the fraction the relaxed torso represents
  /// R_g: per ElementGroup, the volume-fraction change with that group alone held at each of
  /// kCalibrationAlphas (r = contractionR), positive when the group raises the volume. Inspiratory
  /// groups (external intercostals, diaphragm) should raise it, expiratory ones lower it; a group
  /// acting the other way is not used. Linear interpolation between the levels.
  std::array<GroupResponse, kElementGroupCount> response{};
  double contractionR = 0.6;  ///< [-] r of every driven group (Eq. 2)
  /// [s] tau_g: per ElementGroup, the time constant of the lung volume's answer to a step of that
  /// group's activation, identified on the calibration staircase (0 = an instantaneous group); the
  /// controller's feed-forward asks tau_g dv_T/dt ahead of the target. In [0, 10) s.
  std::array<double, kElementGroupCount> timeConstant{};
};

/// [-] R_g(alpha): the calibrated static volume-fraction change of group g alone at activation alpha in
/// [0, 1], interpolated linearly between kCalibrationAlphas.
double groupResponse(const DriveCalibration& calibration, ElementGroup g, double alpha);

/// Feedback settings.
struct PatternControllerOptions {
  /// [-] proportional gain on the fraction error. The internal intercostals move the volume within one
  /// 10 ms step against the lungs' recoil (Cavity), so a stiff loop chatters: at K_p 3 their activation
  /// switched between 0 and 1 every step through focus's and panic's expirations (tracking RMS 15 % and
  /// 12 %). K_p 2 / 1.5 / 1 / 0.7 give focus 11.7 / 8.6 / 4.9 / 4.0 % and panic 9.2 / 8.0 / 5.2 / 4.8 %.
  /// K_p 0.5 with K_i 50 /s (from 1 and 100 /s) halves what the feedback adds to the feed-forward's smooth
  /// demand, so that the simulated flow has no more reversals per breath than the target's and no
  /// frame-to-frame jump above 45 % of peak flow on any affect (AffectFlow test; docs/patterns.md,
  /// "Feedback"); the integral carries the slow lag.
  double kp = 0.5;
  double ki = 50.0;            ///< [1/s] integral gain
  double integralLimit = 0.2;  ///< [-] clamp of the integral term I, in fraction units
  /// [s] first-order smoothing of balance changes: between layers, and at the peak of a cycle with an
  /// inspiratory balance (CycleSpec::inspiratoryBalance)
  double balanceTimeConstant = 0.3;
  /// [s] first-order lag between the drive and the internal intercostals' activation, added to their lever's
  /// lag in the feed-forward. They move the chest within one step (their calibrated lag is 0), and with the
  /// rib necks' costotransverse lock of 300 N m/rad (resources/anatomy/README.md) the chest answers them in
  /// an inflated breath several times as strongly as the calibration from rest says: without the lag the loop
  /// chattered through focus's, panic's and startle's expirations (frame-to-frame flow jumps of 99-121 % of
  /// peak flow, 3-4 reversals per breath). 0.05 s left focus at 52 % and panic at 61 %, 0.08 s and 0.1 s give
  /// 37 / 43 and 33 / 44 % (docs/patterns.md, "Feedback"). 0: no lag.
  double internalIntercostalLag = 0.1;
};

/// Target-versus-measured statistics over the frames seen after control started.
struct TrackingStats {
  long long frames = 0;          ///< [-] frames compared
  double sumSquaredError = 0.0;  ///< [-] sum of (v_T - v_M)^2
  double targetMin = 1.0;        ///< [-]
  double targetMax = 0.0;        ///< [-]
  /// [%] RMS error as a percentage of the target's peak-to-peak (0 when nothing was compared).
  double rmsPercentOfPeakToPeak() const;
};

/// Measures each muscle group's static response curve and lag on `model`: one run per driven group from
/// the settled torso (so that the ribs' slow release after one group cannot enter the next group's
/// baseline). The group rests for 0.6 s (the mean volume of the last 0.3 s is its baseline) and is then
/// held alone at each level of kCalibrationAlphas (r = contractionR) for 0.8 s; R_g(alpha_k) is the mean
/// volume of the last 0.4 s of level k minus the baseline, divided by S. The lag is the method of moments
/// over the steps k that take the group further from rest (|R_g| growing):
///   tau_g = sum_k integral over level k of (V_k - V(t)) dt / sum_k (V_k - V_(k-1))   [s],
/// with V_k the level's settled volume: exact for a first-order response (tau dV/dt + V = V_k) that
/// settles within the level.
/// The first group's baseline is V_rest. 5 x 9 s of simulated time, about 8 s of wall time on the
/// default model.
/// @param options  simulation options (integrator, dt, settleTime, gain scales) to use for the run; an unset
/// dt
///                 steps at kDriveTimeStep, as the drive itself
/// @param stop     checked before every step (Simulation::setStopFlag()); may be null
/// @throws Interrupted when `*stop` became true before the calibration finished.
DriveCalibration calibrateDrive(std::shared_ptr<const Model> model, const SimulationOptions& options = {},
                                double contractionR = 0.6, const std::atomic<bool>* stop = nullptr);

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
  /// Follows a measured volume trace instead of a pattern: v_T(t) = v_rest + trace.sample(t) / S, i.e. the
  /// trace's minimum at the rest volume, cross-faded (smoothstep over kTraceBlend) from the fraction measured
  /// when control starts; after the trace's end its last volume holds. Same feedback and drive as a pattern.
  /// @throws Error as the pattern constructor, or when the trace has no samples.
  PatternController(VolumeTrace trace, DriveCalibration calibration, PatternControllerOptions options = {});

  Activations activations(double t, const Metrics& latest) override;
  std::string describe() const override;
  std::unique_ptr<Controller> clone() const override;
  /// kDriveTimeStep.
  double maxTimeStep() const override { return kDriveTimeStep; }

  /// The pattern clock, the feedback's integral and last frame, the learned rest volume, the tracking
  /// statistics and the whole LayerStack (pushed layers and its random stream included).
  void saveState(CheckpointWriter& out) const override;
  void loadState(CheckpointReader& in) override;

  /// Pushes layers live (the app's affect selector); see LayerStack::push().
  void push(const std::vector<Layer>& playOrder, SwitchMode mode);

  /// [-] target fraction v_T at the last control time.
  double targetFraction() const override { return m_target; }
  /// [-] fraction of the last measured lung volume (0 before the rest volume is known).
  double measuredFraction() const override { return m_measured; }
  /// tracking().rmsPercentOfPeakToPeak().
  double trackingRmsPercent() const override { return m_tracking.rmsPercentOfPeakToPeak(); }
  /// [-] fraction of a lung volume [m^3] under this controller's mapping.
  double volumeToFraction(double volume) const;
  /// [m^3] lung volume of a fraction under this controller's mapping.
  double fractionToVolume(double fraction) const;
  const TrackingStats& tracking() const { return m_tracking; }
  const LayerStack& stack() const { return m_stack; }
  const DriveCalibration& calibration() const { return m_calibration; }

 private:
  // [-] v_T at pattern time tau [s]
  double sampleTarget(double tau);
  // demand d [-], target rate [1/s] and balance b [-] -> alphas
  Activations distribute(double demand, double rate, double balance) const;
  void restart();  // back to the state at construction

  LayerStack m_stack;
  LayerStack m_initialStack;  // for restart()
  DriveCalibration m_calibration;
  DriveCalibration m_givenCalibration;  // as passed in (restVolume may be learned later)
  PatternControllerOptions m_options;
  std::string m_description;
  bool m_isControlling = false;         // false during settling (t = 0 calls)
  double m_restVolumeSeen = 0.0;        // [m^3] latest lung volume seen while settling
  double m_lastTime = 0.0;              // [s] control time of the last call
  double m_startTime = 0.0;             // [s] control time at which control (and the pattern clock) started
  double m_lastFrameTime = -1.0;        // [s] Metrics::time of the last frame used
  double m_lastFrameControlTime = 0.0;  // [s] control time at which that frame arrived
  double m_target = 0.0;                // [-] v_T at m_lastTime
  double m_targetRate = 0.0;            // [1/s] dv_T/dt, backward difference over the last step
  double m_measured = 0.0;              // [-] v_M of the last frame
  double m_error = 0.0;                 // [-] e of the last frame
  double m_integral = 0.0;              // [-] I = ki * integral(e dt), clamped
  double m_balance = 0.5;               // [-] smoothed balance
  double m_internalAlpha = 0.0;         // [-] the internal intercostals' lagged activation
  TrackingStats m_tracking;
  std::shared_ptr<const VolumeTrace> m_trace;  // the trace followed instead of m_stack; null for a pattern
  double m_traceStart = 0.0;                   // [-] fraction measured when control started (trace blend)
};

/// [s] cross-fade from the measured volume into a followed trace (LayerStack's longest blend).
inline constexpr double kTraceBlend = 0.4;

/// A PatternController playing the affect preset NAME from `resourceDir` (resources/) on `model`.
/// @throws Error "unknown affect 'NAME' (valid: ...)" or a preset/calibration error.
std::unique_ptr<PatternController> makeAffectController(const std::string& name,
                                                        const std::string& resourceDir, std::uint64_t seed,
                                                        const DriveCalibration& calibration);

/// A PatternController playing a pattern file (layers and timeline) on `model`.
std::unique_ptr<PatternController> makePatternController(const Pattern& pattern, std::uint64_t seed,
                                                         const DriveCalibration& calibration);

}  // namespace pneuma::sim::pattern
