#include "viz/RunSummary.h"

#include <cmath>
#include <cstdio>

namespace pneuma::viz {

std::string formatNumber(double v) {
  if (!std::isfinite(v)) return "";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

nlohmann::json jsonNumber(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

void writeMotion(const sim::Motion& m, nlohmann::json& j) {
  constexpr double kMm = 1e3, kMl = 1e6;
  j["dome_descent_mm"] = jsonNumber(m.domeDescent * kMm);
  j["dome_anterior_mm"] = jsonNumber(m.domeAnterior * kMm);
  j["sternum_anterior_mm"] = jsonNumber(m.sternumAnterior * kMm);
  j["sternum_cranial_mm"] = jsonNumber(m.sternumCranial * kMm);
  j["xiphoid_anterior_mm"] = jsonNumber(m.xiphoidAnterior * kMm);
  j["xiphoid_cranial_mm"] = jsonNumber(m.xiphoidCranial * kMm);
  j["lower_rib_expansion_mm"] = jsonNumber(m.lowerRibExpansion * kMm);
  // only a model with a shoulder girdle has acromions
  if (std::isfinite(m.acromionCranial)) j["acromion_cranial_mm"] = m.acromionCranial * kMm;
  j["umbilicus_anterior_mm"] = jsonNumber(m.umbilicusAnterior * kMm);
  j["umbilicus_anterior_min_mm"] = jsonNumber(m.umbilicusAnteriorMin * kMm);
  j["rib_cage_tidal_ml"] = jsonNumber(m.ribCageTidal * kMl);
  j["abdomen_tidal_ml"] = jsonNumber(m.abdomenTidal * kMl);
  j["rib_cage_fraction"] = jsonNumber(m.ribCageShare());
  j["rc_ab_phase_deg"] = jsonNumber(m.phaseAngle * 180.0 / M_PI);
  j["flow_sign_changes_per_breath"] = jsonNumber(m.flowSignChanges);
  j["max_flow_jump_pct"] = jsonNumber(m.maxFlowJump * 100.0);
}

nlohmann::json runSummary(const sim::Model& model, const sim::Scenario& scenario,
                          const sim::Simulation* simulation, const RunStatus& status) {
  const sim::Summary sum = simulation ? simulation->summary() : sim::Summary{};
  const nlohmann::json none(nullptr);
  nlohmann::json j;
  j["pneuma_version"] = PNEUMA_VERSION;
  j["model"] = status.modelDir;
  j["model_name"] = model.name;
  j["scenario"] = scenario.name;
  j["controller"] = status.controllerText;
  j["controller_kind"] = sim::controllerKindName(scenario.controller);
  j["integrator"] = sim::integratorName(scenario.options.step.integrator);
  j["posture"] = sim::postureName(scenario.options.step.posture);
  j["dt_s"] = simulation ? nlohmann::json(simulation->dt()) : none;
  j["steps"] = sum.steps;
  j["seed"] = scenario.seed;
  j["settle_time_s"] = scenario.options.settleTime;
  j["duration_s"] = scenario.duration;
  j["simulated_time_s"] = simulation ? simulation->state().time : 0.0;
  j["partial"] = status.isInterrupted || !status.error.empty();
  j["interrupted"] = status.isInterrupted;
  j["error"] = status.error.empty() ? none : nlohmann::json(status.error);
  const bool ran = simulation && status.frames > 0;
  const bool breathed = ran && sum.cycles > 0;  // the breath figures exist only when a full breath was found
  j["real_time_factor"] = ran ? jsonNumber(sum.realTimeFactor) : none;
  j["tidal_volume_ml"] = breathed ? jsonNumber(sum.tidalVolume * 1e6) : none;
  j["breaths_per_minute"] = breathed ? jsonNumber(sum.breathsPerMinute) : none;
  j["cycles"] = sum.cycles;
  j["end_expiratory_volume_ml"] = breathed ? jsonNumber(sum.endExpiratoryVolume * 1e6) : none;
  j["end_inspiratory_volume_ml"] = breathed ? jsonNumber(sum.endInspiratoryVolume * 1e6) : none;
  // the lungs' parts at end-expiration: the right/left split of the latest frame, the constant mediastinum
  const sim::Metrics* latest = ran ? &simulation->latestMetrics() : nullptr;
  const double rightShare = latest != nullptr ? latest->rightLungVolume / latest->lungVolume : sim::kNaN;
  j["end_expiratory_right_lung_volume_ml"] =
      breathed ? jsonNumber(sum.endExpiratoryVolume * rightShare * 1e6) : none;
  j["end_expiratory_left_lung_volume_ml"] =
      breathed ? jsonNumber(sum.endExpiratoryVolume * (1.0 - rightShare) * 1e6) : none;
  j["end_expiratory_thoracic_cavity_volume_ml"] =
      breathed ? jsonNumber((sum.endExpiratoryVolume + model.lungs.mediastinumVolume) * 1e6) : none;
  j["max_gut_volume_error_pct"] = ran ? jsonNumber(sum.maxGutVolumeError * 100.0) : none;
  j["mean_gut_volume_error_pct"] = ran ? jsonNumber(sum.meanGutVolumeError * 100.0) : none;
  writeMotion(sum.motion, j);
  j["tracking_rms_pct"] = simulation && simulation->controller().tracksVolume()
                              ? jsonNumber(simulation->controller().trackingRmsPercent())
                              : none;
  j["morph_blend_rms_mm"] = jsonNumber(status.morphBlendRms * 1e3);
  j["morph_blend_max_mm"] = jsonNumber(status.morphBlendMax * 1e3);
  j["measured_from_s"] = sum.measuredFrom;
  j["frames"] = status.frames;
  j["files"] = status.files;
  return j;
}

}  // namespace pneuma::viz
