#pragma once
/// @file Experiments.h
/// The papers' experiments, rerun on a model, and the quantitative checks of their claims. One place for
/// them: `pneuma-cli validate` writes its report from these, and the validation tests call the same code.
///
/// Experiments (Zordan et al. 2004):
///  - breath styles (Section 8.1, Table 2, Figure 6): calm, deep, panting and forced exhale played by
///    BreathStyleController; tidal volume, rate, end-expiratory volume, gut volume error, landmarks;
///  - heavy impact (Section 6.2, Figure 4): the relaxed torso's anterior abdominal wall is struck inward;
///    the gut's volume error stays small while it deforms;
///  - spine sway (Section 5, Eq. 3): deep breathing with and without rib-joint friction; friction couples
///    the ribs to the spine, which then sways backward during inhale.

#include "pneuma/sim/BreathStyleController.h"
#include "pneuma/sim/Metrics.h"
#include "pneuma/sim/Model.h"
#include "pneuma/sim/Simulation.h"

#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace pneuma::sim {

/// One check of a claim: passes when lower <= measured <= upper.
struct Check {
  std::string id;          ///< stable identifier, e.g. "calm.tidal_volume"
  std::string what;        ///< what is measured, e.g. "tidal volume, calm breathing"
  std::string target;      ///< the target as text, e.g. "500 mL +/- 20 %"
  std::string source;      ///< paper, section, table or figure, e.g. "Zordan et al. 2004, Sec. 8.1, Fig. 6"
  std::string unit;        ///< unit of measured, lower and upper, e.g. "mL"
  double measured = 0.0;   ///< in `unit`
  double lower = -std::numeric_limits<double>::infinity();  ///< in `unit`
  double upper = std::numeric_limits<double>::infinity();   ///< in `unit`
  bool isPassed() const { return measured >= lower && measured <= upper; }
};

/// Durations and the simulation options shared by the experiments.
struct ExperimentSettings {
  SimulationOptions simulation;  ///< integrator, dt, settle time, output rate (defaults of Simulation)
  double styleDuration = 20.0;   ///< [s] periodic styles, after settling (>= 2 cycles of the slowest style)
  double forcedExhaleDuration = 8.0;  ///< [s] the single forced-exhale manoeuvre (6 s) and its end
  double impactDuration = 1.5;   ///< [s] simulated after the impact
  double impactSpeed = 2.0;      ///< [m/s] inward (posterior) speed given to the anterior abdominal wall
  double swayDuration = 12.0;    ///< [s] deep breathing per friction setting
};

/// Settings for a fast run (tests, `validate --quick`): shorter durations, same physics.
ExperimentSettings quickExperimentSettings();

/// A breath-style run.
struct StyleRun {
  BreathStyle style;
  Summary summary;          ///< from settleTime on
  Trace trace;              ///< whole run, settling included
  double settleTime = 0.0;  ///< [s]
};

/// Plays `style` on `model` for settings.styleDuration (forcedExhaleDuration when style.cycles > 0).
/// @throws Error on a blow-up (the message names the time and the cause).
StyleRun runBreathStyle(std::shared_ptr<const Model> model, const BreathStyle& style, const ExperimentSettings& settings);

/// Checks of Section 8.1, Table 2 and Figure 6 on runs named "calm", "deep", "panting" and "forced-exhale"
/// (missing runs are skipped): calm tidal volume 500 mL +/- 20 %, Table 2 rates +/- 10 %, tidal volumes
/// ordered panting < calm < deep and inside the human range, forced exhale below calm end-expiration with
/// the umbilicus >= 10 mm posterior, and gut volume error below 2 % while breathing (Figure 4 caption).
std::vector<Check> breathStyleChecks(const std::vector<StyleRun>& runs);

/// The heavy-impact run (Figure 4).
struct ImpactRun {
  Trace trace;              ///< from the impact on (time 0 = impact)
  double maxVolumeError = 0.0;  ///< [-] max |(V - V0)/V0| after the impact
  double maxWallDisplacement = 0.0;  ///< [m] largest displacement of a wall node after the impact
};

/// Settles the relaxed torso, gives every anterior wall node (region Wall, rest y above the wall's mean)
/// the inward speed settings.impactSpeed along -y, and simulates settings.impactDuration.
ImpactRun runHeavyImpact(std::shared_ptr<const Model> model, const ExperimentSettings& settings);

/// Volume error below 0.5 % after the impact (Figure 4), and a visible deformation (>= 5 mm).
std::vector<Check> impactChecks(const ImpactRun& run);

/// A spine-sway run: deep breathing with rib-joint friction scaled by `frictionScale`.
struct SwayRun {
  double frictionScale = 1.0;     ///< [-] multiplies every joint's mu (Eq. 3)
  std::string spineBody;          ///< the moving thoracic body observed (highest one)
  std::vector<double> time;       ///< [s] from settleTime on
  std::vector<double> spineY;     ///< [m] anterior (+y) displacement of its com from the settled pose
  std::vector<double> lungVolume; ///< [m^3]
  double sway = 0.0;              ///< [m] range of spineY
  double correlation = 0.0;       ///< [-] Pearson correlation of spineY with lung volume (< 0: backward on inhale)
};

/// Plays `deep` with the rib joints' friction scaled by `frictionScale` for settings.swayDuration.
SwayRun runSpineSway(std::shared_ptr<const Model> model, const BreathStyle& deep, double frictionScale,
                     const ExperimentSettings& settings);

/// Section 5: with friction the spine sways (>= 0.5 mm) backward on inhale (correlation < -0.3) and
/// clearly more than without friction (ratio >= 2).
std::vector<Check> swayChecks(const SwayRun& withFriction, const SwayRun& frictionless);

}  // namespace pneuma::sim
