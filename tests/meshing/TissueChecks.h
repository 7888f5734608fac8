#pragma once
// Checks of the soft-tissue volume bodies (meshing/src/TissueBodies.h) of a built model, shared by the preset
// and the shoulder girdle tests: each named body is a closed lens of a plausible volume between the bones and
// the skin (no node inside a bone, every node inside the skin), its deep face tied to the bones and its
// superficial face free.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "SurfaceCrossings.h"
#include "pneuma/meshing/MeshTools.h"
#include "pneuma/meshing/ModelBuilder.h"
#include "pneuma/meshing/ModelSummary.h"
#include "pneuma/sim/Elements.h"
#include "pneuma/sim/State.h"
#include "pneuma/sim/Ties.h"

namespace pneuma::test {

/// Index of the volume body `name` of `m`, or -1.
inline int volumeBody(const sim::Model& m, const std::string& name) {
  for (int k = 0; k < m.volumes.size(); ++k)
    if (m.volumes.name[static_cast<std::size_t>(k)] == name) return k;
  return -1;
}

/// Expects body `name` of `b` (built with a skin) to be a lens of [minVolume, maxVolume] m^3 between the
/// bones and the skin, tied to the bones by some of its nodes and free in the others.
inline void expectBetweenBonesAndSkin(const meshing::BuiltModel& b, const std::string& name, double minVolume,
                                      double maxVolume) {
  SCOPED_TRACE(name);
  const sim::Model& m = b.model;
  const int k = volumeBody(m, name);
  ASSERT_GE(k, 0) << "no volume body " << name;
  ASSERT_GT(m.skin.vertexCount(), 0);
  Eigen::Matrix3Xd skin;
  sim::skinPositions(m.skin, meshing::restPoints(m.skin.anchors, m), skin);
  const std::vector<char> isTied = sim::tiedNodes(m);
  const Eigen::Matrix3Xi& t = m.volumes.triangles[static_cast<std::size_t>(k)];
  const double volume = sim::enclosedVolume(m.nodes.rest, t);
  ::testing::Test::RecordProperty(name + "_volume_mL", std::to_string(volume * 1e6));
  EXPECT_GT(volume, minVolume);
  EXPECT_LT(volume, maxVolume);
  std::vector<int> nodes(t.data(), t.data() + t.size());
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  int tied = 0, failures = 0;
  for (int n : nodes) {
    tied += isTied[static_cast<std::size_t>(n)];
    const Eigen::Vector3d p = m.nodes.rest.col(n);
    if (!isInside(p, skin, m.skin.triangles) && failures++ < 5)
      ADD_FAILURE() << "node " << n << " outside the skin";
    for (int i = 0; i < m.bodies.size(); ++i) {
      const meshing::TriangleMesh& mesh = b.bodyMeshes[static_cast<std::size_t>(i)];
      const Eigen::Matrix3Xd bone = mesh.vertices.colwise() + m.bodies.com.col(i);
      if ((p.array() < bone.rowwise().minCoeff().array()).any() ||
          (p.array() > bone.rowwise().maxCoeff().array()).any())
        continue;
      if (isInside(p, bone, mesh.triangles) && failures++ < 5)
        ADD_FAILURE() << "node " << n << " inside " << m.bodies.name[static_cast<std::size_t>(i)];
    }
  }
  EXPECT_GT(tied, 0) << "a deep face on the bones";
  EXPECT_LT(tied, static_cast<int>(nodes.size())) << "a free superficial face";
}

}  // namespace pneuma::test
