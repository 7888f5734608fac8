#pragma once
/// @file MorphTargets.h
/// Breathing as morph targets baked from the physics (docs/patterns.md, "Morph targets").
///
/// de Melo, Kenny & Gratch (2010, section *Model*) animate breathing by blending a neutral mesh (maximum
/// expiration) towards a breathing target (maximum inspiration); here the shapes come from simulation runs
/// of the skinned model, posed by sim::poseGeometry():
///   - base:      the skin at the smallest lung volume of a deep-breathing run (upright): the relaxed torso
///   at
///                the end of settling, which the deep style does not breathe below,
///   - breathing: the skin at that breath's maximum inspiration, as a displacement from the base,
///   - chest:     the tidal displacement of panting (rib-cage dominant), scaled to the deep breath's volume,
///   - belly:     the tidal displacement of a supine deep breath (abdomen dominant), scaled likewise,
///   - shoulders: (a model with a shoulder girdle) the part of the deep breath recruited above a lung volume,
///                the accessory muscles' shrug; the breathing target is then the part linear in the volume
///                (MorphTarget::onsetVolume).
/// A skin x is then approximated by the linear blend  x ~ base + sum_k w_k D_k.
/// The bones are baked at the same extremes, so that the same weights pose the skeleton too (blendBones()).

#include <Eigen/Geometry>
#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "pneuma/sim/Model.h"
#include "pneuma/sim/pattern/LayerStack.h"
#include "pneuma/sim/pattern/Pattern.h"

namespace pneuma::sim {

/// Poses of every body (MorphTargets::bones), or their displacements: a translation of the body's centre of
/// mass and the coefficients of its body -> world rotation quaternion, in the model frame.
struct BonePoses {
  Eigen::Matrix3Xd translation;  ///< [m] centre of mass, world (3 x #B)
  Eigen::Matrix4Xd rotation;     ///< [-] quaternion coefficients x, y, z, w (Eigen's order) (4 x #B)

  int size() const { return static_cast<int>(translation.cols()); }
};

/// One morph target: a displacement of every skin vertex from the base, and of every bone's pose.
struct MorphTarget {
  std::string name;               ///< "breathing", "chest", "belly" or "shoulders"
  Eigen::Matrix3Xd displacement;  ///< [m] D_k, per skin vertex (3 x #V)
  double ribCageShare = 0.0;      ///< [-] rib cage's share of the tidal volume of the run it came from
  /// the bones at this target minus the base bones: translations [m] and quaternion coefficients [-], the
  /// latter q_k - q_base with q_k the bone's rotation at weight 1 on the base's side (q_k . q_base >= 0);
  /// empty when the targets were baked without bones
  BonePoses boneDisplacement;
  /// [m^3] V_s of a recruited shape, < 0 for a breathing one. A recruited shape is the part of the deep
  /// breath that appears only above a lung volume: the shoulders, which the accessory muscles lift only in
  /// deep breaths (a model with a shoulder girdle). Its weight is max(0, V - V_s) / (V_t - V_s) with V_t the
  /// breathing target's volume (patternWeights()), and the breathing target is then the part linear in the
  /// volume (bakeMorphTargets()).
  double onsetVolume = -1.0;

  bool isRecruited() const { return onsetVolume >= 0.0; }
};

/// The baked shapes and the volume-to-shape calibration of one model.
struct MorphTargets {
  Eigen::Matrix3Xd base;             ///< [m] skin at the deep run's smallest lung volume (3 x #V)
  std::vector<MorphTarget> targets;  ///< breathing, chest, belly (each scaled to the same volume change),
                                     ///< and shoulders for a model with a shoulder girdle (recruited)
  double restVolume = 0.0;    ///< [m^3] settled lung volume of the relaxed torso (pattern fraction 0.05)
  double baseVolume = 0.0;    ///< [m^3] lung volume of the base shape
  double targetVolume = 0.0;  ///< [m^3] lung volume of the breathing target (weight 1)
  double volumePerFraction = 2.5e-3;  ///< [m^3] S of the pattern drive: V(v) = restVolume + (v - 0.05) S
  /// [1/m^3] calibrated volume-to-shape slope: the least-squares line, through the origin, of the summed
  /// fitted weights of the deep run's frames against their lung volume above baseVolume.
  double weightPerVolume = 0.0;
  std::vector<std::string> bones;  ///< body names (Bodies::name) the bone poses belong to; empty: none (#B)
  BonePoses boneBase;              ///< the bones at the base shape (#B)

