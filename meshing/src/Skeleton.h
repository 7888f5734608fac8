#pragma once
/// @file Skeleton.h
/// Procedural bones of the torso (world frame, rest pose) before remeshing and mass properties.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "pneuma/meshing/AnatomyParams.h"
#include "pneuma/meshing/TriangleMesh.h"

namespace pneuma::meshing {

/// Index of the right (+x) and left (-x) side.
enum Side : int { kRight = 0, kLeft = 1 };

/// Centreline of one rib, head (costovertebral joint) first.
struct RibCurve {
  std::vector<Eigen::Vector3d> centre;  ///< [m] centreline points, head to costochondral junction
  std::vector<Eigen::Vector3d> inward;  ///< unit in-plane normals pointing into the ribcage
  std::vector<Eigen::Vector3d> normal;  ///< unit rib-plane normals (superior side)
  std::vector<double> arc;              ///< [m] cumulative arc length at each point
  double height = 0.0;                  ///< [m] cross-section height
  double thickness = 0.0;               ///< [m] cross-section thickness
  /// Point at arc length `s` [m] (clamped), linear between samples; `offsetIn` [m] inward, `offsetUp` [m]
  /// upward.
  Eigen::Vector3d at(double s, double offsetIn = 0.0, double offsetUp = 0.0) const;
  /// Unit tangent (head to tip) at arc length `s`.
  Eigen::Vector3d tangent(double s) const;
  double length() const { return arc.back(); }
};

/// One bone: a future rigid body.
struct Bone {
  std::string name;
  bool isFixed = false;
  TriangleMesh mesh;         ///< [m] world frame, closed, outward
  double mass = 0.0;         ///< [kg] segment mass; 0: the mesh's volume at the bone density
  bool isSupported = false;  ///< held against gravity by a postural support (sim::Bodies::isSupported)
  /// [m] world, rest pose: the joint a supported segment hangs from (an arm's shoulder joint), or none; its
  /// support height (sim::Bodies::supportHeight) is the distance from its centre of mass to this point
  std::optional<Eigen::Vector3d> hangsFrom;
};

/// A ball joint between two bones.
struct JointSpec {
  std::string name;
  int parent = -1;
  int child = -1;
  Eigen::Vector3d anchor{0, 0, 0};  ///< [m] world
  JointKind kind = kSpineJoint;     ///< its row of gains (muscle_gains.json `joints`)
  Eigen::Vector3d axis{1, 0,
                       0};  ///< [-] unit axis, world at rest: the rib-neck axis, the elbow's flexion axis
};

/// One side of the shoulder girdle and arm (world, rest) [m].
struct GirdleSide {
  int clavicle = -1, scapula = -1, humerus = -1, forearm = -1;  ///< bone indices
  Eigen::Vector3d sternoclavicular{0, 0, 0};                    ///< joint centres
  Eigen::Vector3d acromioclavicular{0, 0, 0};
  Eigen::Vector3d glenohumeral{0, 0, 0};
  Eigen::Vector3d elbow{0, 0, 0};
  Eigen::Vector3d wrist{0, 0, 0};
  Eigen::Vector3d acromion{0, 0, 0};       ///< the acromion's superolateral tip (landmark)
  Eigen::Vector3d coracoid{0, 0, 0};       ///< the coracoid process's tip
  Eigen::Vector3d superiorAngle{0, 0, 0};  ///< of the scapula
  Eigen::Vector3d inferiorAngle{0, 0, 0};
  Eigen::Vector3d spineRoot{0, 0, 0};  ///< the medial end of the scapular spine
  Eigen::Vector3d mastoid{0, 0, 0};    ///< the mastoid process (on the head)
};

/// The whole rest-pose skeleton.
struct Skeleton {
  std::vector<Bone> bones;
  std::vector<JointSpec> joints;
  int lumbar = -1;                      ///< bone index of the fixed lumbar spine
  int pelvis = -1;                      ///< bone index of the fixed pelvis
  int sternum = -1;                     ///< bone index of the sternum
  std::vector<int> thoracicSegment;     ///< bone index of the segment holding vertebra T1..T12 (index 0 = T1)
  std::vector<std::array<int, 2>> rib;  ///< bone index of rib level 1..12 (index 0 = rib 1), [kRight, kLeft]
  std::vector<std::array<RibCurve, 2>> ribCurve;            ///< centrelines, same indexing
  std::vector<std::array<Eigen::Vector3d, 2>> costalNotch;  ///< [m] sternal attachment of ribs 1..7
  Eigen::Vector3d sternumAxis{0, 0, -1};                    ///< unit direction down the sternum
  Eigen::Vector3d xiphoidTip{0, 0, 0};                      ///< [m] lower end of the sternum
  Eigen::Vector3d jugularNotch{0, 0, 0};       ///< [m] upper end of the manubrium (suprasternal notch)
  std::vector<Eigen::Vector3d> sternumInner;   ///< [m] points on the sternum's posterior face
  std::vector<Eigen::Vector3d> lumbarFront;    ///< [m] anterior points of L1..L3 (crura), top down
  std::vector<double> vertebraTop;             ///< [m] z of the top of T1..T12
  std::vector<double> vertebraCentreY;         ///< [m] y of the body centre of T1..T12
  std::vector<Eigen::Vector3d> thoracicFront;  ///< [m] anterior mid-height points of T1..T12
  // the shoulder girdle (AnatomyParams::hasShoulderGirdle), else empty
  bool hasGirdle = false;
  std::array<GirdleSide, 2> girdle;             ///< [kRight, kLeft]
  int cervical = -1;                            ///< bone index of the fixed cervical spine
  int head = -1;                                ///< bone index of the fixed head
  std::vector<Eigen::Vector3d> cervicalCentre;  ///< [m] vertebral body centres C1..C7 (index 0 = C1)
};

/// Adds the shoulder girdle, arms, cervical spine and head of `a` to `sk` (built by buildSkeleton()).
void addGirdle(const AnatomyParams& a, Skeleton& sk);

/// Builds the bones and joints of `a`. @throws sim::Error when ribs overlap (naming the rib levels).
Skeleton buildSkeleton(const AnatomyParams& a);

}  // namespace pneuma::meshing
