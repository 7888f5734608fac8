#include "pneuma/meshing/ModelBuilder.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "SurfaceCrossings.h"
#include "TissueChecks.h"
#include "pneuma/meshing/MeshTools.h"
#include "pneuma/meshing/ModelSummary.h"
#include "pneuma/sim/BreathStyleController.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/ModelIO.h"
#include "pneuma/sim/Simulation.h"
#include "pneuma/sim/State.h"

namespace pneuma::meshing {
namespace {

using sim::ElementGroup;

/// Physiological ranges (resources/anatomy/README.md, "Volume targets").
constexpr double kCavityMinMl = 3000.0, kCavityMaxMl = 6500.0;  // thoracic cavity at FRC
constexpr double kGutMinMl = 4500.0, kGutMaxMl = 11000.0;       // abdominopelvic cavity

/// Each preset is built once per test process, when a test first needs it.
class BuiltPresets : public ::testing::TestWithParam<std::string> {
 protected:
  static void TearDownTestSuite() { s_built.clear(); }
  const BuiltModel& built() const {
    auto it = s_built.find(GetParam());
    if (it == s_built.end()) {
      it = s_built
               .emplace(GetParam(), buildModel(loadAnatomy(std::string(PNEUMA_RESOURCE_DIR) + "/anatomy/" +
                                                           GetParam() + ".json")))
               .first;
    }
    return it->second;
  }
  const sim::Model& model() const { return built().model; }