  int vertexCount() const { return static_cast<int>(base.cols()); }
};

/// How far a blend is from a skin, over the vertices [m].
struct BlendError {
  double rms = 0.0;  ///< [m] sqrt(mean_v |x_v - blend_v|^2)
  double max = 0.0;  ///< [m] max_v |x_v - blend_v|
};

/// The bones posed by morph weights w, with the skin's blend: translations linearly, rotations by normalised
/// linear interpolation of the baked quaternions (nlerp), the same weights as the skin:
///   t_b = t_base,b + sum_k w_k dt_k,b,   q_b = normalise(q_base,b + sum_k w_k dq_k,b).
/// @return body frame -> world per bone of `targets.bones` (#B); empty when the targets have no bones.
std::vector<Eigen::Isometry3d> blendBones(const MorphTargets& targets, const Eigen::VectorXd& weights);

/// How far blended bones are from posed ones.
struct BoneBlendError {
  double tipRms = 0.0;    ///< [m] RMS over the ribs' tips (boneTips()) of |x_blend - x_posed|
  double tipMax = 0.0;    ///< [m] the largest of those distances
  double angleRms = 0.0;  ///< [rad] RMS over the moving bones of the angle of R_blend R_posed^T
  double angleMax = 0.0;  ///< [rad] the largest of those angles
};

/// [m] the tip of every body in its own frame (3 x #B): of the points the body holds (its element endpoints,
/// apposition springs left out, and the anchors of its joints), the one farthest from the joint to its
/// parent; for a rib, the anterior end where its costal cartilage starts. The com when it holds no point.
Eigen::Matrix3Xd boneTips(const Model& model);

/// The error of blended bone poses `blend` against posed ones `posed` (both body -> world, #B) of `model`:
/// tip distances over the bodies whose name starts with "rib", angles over every moving body.
BoneBlendError boneBlendError(const Model& model, const Eigen::Matrix3Xd& tips,
                              const std::vector<Eigen::Isometry3d>& blend,
                              const std::vector<Eigen::Isometry3d>& posed);

/// Called during a bake with the stage ("deep", "panting", "supine deep") and its progress in [0, 1].
using BakeProgress = std::function<void(const std::string& stage, double fraction)>;

/// Runs the three breath-style presets (`resourceDir`/presets: deep upright, panting upright, deep supine;
/// 2 s settling and two breaths each, about 30 simulated seconds) on `model` and extracts the shapes, of the
/// skin and of every bone at the same instants (a chest or belly target's rotation is its run's rotation
/// between the extremes, scaled in angle like the displacements and applied to the base).
/// @throws Error when the model has no skin, a preset cannot be loaded or a run fails; Interrupted when
///         `stop` (may be null) is set.
MorphTargets bakeMorphTargets(std::shared_ptr<const Model> model, const std::string& resourceDir,
                              const BakeProgress& progress = {}, const std::atomic<bool>* stop = nullptr);

/// Least-squares fit of skins onto the targets: w = argmin |x - base - sum_k w_k D_k|^2 over all vertex
/// coordinates, solved once through the normal equations (D^T D) w = D^T (x - base).
class MorphFit {
 public:
  explicit MorphFit(const MorphTargets& targets);
  /// [-] the weights of `skin` (3 x #V) [m], one per target.
  Eigen::VectorXd weights(const Eigen::Matrix3Xd& skin) const;
  /// [m] base + sum_k w_k D_k (3 x #V).
  Eigen::Matrix3Xd blend(const Eigen::VectorXd& weights) const;
  /// The distance between `skin` and the blend of its fitted weights.
  BlendError error(const Eigen::Matrix3Xd& skin) const;

 private:
  Eigen::Matrix3Xd m_base;   // [m] (3 x #V)
  Eigen::MatrixXd m_basis;   // [m] the displacements as columns (3#V x #K)
  Eigen::MatrixXd m_normal;  // [m^2] D^T D (#K x #K), inverted
};

/// de Melo's real-time mapping of a respiration pattern straight to morph weights, without physics.
/// The pattern's volume fraction v becomes a lung volume V(v) = restVolume + (v - 0.05) volumePerFraction
/// (the pattern drive's mapping, docs/patterns.md) and an amplitude a = weightPerVolume (V - baseVolume),
/// at least 0. The balance b (0 all belly, 1 all chest) is read as the rib cage's share of the breath:
/// the shapes are ordered by their ribCageShare and a is split between the two whose shares enclose b,
/// linearly in b (all to the nearest one outside their range). @return one weight per target [-].
Eigen::VectorXd patternWeights(const MorphTargets& targets, double fraction, double balance);

/// de Melo's real-time playback of a pattern on the targets, as a game engine plays it: the pattern's layer
/// stack sampled at increasing times, its balance b smoothed first-order as the physics controller smooths it
/// (b += (b_layer - b) (1 - exp(-dt / tau)), tau = PatternControllerOptions::balanceTimeConstant), and
/// patternWeights() of the two. No physics. Used by `pneuma-cli play` and the app's morph playback.
class MorphPlayer {
 public:
  /// Plays `pattern` (seeded irregularity `seed`) from t = 0, starting from the rest volume (fraction 0.05).
  MorphPlayer(const pattern::Pattern& pattern, std::uint64_t seed);
  /// [-] one weight per target of `targets` at time `t` [s] (t >= 0, not decreasing between calls).
  /// @throws Error when t decreases or is not finite.
  Eigen::VectorXd weightsAt(const MorphTargets& targets, double t);

 private:
  pattern::LayerStack m_stack;
  double m_balance = 0.0;  // [-] smoothed balance
  double m_time = -1.0;    // [s] of the last call; < 0 before the first
};

}  // namespace pneuma::sim
