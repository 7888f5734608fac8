#include "pneuma/sim/BreathStyleController.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "pneuma/sim/Error.h"
#include "pneuma/sim/JsonReader.h"
#include "pneuma/sim/Limits.h"
#include "pneuma/sim/Resources.h"

namespace pneuma::sim {

namespace {

constexpr double kPi = 3.14159265358979323846;

void requireRange(const std::string& field, double v, double lo, double hi, bool openLow) {
  const bool ok = std::isfinite(v) && (openLow ? v > lo : v >= lo) && v <= hi;
  if (!ok) {
    std::ostringstream os;
    os << field << ": must be in " << (openLow ? "(" : "[") << lo << ", " << hi << "], got " << v;
    throw Error(os.str());
  }
}

GroupActivation& slot(Activations& a, ElementGroup g) { return a[static_cast<std::size_t>(g)]; }

// [-] 0 -> 1 as u goes from 0 to `width` (> 0): s(x) = 3x^2 - 2x^3, x = u / width clamped to [0, 1]
double smoothRise(double u, double width) {
  const double x = std::clamp(u / width, 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);
}

}  // namespace

void validateBreathStyle(const BreathStyle& s) {
  const std::string p = "breath style '" + excerptOf(s.name) + "': ";
  kBreathRateRange.check(p + "breaths_per_minute", s.breathsPerMinute);
  requireRange(p + "inhale_fraction", s.inhaleFraction, 0.0, 0.999, true);
  requireRange(p + "diaphragm_r", s.diaphragmR, 0.0, 1.5, true);
  requireRange(p + "diaphragm_alpha", s.diaphragmAlpha, 0.0, 1.0, true);
  requireRange(p + "drive_decay_fraction", s.driveDecayFraction, 0.0, 1.0, true);
  requireRange(p + "expiratory_rise_fraction", s.expiratoryRiseFraction, 0.0, 1.0, true);
  requireRange(p + "expiratory_fall_fraction", s.expiratoryFallFraction, 0.0, 1.0, true);
  requireRange(p + "expiratory_rise_fraction + expiratory_fall_fraction",
               s.expiratoryRiseFraction + s.expiratoryFallFraction, 0.0, 1.0, true);
  requireRange(p + "internal_intercostal_alpha", s.internalIntercostalAlpha, 0.0, 1.0, false);
  requireRange(p + "intercostal_alpha", s.intercostalAlpha, 0.0, 1.0, true);
  requireRange(p + "intercostal_amplitude", s.intercostalAmplitude, 0.0, 1.5, false);
  requireRange(p + "intercostal_mean - intercostal_amplitude", s.intercostalMean - s.intercostalAmplitude,
               0.0, 1.5, true);
  requireRange(p + "intercostal_mean + intercostal_amplitude", s.intercostalMean + s.intercostalAmplitude,
               0.0, 1.5, true);
  requireRange(p + "rectus_r", s.rectusR, 0.0, 1.5, true);
  requireRange(p + "intercostal_lead_s", s.intercostalLead, 0.0, 0.5 * 60.0 / s.breathsPerMinute, false);
  if (s.cycles < 0) throw Error(p + "cycles: must be >= 0, got " + std::to_string(s.cycles));
}

BreathStyle parseBreathStyle(const std::string& jsonText, const std::string& source) {
  const JsonDocument doc = JsonDocument::parse(jsonText, source);
  const JsonReader j = doc.root();
  j.allowKeys({"name", "note", "breaths_per_minute", "inhale_fraction", "diaphragm_r", "diaphragm_alpha",
               "drive_decay_fraction", "expiratory_rise_fraction", "expiratory_fall_fraction",
               "intercostal_mean", "intercostal_amplitude", "intercostal_alpha", "internal_intercostal_alpha",
               "intercostal_lead_s", "rectus_r", "rectus_active", "cycles"});
  BreathStyle s;
  // required fields, then optional ones that keep their defaults when absent
  s.name = j.at("name").string();
  s.note = j.stringOr("note", s.note);
  s.breathsPerMinute = j.at("breaths_per_minute").number();
  s.diaphragmR = j.at("diaphragm_r").number();
  s.intercostalMean = j.at("intercostal_mean").number();
  s.intercostalAmplitude = j.at("intercostal_amplitude").number();
  s.inhaleFraction = j.numberOr("inhale_fraction", s.inhaleFraction);
  s.diaphragmAlpha = j.numberOr("diaphragm_alpha", s.diaphragmAlpha);
  s.driveDecayFraction = j.numberOr("drive_decay_fraction", s.driveDecayFraction);
  s.expiratoryRiseFraction = j.numberOr("expiratory_rise_fraction", s.expiratoryRiseFraction);
  s.expiratoryFallFraction = j.numberOr("expiratory_fall_fraction", s.expiratoryFallFraction);
  s.intercostalAlpha = j.numberOr("intercostal_alpha", s.intercostalAlpha);
  s.internalIntercostalAlpha = j.numberOr("internal_intercostal_alpha", s.internalIntercostalAlpha);
  s.intercostalLead = j.numberOr("intercostal_lead_s", s.intercostalLead);
  s.rectusR = j.numberOr("rectus_r", s.rectusR);
  if (j.has("rectus_active")) s.rectusActive = j.at("rectus_active").boolean();
  if (j.has("cycles"))
    s.cycles = static_cast<int>(j.at("cycles").integerIn(0, std::numeric_limits<int>::max()));
  try {
    validateBreathStyle(s);
  } catch (const Error& e) {
    throw Error(source + ": " + e.what());
  }
  return s;
}

std::string serializeBreathStyle(const BreathStyle& s) {
  const nlohmann::json j = {{"name", s.name},
                            {"note", s.note},
                            {"breaths_per_minute", s.breathsPerMinute},
                            {"inhale_fraction", s.inhaleFraction},
                            {"diaphragm_r", s.diaphragmR},
                            {"diaphragm_alpha", s.diaphragmAlpha},
                            {"drive_decay_fraction", s.driveDecayFraction},
                            {"expiratory_rise_fraction", s.expiratoryRiseFraction},
                            {"expiratory_fall_fraction", s.expiratoryFallFraction},
                            {"intercostal_mean", s.intercostalMean},
                            {"intercostal_amplitude", s.intercostalAmplitude},
                            {"intercostal_alpha", s.intercostalAlpha},
                            {"internal_intercostal_alpha", s.internalIntercostalAlpha},
                            {"intercostal_lead_s", s.intercostalLead},
                            {"rectus_active", s.rectusActive},
                            {"rectus_r", s.rectusR},
                            {"cycles", s.cycles}};
  return j.dump(2) + "\n";
}

std::string defaultPresetDir() { return resourceDir() + "/presets"; }

std::vector<std::string> breathStyleNames(const std::string& presetDir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(presetDir, ec)) {
    if (entry.is_regular_file() && entry.path().extension() == ".json")
      names.push_back(entry.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

BreathStyle loadBreathStyle(const std::string& nameOrPath, const std::string& presetDir) {
  const bool isPath = nameOrPath.size() > 5 && nameOrPath.substr(nameOrPath.size() - 5) == ".json";
  const std::string path = isPath ? nameOrPath : presetDir + "/" + nameOrPath + ".json";
  if (!isPath && !std::filesystem::exists(path)) {
    std::string valid;
    for (const std::string& n : breathStyleNames(presetDir)) valid += (valid.empty() ? "" : ", ") + n;
    throw Error("unknown breath style '" + excerptOf(nameOrPath) +
                "'; valid: " + (valid.empty() ? "(none in " + presetDir + ")" : valid));
  }
  return parseBreathStyle(readInputFile(path), path);
}

BreathStyleController::BreathStyleController(BreathStyle style) : m_style(std::move(style)) {
  validateBreathStyle(m_style);
}

double inspiratoryDrive(const BreathStyle& s, double phase) {
  if (phase < s.inhaleFraction) return 0.5 * (1.0 - std::cos(kPi * phase / s.inhaleFraction));
  const double x = (phase - s.inhaleFraction) / ((1.0 - s.inhaleFraction) * s.driveDecayFraction);
  return 1.0 - smoothRise(x, 1.0);
}

double expiratoryDrive(const BreathStyle& s, double phase) {
  if (phase < s.inhaleFraction) return 0.0;
  const double x = (phase - s.inhaleFraction) / (1.0 - s.inhaleFraction);  // [-] 0 to 1 over the exhale
  const double fall = s.expiratoryFallFraction;
  return smoothRise(x, s.expiratoryRiseFraction) * (1.0 - smoothRise(x - 1.0 + fall, fall));
}

Activations BreathStyleController::activations(double t, const Metrics& /*latest*/) {
  const BreathStyle& s = m_style;
  const double period = 60.0 / s.breathsPerMinute;  // [s]
  // after a finite number of cycles, hold the cycle-start posture
  const double tc = (s.cycles > 0 && t >= s.cycles * period) ? 0.0 : std::max(t, 0.0);
  const double phase = std::fmod(tc, period) / period;  // [-] 0 = start of inhale
  // the cycle-start posture itself (settling, holds) is the relaxed end of an exhale: every muscle off
  const bool isRest = tc == 0.0;
  const double in = isRest ? 0.0 : inspiratoryDrive(s, phase);
  const double out = isRest ? 0.0 : expiratoryDrive(s, phase);
  Activations a = relaxedActivations();
  // inspiratory muscles: diaphragm and external intercostals share the inspiratory drive
  slot(a, ElementGroup::Diaphragm) =
      in > 0.0 ? GroupActivation{s.diaphragmR, in * s.diaphragmAlpha} : GroupActivation{1.0, 0.0};
  const double ric =
      s.intercostalMean - s.intercostalAmplitude;  // [-] Table 2's deepest intercostal contraction
  // their drive runs intercostalLead ahead, so the rib cage, slowed by the rib friction, moves with the belly
  const double inLead =
      isRest ? 0.0 : inspiratoryDrive(s, std::fmod(phase + s.intercostalLead / period, 1.0));
  slot(a, ElementGroup::IntercostalExternal) = {ric, inLead * s.intercostalAlpha};
  // expiratory muscles: internal intercostals and rectus on the expiratory drive (quiet breathing: none)
  slot(a, ElementGroup::IntercostalInternal) = {ric, out * s.internalIntercostalAlpha};
  if (s.rectusActive) slot(a, ElementGroup::Rectus) = {s.rectusR, out};
  return a;
}

std::string BreathStyleController::describe() const {
  std::ostringstream os;
  os << "breath style '" << m_style.name << "' (" << m_style.breathsPerMinute << " b/m"
     << (m_style.cycles > 0 ? ", " + std::to_string(m_style.cycles) + " cycle(s)" : std::string()) << ")";
  return os.str();
}

std::unique_ptr<Controller> BreathStyleController::clone() const {
  return std::make_unique<BreathStyleController>(*this);
}

}  // namespace pneuma::sim
