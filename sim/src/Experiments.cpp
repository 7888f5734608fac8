#include "pneuma/sim/Experiments.h"

#include "pneuma/sim/Error.h"
#include "pneuma/sim/State.h"
#include "pneuma/sim/Step.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

namespace pneuma::sim {

namespace {

constexpr double kMl = 1e6;   // [mL/m^3]
constexpr double kMm = 1e3;   // [mm/m]
constexpr double kPct = 1e2;  // [%/1]
const char* const kZordan = "Zordan et al. 2004";

std::string fmt(const char* format, double a, double b = 0.0) {
  char buf[128];
  std::snprintf(buf, sizeof buf, format, a, b);
  return buf;
}

Check check(std::string id, std::string what, std::string target, std::string source, std::string unit, double measured,
            double lower, double upper) {
  Check c;
  c.id = std::move(id);
  c.what = std::move(what);
  c.target = std::move(target);
  c.source = std::move(source);
  c.unit = std::move(unit);
  c.measured = measured;
  c.lower = lower;
  c.upper = upper;
  return c;
}

// frames of `trace` from time `from` on: [first index, size)
std::size_t firstFrame(const Trace& trace, double from) {
  return static_cast<std::size_t>(std::lower_bound(trace.time.begin(), trace.time.end(), from) - trace.time.begin());
}

double pearson(const std::vector<double>& a, const std::vector<double>& b) {
  const double n = static_cast<double>(a.size());
  if (a.size() < 2) return 0.0;
  double ma = 0.0, mb = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) ma += a[i] / n, mb += b[i] / n;
  double sab = 0.0, saa = 0.0, sbb = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return saa > 0.0 && sbb > 0.0 ? sab / std::sqrt(saa * sbb) : 0.0;
}

}  // namespace

ExperimentSettings quickExperimentSettings() {
  ExperimentSettings s;
  s.simulation.settleTime = 1.0;
  s.simulation.outputRate = 30.0;
  s.styleDuration = 10.0;
  s.forcedExhaleDuration = 7.0;
  s.impactDuration = 0.6;
  s.swayDuration = 6.0;
  return s;
}

StyleRun runBreathStyle(std::shared_ptr<const Model> model, const BreathStyle& style, const ExperimentSettings& settings) {
  StyleRun run;
  run.style = style;
  run.settleTime = settings.simulation.settleTime;
  Simulation sim(std::move(model), std::make_unique<BreathStyleController>(style), settings.simulation);
  sim.advance(settings.simulation.settleTime + (style.cycles > 0 ? settings.forcedExhaleDuration : settings.styleDuration));
  run.summary = sim.summary();
  run.trace = sim.trace();
  return run;
}

