#include "pneuma/meshing/ModelBuilder.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>

#include "Anchors.h"
#include "GutSurface.h"
#include "LungCavity.h"
#include "MuscleNetwork.h"
#include "Skeleton.h"
#include "Skin.h"
#include "TissueBodies.h"
#include "pneuma/meshing/MeshTools.h"
#include "pneuma/meshing/Tetrahedralizer.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/ModelIO.h"

namespace pneuma::meshing {

namespace {

constexpr double kTetVolumeTolerance = 1e-3;  // [-] TetGen vs divergence-theorem gut volume

/// Remeshes every bone (a left rib is the mirror image of its remeshed right rib) and fills the bodies.
void buildBodies(const AnatomyParams& a, const Skeleton& sk, BuiltModel& out) {
  std::map<int, int> mirrorOf;  // left rib -> right rib
  for (const auto& pair : sk.rib) mirrorOf[pair[kLeft]] = pair[kRight];
  if (sk.hasGirdle) {
    const GirdleSide &r = sk.girdle[kRight], &l = sk.girdle[kLeft];
    for (const auto& [left, right] : {std::pair{l.clavicle, r.clavicle}, std::pair{l.scapula, r.scapula},
                                      std::pair{l.humerus, r.humerus}, std::pair{l.forearm, r.forearm}})
      mirrorOf[left] = right;
  }

  const int n = static_cast<int>(sk.bones.size());
  std::vector<TriangleMesh> world(static_cast<std::size_t>(n));
  sim::Bodies& b = out.model.bodies;
  b.mass.resize(n);
  b.com.resize(3, n);
  for (int i = 0; i < n; ++i) {
    const Bone& bone = sk.bones[static_cast<std::size_t>(i)];
    auto m = mirrorOf.find(i);
    world[static_cast<std::size_t>(i)] = m != mirrorOf.end()
                                             ? world[static_cast<std::size_t>(m->second)].mirroredX()
                                             : remeshIsotropic(bone.mesh, a.resolution.boneEdge, bone.name);
    const MassProperties mp = massProperties(world[static_cast<std::size_t>(i)], a.boneDensity);
    // a segment of given mass: the mesh's shape at the density that gives it
    const double scale = bone.mass > 0.0 ? bone.mass / mp.mass : 1.0;
    b.name.push_back(bone.name);
    b.isFixed.push_back(bone.isFixed ? 1 : 0);
    if (bone.isSupported) {
      b.isSupported.resize(static_cast<std::size_t>(n), 0);
      b.isSupported[static_cast<std::size_t>(i)] = 1;
    }
    if (bone.hangsFrom) {
      if (b.supportHeight.size() == 0) b.supportHeight.setZero(n);
      b.supportHeight(i) = (*bone.hangsFrom - mp.com).norm();
    }
    b.mass(i) = scale * mp.mass;
    b.com.col(i) = mp.com;
    b.inertia.push_back(scale * mp.inertia);
    b.mesh.push_back("meshes/" + bone.name + ".vtp");
    out.bodyMeshes.push_back(world[static_cast<std::size_t>(i)].translated(-mp.com));
    out.report.boneTriangles += world[static_cast<std::size_t>(i)].triangleCount();
  }
}

void buildJoints(const AnatomyParams& a, const Skeleton& sk, sim::Joints& j) {
  const int n = static_cast<int>(sk.joints.size());
  j.anchor.resize(3, n);
  j.friction.resize(n);
  j.stiffness.resize(n);
  j.axis.resize(3, n);
  j.lockStiffness.resize(n);
  for (int i = 0; i < n; ++i) {
    const JointSpec& s = sk.joints[static_cast<std::size_t>(i)];
    j.name.push_back(s.name);
    j.parent.push_back(s.parent);
    j.child.push_back(s.child);
    j.anchor.col(i) = s.anchor;
    const JointGains& g = a.gains.joints[static_cast<std::size_t>(s.kind)];
    j.friction(i) = s.kind == kCostovertebralJoint ? a.ribJointFrictionScale * g.friction : g.friction;
    j.stiffness(i) = g.stiffness;
    j.axis.col(i) = s.axis;
    j.lockStiffness(i) = g.lockStiffness;
  }
}

/// Gut nodes with equal point masses within a region: the moving wall nodes add up to the wall mass
/// (8 kg, Section 6.1), the dome nodes to the diaphragm's mass; fixed nodes weigh as much as a wall node.
void buildGutNodes(const AnatomyParams& a, const GutSurface& g, BuiltModel& out) {
  sim::Model& m = out.model;
  m.nodes.rest = g.rest;
  m.nodes.region = g.region;
  const auto count = [&](sim::NodeRegion region) {
    return std::count(g.region.begin(), g.region.end(), region);
  };
  const double wallNode = a.gains.wallMass / static_cast<double>(count(sim::NodeRegion::Wall));
  const double domeNode = a.gains.diaphragmMass / static_cast<double>(count(sim::NodeRegion::Diaphragm));
  m.nodes.mass.resize(g.rest.cols());
  for (Eigen::Index i = 0; i < g.rest.cols(); ++i) {
    m.nodes.mass(i) =
        g.region[static_cast<std::size_t>(i)] == sim::NodeRegion::Diaphragm ? domeNode : wallNode;
  }
  m.gut.triangles = g.triangles;
  m.gut.kappa = a.gains.gutKappa;
  m.gut.drag = a.gains.gutDrag;
  m.gut.wallToneUpright = a.gains.wallToneUpright;

  // tetrahedralise the enclosed volume and check it against the surface volume
  TriangleMesh surface{g.rest, g.triangles};
  const MeshCheck check = checkMesh(surface);
  if (!check.isValid()) {
    throw sim::Error(std::string("gut: surface is not sealed: manifold ") +
                     (check.isManifold ? "yes" : "no") + ", closed " + (check.isClosed ? "yes" : "no") +
                     ", self-intersecting " + (check.isSelfIntersecting ? "yes" : "no") + ", outward " +
                     (check.isOutward ? "yes" : "no"));
  }
  const TetMesh tets = tetrahedralize(surface, "gut");
  const double v = enclosedVolume(g.rest, g.triangles);
  if (std::abs(tets.volume - v) > kTetVolumeTolerance * v) {
    std::ostringstream s;
    s << "gut: TetGen volume " << tets.volume * 1e6 << " mL differs from the surface volume " << v * 1e6
      << " mL";
    throw sim::Error(s.str());
  }
  out.report.tetrahedra = static_cast<int>(tets.tets.cols());
  out.report.tetVolume = tets.volume;

  // pressure-surface triangle quality
  double qMin = 1.0, qSum = 0.0;
  for (int f = 0; f < g.triangles.cols(); ++f) {
    const double q = triangleQuality(g.rest.col(g.triangles(0, f)), g.rest.col(g.triangles(1, f)),
                                     g.rest.col(g.triangles(2, f)));
    qMin = std::min(qMin, q);
    qSum += q;
  }
  out.report.gutQualityMin = qMin;
  out.report.gutQualityMean = qSum / static_cast<double>(g.triangles.cols());
}

void buildLandmarks(const AnatomyParams& a, const Skeleton& sk, const GutSurface& g, sim::Model& m) {
  auto add = [&](const std::string& name, const Endpoint& e) {
    m.landmarks.name.push_back(name);
    addEndpoint(m.landmarks.points, e, m.bodies);
  };
  add("xiphoid", Endpoint::onBody(sk.sternum, sk.xiphoidTip));
  add("jugular_notch", Endpoint::onBody(sk.sternum, sk.jugularNotch));
  // umbilicus: the anterior midline wall node nearest the preset's umbilicus height
  int navel = g.wallRing.front().front();
  for (const auto& ring : g.wallRing) {
    const int n = ring.front();
    if (std::abs(g.rest(2, n) - a.abdomen.umbilicusLevel) <
        std::abs(g.rest(2, navel) - a.abdomen.umbilicusLevel))
      navel = n;
  }
  add("umbilicus", Endpoint::atNode(navel, g.rest));
  add("diaphragm_apex", Endpoint::atNode(g.apex, g.rest));
  // rib 8 lateral: its centreline point farthest from the midline
  for (int side : {kRight, kLeft}) {
    const RibCurve& r = sk.ribCurve[7][static_cast<std::size_t>(side)];
    std::size_t best = 0;
    for (std::size_t i = 0; i < r.centre.size(); ++i) {
      if (std::abs(r.centre[i].x()) > std::abs(r.centre[best].x())) best = i;
    }
    add(side == kRight ? "rib8_lateral_right" : "rib8_lateral_left",
        Endpoint::onBody(sk.rib[7][static_cast<std::size_t>(side)], r.centre[best]));
  }
  // acromions: the superolateral tips of the scapulae, when the model has them
  if (sk.hasGirdle)
    for (int side : {kRight, kLeft}) {
      const GirdleSide& s = sk.girdle[static_cast<std::size_t>(side)];
      add(side == kRight ? "acromion_right" : "acromion_left", Endpoint::onBody(s.scapula, s.acromion));
    }
}

}  // namespace

BuiltModel buildModel(const AnatomyParams& a, const std::string& skinFile) {
  BuiltModel out;
  out.model.name = a.name;
  out.model.anatomy = a.source.substr(a.source.find_last_of('/') + 1);

  // bones and joints
  const Skeleton sk = buildSkeleton(a);
  buildBodies(a, sk, out);
  buildJoints(a, sk, out.model.joints);

  // gut, elements, cavity and landmarks
  const GutSurface gut = buildGut(a, sk);
  buildGutNodes(a, gut, out);
  buildElements(a, sk, gut, out.model);
  buildCavity(sk, gut, out.model);
  out.model.cavity.recoilPressure = a.gains.lungRecoil;
  out.model.cavity.compliance = a.gains.lungCompliance;
  buildLandmarks(a, sk, gut, out.model);
  // the pectoral and shoulder volume bodies, on the bones and under the skin
  buildTissueBodies(a, sk, out.model);
  if (!skinFile.empty()) {
    if (skinFile == kDefaultSkinFile && !std::filesystem::exists(skinFile))
      throw sim::Error(
          skinFile +
          ": the default skin mesh is missing; install it with 'apt-get install assimp-testmodels' "
          "(Debian) or give another with --skin FILE");
    buildSkin(a, skinFile, out);
  }

  sim::validateModel(out.model);
  out.report.summary = summarizeModel(out.model);
  return out;
}

}  // namespace pneuma::meshing
