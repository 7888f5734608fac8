/// @file MorphTargets.cpp
/// Baking breathing morph targets from physics runs, fitting skins onto them, and de Melo's pattern-to-weight
/// mapping (MorphTargets.h).

#include "pneuma/sim/MorphTargets.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>

#include "pneuma/sim/Error.h"
#include "pneuma/sim/PosedGeometry.h"
#include "pneuma/sim/Scenario.h"
#include "pneuma/sim/Simulation.h"
#include "pneuma/sim/pattern/PatternController.h"

namespace pneuma::sim {

namespace {

constexpr int kCalibrationStride = 6;  // keep every 6th deep-run frame (10 Hz) for the calibration

/// The skins at the smallest and largest lung volume of one run, from `skip` seconds after settling on.
struct RunExtremes {
  Eigen::Matrix3Xd minSkin, maxSkin;                            // [m] (3 x #V)
  double minVolume = std::numeric_limits<double>::infinity();   // [m^3]
  double maxVolume = -std::numeric_limits<double>::infinity();  // [m^3]
  double restVolume = 0.0;                                      // [m^3] lung volume at the end of settling
  double ribCageShare = 0.0;                                    // [-]
  std::vector<double> sampleVolume;                             // [m^3] kept frames
  std::vector<Eigen::Matrix3Xd> sampleSkin;                     // [m] kept frames (3 x #V)
};

RunExtremes runStyle(const std::shared_ptr<const Model>& model, const std::string& resourceDir,
                     const std::string& style, Posture posture, double duration, double skip,
                     bool keepSamples, const BakeProgress& progress, const std::atomic<bool>* stop) {
  Scenario scenario;
  scenario.controller = ControllerKind::Style;
  scenario.controllerName = style;
  scenario.options.step.posture = posture;
  scenario.options.recordSeconds = kTraceOnlyRecordSeconds;
  Simulation sim(model, makeController(scenario, model, resourceDir, stop), scenario.options);
  sim.setStopFlag(stop);
  const std::string stage =
      posture == Posture::Upright ? style : std::string(postureName(posture)) + " " + style;
  const double settle = scenario.options.settleTime;  // [s]
  const double total = settle + duration;             // [s]

  RunExtremes run;
  PosedGeometry posed;
  long long frame = 0;
  sim.advance(total, [&](const Simulation& s) {
    const double t = s.state().time;                     // [s]
    const double volume = s.latestMetrics().lungVolume;  // [m^3]
    if (t <= settle) run.restVolume = volume;
    if (t >= settle + skip) {
      const bool isMin = volume<run.minVolume, isMax = volume> run.maxVolume;
      const bool isSample = keepSamples && frame % kCalibrationStride == 0;
      if (isMin || isMax || isSample) poseGeometry(*model, s.state(), posed);
      if (isMin) run.minVolume = volume, run.minSkin = posed.skin;
      if (isMax) run.maxVolume = volume, run.maxSkin = posed.skin;
      if (isSample) run.sampleVolume.push_back(volume), run.sampleSkin.push_back(posed.skin);
      ++frame;
    }
    if (progress) progress(stage, t / total);
    return true;
  });
  if (sim.wasStopped()) throw Interrupted("bake stopped by request during the " + stage + " run");
  run.ribCageShare = sim.summary().motion.ribCageShare();
  if (!(run.maxVolume > run.minVolume) || !std::isfinite(run.ribCageShare))
    throw Error("bake: the " + stage + " run did not breathe (no tidal volume)");
  return run;
}

}  // namespace

MorphTargets bakeMorphTargets(std::shared_ptr<const Model> model, const std::string& resourceDir,
                              const BakeProgress& progress, const std::atomic<bool>* stop) {
  if (model->skin.vertexCount() == 0)
    throw Error("model '" + model->name + "' has no skin: rebuild it with pneuma-cli model build");

  // three runs, two breaths each (deep 12 b/m, panting 60 b/m); the deep run's minimum includes the relaxed
  // torso at the end of settling (the deep style breathes out to about 0.4 L above it), the others skip the
  // first second so that their extremes are one breath's
  const RunExtremes deep =
      runStyle(model, resourceDir, "deep", Posture::Upright, 10.0, 0.0, true, progress, stop);
  const RunExtremes pant =
      runStyle(model, resourceDir, "panting", Posture::Upright, 3.0, 1.0, false, progress, stop);
  const RunExtremes supine =
      runStyle(model, resourceDir, "deep", Posture::Supine, 10.0, 1.0, false, progress, stop);

  // the shapes: every target is the displacement of a breath as large as the deep one
  MorphTargets m;
  m.base = deep.minSkin;
  m.restVolume = deep.restVolume;
  m.baseVolume = deep.minVolume;
  m.targetVolume = deep.maxVolume;
  const double tidal = deep.maxVolume - deep.minVolume;  // [m^3]
  auto target = [&](const std::string& name, const RunExtremes& r) {
    const double scale = tidal / (r.maxVolume - r.minVolume);
    return MorphTarget{name, (r.maxSkin - r.minSkin) * scale, std::clamp(r.ribCageShare, 0.0, 1.0)};
  };
  m.targets.push_back(
      MorphTarget{"breathing", deep.maxSkin - deep.minSkin, std::clamp(deep.ribCageShare, 0.0, 1.0)});
  m.targets.push_back(target("chest", pant));
  m.targets.push_back(target("belly", supine));

  // volume-to-shape calibration: summed fitted weight against the volume above the base, through the origin
  const MorphFit fit(m);
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t i = 0; i < deep.sampleSkin.size(); ++i) {
    const double x = deep.sampleVolume[i] - m.baseVolume;  // [m^3]
    sxy += x * fit.weights(deep.sampleSkin[i]).sum();
    sxx += x * x;
  }
  m.weightPerVolume = sxx > 0.0 ? sxy / sxx : 1.0 / tidal;
  return m;
}