std::vector<Check> breathStyleChecks(const std::vector<StyleRun>& runs) {
  std::map<std::string, const StyleRun*> byName;
  for (const StyleRun& r : runs) byName[r.style.name] = &r;
  auto find = [&](const char* name) { return byName.count(name) ? byName[name] : nullptr; };
  const StyleRun* calm = find("calm");
  const StyleRun* deep = find("deep");
  const StyleRun* panting = find("panting");
  const StyleRun* forced = find("forced-exhale");
  const std::string fig6 = std::string(kZordan) + ", Sec. 8.1, Fig. 6";
  const std::string table2 = std::string(kZordan) + ", Sec. 8.1, Table 2";
  std::vector<Check> out;

  // Figure 6: calm tidal volume on the 500 mL textbook average
  if (calm)
    out.push_back(check("calm.tidal_volume", "tidal volume, calm breathing", "500 mL +/- 20 %", fig6, "mL",
                        calm->summary.tidalVolume * kMl, 400.0, 600.0));

  // Table 2: the rate each periodic style is driven at shows in the volume signal
  for (const StyleRun* r : {calm, deep, panting}) {
    if (!r) continue;
    const double bpm = r->style.breathsPerMinute;
    out.push_back(check(r->style.name + ".rate", "breathing rate, " + r->style.name, fmt("%.0f b/m +/- 10 %%", bpm), table2,
                        "b/m", r->summary.breathsPerMinute, 0.9 * bpm, 1.1 * bpm));
  }

  // Figure 6 and Section 8.1: deep reaches further than calm, panting is shallower; all in the human range
  if (calm && deep)
    out.push_back(check("deep.tidal_ratio", "tidal volume deep / calm", ">= 1.5 (deep belly breath, full range)",
                        std::string(kZordan) + ", Sec. 8.1 'Slow deep breath', Fig. 6", "-",
                        deep->summary.tidalVolume / std::max(calm->summary.tidalVolume, 1e-12), 1.5, 1e9));
  if (calm && panting)
    out.push_back(check("panting.tidal_ratio", "tidal volume panting / calm", "< 1 (small rapid breaths)",
                        std::string(kZordan) + ", Sec. 8.1 'Panting breathing', Fig. 6", "-",
                        panting->summary.tidalVolume / std::max(calm->summary.tidalVolume, 1e-12), 0.0, 1.0));
  for (const StyleRun* r : {calm, deep, panting})
    if (r)
      out.push_back(check(r->style.name + ".tidal_range", "tidal volume, " + r->style.name,
                          "50 - 4800 mL (human range: dead space to vital capacity)", fig6 + " caption", "mL",
                          r->summary.tidalVolume * kMl, 50.0, 4800.0));

  // forced exhale: below calm end-expiration, abdomen pulled in by the rectus (Figure 5)
  if (forced && calm) {
    const std::size_t i0 = firstFrame(forced->trace, forced->settleTime);
    double vMin = forced->trace.lungVolume.empty() ? 0.0 : forced->trace.lungVolume[i0];
    for (std::size_t i = i0; i < forced->trace.size(); ++i) vMin = std::min(vMin, forced->trace.lungVolume[i]);
    out.push_back(check("forced-exhale.below_calm", "calm end-expiratory volume minus forced-exhale minimum",
                        "> 0 mL (empties beyond quiet expiration)", std::string(kZordan) + ", Sec. 8.1 'Forced exhale'",
                        "mL", (calm->summary.endExpiratoryVolume - vMin) * kMl, 0.0, 1e9));
  }
  if (forced) {
    out.push_back(check("forced-exhale.umbilicus", "umbilicus displacement range, forced exhale", ">= 10 mm",
                        std::string(kZordan) + ", Sec. 8.1, Fig. 5", "mm", forced->summary.umbilicusExcursion * kMm, 10.0,
                        1e9));
  }

  // Figure 4 caption / Section 6.2: tolerable gut volume error while breathing
  for (const StyleRun* r : {calm, deep, panting, forced})
    if (r)
      out.push_back(check(r->style.name + ".gut_volume_error", "max gut volume error, " + r->style.name, "< 2 %",
                          std::string(kZordan) + ", Sec. 6.2, Fig. 4 caption", "%", r->summary.maxGutVolumeError * kPct,
                          0.0, 2.0));
  return out;
}

ImpactRun runHeavyImpact(std::shared_ptr<const Model> modelPtr, const ExperimentSettings& settings) {
  const Model& model = *modelPtr;
  const SimulationOptions& o = settings.simulation;
  validateSimulationOptions(o);
  const double dt = o.dt > 0.0 ? o.dt : defaultTimeStep(o.step.integrator);
  State state = makeInitialState(model);
  StepWork work = makeStepWork(model);
  const Activations relaxed = relaxedActivations();
  Metrics metrics;

  // settle the relaxed torso
  const long long settleSteps = static_cast<long long>(std::llround(o.settleTime / dt));
  for (long long k = 0; k < settleSteps; ++k) {
    step(model, state, dt, relaxed, o.step, work);
    checkState(model, state, work, dt);
  }

  // the blow: anterior wall nodes move inward (posterior, -y)
  double meanY = 0.0;
  int wallCount = 0;
  for (int n = 0; n < model.nodes.size(); ++n)
    if (model.nodes.region[static_cast<std::size_t>(n)] == NodeRegion::Wall) meanY += model.nodes.rest(1, n), ++wallCount;
  if (wallCount == 0) throw Error("heavy impact: the model has no abdominal wall nodes");
  meanY /= wallCount;
  const Eigen::Matrix3Xd before = state.nodePosition;
  for (int n = 0; n < model.nodes.size(); ++n)
    if (model.nodes.region[static_cast<std::size_t>(n)] == NodeRegion::Wall && model.nodes.rest(1, n) > meanY)
      state.nodeVelocity(1, n) -= settings.impactSpeed;

  // follow the deformation, measuring at the output rate
  ImpactRun run;
  const double t0 = state.time;
  const long long steps = static_cast<long long>(std::llround(settings.impactDuration / dt));
  const long long every = std::max(1LL, static_cast<long long>(std::llround(1.0 / (o.outputRate * dt))));
  for (long long k = 1; k <= steps; ++k) {
    step(model, state, dt, relaxed, o.step, work);
    checkState(model, state, work, dt);
    if (k % every != 0) continue;
    computeMetrics(model, state, relaxed, o.step, work, metrics);
    metrics.time = state.time - t0;
    run.trace.append(metrics);
    run.maxVolumeError = std::max(run.maxVolumeError, std::abs(metrics.gutVolumeError));
    run.maxWallDisplacement = std::max(run.maxWallDisplacement, (state.nodePosition - before).colwise().norm().maxCoeff());
  }
  return run;
}

