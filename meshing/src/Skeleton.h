#pragma once
/// @file Skeleton.h
/// Procedural bones of the torso (world frame, rest pose) before remeshing and mass properties.

#include <array>
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
  TriangleMesh mesh;  ///< [m] world frame, closed, outward
};

/// A ball joint between two bones.
struct JointSpec {
  std::string name;
  int parent = -1;
  int child = -1;
  Eigen::Vector3d anchor{0, 0, 0};  ///< [m] world
  bool isSpine = false;             ///< spine joint (else costovertebral)
  Eigen::Vector3d axis{1, 0, 0};    ///< [-] unit rib-neck axis, world at rest (costovertebral joints only)
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
};

/// Builds the bones and joints of `a`. @throws sim::Error when ribs overlap (naming the rib levels).
Skeleton buildSkeleton(const AnatomyParams& a);

}  // namespace pneuma::meshing
