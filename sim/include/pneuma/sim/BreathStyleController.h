#pragma once
/// @file BreathStyleController.h
/// Breath-style presets (Zordan et al. 2004, Section 7, Section 8.1 and Table 2) and the open-loop
/// controller that plays them.
///
/// One breath cycle of period T = 60 / breathsPerMinute starts at the beginning of inhale:
///  - diaphragm: a step function (the "pump"), alpha = diaphragmAlpha and r = diaphragmR during the
///    inhale part [0, inhaleFraction T), alpha = 0 and r = 1 otherwise. The paper switches alpha
///    between 0 and 1; a partial level (panting) is our calibration choice, see the preset notes.
///    Our choice: the step's edges are smoothed over diaphragmRiseTime (alpha = s(t / rise) diaphragmAlpha,
///    s(x) = 3x^2 - 2x^3, from the start of inhale; 1 - s(t / rise) from the start of exhale, r = diaphragmR
///    throughout). A muscle's force rises over tens to hundreds of ms (excitation-contraction coupling;
///    the phrenic nerve's inspiratory discharge is a ramp), and a sharp step made the stiff diaphragm
///    (kac 28.8 kN/m) jolt in about 20 ms and ring, so the run depended on dt (calm 474 mL at dt 10 ms,
///    a ring counted as a second breath at 5 ms). With a 0.2 s rise calm, deep and panting agree within
///    1 % from dt 5 ms to 1/60 s. 0 gives the sharp step;
///  - outer intercostals: r(t) = mean + amplitude cos(2 pi t / T), alpha = intercostalAlpha: r drops
///    smoothly during the first half-cycle (inhale) and rises again during exhale;
///  - inner intercostals: out of phase, r(t) = mean - amplitude cos(2 pi t / T), alpha = intercostalAlpha;
///  - rectus: only when rectusActive (forced exhale): alpha = 1 and r = rectusR during exhale;
///  - transversus/obliques and cartilage stay passive (alpha = 0, r = 1).
/// The cycle-start posture (t <= 0, i.e. during settling, and the hold after a finite style) is the relaxed end
/// of an exhale: diaphragm and rectus off, intercostals at their t = 0 values. When cycles > 0 the style plays that many cycles
/// and then holds that posture.

#include "pneuma/sim/Controller.h"

#include <string>
#include <vector>

namespace pneuma::sim {

/// A breath-style preset, stored as resources/presets/<name>.json (see the files for the fields).
struct BreathStyle {
  std::string name;                   ///< "calm", "deep", "panting", "forced-exhale"
  std::string note;                   ///< how the numbers were chosen and calibrated
  double breathsPerMinute = 15.0;     ///< [1/min] > 0
  double inhaleFraction = 0.4;        ///< [-] part of the cycle with the diaphragm on, in (0, 1)
  double diaphragmR = 0.85;           ///< [-] diaphragm contraction ratio during inhale, (0, 1.5]
  double diaphragmAlpha = 1.0;        ///< [-] diaphragm activation level during inhale, (0, 1]
  double diaphragmRiseTime = 0.2;     ///< [s] rise and fall time of the diaphragm's step, [0, inhale and exhale time]
  double intercostalMean = 0.92;      ///< [-] mean r of the intercostal sinusoids
  double intercostalAmplitude = 0.08; ///< [-] amplitude of the intercostal sinusoids (Table 2 "±")
  double intercostalAlpha = 1.0;      ///< [-] intercostal activation level, (0, 1]
  bool rectusActive = false;          ///< rectus contracts during exhale (forced exhale only)
  double rectusR = 1.0;               ///< [-] rectus contraction ratio when active
  int cycles = 0;                     ///< [-] 0 = periodic; n > 0 = n cycles, then hold
};

/// Checks ranges: rate > 0, inhaleFraction in (0, 1), every resulting r in (0, 1.5], diaphragmRiseTime at most
/// the inhale and the exhale time, cycles >= 0.
/// @throws Error naming the field and value.
void validateBreathStyle(const BreathStyle& s);

/// Parses a preset from JSON text (fields: name, note, breaths_per_minute, inhale_fraction,
/// diaphragm_r, diaphragm_alpha (optional, default 1), diaphragm_rise_time_s (optional, default 0.2), intercostal_mean,
/// intercostal_alpha (optional, default 1), intercostal_amplitude, rectus_active, rectus_r, cycles).
/// @throws Error naming `source` and the field.
BreathStyle parseBreathStyle(const std::string& jsonText, const std::string& source);

/// Serialises a preset to JSON text with the fields parseBreathStyle() reads (round-trips exactly).
std::string serializeBreathStyle(const BreathStyle& s);

/// Directory holding the breath-style presets: $PNEUMA_RESOURCE_DIR/presets when that variable is
/// set, else the source tree's resources/presets.
std::string defaultPresetDir();

/// Names of the presets (*.json) in `presetDir`, sorted.
std::vector<std::string> breathStyleNames(const std::string& presetDir = defaultPresetDir());

/// Loads a preset by name ("calm") from `presetDir`, or by path when `nameOrPath` ends in ".json".
/// @throws Error "unknown breath style 'x'; valid: calm, deep, forced-exhale, panting" on an unknown name.
BreathStyle loadBreathStyle(const std::string& nameOrPath, const std::string& presetDir = defaultPresetDir());

/// Open-loop controller playing a BreathStyle (Section 7).
class BreathStyleController : public Controller {
 public:
  /// @throws Error when the style is invalid (validateBreathStyle()).
  explicit BreathStyleController(BreathStyle style);
  Activations activations(double t, const Metrics& latest) override;
  std::string describe() const override;
  std::unique_ptr<Controller> clone() const override;
  const BreathStyle& style() const { return m_style; }

 private:
  BreathStyle m_style;
};

}  // namespace pneuma::sim