std::vector<Check> impactChecks(const ImpactRun& run) {
  const std::string fig4 = std::string(kZordan) + ", Sec. 6.2, Fig. 4";
  return {check("impact.gut_volume_error", "max gut volume error after a heavy impact", "< 0.5 %", fig4, "%",
                run.maxVolumeError * kPct, 0.0, 0.5),
          check("impact.deformation", "largest abdominal-wall displacement after the impact",
                ">= 5 mm (the gut visibly deforms)", fig4, "mm", run.maxWallDisplacement * kMm, 5.0, 1e9)};
}

SwayRun runSpineSway(std::shared_ptr<const Model> model, const BreathStyle& deep, double frictionScale,
                     const ExperimentSettings& settings) {
  // the highest moving thoracic body
  int spine = -1;
  for (int b = 0; b < model->bodies.size(); ++b) {
    const std::string& name = model->bodies.name[static_cast<std::size_t>(b)];
    if (name.rfind("thoracic", 0) != 0 || model->bodies.isFixed[static_cast<std::size_t>(b)]) continue;
    if (spine < 0 || model->bodies.com(2, b) > model->bodies.com(2, spine)) spine = b;
  }
  if (spine < 0) throw Error("spine sway: the model has no moving body named thoracic*");

  SwayRun run;
  run.frictionScale = frictionScale;
  run.spineBody = model->bodies.name[static_cast<std::size_t>(spine)];
  SimulationOptions options = settings.simulation;
  options.step.jointFrictionScale *= frictionScale;
  Simulation sim(std::move(model), std::make_unique<BreathStyleController>(deep), options);
  sim.advance(options.settleTime);
  const double y0 = sim.state().bodyPosition(1, spine);
  sim.advance(settings.swayDuration, [&](const Simulation& s) {
    run.time.push_back(s.state().time);
    run.spineY.push_back(s.state().bodyPosition(1, spine) - y0);
    run.lungVolume.push_back(s.latestMetrics().lungVolume);
    return true;
  });
  if (!run.spineY.empty()) {
    const auto [lo, hi] = std::minmax_element(run.spineY.begin(), run.spineY.end());
    run.sway = *hi - *lo;
  }
  run.correlation = pearson(run.spineY, run.lungVolume);
  return run;
}

std::vector<Check> swayChecks(const SwayRun& withFriction, const SwayRun& frictionless) {
  const std::string sec5 = std::string(kZordan) + ", Sec. 5, Eq. 3";
  return {check("sway.amplitude", "spine sway (" + withFriction.spineBody + " anterior-posterior range), deep breathing with joint friction",
                ">= 0.5 mm", sec5, "mm", withFriction.sway * kMm, 0.5, 1e9),
          check("sway.direction", "correlation of spine anterior position with lung volume, with friction",
                "<= -0.3 (spine moves backward on inhale)", sec5, "-", withFriction.correlation, -1.0, -0.3),
          check("sway.friction_ratio", "spine sway with friction / without friction", ">= 2 (friction couples ribs and spine)",
                sec5, "-", withFriction.sway / std::max(frictionless.sway, 1e-9), 2.0, 1e12)};
}

}  // namespace pneuma::sim
