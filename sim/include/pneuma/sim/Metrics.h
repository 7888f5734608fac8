#pragma once
/// @file Metrics.h
/// Per-frame measurements of a running simulation and the Summary over a run.
/// Everything is SI ([m^3], [N], [J], [m], [Pa]); convert to mL, mm or cmH2O only at the edges.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "pneuma/sim/Activation.h"

namespace pneuma::sim {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Measurements at one output frame.
struct Metrics {
  double time = 0.0;  ///< [s] simulated time of the frame
  /// [m^3] the two lungs: thoracicCavityVolume minus the mediastinum's constant volume (Lungs), so its tidal
  /// swing is the cavity's (Figure 6)
  double lungVolume = 0.0;
  double thoracicCavityVolume = 0.0;  ///< [m^3] volume enclosed by the bound lung-cavity surface (Cavity)
  double rightLungVolume =
      kNaN;  ///< [m^3] the right lung's share of lungVolume (Lungs); NaN without lung surfaces
  double leftLungVolume = kNaN;  ///< [m^3] the left lung's share, lungVolume - rightLungVolume
  double gutVolume = 0.0;        ///< [m^3] gut volume V (sum of centroid -> face tetrahedra, Section 6.2)
  double gutVolumeError = 0.0;   ///< [-] signed relative error (V - V0) / V0
  double gutPressure = 0.0;      ///< [Pa] P = kappa (V0/V - 1), Eq. 4 (before clamping at 0)
  /// [m^3] coneVolume() from the gut's rest centroid over its abdominal-wall faces (at least two Wall nodes):
  /// its change is the volume the abdominal wall displaces, the abdomen compartment of Konno & Mead (1967)
  double abdomenVolume = 0.0;
  /// [-] signed relative volume error (V_k - V0_k) / V0_k of each soft-tissue volume body (Model::volumes)
  /// (#K)
  Eigen::VectorXd volumeBodyError;
  Eigen::VectorXd elementForce;       ///< [N] signed scalar force per element, <= 0 is tension (#E)
  std::vector<std::uint8_t> isSlack;  ///< 1 when a muscle element carries no force (#E)
  /// [N] mean over each group's elements of their tension max(0, -F) (slack ones count 0): a per-element
  /// force, on the scale of one element's trace; a sum would add up elements that sit in series along a
  /// muscle
  std::array<double, kElementGroupCount> groupMeanTension{};
  Activations activations{};   ///< control input in effect at this frame
  double kineticEnergy = 0.0;  ///< [J] sum of 1/2 m v^2 + 1/2 w^T I w over bodies and nodes
  double elasticEnergy =
      0.0;  ///< [J] springs (one-sided muscles, two-sided cartilage), gut and volume-body pressure, joints
  double gravityEnergy = 0.0;  ///< [J] -m g . x summed with the posture's g (postureGravity()), relative to
                               ///< the rest pose (0 when gravity is off), with the postural supports'
                               ///< potential (postureSupportPoint(), Step.h)
  double maxJointError = 0.0;  ///< [m] largest ball-joint separation after the step
  Eigen::Matrix3Xd landmarks;  ///< [m] landmark positions, world, in Model::landmarks order (3 x #L)
};

/// Light per-frame series kept over a whole run for the Summary and the plots.
struct Trace {
  std::vector<double> time;                 ///< [s]
  std::vector<double> lungVolume;           ///< [m^3]
  std::vector<double> gutVolumeError;       ///< [-] signed
  std::vector<double> abdomenVolume;        ///< [m^3] Metrics::abdomenVolume
  std::vector<Eigen::Matrix3Xd> landmarks;  ///< [m] (3 x #L) per frame