MorphFit::MorphFit(const MorphTargets& targets) : m_base(targets.base) {
  const Eigen::Index n = 3 * targets.base.cols();
  const Eigen::Index k = static_cast<Eigen::Index>(targets.targets.size());
  m_basis.resize(n, k);
  for (Eigen::Index j = 0; j < k; ++j)
    m_basis.col(j) = targets.targets[static_cast<std::size_t>(j)].displacement.reshaped();
  m_normal = (m_basis.transpose() * m_basis).ldlt().solve(Eigen::MatrixXd::Identity(k, k));
}

Eigen::VectorXd MorphFit::weights(const Eigen::Matrix3Xd& skin) const {
  const Eigen::VectorXd d = (skin - m_base).reshaped();
  return m_normal * (m_basis.transpose() * d);
}

Eigen::Matrix3Xd MorphFit::blend(const Eigen::VectorXd& weights) const {
  const Eigen::VectorXd x = m_base.reshaped() + m_basis * weights;
  return x.reshaped(3, m_base.cols());
}

BlendError MorphFit::error(const Eigen::Matrix3Xd& skin) const {
  const Eigen::VectorXd distance = (skin - blend(weights(skin))).colwise().norm().transpose();
  if (distance.size() == 0) return {};
  return {std::sqrt(distance.squaredNorm() / static_cast<double>(distance.size())), distance.maxCoeff()};
}

Eigen::VectorXd patternWeights(const MorphTargets& targets, double fraction, double balance) {
  const std::size_t k = targets.targets.size();
  Eigen::VectorXd w = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(k));
  if (k == 0) return w;
  const double volume = targets.restVolume + (fraction - 0.05) * targets.volumePerFraction;  // [m^3]
  const double a = std::max(0.0, targets.weightPerVolume * (volume - targets.baseVolume));

  // the shapes in order of their rib-cage share; the two enclosing the balance share the amplitude
  std::vector<std::size_t> order(k);
  for (std::size_t i = 0; i < k; ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t p, std::size_t q) {
    return targets.targets[p].ribCageShare < targets.targets[q].ribCageShare;
  });
  auto share = [&](std::size_t i) { return targets.targets[order[i]].ribCageShare; };
  if (balance <= share(0)) {
    w(static_cast<Eigen::Index>(order[0])) = a;
    return w;
  }
  for (std::size_t i = 0; i + 1 < k; ++i) {
    if (balance <= share(i + 1)) {
      const double span = share(i + 1) - share(i);
      const double t = span > 0.0 ? (balance - share(i)) / span : 1.0;
      w(static_cast<Eigen::Index>(order[i])) += a * (1.0 - t);
      w(static_cast<Eigen::Index>(order[i + 1])) += a * t;
      return w;
    }
  }
  w(static_cast<Eigen::Index>(order[k - 1])) = a;
  return w;
}

MorphPlayer::MorphPlayer(const pattern::Pattern& pattern, std::uint64_t seed)
    : m_stack(pattern::makeLayerStack(pattern, seed)) {
  m_stack.setStartVolume(0.05);
}

Eigen::VectorXd MorphPlayer::weightsAt(const MorphTargets& targets, double t) {
  const double v = m_stack.sample(t);                                          // throws when t decreases
  const double tau = pattern::PatternControllerOptions{}.balanceTimeConstant;  // [s]
  m_balance = m_time < 0.0
                  ? m_stack.balance()
                  : m_balance + (m_stack.balance() - m_balance) * (1.0 - std::exp(-(t - m_time) / tau));
  m_time = t;
  return patternWeights(targets, v, m_balance);
}

}  // namespace pneuma::sim
