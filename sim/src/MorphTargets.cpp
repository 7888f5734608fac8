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
constexpr int kOnsetSteps = 20;        // onsets tried for a recruited target: the deep breath in 20 steps
/// [-] a recruited target is baked when it takes at least this share off the deep run's skin residual
constexpr double kRecruitedGain = 0.2;

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
  std::vector<std::vector<Eigen::Isometry3d>> sampleBones;      // kept frames, body -> world (#B)
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
      if (isSample) {
        run.sampleVolume.push_back(volume);
        run.sampleSkin.push_back(posed.skin);
        run.sampleBones.push_back(posed.body);
      }
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

/// The bones of `poses` as one vector: translations [m] then quaternion coefficients [-] on the side of
/// `base`'s (7 #B), minus `base`'s.
Eigen::VectorXd boneVector(const std::vector<Eigen::Isometry3d>& poses, const BonePoses& base) {
  const Eigen::Index n = base.size();
  Eigen::VectorXd v(7 * n);
  for (Eigen::Index b = 0; b < n; ++b) {
    const auto i = static_cast<std::size_t>(b);
    v.segment<3>(3 * b) = poses[i].translation() - base.translation.col(b);
    v.segment<4>(3 * n + 4 * b) =
        rotationOf(poses[i], Eigen::Quaterniond(base.rotation.col(b))).coeffs() - base.rotation.col(b);
  }
  return v;
}

BonePoses bonePoses(const Eigen::VectorXd& v, Eigen::Index n) {
  BonePoses d{Eigen::Matrix3Xd(3, n), Eigen::Matrix4Xd(4, n)};
  for (Eigen::Index b = 0; b < n; ++b) {
    d.translation.col(b) = v.segment<3>(3 * b);
    d.rotation.col(b) = v.segment<4>(3 * n + 4 * b);
  }
  return d;
}

/// The deep run's shape split into a part linear in the volume and a recruited part
/// (MorphTarget::onsetVolume): for each onset V_s on a grid between the base and the peak, the least-squares
/// shapes D_b, D_s of
///   x_i - base = a_i D_b + s_i D_s,  a_i = (V_i - V_b) / (V_t - V_b),  s_i = max(0, V_i - V_s) / (V_t - V_s)
/// over the run's kept frames (skin and bones alike), keeping the onset of least skin residual.
struct RecruitedSplit {
  Eigen::VectorXd linearSkin, recruitedSkin;    // [m] (3 #V)
  Eigen::VectorXd linearBones, recruitedBones;  // (7 #B), boneVector()
  double onset = 0.0;                           // [m^3] V_s
  double residual = 0.0, linearResidual = 0.0;  // [m^2] summed squared skin residual with and without D_s
};

