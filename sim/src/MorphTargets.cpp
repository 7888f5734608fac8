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
#include "pneuma/sim/Ties.h"
#include "pneuma/sim/pattern/PatternController.h"

namespace pneuma::sim {

namespace {

constexpr int kCalibrationStride = 6;  // keep every 6th deep-run frame (10 Hz) for the calibration

/// The skins at the smallest and largest lung volume of one run, from `skip` seconds after settling on.
struct RunExtremes {
  Eigen::Matrix3Xd minSkin, maxSkin;                            // [m] (3 x #V)
  std::vector<Eigen::Isometry3d> minBones, maxBones;            // body -> world (#B)
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
      if (isMin) run.minVolume = volume, run.minSkin = posed.skin, run.minBones = posed.body;
      if (isMax) run.maxVolume = volume, run.maxSkin = posed.skin, run.maxBones = posed.body;
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

/// The quaternion of a pose, on the side of `reference` (q . reference >= 0).
Eigen::Quaterniond rotationOf(const Eigen::Isometry3d& pose, const Eigen::Quaterniond& reference) {
  Eigen::Quaterniond q(pose.linear());
  q.normalize();
  if (q.dot(reference) < 0.0) q.coeffs() = -q.coeffs();
  return q;
}

/// The bones of a target: the run's motion from its minimum to its maximum, `scale` times, added to `base`:
/// translations scaled linearly, rotations in angle about the same axis (r^scale, r = q_max q_min^-1).
BonePoses boneDisplacement(const BonePoses& base, const RunExtremes& r, double scale) {
  const Eigen::Index n = base.size();
  BonePoses d{Eigen::Matrix3Xd(3, n), Eigen::Matrix4Xd(4, n)};
  for (Eigen::Index b = 0; b < n; ++b) {
    const auto i = static_cast<std::size_t>(b);
    const Eigen::Quaterniond q0(base.rotation.col(b));
    d.translation.col(b) = (r.maxBones[i].translation() - r.minBones[i].translation()) * scale;
    const Eigen::AngleAxisd turn(rotationOf(r.maxBones[i], Eigen::Quaterniond::Identity()) *
                                 rotationOf(r.minBones[i], Eigen::Quaterniond::Identity()).conjugate());
    Eigen::Quaterniond q = Eigen::Quaterniond(Eigen::AngleAxisd(scale * turn.angle(), turn.axis())) * q0;
    if (q.dot(q0) < 0.0) q.coeffs() = -q.coeffs();
    d.rotation.col(b) = q.coeffs() - q0.coeffs();
  }
  return d;
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
  // the bones at the base: the deep run's at its smallest volume
  m.bones = model->bodies.name;
  const Eigen::Index bodies = model->bodies.size();
  m.boneBase = {Eigen::Matrix3Xd(3, bodies), Eigen::Matrix4Xd(4, bodies)};
  for (Eigen::Index b = 0; b < bodies; ++b) {
    const Eigen::Isometry3d& pose = deep.minBones[static_cast<std::size_t>(b)];
    m.boneBase.translation.col(b) = pose.translation();
    m.boneBase.rotation.col(b) = rotationOf(pose, Eigen::Quaterniond::Identity()).coeffs();
  }
  auto target = [&](const std::string& name, const RunExtremes& r) {
    const double scale = tidal / (r.maxVolume - r.minVolume);
    return MorphTarget{name, (r.maxSkin - r.minSkin) * scale, std::clamp(r.ribCageShare, 0.0, 1.0),
                       boneDisplacement(m.boneBase, r, scale)};
  };
  m.targets.push_back(target("breathing", deep));  // scale 1: the deep breath itself
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

std::vector<Eigen::Isometry3d> blendBones(const MorphTargets& targets, const Eigen::VectorXd& weights) {
  if (targets.bones.empty()) return {};
  Eigen::Matrix3Xd t = targets.boneBase.translation;  // [m]
  Eigen::Matrix4Xd q = targets.boneBase.rotation;     // [-]
  for (std::size_t k = 0; k < targets.targets.size(); ++k) {
    const double w = weights(static_cast<Eigen::Index>(k));
    t += w * targets.targets[k].boneDisplacement.translation;
    q += w * targets.targets[k].boneDisplacement.rotation;
  }
  std::vector<Eigen::Isometry3d> poses(targets.bones.size(), Eigen::Isometry3d::Identity());
  for (std::size_t b = 0; b < poses.size(); ++b) {
    const auto i = static_cast<Eigen::Index>(b);
    poses[b].linear() = Eigen::Quaterniond(q.col(i)).normalized().toRotationMatrix();
    poses[b].translation() = t.col(i);
  }
  return poses;
}

Eigen::Matrix3Xd boneTips(const Model& model) {
  const int n = model.bodies.size();
  // the joint to each body's parent, in the body's frame (its com when it has none)
  Eigen::Matrix3Xd root = Eigen::Matrix3Xd::Zero(3, n);
  for (int j = 0; j < model.joints.size(); ++j) {
    const int c = model.joints.child[static_cast<std::size_t>(j)];
    root.col(c) = model.joints.anchor.col(j) - model.bodies.com.col(c);
  }
  Eigen::Matrix3Xd tip = Eigen::Matrix3Xd::Zero(3, n);
  Eigen::VectorXd reach = Eigen::VectorXd::Zero(n);  // [m] the tip's distance from the root
  auto consider = [&](int b, const Eigen::Vector3d& p) {
    if (b < 0) return;
    const double d = (p - root.col(b)).norm();
    if (d > reach(b)) reach(b) = d, tip.col(b) = p;
  };
  const Elements& e = model.elements;
  for (int i = 0; i < e.size(); ++i) {
    if (isTie(e, i)) continue;
    const auto k = static_cast<std::size_t>(i);
    consider(e.endA.body[k], e.endA.local.col(i));
    consider(e.endB.body[k], e.endB.local.col(i));
  }
  for (int j = 0; j < model.joints.size(); ++j) {
    const int p = model.joints.parent[static_cast<std::size_t>(j)];
    consider(p, model.joints.anchor.col(j) - model.bodies.com.col(p));
  }
  return tip;
}

BoneBlendError boneBlendError(const Model& model, const Eigen::Matrix3Xd& tips,
                              const std::vector<Eigen::Isometry3d>& blend,
                              const std::vector<Eigen::Isometry3d>& posed) {
  BoneBlendError e;
  double tipSquares = 0.0, angleSquares = 0.0;  // [m^2], [rad^2]
  int ribs = 0, moving = 0;
  const std::size_t n = std::min({blend.size(), posed.size(), model.bodies.name.size()});
  for (std::size_t b = 0; b < n; ++b) {
    if (model.bodies.isFixed[b] != 0) continue;
    const double angle = Eigen::AngleAxisd(blend[b].linear() * posed[b].linear().transpose()).angle();
    angleSquares += angle * angle;
    e.angleMax = std::max(e.angleMax, angle);
    ++moving;
    if (model.bodies.name[b].rfind("rib", 0) != 0) continue;
    const Eigen::Vector3d p = tips.col(static_cast<Eigen::Index>(b));
    const double d = (blend[b] * p - posed[b] * p).norm();
    tipSquares += d * d;
    e.tipMax = std::max(e.tipMax, d);
    ++ribs;
  }
  if (ribs > 0) e.tipRms = std::sqrt(tipSquares / ribs);
  if (moving > 0) e.angleRms = std::sqrt(angleSquares / moving);
  return e;
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
