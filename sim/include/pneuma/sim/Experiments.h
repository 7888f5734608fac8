#pragma once
/// @file Experiments.h
/// The papers' experiments, rerun on a model, and the quantitative checks of their claims. One place for
/// them: `pneuma-cli validate` writes its report from these, and the validation tests
/// (tests/validation/Breathing_test.cpp) assert the same checks.
///
/// Experiments (Zordan et al. 2004):
///  - breath styles (Section 8.1, Table 2, Figures 5 and 6): calm, deep, panting and forced exhale played
///    by BreathStyleController;
///  - spine sway (Section 5, Eq. 3): deep breathing with and without rib-joint friction; friction couples
///    the ribs to the spine, which then moves backward during a deep inhale;
///  - heavy impact (Section 6.2, Figure 4): the relaxed torso's anterior abdominal wall around the
///    umbilicus is struck posteriorly; the gut deforms while its volume error stays small.

#include <Eigen/Core>
#include <array>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "pneuma/sim/BreathStyleController.h"
#include "pneuma/sim/Metrics.h"
#include "pneuma/sim/Model.h"
#include "pneuma/sim/Simulation.h"

namespace pneuma::sim {

/// One check of a claim: passes when lower <= measured <= upper.
struct Check {
  std::string id;         ///< stable identifier, e.g. "calm.tidal_volume"
  std::string what;       ///< what is measured, e.g. "tidal volume, calm"
  std::string target;     ///< the target as text, e.g. "500 +/- 50 mL"
  std::string source;     ///< paper, section, table or figure, e.g. "Zordan et al. 2004, Sec. 8.1, Fig. 6"
  std::string unit;       ///< unit of measured, lower and upper, e.g. "mL"
  double measured = 0.0;  ///< in `unit`
  double lower = -std::numeric_limits<double>::infinity();  ///< in `unit`
  double upper = std::numeric_limits<double>::infinity();   ///< in `unit`
  bool isPassed() const { return measured >= lower && measured <= upper; }
};

/// Durations and the simulation options shared by the experiments.
struct ExperimentSettings {
  SimulationOptions simulation;  ///< integrator, dt, settle time; output rate 30 Hz; 1 s recorder window (the
                                 ///< experiments read the trace, not the recorder's timeline)
  double styleDuration = 12.0;   ///< [s] periodic styles after settling (>= 2 cycles of deep breathing)
  double forcedExhaleDuration = 8.0;  ///< [s] the single 6 s forced-exhale manoeuvre and its end
  double impactSettle = 2.0;          ///< [s] relaxed settling before the impact
  double impactDuration = 1.5;        ///< [s] simulated after the impact
  double impactSpeed = 2.0;           ///< [m/s] posterior speed given to the struck wall nodes
  double impactRadius = 0.06;         ///< [m] wall nodes within this distance of the umbilicus are struck
  ExperimentSettings() {
    simulation.outputRate = 30.0;
    simulation.recordSeconds = kTraceOnlyRecordSeconds;
  }
  /// Shorter runs for the same checks (`--quick` of validate and silhouette): 1 s settling, 10 s of a
  /// periodic style, 7 s of the forced exhale, 1 s + 0.5 s around the impact.
  static ExperimentSettings quick() {
    ExperimentSettings s;
    s.simulation.settleTime = 1.0;
    s.styleDuration = 10.0;
    s.forcedExhaleDuration = 7.0;
    s.impactSettle = 1.0;
    s.impactDuration = 0.5;
    return s;
  }
};

/// A breath-style run.
struct StyleRun {
  BreathStyle style;
  double frictionScale = 1.0;  ///< [-] multiplier of the rib joints' mu (Eq. 3) in this run
  Summary summary;             ///< from settleTime on
  Trace trace;                 ///< every output frame, settling included
  double settleTime = 0.0;     ///< [s]
  std::string spineBody;       ///< name of the highest moving thoracic body ("" when the model has none)
  std::vector<Eigen::Vector3d> spineTop;  ///< [m] its com at every frame of `trace`
  int umbilicus = -1;  ///< column of the "umbilicus" landmark in trace.landmarks, -1 if missing
  int xiphoid = -1;    ///< column of the "xiphoid" landmark in trace.landmarks, -1 if missing
  std::shared_ptr<const Model> model;  ///< the model it ran on
  /// The poses of the last full cycle after settling (the single manoeuvre of a forced exhale): the frame of
  /// largest lung volume, and the frame of smallest volume after it in the same cycle. Valid when
  /// hasBreathPoses.
  State endInspiration;
  State endExpiration;  ///< see endInspiration
  bool hasBreathPoses = false;
  double endInspirationVolume = 0.0;  ///< [m^3] lung volume at endInspiration
  double endExpirationVolume = 0.0;   ///< [m^3] lung volume at endExpiration
};

/// Plays `style` on `model` for settings.styleDuration after settling (forcedExhaleDuration when the style
/// is not periodic), with the rib joints' friction (Eq. 3: the costovertebral joints, named
/// "costovertebral_rib<level>_<side>") scaled by `frictionScale`; other joints (spine, shoulder girdle) keep
/// theirs, so that a frictionless run differs from the calibrated one in Section 5's friction only.
/// @throws Error on a blow-up (the message names the time and the cause).
StyleRun runBreathStyle(std::shared_ptr<const Model> model, const BreathStyle& style,
                        const ExperimentSettings& settings, double frictionScale = 1.0);

/// Checks of Section 8.1, Table 2 and Figures 4-6 on runs named "calm", "deep", "panting" and
/// "forced-exhale" (checks whose runs are missing are left out): gut volume error < 2 % in every style;
/// calm tidal volume 500 +/- 50 mL at 15 +/- 0.5 b/m, its exhales without a rebound above 10 mL
/// (expirationRebound()); deep above calm, 0.6-3 L, 12 +/- 0.5 b/m; panting 60 +/- 1 b/m, below calm,
/// chest-dominant (the ratio of the xiphoid's to the umbilicus's anterior-posterior excursion, the motion
/// seen from the side as in Fig. 5, above calm's); forced exhale below calm end-expiration, umbilicus >= 1 cm
/// posterior, xiphoid down.
std::vector<Check> breathStyleChecks(const std::vector<StyleRun>& runs);

/// One rib's turn from end-expiration to end-inspiration of a run, from the bones' poses (the way Wilson et
/// al. 1987, J Appl Physiol 62:1872, measured ribs by CT from FRC to TLC).
struct RibMotion {
  std::string rib;    ///< body name, e.g. "rib3_right"
  int level = 0;      ///< 1 (top) .. 10
  double turn = 0.0;  ///< [rad] angle of the rotation R_insp R_exp^-1
  /// [rad] angle between the rotation axis and the midsagittal plane, asin |a_x|: 0 an anteroposterior axis
  /// (bucket handle), pi/2 a left-right axis (pump handle)
  double axisFromMidsagittal = 0.0;
  /// [rad] the rotation vector's component along the rib's neck axis (its costovertebral joint's axis, turned
  /// with the parent at end-expiration), signed so that > 0 lifts the rib's centre of mass
  double aboutNeck = 0.0;
  Eigen::Vector3d comMotion = Eigen::Vector3d::Zero();  ///< [m] its centre of mass's motion, world (RAS)
};

/// Every rib with a costovertebral joint (a joint named "costovertebral_rib<level>_<side>") of `run`'s model,
/// in joint order; empty when the run has no breath poses.
std::vector<RibMotion> ribMotions(const StyleRun& run);

/// The breath's motion in anatomical axes (Summary::motion) against published physiology, on runs named
/// "calm" and "deep" (ids "physiology.<style>.<figure>"; checks whose runs are missing are left out), each
/// with its source: calm dome descent 12-25 mm (M-mode ultrasound, Boussuges et al. 2009); deep dome descent
/// >= 2 x calm and 20-35 mm per litre inspired; the umbilicus forward on every calm inhale; rib 8's lateral
/// distance growing
/// >= 2 mm calm and >= 10 mm deep; the calm rib-cage share 55-85 % upright; calm rib-cage / abdomen phase
/// < 30 deg; two flow reversals per calm breath and no frame-to-frame flow jump above 20 % of peak flow;
/// for every other periodic style among `runs` (deep, panting, ...) two flow reversals per breath and no jump
/// above max(20 %, 2 x 2 pi f / fs) of peak flow, f the breathing frequency and fs the trace's frame rate
/// (a pure sinusoid changes by up to 2 pi f / fs of its peak per frame: 21 % at 60 b/m and 30 frames/s).
/// A model with a shoulder girdle (acromion landmarks) adds the deep breath's acromion lift over calm's,
/// >= 10 mm.
std::vector<Check> physiologyChecks(const std::vector<StyleRun>& runs);

/// [m] backward sway of the spine top during inhales (Section 5: "during a deep inhale, as the ribs are
/// pulled upward, the spine moves backward"): for every full inhale after settling (the controller's
/// windows [settle + k T, settle + (k + inhaleFraction) T), T = 60 / breathsPerMinute), the most posterior
/// displacement of the spine top's y from its value at the inhale's start, averaged over the inhales
/// (< 0: the spine moves backward). Measured during the inhale rather than at peak volume because the
/// friction torque of Eq. 3 follows the ribs' angular velocity and vanishes when they stop.
double spineSway(const StyleRun& run);

/// [m^3] the largest bounce of the lung volume during an exhale: over the controller's exhale windows
/// [settle + (k + inhaleFraction) T, settle + (k + 1) T) of the full cycles after settling, from the window's
/// highest volume on, the largest rise of the volume above its running minimum (0 for a monotone fall).
double expirationRebound(const StyleRun& run);

/// Section 5: with friction the spine moves backward on a deep inhale (sway < -0.1 mm), and without
/// friction by less than half as much.
std::vector<Check> swayChecks(const StyleRun& deepWithFriction, const StyleRun& deepFrictionless);

/// [m^3] lung-volume change over the last `window` [s] of the settling phase, V(settle) - V(settle - window):
/// how far the relaxed torso still is from its equilibrium when the controller starts (0 when the trace is
/// shorter).
double settleDrift(const StyleRun& run, double window = 0.5);

/// Posture (StepOptions::posture): the same breath style played upright and supine (lying on the back).
/// People breathe more with the abdomen supine (Sharp et al. 1975, J Appl Physiol 39:608; Konno & Mead 1967),
/// and their end-expiratory lung volume falls supine (lung volumes 5.3-14.7 % larger sitting or standing,
/// Yamada et al. 2020). Checks: rib-cage share of the tidal volume (Motion::ribCageTidal over the tidal
/// volume) at least 1 percentage point lower supine; end-expiratory volume at least 1 % lower supine; the
/// supine run settled (|settleDrift()| under 2 % of its tidal volume in the last 0.5 s of settling).
std::vector<Check> postureChecks(const StyleRun& upright, const StyleRun& supine);

/// [-] Where the chest line of the silhouette figures meets the sternum: this fraction of the way from the
/// jugular notch to the xiphoid tip, the 4th intercostal space (the nipple line). On the model's sternum the
/// 4th space lies midway between costal notches 4 and 5, manubrium + half the body down: (52 + 55) / 202 mm
/// male, (48 + 46) / 175 mm female (resources/anatomy, Gray's Anatomy: costal cartilages 3-6 evenly on the
/// body).
constexpr double kChestLineOnSternum = 0.53;

/// The body's silhouette in one breath of a style run: the posed skin at end-expiration and end-inspiration
/// (StyleRun::endExpiration, endInspiration) and the change of its anteroposterior depth, seen from the side
/// (silhouetteWidth(), SilhouetteView::Lateral), along two horizontal lines held at their end-expiration
/// heights, as a camera or a laser line sees the silhouette move: the chest line (kChestLineOnSternum of the
/// way down the sternum) and the belly line (the umbilicus). On the sloping upper chest the silhouette's
/// forward motion at a fixed height includes the skin's rise (chestLift, bellyLift give the landmarks'). Seen
/// from the side, the trunk only: the skin within trunkBand of the midsagittal plane, so that the arms (held
/// forward of the belly in the skin's pose) do not hide it.
struct SilhouetteBreath {
  std::string style;                 ///< the run's style name
  Eigen::Matrix3Xd skinExpiration;   ///< [m] posed skin at end-expiration (3 x #V)
  Eigen::Matrix3Xd skinInspiration;  ///< [m] posed skin at end-inspiration (3 x #V)
  double chestHeight = 0.0;          ///< [m] z of the chest line at end-expiration
  double bellyHeight = 0.0;          ///< [m] z of the belly line at end-expiration
  double chestLift = 0.0;  ///< [m] rise of the chest line's landmarks from end-expiration to end-inspiration
  double bellyLift = 0.0;  ///< [m] rise of the umbilicus
  double trunkBand = 0.0;  ///< [m] half-width of the trunk seen from the side: rib 8's lateral half-distance
  double chestChange = 0.0;  ///< [m] AP depth along the chest line, end-inspiration minus end-expiration
  double bellyChange = 0.0;  ///< [m] the same along the belly line
  double lungChange = 0.0;   ///< [m^3] lung volume, end-inspiration minus end-expiration
  /// [m] motion of a marker on the skin, end-inspiration minus end-expiration: the material point where the
  /// midline (x = 0) meets the front of the skin at the chest line at end-expiration, carried by its triangle
  /// (a material point, as optoelectronic plethysmography tracks, where chestChange is a section at a fixed
  /// height that the skin rises through); zero when the line misses the skin
  Eigen::Vector3d chestMarker{0.0, 0.0, 0.0};
};

/// The silhouette breath of `run`. @throws Error when the run has no breath poses, its model no skin or no
/// "jugular_notch", "xiphoid" and "umbilicus" landmarks.
SilhouetteBreath silhouetteBreath(const StyleRun& run);

/// The silhouette's anteroposterior change per style against published chest-wall motion (ids
/// "silhouette.<style>.chest" and ".belly", in mm, and "silhouette.calm.chest_marker"; checks whose styles
/// are missing are left out):
///  - calm chest marker 1.5 - 10 mm: the displacement of a marker on the skin at the front of the chest
///    line (SilhouetteBreath::chestMarker), the quantity De Groote et al. 1997 measured (3-5 mm at the 3rd
///    and 5th costal cartilages), with the same band as the chest silhouette's;
///  - calm chest 1.5 - 10 mm: seated tidal breathing moves the chest wall at the 3rd and 5th costal
///  cartilages
///    3-5 mm, mostly ventrally and cranially (De Groote et al. 1997, J Appl Physiol 83:1531, optoelectronic
///    markers); the band is half the lower and twice the upper figure, for the spread between people;
///  - calm belly > 0: at the umbilicus the wall moves almost only ventrally (De Groote et al. 1997; Konno &
///    Mead 1967, J Appl Physiol 22:407);
///  - deep chest and belly above calm's: quiet-breathing movements are less than a third of deep-breathing
///    ones, sitting and supine (Kaneko & Horie 2012, Respir Care 57:1442, 100 subjects); their deep breaths
///    were fuller than the deep style's (about twice calm's volume), so only the direction is checked;
///  - panting chest > 0 and belly below calm's belly/chest proportion of the chest: fast manoeuvres are
///  mostly
///    rib cage (Sharp et al. 1975, J Appl Physiol 39:608; Zordan et al. 2004 Sec. 8.1);
///  - forced exhale chest > 0 (the rib cage falls) and belly >= 10 mm (the rectus pulls the abdomen in by
///    more than a centimetre, Zordan et al. 2004 Sec. 8.1, Fig. 5).
std::vector<Check> silhouetteChecks(const std::vector<SilhouetteBreath>& breaths);

/// The heavy-impact run (Figure 4).
struct ImpactRun {
  int struckNodes = 0;                 ///< wall nodes given the impact speed
  std::vector<double> time;            ///< [s] since the impact, every step
  std::vector<double> gutVolumeError;  ///< [-] signed (V - V0)/V0, every step
  double maxVolumeError = 0.0;         ///< [-] max |(V - V0)/V0| after the impact
  double maxDent = 0.0;                ///< [m] largest posterior displacement of the umbilicus landmark
};

/// Settles the relaxed torso for settings.impactSettle, gives the wall nodes within impactRadius of the
/// umbilicus a posterior velocity of impactSpeed, and steps settings.impactDuration.
/// @throws Error when the model has no umbilicus or no wall node near it, or on a blow-up.
ImpactRun runHeavyImpact(std::shared_ptr<const Model> model, const ExperimentSettings& settings);

/// Volume error below 0.5 % after the impact (Figure 4), with a visible dent (> 5 mm).
std::vector<Check> impactChecks(const ImpactRun& run);

/// A run of a shipped scenario for teaching (resources/scenarios/teaching/, docs/app.md "Teaching presets"),
/// or of the calm reference (resources/scenarios/calm.json): `kTeachingSeconds` after the scenario's
/// settling, at 30 frames/s.
struct TeachingRun {
  std::string scenario;  ///< the file relative to resources/scenarios/, e.g. "teaching/supine.json"
  Summary summary;       ///< from the scenario's settle time on
  /// [mm/L] least-squares slope of each hemidiaphragm's mean height (the gut nodes its diaphragm elements
  /// hold, midline strands excluded) against the lung volume over the run, {left, right}: < 0 when the half
  /// descends on inspiration, > 0 when it rises with it (paradoxical motion)
  std::array<double, 2> domeRisePerLitre{};
};
constexpr double kTeachingSeconds = 12.0;  ///< [s] simulated after settling in a TeachingRun

/// The calm reference and the teaching presets teachingChecks() knows, relative to resources/scenarios/
/// (the calm reference first).
std::vector<std::string> teachingScenarios();

/// Runs `scenario` (relative to `resourceDir`/scenarios/) on `model`.
/// @throws Error when the scenario cannot be read or the run blows up.
TeachingRun runTeachingScenario(std::shared_ptr<const Model> model, const std::string& scenario,
                                const std::string& resourceDir);

/// Each teaching preset against calm upright breathing: the figure its description names moves in the
/// direction the physiology it cites gives (ids "teaching.<preset>.<figure>"):
///  - calm: both hemidiaphragms descend on inspiration (< -1 mm/L);
///  - paralysed left/right hemidiaphragm: tidal volume < 90 % of calm (Laroche et al. 1988), the paralysed
///    dome rises with inspiration (> 0 mm/L) while the other descends (Alexander 1966, the sniff test);
///  - weak intercostals: rib-cage share 5 points below calm, tidal volume < 90 % (De Troyer & Estenne 1984);
///  - stiff chest wall: rib-cage share 20 points below calm, rib-8 widening < half of calm, the umbilicus
///    moving further forward, tidal volume < 90 % (Romagnoli et al. 2004);
///  - abdominal binding: rib-cage share 5 points above calm, a smaller tidal volume (Hussain et al. 1985);
///  - supine: rib-cage share 5 points below upright (Sharp et al. 1975), end-expiratory volume 1 % lower
///    (Yamada et al. 2020).
/// Runs missing from `runs` (found by TeachingRun::scenario) give no checks; without the calm run, none.
std::vector<Check> teachingChecks(const std::vector<TeachingRun>& runs);

}  // namespace pneuma::sim