RecruitedSplit splitRecruited(const RunExtremes& deep, const Eigen::Matrix3Xd& base, const BonePoses& bones) {
  const double vb = deep.minVolume, vt = deep.maxVolume;
  const std::size_t n = deep.sampleSkin.size();
  std::vector<Eigen::VectorXd> skin(n), bone(n);
  std::vector<double> a(n);
  for (std::size_t i = 0; i < n; ++i) {
    skin[i] = (deep.sampleSkin[i] - base).reshaped();
    bone[i] = boneVector(deep.sampleBones[i], bones);
    a[i] = (deep.sampleVolume[i] - vb) / (vt - vb);
  }
  auto residualOf = [&](const std::vector<double>& s, const Eigen::VectorXd& db, const Eigen::VectorXd& ds) {
    double r = 0.0;
    for (std::size_t i = 0; i < n; ++i) r += (skin[i] - a[i] * db - s[i] * ds).squaredNorm();
    return r;
  };
  // the linear shape alone: D = sum a d / sum a^2
  RecruitedSplit best;
  double saa = 0.0;
  Eigen::VectorXd sad = Eigen::VectorXd::Zero(skin.front().size());
  for (std::size_t i = 0; i < n; ++i) saa += a[i] * a[i], sad += a[i] * skin[i];
  const std::vector<double> none(n, 0.0);
  best.linearResidual = residualOf(none, sad / saa, Eigen::VectorXd::Zero(sad.size()));
  best.residual = std::numeric_limits<double>::infinity();
  for (int g = 1; g < kOnsetSteps; ++g) {
    const double onset = vb + (vt - vb) * g / kOnsetSteps;
    std::vector<double> s(n);
    double sas = 0.0, sss = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      s[i] = std::max(0.0, deep.sampleVolume[i] - onset) / (vt - onset);
      sas += a[i] * s[i], sss += s[i] * s[i];
    }
    const double det = saa * sss - sas * sas;
    if (!(det > 1e-12 * saa * sss)) continue;
    auto solve = [&](const std::vector<Eigen::VectorXd>& d, Eigen::VectorXd& db, Eigen::VectorXd& ds) {
      Eigen::VectorXd ra = Eigen::VectorXd::Zero(d.front().size()), rs = ra;
      for (std::size_t i = 0; i < n; ++i) ra += a[i] * d[i], rs += s[i] * d[i];
      db = (sss * ra - sas * rs) / det;
      ds = (saa * rs - sas * ra) / det;
    };
    Eigen::VectorXd db, ds;
    solve(skin, db, ds);
    const double r = residualOf(s, db, ds);
    if (r >= best.residual) continue;
    best.residual = r, best.onset = onset, best.linearSkin = db, best.recruitedSkin = ds;
    solve(bone, best.linearBones, best.recruitedBones);
  }
  return best;
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
  // the shoulders of a model with a shoulder girdle (bodies with a postural support): a shape recruited above
  // a volume (the accessory muscles lift the girdle only in deep breaths), when it explains enough of the
  // deep run that the linear shape does not
  const bool hasGirdle = model->bodies.anySupported();
  const RecruitedSplit split = hasGirdle ? splitRecruited(deep, m.base, m.boneBase) : RecruitedSplit{};
  if (hasGirdle && std::isfinite(split.residual) &&
      split.residual < (1.0 - kRecruitedGain) * split.linearResidual) {
    MorphTarget& breathing = m.targets.front();
    breathing.displacement = split.linearSkin.reshaped(3, m.base.cols());
    breathing.boneDisplacement = bonePoses(split.linearBones, bodies);
    MorphTarget shoulders{"shoulders", split.recruitedSkin.reshaped(3, m.base.cols()), breathing.ribCageShare,
                          bonePoses(split.recruitedBones, bodies)};
    shoulders.onsetVolume = split.onset;
    m.targets.push_back(std::move(shoulders));
  }

  // volume-to-shape calibration: the breathing targets' summed fitted weight against the volume above the
  // base, through the origin
  const MorphFit fit(m);
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t i = 0; i < deep.sampleSkin.size(); ++i) {
    const double x = deep.sampleVolume[i] - m.baseVolume;  // [m^3]
    const Eigen::VectorXd w = fit.weights(deep.sampleSkin[i]);
    for (std::size_t k = 0; k < m.targets.size(); ++k)
      if (!m.targets[k].isRecruited()) sxy += x * w(static_cast<Eigen::Index>(k));
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
  std::size_t k = targets.targets.size();
  Eigen::VectorXd w = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(k));
  if (k == 0) return w;
  const double volume = targets.restVolume + (fraction - 0.05) * targets.volumePerFraction;  // [m^3]
  const double a = std::max(0.0, targets.weightPerVolume * (volume - targets.baseVolume));

  // a recruited shape by its own ramp; the others in order of their rib-cage share, the two enclosing the
  // balance sharing the amplitude
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < k; ++i) {
    const MorphTarget& t = targets.targets[i];
    if (t.isRecruited())
      w(static_cast<Eigen::Index>(i)) =
          std::max(0.0, volume - t.onsetVolume) / std::max(targets.targetVolume - t.onsetVolume, 1e-12);
    else
      order.push_back(i);
  }
  k = order.size();
  if (k == 0) return w;
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
