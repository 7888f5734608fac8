#pragma once
/// @file BreathStyleController.h
/// Breath-style presets (Zordan et al. 2004, Section 7, Section 8.1 and Table 2) and the open-loop
/// controller that plays them.
///
/// One breath cycle of period T = 60 / breathsPerMinute starts at the beginning of inhale (phase x = t / T
/// mod 1, inhale for x < f = inhaleFraction). The muscles take turns, as in a body (De Troyer & Boriek 2011,
/// Compr Physiol 1:1273; De Troyer, Kirkwood & Wilson 2005, Physiol Rev 85:717), on two smooth drives in [0,
/// 1]:
///  - inspiratory drive d(x) (inspiratoryDrive()): a rounded rise over the inhale, d = (1 - cos(pi x / f)) /
///  2,
///    then the post-inspiratory decay of early expiration, d = 1 - s(x' / w) with x' the fraction of the
///    exhale gone and w = driveDecayFraction, s(u) = 3u^2 - 2u^3 clamped. Quiet expiration is braked, not a
///    drop: the inspiratory muscles' pressure falls to 50 % at 23 % of the exhale and to 0 at 79 % (J Appl
///    Physiol 1985, 58:1859); w = 0.6 gives 50 % at 30 % and 0 at 60 %. The diaphragm gets alpha = d
///    diaphragmAlpha at r = diaphragmR, the external intercostals (with the parasternals they stand for)
///    alpha = d intercostalAlpha at r = intercostalMean - intercostalAmplitude, Table 2's deepest
///    contraction, with their drive taken intercostalLead seconds ahead (d(x + lead / T)): the rib friction
///    (Eq. 3) makes the rib cage lag its muscles by about 0.18 s, so without the lead it moved 40 deg behind
///    the belly in a calm breath (healthy adults: 12-23 deg, Chen et al. 2015); 0.15 s gives 16 deg;
///  - expiratory drive e(x) (expiratoryDrive()): 0 during the inhale; over the exhale
///    e = s(x' / a) (1 - s((x' - 1 + b) / b)), a = expiratoryRiseFraction (default 0.3), b =
///    expiratoryFallFraction (default 0.15). Panting uses a = b = 0.5, a smooth bump over the exhale: with
///    the defaults the expiratory muscles let go in the last 75 ms of its 0.5 s exhale, the rib cage sprang
///    back and the flow reversed twice more per breath. The internal intercostals get alpha = e
///    internalIntercostalAlpha (0 in quiet breathing, where expiration is passive recoil), the rectus alpha =
///    e at r = rectusR when rectusActive (forced exhale).
/// This replaces the paper's control (Section 7, Table 2: a diaphragm step and out-of-phase intercostal
/// sinusoids of r at alpha 1): with both intercostal layers always at full activation the antagonists
/// co-contracted at kilonewtons, and the diaphragm's step moved the abdomen a fraction of a second before the
/// rib cage. Table 2's rates, inhale fractions and r values are kept. The cycle-start posture (t <= 0, i.e.
/// during settling, and the hold after a finite style) is the relaxed end of an exhale: every muscle off.
/// When cycles > 0 the style plays that many cycles and then holds that posture.

#include <string>
#include <vector>

#include "pneuma/sim/Controller.h"

namespace pneuma::sim {

/// A breath-style preset, stored as resources/presets/<name>.json (see the files for the fields).
struct BreathStyle {
  std::string name;                ///< "calm", "deep", "panting", "forced-exhale"
  std::string note;                ///< how the numbers were chosen and calibrated
  double breathsPerMinute = 15.0;  ///< [1/min] > 0
  double inhaleFraction = 0.4;     ///< [-] part of the cycle with the diaphragm on, in (0, 1)
  double diaphragmR = 0.85;        ///< [-] diaphragm contraction ratio during inhale, (0, 1.5]
  double diaphragmAlpha = 1.0;     ///< [-] diaphragm activation level during inhale, (0, 1]
  double driveDecayFraction =
      1.0;  ///< [-] part of the exhale over which the inspiratory drive decays, (0, 1]
  double expiratoryRiseFraction =
      0.3;  ///< [-] part of the exhale over which the expiratory drive rises to 1, (0, 1]
  double expiratoryFallFraction =
      0.15;  ///< [-] part at the exhale's end over which it falls back to 0, (0, 1], rise + fall <= 1
  double intercostalMean = 0.92;       ///< [-] mean r of the intercostal sinusoids
  double intercostalAmplitude = 0.08;  ///< [-] amplitude of the intercostal sinusoids (Table 2 "±")
  double intercostalAlpha = 1.0;  ///< [-] external intercostal activation at full inspiratory drive, (0, 1]
  double internalIntercostalAlpha =
      0.0;                       ///< [-] internal intercostal activation at full expiratory drive, [0, 1]
  double intercostalLead = 0.0;  ///< [s] the external intercostals' drive runs this far ahead, [0, T / 2]
  bool rectusActive = false;     ///< rectus contracts during exhale (forced exhale only)
  double rectusR = 1.0;          ///< [-] rectus contraction ratio when active
  int cycles = 0;                ///< [-] 0 = periodic; n > 0 = n cycles, then hold
};

/// Checks ranges: rate > 0, inhaleFraction in (0, 1), every resulting r in (0, 1.5], driveDecayFraction in
/// (0, 1], expiratoryRiseFraction and expiratoryFallFraction in (0, 1] with a sum <= 1,
/// internalIntercostalAlpha in [0, 1], intercostalLead in [0, T / 2], cycles >= 0.
/// @throws Error naming the field and value.
void validateBreathStyle(const BreathStyle& s);

/// Parses a preset from JSON text (fields: name, note, breaths_per_minute, inhale_fraction,
/// diaphragm_r, diaphragm_alpha (optional, default 1), drive_decay_fraction (optional, default 1),
/// expiratory_rise_fraction (optional, default 0.3), expiratory_fall_fraction (optional, default 0.15),
/// intercostal_mean, intercostal_alpha (optional, default 1), internal_intercostal_alpha (optional, default
/// 0), intercostal_lead_s (optional, default 0), intercostal_amplitude, rectus_active, rectus_r, cycles).
/// @throws Error naming `source` and the field.
BreathStyle parseBreathStyle(const std::string& jsonText, const std::string& source);

/// [-] the inspiratory drive d in [0, 1] at cycle phase `phase` in [0, 1) (see the file comment).
double inspiratoryDrive(const BreathStyle& s, double phase);
/// [-] the expiratory drive e in [0, 1] at cycle phase `phase` in [0, 1) (see the file comment).
double expiratoryDrive(const BreathStyle& s, double phase);

/// Serialises a preset to JSON text with the fields parseBreathStyle() reads (round-trips exactly).
std::string serializeBreathStyle(const BreathStyle& s);

/// Directory holding the breath-style presets: resourceDir()/presets (Resources.h).
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