  /// Appends the scalar parts of one frame.
  void append(const Metrics& m);
  std::size_t size() const { return time.size(); }
  void clear();
  /// Keeps frames 0, 2, 4, ... of every series (how a long run's trace stays bounded, Simulation::trace()).
  void keepEveryOtherFrame();
};

/// How the body moves in a breath, in anatomical axes (world RAS: x lateral, y anteroposterior, z
/// craniocaudal). Displacements are end-inspiration (the frame of a cycle's largest lung volume) minus
/// end-expiration (its smallest), averaged over the full cycles; NaN when a landmark is missing or no cycle
/// was found.
struct Motion {
  double domeDescent = kNaN;      ///< [m] caudal motion of "diaphragm_apex" (the central tendon), > 0 = down
  double domeAnterior = kNaN;     ///< [m] its anterior motion (> 0 = forward)
  double sternumAnterior = kNaN;  ///< [m] anterior motion of "jugular_notch" (top of the manubrium)
  double sternumCranial = kNaN;   ///< [m] its cranial motion (> 0 = up)
  double xiphoidAnterior = kNaN;  ///< [m] anterior motion of "xiphoid"
  double xiphoidCranial = kNaN;   ///< [m] its cranial motion
  double lowerRibExpansion = kNaN;  ///< [m] change of the distance between "rib8_lateral_left" and "_right"
  /// [m] cranial motion of the acromions ("acromion_left", "acromion_right": the shoulder girdle's), their
  /// mean; NaN in a model without a shoulder girdle
  double acromionCranial = kNaN;
  double umbilicusAnterior = kNaN;  ///< [m] anterior motion of "umbilicus"
  double umbilicusAnteriorMin =
      kNaN;  ///< [m] its smallest value over the cycles (> 0: forward on every inhale)
  /// [m^3] abdomen's share of the tidal volume: the change of Metrics::abdomenVolume (Konno & Mead 1967)
  double abdomenTidal = kNaN;
  double ribCageTidal = kNaN;  ///< [m^3] the rest of the lung-volume change, tidal minus abdomenTidal
  /// [rad] in [0, pi]: phase difference of the breath-frequency Fourier components of the rib-cage volume
  /// (lung minus abdomen) and the abdomen volume over the full cycles; 0 = in phase, pi = paradoxical
  double phaseAngle = kNaN;
  double flowSignChanges = kNaN;  ///< [-] sign changes of the flow dV/dt (central differences) per cycle
  double maxFlowJump = kNaN;      ///< [-] largest frame-to-frame change of dV/dt over the largest |dV/dt|

  /// [-] the rib cage's share of the tidal volume, ribCageTidal / (ribCageTidal + abdomenTidal) (Konno & Mead
  /// 1967); NaN when the breath does not define it. The one rule for summary.json, validate and the app.
  double ribCageShare() const { return ribCageTidal / (ribCageTidal + abdomenTidal); }
};

/// Figures over a run, measured after the settling phase.
struct Summary {
  double tidalVolume = 0.0;           ///< [m^3] peak-to-peak lung volume, averaged over full cycles
  double breathsPerMinute = 0.0;      ///< [1/min] from the period of the volume signal (0 if < 2 cycles)
  double endExpiratoryVolume = 0.0;   ///< [m^3] mean of the per-cycle minima (the run's minimum if < 1 cycle)
  double endInspiratoryVolume = 0.0;  ///< [m^3] mean of the per-cycle maxima (the run's maximum if < 1 cycle)
  int cycles = 0;                     ///< [-] number of full cycles found
  double maxGutVolumeError = 0.0;     ///< [-] max |(V - V0)/V0|
  double meanGutVolumeError = 0.0;    ///< [-] mean |(V - V0)/V0|
  Motion motion;                      ///< the breath's motion in anatomical axes (see Motion)
  double realTimeFactor = 0.0;        ///< [-] simulated seconds per wall-clock second (stepping only)
  long long steps = 0;                ///< [-] steps taken in the whole run, settling included
  double dt = 0.0;                    ///< [s] time step
  double measuredFrom = 0.0;          ///< [s] start of the analysed window (end of settling)
};

/// Analyses `trace` from time `from` [s] on: cycles are delimited by successive upward crossings of
/// the mean lung volume (with a hysteresis of 25 % of the range from the first upward crossing on); tidal
/// volume is the mean per-cycle peak-to-peak, the rate is 60 / mean period. Motion (see Motion) uses the
/// landmarks "diaphragm_apex", "jugular_notch", "xiphoid", "rib8_lateral_left", "rib8_lateral_right" and
/// "umbilicus". Fills the volume, rate, gut-error and motion fields; the caller sets rtf, steps and dt.
Summary summarize(const Trace& trace, const std::vector<std::string>& landmarkNames, double from);

}  // namespace pneuma::sim
