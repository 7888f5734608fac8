#pragma once
/// @file GltfWriter.h
/// glTF 2.0 binary (.glb) export of a breathing body: the skin with its baked morph targets
/// (sim/MorphTargets.h) and normals, every bone as a node with its own mesh, and animations that play runs as
/// morph-weight and node (translation, rotation) channels. Written with tinygltf through a temporary file and
/// a rename (AtomicFile.h).
///
/// Frames: the model is RAS, z up (+x the subject's right, +y anterior, +z superior), metres; glTF is +Y up,
/// +Z forward (the asset's front), +X to the asset's left, metres (glTF 2.0 spec, "Coordinate system and
/// units"). modelToGltf() is the one conversion: (X, Y, Z) = (-x, z, y), a proper rotation.

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "pneuma/sim/Model.h"
#include "pneuma/sim/MorphTargets.h"
#include "pneuma/sim/PosedGeometry.h"
#include "pneuma/sim/State.h"

namespace pneuma::viz {

/// [-] the rotation taking model coordinates (RAS, z up) to glTF coordinates (+Y up, +Z forward).
const Eigen::Matrix3d& modelToGltf();

/// One animation: frames of morph weights and, optionally, bone poses.
struct GltfAnimation {
  std::string name;                                    ///< e.g. "calm" or "fear"
  std::vector<double> time;                            ///< [s] frame times, strictly increasing (#F)
  Eigen::MatrixXd weights;                             ///< [-] morph weight per target and frame (#K x #F)
  std::vector<std::vector<Eigen::Isometry3d>> bodies;  ///< body frame -> world per frame, model frame (#F x
                                                       ///< #B); empty: the bones stay at their rest pose
};

/// Collects the frames of a run as a GltfAnimation: each state's skin (sim::poseGeometry) fitted onto the
/// morph targets (sim::MorphFit) and its bone poses, with the blend error over all frames.
class GltfAnimationBuilder {
 public:
  /// `model` and `targets` must outlive the builder.
  GltfAnimationBuilder(const sim::Model& model, const sim::MorphTargets& targets);
  /// Adds `state` as the frame at `time` [s]; a time not after the previous frame's is skipped.
  void add(double time, const sim::State& state);
  /// The frames so far as an animation named `name`.
  GltfAnimation animation(const std::string& name) const;
  /// The blend error over the frames so far: RMS over every vertex of every frame, maximum over all [m].
  sim::BlendError error() const;
  /// The error of the bones posed by each frame's fitted weights (sim::blendBones) against the frame's bones,
  /// RMS over every frame's ribs or bones, maxima over all; zero when the targets have no bones.
  sim::BoneBlendError boneError() const;
  std::size_t frames() const { return m_time.size(); }

 private:
  const sim::Model& m_model;
  const sim::MorphTargets& m_targets;
  sim::MorphFit m_fit;
  Eigen::Matrix3Xd m_tips;  // [m] sim::boneTips() (3 x #B)
  sim::PosedGeometry m_posed;
  std::vector<double> m_time;                            // [s] (#F)
  std::vector<Eigen::VectorXd> m_weights;                // [-] (#F x #K)
  std::vector<std::vector<Eigen::Isometry3d>> m_bodies;  // (#F x #B)
  double m_squares = 0.0;      // [m^2] sum over frames of the frame's mean squared distance
  double m_max = 0.0;          // [m]
  sim::BoneBlendError m_bone;  // sums of squares in the RMS fields until boneError()
};

/// A one-breath demonstration of the breathing target (in 2 s, out 3 s), for a file of baked targets; the
/// bones follow (sim::blendBones) when the targets have them.
GltfAnimation breathingDemo(const sim::MorphTargets& targets);

/// Writes `path` (.glb): scene "pneuma" with node "skin" (the base skin of `targets`, its morph targets
/// named in mesh.extras.targetNames) and node "bones" holding one node per body of `model` (its render mesh
/// from `modelDir`, at rest; every body of the model, named as in the model). Each animation drives the
/// skin's weights and the moving bodies' translation and rotation, linearly interpolated. The targets' bone
/// poses (MorphTargets::bones) are kept in mesh.extras.pneuma.bones, glTF frame: "names", "base" (7 numbers
/// per bone: translation X, Y, Z [m], rotation quaternion x, y, z, w) and "targets" (the same 7 per bone and
/// target, displacements from the base).
/// @throws sim::Error when the model has no skin or `targets` does not match it, or a bone mesh cannot be
///         read; std::runtime_error "cannot write <path>: <reason>" when the file cannot be written (then
///         nothing is left under `path`).
void writeGltf(const std::string& path, const sim::Model& model, const std::string& modelDir,
               const sim::MorphTargets& targets, const std::vector<GltfAnimation>& animations);

/// Reads back the morph targets, their bone poses and their calibration from a .glb written by writeGltf()
/// (the skin mesh's positions and target positions, mesh.extras.pneuma), in the model frame [m]. A file
/// written before bones were baked gives targets without bones.
/// @throws sim::Error "<path>: ..." when the file cannot be read or holds no Pneuma skin.
sim::MorphTargets readGltfMorphTargets(const std::string& path);

}  // namespace pneuma::viz