  static std::map<std::string, BuiltModel> s_built;
};
std::map<std::string, BuiltModel> BuiltPresets::s_built;

int bodyIndex(const sim::Model& m, const std::string& name) {
  for (int b = 0; b < m.bodies.size(); ++b) {
    if (m.bodies.name[static_cast<std::size_t>(b)] == name) return b;
  }
  return -1;
}

TEST_P(BuiltPresets, EveryBoneIsClosedAndFreeOfSelfIntersections) {
  for (std::size_t b = 0; b < built().bodyMeshes.size(); ++b) {
    const MeshCheck c = checkMesh(built().bodyMeshes[b]);
    EXPECT_TRUE(c.isValid()) << model().bodies.name[b] << " closed " << c.isClosed << " self-intersecting "
                             << c.isSelfIntersecting << " outward " << c.isOutward;
  }
}

TEST_P(BuiltPresets, ArticulationMatchesSection5) {
  const sim::Model& m = model();
  // ribs 1-10 on each side and the sternum move; the lumbar spine and pelvis are fixed
  for (int level = 1; level <= 10; ++level) {
    for (const char* side : {"_left", "_right"}) {
      const int b = bodyIndex(m, "rib" + std::to_string(level) + side);
      ASSERT_GE(b, 0);
      EXPECT_FALSE(m.bodies.isFixed[static_cast<std::size_t>(b)]);
    }
  }
  EXPECT_FALSE(m.bodies.isFixed[static_cast<std::size_t>(bodyIndex(m, "sternum"))]);
  EXPECT_TRUE(m.bodies.isFixed[static_cast<std::size_t>(bodyIndex(m, "lumbar_spine"))]);
  EXPECT_TRUE(m.bodies.isFixed[static_cast<std::size_t>(bodyIndex(m, "pelvis"))]);
  // at least 3 articulated thoracic segments, each on a ball joint
  int segments = 0;
  for (int j = 0; j < m.joints.size(); ++j) {
    if (m.joints.name[static_cast<std::size_t>(j)].rfind("spine_", 0) == 0) ++segments;
  }
  EXPECT_GE(segments, 3);
  // every moving rib hangs on one costovertebral joint; the sternum hangs on cartilage springs only
  for (int b = 0; b < m.bodies.size(); ++b) {
    int joints = 0;
    for (int j = 0; j < m.joints.size(); ++j)
      joints += m.joints.child[static_cast<std::size_t>(j)] == b ? 1 : 0;
    const std::string& n = m.bodies.name[static_cast<std::size_t>(b)];
    if (n.rfind("rib", 0) == 0) {
      EXPECT_EQ(joints, m.bodies.isFixed[static_cast<std::size_t>(b)] ? 0 : 1) << n;
    }
    if (n == "sternum") {
      EXPECT_EQ(joints, 0);
    }
  }
}

TEST_P(BuiltPresets, LeftAndRightAreMirrorSymmetricWithin1mm) {
  const sim::Model& m = model();
  constexpr double kTol = 1e-3;  // [m]
  auto mirror = [](Eigen::Vector3d p) {
    p.x() = -p.x();
    return p;
  };
  for (int b = 0; b < m.bodies.size(); ++b) {
    const std::string& n = m.bodies.name[static_cast<std::size_t>(b)];
    const std::size_t at = n.find("_left");
    if (at == std::string::npos) {
      if (n.find("_right") == std::string::npos) {
        EXPECT_LT(std::abs(m.bodies.com(0, b)), kTol) << n;  // midline bone
      }
      continue;
    }
    const int r = bodyIndex(m, n.substr(0, at) + "_right");
    ASSERT_GE(r, 0) << n;
    EXPECT_LT((mirror(m.bodies.com.col(b)) - m.bodies.com.col(r)).norm(), kTol) << n;
    EXPECT_NEAR(m.bodies.mass(b), m.bodies.mass(r), 1e-3 * m.bodies.mass(r)) << n;
  }
  // every gut node has a mirror node
  for (int i = 0; i < m.nodes.size(); ++i) {
    double best = 1e9;
    for (int k = 0; k < m.nodes.size(); ++k)
      best = std::min(best, (mirror(m.nodes.rest.col(i)) - m.nodes.rest.col(k)).norm());
    EXPECT_LT(best, kTol) << "node " << i;
  }
  const int l = m.landmarks.find("rib8_lateral_left"), r = m.landmarks.find("rib8_lateral_right");
  const Eigen::Matrix3Xd lm = restPoints(m.landmarks.points, m);
  EXPECT_LT((mirror(lm.col(l)) - lm.col(r)).norm(), kTol);
}

TEST_P(BuiltPresets, ExternalAndInternalIntercostalsHaveOppositeObliquity) {
  // angle round the ribcage's vertical axis, from the posterior midline toward the sternum on either side
  const sim::Model& m = model();
  const Eigen::Matrix3Xd a = restPoints(m.elements.endA, m);
  const Eigen::Matrix3Xd b = restPoints(m.elements.endB, m);
  // the ribcage's vertical axis passes through the mean rib centre of mass
  double axisY = 0.0;
  int ribs = 0;
  for (int r = 0; r < m.bodies.size(); ++r) {
    if (m.bodies.name[static_cast<std::size_t>(r)].rfind("rib", 0) != 0) continue;
    axisY += m.bodies.com(1, r);
    ++ribs;
  }
  axisY /= ribs;
  auto around = [&](const Eigen::Vector3d& p) { return std::atan2(std::abs(p.x()), axisY - p.y()); };
  std::map<ElementGroup, std::array<int, 2>> forwardBackward;
  int down = 0, total = 0;
  for (int e = 0; e < m.elements.size(); ++e) {
    const ElementGroup g = m.elements.group[static_cast<std::size_t>(e)];
    if (g != ElementGroup::IntercostalExternal && g != ElementGroup::IntercostalInternal) continue;
    ++forwardBackward[g][around(b.col(e)) > around(a.col(e)) ? 0 : 1];
    // spaces 1-8 (the lower rib, end b, above rib 10): below rib 9 the spaces' anterior ends follow the
    // costal arch, which rises toward the xiphoid
    const std::string& lower =
        m.bodies.name[static_cast<std::size_t>(m.elements.endB.body[static_cast<std::size_t>(e)])];
    if (lower.rfind("rib10", 0) == 0 || lower.rfind("rib11", 0) == 0 || lower.rfind("rib12", 0) == 0)
      continue;
    down += b(2, e) < a(2, e) ? 1 : 0;
    ++total;
  }
  // in spaces 1-8 they run from the rib above down to the rib below (except a few where the cartilage ends
  // curl up)
  EXPECT_GT(down, 0.9 * total);
  // external: down and forward; internal: down and backward (all but a few at the rib ends)
  const auto ext = forwardBackward[ElementGroup::IntercostalExternal];
  const auto in = forwardBackward[ElementGroup::IntercostalInternal];
  EXPECT_GT(ext[0], 9 * ext[1]) << ext[0] << " forward, " << ext[1] << " backward";
  EXPECT_GT(in[1], 9 * in[0]) << in[0] << " forward, " << in[1] << " backward";
}

TEST_P(BuiltPresets, GroupCountsFollowTable1Within25Percent) {
  const ModelSummary& s = built().report.summary;
  auto count = [&](ElementGroup g) { return s.elements[static_cast<std::size_t>(g)]; };
  auto expectNear = [](int n, double guide, const char* what) {
    EXPECT_GE(n, 0.75 * guide) << what;
    EXPECT_LE(n, 1.25 * guide) << what;
  };
  expectNear(count(ElementGroup::IntercostalExternal) + count(ElementGroup::IntercostalInternal), 516,
             "intercostals");
  expectNear(count(ElementGroup::IntercostalExternal), 258, "external intercostals");
  expectNear(count(ElementGroup::IntercostalInternal), 258, "internal intercostals");
  expectNear(count(ElementGroup::Diaphragm), 464, "diaphragm");
  expectNear(count(ElementGroup::Rectus), 85, "rectus");
  expectNear(count(ElementGroup::TransversusObliques), 350, "transversus and obliques");
  EXPECT_GE(count(ElementGroup::Cartilage),
            6 * 20);  // at least 6 springs per cartilage, ribs 1-10 both sides
}

TEST_P(BuiltPresets, VolumesAreWithinPhysiologicalRanges) {
  const ModelSummary& s = built().report.summary;
  EXPECT_GT(s.cavityVolume * 1e6, kCavityMinMl);
  EXPECT_LT(s.cavityVolume * 1e6, kCavityMaxMl);
  EXPECT_GT(s.gutVolume * 1e6, kGutMinMl);
  EXPECT_LT(s.gutVolume * 1e6, kGutMaxMl);
}

// the two lungs: closed, outward, free of self-intersections at rest (CGAL), split 53.5 : 46.5 as on upright
// CT (Yamada et al. 2020: right 53.3 +/- 1.3 % standing), with the mediastinum (heart about 0.8 L, great
// vessels, trachea, oesophagus, the vertebral bodies' bulge) between them; lungs at end-expiration in the
// range of FRC gas plus lung tissue (resources/anatomy/README.md, "Lungs")
TEST_P(BuiltPresets, LungsSplitAsOnCtAroundTheMediastinum) {
  const sim::Model& m = model();
  Eigen::Matrix3Xd cavity(3, m.cavity.vertices.size());
  for (int i = 0; i < m.cavity.vertices.size(); ++i) {
    const int b = m.cavity.vertices.body[static_cast<std::size_t>(i)];
    if (b >= 0) {
      cavity.col(i) = m.bodies.com.col(b) + m.cavity.vertices.local.col(i);
      continue;
    }
    cavity.col(i).setZero();
    for (int k = 0; k < 3; ++k)
      if (m.cavity.vertices.nodes(k, i) >= 0)
        cavity.col(i) += m.cavity.vertices.weights(k, i) * m.nodes.rest.col(m.cavity.vertices.nodes(k, i));
  }
  double volume[2] = {0.0, 0.0};
  int side = 0;
  for (const sim::LungSurface* lung : {&m.lungs.right, &m.lungs.left}) {
    TriangleMesh mesh;
    sim::lungPositions(*lung, cavity, mesh.vertices);
    mesh.triangles = lung->triangles;
    const MeshCheck c = checkMesh(mesh);
    EXPECT_TRUE(c.isValid()) << GetParam() << " lung " << side << ": manifold " << c.isManifold << ", closed "
                             << c.isClosed << ", self-intersecting " << c.isSelfIntersecting;
    volume[side++] = enclosedVolume(mesh.vertices, mesh.triangles);
  }
  const double cavityVolume = enclosedVolume(cavity, m.cavity.triangles);
  EXPECT_NEAR(volume[0] / (volume[0] + volume[1]), 0.535, 0.002) << GetParam();
  EXPECT_NEAR(m.lungs.mediastinumVolume, cavityVolume - volume[0] - volume[1], 1e-9);
  EXPECT_GT(m.lungs.mediastinumVolume * 1e6, 700.0) << GetParam();  // the heart alone is 0.6-0.9 L
  EXPECT_LT(m.lungs.mediastinumVolume * 1e6, 1600.0) << GetParam();
  RecordProperty("lungs_ml", std::to_string((cavityVolume - m.lungs.mediastinumVolume) * 1e6));
  RecordProperty("mediastinum_ml", std::to_string(m.lungs.mediastinumVolume * 1e6));
  std::printf("%s: cavity %.0f mL, mediastinum %.0f mL, lungs %.0f mL (right %.0f, left %.0f)\n",
              GetParam().c_str(), cavityVolume * 1e6, m.lungs.mediastinumVolume * 1e6,
              (cavityVolume - m.lungs.mediastinumVolume) * 1e6, volume[0] * 1e6, volume[1] * 1e6);
}

// each lung's flat face on the central mediastinal block (x constant, its vertices where the block's side
// meets the cavity's walls) is a Delaunay triangulation in that plane (LungCavity.cpp, flipMediastinalFaces,
// Lawson 1977): no interior edge of the face has the opposite corner of its other triangle inside its
// triangle's circumcircle. The corefinement's slivers there folded through the walls and the gut as they
// moved (crossing pairs summed over every style and affect, tests/validation/Surfaces_test.cpp: 1558 with the
// slivers, 877 after the flips)
TEST_P(BuiltPresets, LungMediastinalFacesAreDelaunay) {
  const sim::Model& m = model();
  const Eigen::Matrix3Xd cavity = restPoints(m.cavity.vertices, m);
  for (const sim::LungSurface* lung : {&m.lungs.right, &m.lungs.left}) {
    const std::string side = lung == &m.lungs.right ? "right" : "left";
    Eigen::Matrix3Xd x;
    sim::lungPositions(*lung, cavity, x);
    // the face's plane: the x that most of the lung's vertices share (to 1 um), those where the block's side
    // meets the cavity's walls
    std::map<long long, int> atX;
    for (int v = 0; v < lung->vertexCount(); ++v) ++atX[std::llround(x(0, v) * 1e6)];
    const auto plane = std::max_element(atX.begin(), atX.end(),
                                        [](const auto& a, const auto& b) { return a.second < b.second; });
    ASSERT_GT(plane->second, 20) << GetParam() << " " << side;
    double faceX = 0.0;
    for (int v = 0; v < lung->vertexCount(); ++v)
      if (std::llround(x(0, v) * 1e6) == plane->first) faceX += x(0, v) / plane->second;
    std::map<std::pair<int, int>, std::vector<std::pair<int, int>>> edges;  // edge -> (triangle, opposite)
    int flat = 0;
    for (int f = 0; f < lung->triangles.cols(); ++f) {
      const Eigen::Vector3i t = lung->triangles.col(f);
      if ((x(0, t(0)) - faceX) * (x(0, t(0)) - faceX) + (x(0, t(1)) - faceX) * (x(0, t(1)) - faceX) +
              (x(0, t(2)) - faceX) * (x(0, t(2)) - faceX) >
          1e-14)
        continue;
      ++flat;
      for (int k = 0; k < 3; ++k) {
        const int a = t(k), b = t((k + 1) % 3);
        edges[{std::min(a, b), std::max(a, b)}].push_back({f, t((k + 2) % 3)});
      }
    }
    EXPECT_GT(flat, 20) << GetParam() << " " << side;
    // > 0 when d lies inside the circumcircle of (a, b, c), for either orientation (y-z coordinates)
    auto inCircle = [&](int a, int b, int c, int d) {
      Eigen::Matrix3d q;
      const int abc[3] = {a, b, c};
      for (int i = 0; i < 3; ++i) {
        const Eigen::Vector2d p = x.block<2, 1>(1, abc[i]) - x.block<2, 1>(1, d);
        q.row(i) << p.x(), p.y(), p.squaredNorm();
      }
      const Eigen::Vector2d u = x.block<2, 1>(1, b) - x.block<2, 1>(1, a),
                            w = x.block<2, 1>(1, c) - x.block<2, 1>(1, a);
      return (u.x() * w.y() - u.y() * w.x() > 0.0 ? 1.0 : -1.0) * q.determinant();
    };
    int notDelaunay = 0, interior = 0;
    for (const auto& [e, sides] : edges) {
      if (sides.size() != 2) continue;
      ++interior;
      const int c = sides[0].second, d = sides[1].second;
      double size = 0.0;
      for (const int v : {e.second, c, d}) size = std::max(size, (x.col(v) - x.col(e.first)).norm());
      // a tolerance of the flips' own (1e-6 of the quadrilateral's size^4) and the rounding of the rest pose
      notDelaunay += inCircle(e.first, e.second, c, d) > 1e-5 * std::pow(size, 4);
    }
    EXPECT_GT(interior, 10) << GetParam() << " " << side;
    EXPECT_EQ(notDelaunay, 0) << GetParam() << " " << side << ": of " << interior << " interior edges on "
                              << flat << " triangles";
  }
}

TEST_P(BuiltPresets, TetGenVolumeEqualsSurfaceVolumeAndSurfaceHasNoSlivers) {
  const BuildReport& r = built().report;
  EXPECT_NEAR(r.tetVolume, r.summary.gutVolume, 1e-3 * r.summary.gutVolume);
  EXPECT_GT(r.tetrahedra, 0);
  EXPECT_GT(r.gutQualityMin, 0.2);  // no slivers
  EXPECT_GT(r.gutQualityMean, 0.65);
}

// the dome has no slivers: its inner rings follow the spine notch, so zipping them ring to ring left a
// triangle 3.7 mm high on a 31 mm base beside the apex (quality 0.24 in both presets), which turned over at
// calm end-inspiration; the cap's Delaunay triangulation (GutSurface.cpp) brings the worst to 0.37 (male) and
// 0.43 (female). Quality q = 4 sqrt(3) area / sum of squared edges (triangleQuality): 1 equilateral, 0
// degenerate
TEST_P(BuiltPresets, DiaphragmDomeHasNoSlivers) {
  const sim::Model& m = model();
  const auto isDome = [&](int v) {
    return m.nodes.region[static_cast<std::size_t>(v)] == sim::NodeRegion::Diaphragm;
  };
  double worst = 1.0;
  int dome = 0;
  for (Eigen::Index f = 0; f < m.gut.triangles.cols(); ++f) {
    const Eigen::Vector3i t = m.gut.triangles.col(f);
    if (!isDome(t(0)) || !isDome(t(1)) || !isDome(t(2))) continue;
    ++dome;
    worst = std::min(worst,
                     triangleQuality(m.nodes.rest.col(t(0)), m.nodes.rest.col(t(1)), m.nodes.rest.col(t(2))));
  }
  EXPECT_GT(dome, 100) << GetParam();
  EXPECT_GT(worst, 0.3) << GetParam();
  RecordProperty("dome_quality_min", std::to_string(worst));
}

TEST_P(BuiltPresets, WallMassesAddUpTo8kgAndDiaphragmToItsMass) {
  const sim::Model& m = model();
  double wall = 0.0, dome = 0.0;
  for (int i = 0; i < m.nodes.size(); ++i) {
    const sim::NodeRegion r = m.nodes.region[static_cast<std::size_t>(i)];
    if (r == sim::NodeRegion::Wall) wall += m.nodes.mass(i);
    if (r == sim::NodeRegion::Diaphragm) dome += m.nodes.mass(i);
  }
  EXPECT_NEAR(wall, 8.0, 1e-9);
  EXPECT_NEAR(dome, 1.8, 1e-9);  // diaphragm_mass_kg of resources/anatomy/muscle_gains.json
  // the gut's nodes (the volume bodies' follow them, region tissue)
  const auto gutNodes = std::count_if(m.nodes.region.begin(), m.nodes.region.end(),
                                      [](sim::NodeRegion r) { return r != sim::NodeRegion::Tissue; });
  EXPECT_GE(gutNodes, 300);
  EXPECT_LE(gutNodes, 800);
}

TEST_P(BuiltPresets, GutSurfaceIsSealedAndHasItsRegions) {
  const sim::Model& m = model();
  TriangleMesh gut{m.nodes.rest, m.gut.triangles};
  EXPECT_TRUE(checkMesh(gut).isValid());
  // the diaphragm is the top of the gut and is meshed finer than the wall; the gut's nodes only (the volume
  // bodies' nodes, region Tissue, lie on the chest above it)
  const auto isGut = [&](int i) {
    return m.nodes.region[static_cast<std::size_t>(i)] != sim::NodeRegion::Tissue;
  };
  std::array<double, 3> zMean{}, count{};
  for (int i = 0; i < m.nodes.size(); ++i) {
    if (!isGut(i)) continue;
    const auto r = static_cast<std::size_t>(m.nodes.region[static_cast<std::size_t>(i)]);
    zMean[r] += m.nodes.rest(2, i);
    count[r] += 1;
  }
  for (std::size_t r = 0; r < 3; ++r) ASSERT_GT(count[r], 0) << "region " << r;
  EXPECT_GT(zMean[1] / count[1], zMean[0] / count[0]);
  const int apex = m.landmarks.find("diaphragm_apex");
  const int navel = m.landmarks.find("umbilicus");
  EXPECT_EQ(m.nodes.region[static_cast<std::size_t>(m.landmarks.points.nodes(0, apex))],
            sim::NodeRegion::Diaphragm);
  EXPECT_EQ(m.nodes.region[static_cast<std::size_t>(m.landmarks.points.nodes(0, navel))],
            sim::NodeRegion::Wall);
  for (int i = 0; i < m.nodes.size(); ++i) {
    if (isGut(i)) {
      EXPECT_LE(m.nodes.rest(2, i), m.nodes.rest(2, m.landmarks.points.nodes(0, apex)) + 1e-12);
    }
  }
}

TEST_P(BuiltPresets, RoundTripsThroughModelJson) {
  const std::string text = sim::serializeModel(model());
  const sim::Model back = sim::parseModel(text);
  EXPECT_TRUE(sim::serializeModel(back) == text) << "model.json does not round-trip";
  const ModelSummary a = summarizeModel(back);
  EXPECT_EQ(summaryJson(a), summaryJson(built().report.summary));
}

TEST(ModelBuilder, BuildIsDeterministicAndDirectoryIsReplacedWhole) {
  namespace fs = std::filesystem;
  const AnatomyParams a = loadAnatomy(std::string(PNEUMA_RESOURCE_DIR) + "/anatomy/female.json");
  const BuiltModel one = buildModel(a);
  const BuiltModel two = buildModel(a);
  // bodies, joints, nodes, gut, elements, landmarks and the skin are bit-identical; the cavity's and the
  // lungs' triangulations come from CGAL corefinement, whose tie-breaking follows heap addresses inside one
  // process (separate processes, as at build time, give identical bytes), so they are compared by their
  // volumes
  EXPECT_NEAR(two.report.summary.cavityVolume, one.report.summary.cavityVolume,
              1e-9 * one.report.summary.cavityVolume);
  sim::Model a1 = one.model, a2 = two.model;
  for (const auto& [lung1, lung2] :
       {std::pair{&a1.lungs.right, &a2.lungs.right}, {&a1.lungs.left, &a2.lungs.left}}) {
    Eigen::Matrix3Xd c, x1, x2;
    c = restPoints(a1.cavity.vertices, a1);
    sim::lungPositions(*lung1, c, x1);
    c = restPoints(a2.cavity.vertices, a2);
    sim::lungPositions(*lung2, c, x2);
    EXPECT_NEAR(enclosedVolume(x2, lung2->triangles), enclosedVolume(x1, lung1->triangles), 1e-9);
  }
  a2.cavity = a1.cavity;
  a2.lungs = a1.lungs;
  EXPECT_TRUE(sim::serializeModel(a1) == sim::serializeModel(a2)) << "two builds differ";

  const fs::path dir = fs::temp_directory_path() / ("pneuma_mesh_test_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  { std::ofstream(dir / "model.json") << "{}"; }  // an earlier model
  { std::ofstream(dir / "stale.txt") << "old"; }
  writeModelDirectory(one, dir.string());
  EXPECT_FALSE(fs::exists(dir / "stale.txt"));
  for (const auto& e : fs::directory_iterator(dir.parent_path()))
    EXPECT_EQ(e.path().filename().string().rfind(dir.filename().string() + ".", 0), std::string::npos)
        << e.path();
  EXPECT_TRUE(fs::exists(dir / "meshes" / "sternum.vtp"));
  const sim::Model loaded = sim::loadModel(dir.string());
  EXPECT_TRUE(sim::serializeModel(loaded) == sim::serializeModel(one.model))
      << "model.json does not round-trip";
  fs::remove_all(dir);
}

// data loss: a folder that is not a model is never replaced, and siblings the writer did not make survive
TEST(ModelBuilder, WriterReplacesOnlyModelDirectoriesAndLeavesSiblingsAlone) {
  namespace fs = std::filesystem;
  const BuiltModel one = buildModel(loadAnatomy(std::string(PNEUMA_RESOURCE_DIR) + "/anatomy/female.json"));
  const fs::path base = fs::temp_directory_path() / ("pneuma_mesh_siblings_" + std::to_string(::getpid()));
  fs::remove_all(base);
  const fs::path dir = base / "m";
  fs::create_directories(dir);
  { std::ofstream(dir / "thesis.tex") << "precious"; }
  for (const char* sib : {".old", ".tmp"}) {
    fs::create_directories(dir.string() + sib);
    std::ofstream(dir.string() + sib + "/keep.txt") << "mine";
  }
  try {
    writeModelDirectory(one, dir.string());
    ADD_FAILURE() << "a non-model folder was replaced";
  } catch (const sim::Error& e) {
    EXPECT_NE(std::string(e.what()).find("not a model directory"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::exists(dir / "thesis.tex"));

  // an empty folder, given with a trailing slash, takes the model; then the model is rebuilt in place
  fs::remove(dir / "thesis.tex");
  writeModelDirectory(one, dir.string() + "/");
  writeModelDirectory(one, dir.string() + "/");
  EXPECT_TRUE(fs::exists(dir / "model.json"));
  for (const char* sib : {".old", ".tmp"}) EXPECT_TRUE(fs::exists(dir.string() + sib + "/keep.txt")) << sib;
  int entries = 0;
  for (const auto& e : fs::directory_iterator(base)) entries += e.is_directory() ? 1 : 0;
  EXPECT_EQ(entries, 3);  // m, m.old, m.tmp: nothing left behind
  fs::remove_all(base);
}

TEST_P(BuiltPresets, CorruptedModelJsonIsRejected) {
  // a built model written out, then one rest length zeroed in the file
  nlohmann::json j = nlohmann::json::parse(sim::serializeModel(model()));
  j["elements"][3]["rest_length"] = 0.0;
  try {
    sim::parseModel(j.dump());
    FAIL() << "zero rest length accepted";
  } catch (const sim::Error& e) {
    EXPECT_NE(std::string(e.what()).find("elements[3].rest_length: must be > 0"), std::string::npos)
        << e.what();
  }
}

// the skin: a closed body surface free of self-crossings, no vertex inside or within 5 mm of a bone,
// registered to the landmarks within 20 mm, and bound through a TetGen mesh of the soft tissue
TEST_P(BuiltPresets, SkinIsAClosedBodySurfaceOutsideEveryBone) {
  const sim::Model& m = model();
  ASSERT_GT(m.skin.vertexCount(), 5000);
  EXPECT_GT(m.skin.tetrahedra, m.skin.vertexCount());
  Eigen::Matrix3Xd x;
  sim::skinPositions(m.skin, restPoints(m.skin.anchors, m), x);
  EXPECT_EQ(pneuma::test::countSelfCrossings(x, m.skin.triangles), 0);
  // a body without its lower legs and feet: 40-100 L
  const double volume = enclosedVolume(x, m.skin.triangles);
  EXPECT_GT(volume, 0.040);
  EXPECT_LT(volume, 0.100);

  int inside = 0;
  for (int b = 0; b < m.bodies.size(); ++b) {
    const TriangleMesh& mesh = built().bodyMeshes[static_cast<std::size_t>(b)];
    const Eigen::Matrix3Xd bone = mesh.vertices.colwise() + m.bodies.com.col(b);
    const Eigen::Vector3d lo = bone.rowwise().minCoeff(), hi = bone.rowwise().maxCoeff();
    for (int i = 0; i < x.cols(); ++i) {
      const Eigen::Vector3d p = x.col(i);
      if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any()) continue;
      if (pneuma::test::isInside(p, bone, mesh.triangles)) {
        ++inside;
        ADD_FAILURE() << "skin vertex " << i << " inside " << m.bodies.name[static_cast<std::size_t>(b)];
        if (inside > 5) return;
      }
    }
  }
  EXPECT_GE(built().report.skinBoneClearance, 0.005);
  EXPECT_LT(built().report.skinLandmarkResidual, 0.020);
  RecordProperty("skin_bone_clearance_mm", std::to_string(built().report.skinBoneClearance * 1e3));
  RecordProperty("skin_landmark_residual_mm", std::to_string(built().report.skinLandmarkResidual * 1e3));
}

// the pectoral volume bodies (meshing/src/TissueBodies.h): closed lenses of a plausible volume on the chest
// wall, between the bones and the skin, their deep face tied to the bones and their superficial face free
// (TissueChecks.h)
TEST_P(BuiltPresets, PectoralVolumesLieBetweenTheBonesAndTheSkin) {
  const sim::Model& m = model();
  ASSERT_GE(m.volumes.size(), 2);
  EXPECT_EQ(m.volumes.name[0], "pectoral_right");
  EXPECT_EQ(m.volumes.name[1], "pectoral_left");
  // [m^3] pectoralis major with its fascia: 100-400 mL
  for (const char* name : {"pectoral_right", "pectoral_left"})
    pneuma::test::expectBetweenBonesAndSkin(built(), name, 50e-6, 600e-6);
}

// the pectorals slide on the chest wall, not into it: at the end of a deep inhale (the largest lung volume of
// a deep breath after settling) no volume-body node lies inside a bone. Their sliding deep nodes are held
// along the chest wall's normal (TissueBodies.h); held along each rib's own normal, which tilts about 40 deg
// down at the front of the lower ribs, 23 of them sank up to 2.2 mm into ribs 3-6 of the male preset
TEST_P(BuiltPresets, VolumeBodiesStayOutOfTheBonesInADeepBreath) {
  const BuiltModel& b = built();
  const auto model = std::make_shared<const sim::Model>(b.model);
  const sim::Model& m = *model;
  sim::SimulationOptions o;
  o.outputRate = 30.0;
  o.recordSeconds = sim::kTraceOnlyRecordSeconds;
  sim::Simulation run(model, std::make_unique<sim::BreathStyleController>(sim::loadBreathStyle("deep")), o);
  sim::State hi;
  double most = 0.0;  // [m^3]
  run.advance(o.settleTime + 7.0, [&](const sim::Simulation& s) {
    if (s.state().time >= o.settleTime && s.latestMetrics().lungVolume > most) {
      most = s.latestMetrics().lungVolume;
      hi = s.state();
    }
    return true;
  });
  ASSERT_GT(most, 0.0);
  int inside = 0;
  for (int i = 0; i < m.bodies.size(); ++i) {
    const meshing::TriangleMesh& mesh = b.bodyMeshes[static_cast<std::size_t>(i)];
    const Eigen::Matrix3Xd bone =
        (hi.bodyOrientation[static_cast<std::size_t>(i)].toRotationMatrix() * mesh.vertices).colwise() +
        hi.bodyPosition.col(i);
    const Eigen::Vector3d lo = bone.rowwise().minCoeff(), up = bone.rowwise().maxCoeff();
    for (int n = 0; n < m.nodes.size(); ++n) {
      if (m.nodes.region[static_cast<std::size_t>(n)] != sim::NodeRegion::Tissue) continue;
      const Eigen::Vector3d p = hi.nodePosition.col(n);
      if ((p.array() < lo.array()).any() || (p.array() > up.array()).any()) continue;
      if (pneuma::test::isInside(p, bone, mesh.triangles) && inside++ < 5)
        ADD_FAILURE() << "node " << n << " inside " << m.bodies.name[static_cast<std::size_t>(i)];
    }
  }
  RecordProperty("tissue_nodes_inside_bones", std::to_string(inside));
  EXPECT_EQ(inside, 0);
}

INSTANTIATE_TEST_SUITE_P(Presets, BuiltPresets, ::testing::Values("male", "female"));

}  // namespace
}  // namespace pneuma::meshing
