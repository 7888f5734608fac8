#include "Skeleton.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <tuple>
#include <utility>

#include "pneuma/meshing/Sweep.h"
#include "pneuma/sim/Error.h"

namespace pneuma::meshing {

namespace {

constexpr int kAround = 10;       // cross-section points of bone sweeps (remeshing refines them)
constexpr int kRibStations = 48;  // centreline samples per rib

/// One vertebral body of the stacked column.
struct Vertebra {
  double zBottom = 0.0;  // [m]
  double zTop = 0.0;     // [m]
  double width = 0.0;    // [m]
  double depth = 0.0;    // [m]
  double y = 0.0;        // [m] centre
};

/// Vertebrae L5..L1 then T12..T1, stacked from z = 0; thoracic ones follow the kyphosis.
std::vector<Vertebra> stackVertebrae(const SpineParams& s) {
  std::vector<Vertebra> v;
  double z = 0.0;
  for (double h : s.lumbarHeights) {
    v.push_back({z, z + h, s.lumbarBody[0], s.lumbarBody[1], 0.0});
    z += h + s.lumbarDisc;
  }
  for (int i = 0; i < 12; ++i) {
    const double f = i / 11.0;  // 0 at T12, 1 at T1
    const double h = s.thoracicHeights[static_cast<std::size_t>(i)];
    v.push_back({z, z + h, (1 - f) * s.thoracicBodyBottom[0] + f * s.thoracicBodyTop[0],
                 (1 - f) * s.thoracicBodyBottom[1] + f * s.thoracicBodyTop[1], 0.0});
    z += h + s.thoracicDisc;
  }
  // thoracic kyphosis: a half sine bulging backward between T12 and T1
  const double z0 = v[5].zBottom;
  const double z1 = v.back().zTop;
  for (std::size_t i = 5; i < v.size(); ++i) {
    const double zc = 0.5 * (v[i].zBottom + v[i].zTop);
    v[i].y = -s.kyphosis * std::sin(M_PI * (zc - z0) / (z1 - z0));
  }
  return v;
}

/// The vertebral body as an elliptic cylinder and its spinous process as a separate small tube.
TriangleMesh vertebraMesh(const Vertebra& v, double spinousLength) {
  const double zc = 0.5 * (v.zBottom + v.zTop);
  const double h = v.zTop - v.zBottom;
  std::vector<SweepStation> body;
  for (double z : {v.zBottom, zc, v.zTop}) {
    body.push_back({Eigen::Vector3d(0, v.y, z), Eigen::Vector3d::UnitX(), 0.5 * v.width, 0.5 * v.depth});
  }
  TriangleMesh m = sweepTube(body, kAround, false);
  // spinous process: backward and 30 degrees down, starting behind the vertebral arch gap
  const Eigen::Vector3d start(0, v.y - 0.5 * v.depth - 0.012, zc);
  const Eigen::Vector3d dir(0, -std::cos(M_PI / 6), -std::sin(M_PI / 6));
  std::vector<SweepStation> spine;
  for (double f : {0.0, 0.5, 1.0}) {
    spine.push_back({start + f * spinousLength * dir, Eigen::Vector3d::UnitZ(), 0.3 * h, 0.004});
  }
  m.append(sweepTube(spine, kAround, false));
  return m;
}

/// Centreline of a right rib in its plane (u lateral, v anterior): the "half-egg" curve of RibLevel.
Eigen::Vector2d ribPlanar(const RibLevel& r, double lateral, double theta) {
  const double b = (std::sin(theta) > 0 ? r.posteriorRatio : r.anteriorRatio) * lateral;
  return {lateral * (1.0 - std::cos(theta)), -b * std::sin(theta)};
}

/// Builds the right rib `r` with its head at `head`; the centreline has the preset's arc length.
RibCurve ribCurve(const RibLevel& r, const Eigen::Vector3d& head) {
  // arc length of the unit-size curve, then the lateral semi-axis that gives the preset length
  constexpr int kFine = 2000;
  double unitLength = 0.0;
  for (int i = 0; i < kFine; ++i) {
    unitLength +=
        (ribPlanar(r, 1.0, r.endAngle * (i + 1) / kFine) - ribPlanar(r, 1.0, r.endAngle * i / kFine)).norm();
  }
  const double lateral = r.arcLength / unitLength;

  // rib plane: pitched down anteriorly, then tilted down laterally
  const Eigen::Matrix3d rot = (Eigen::AngleAxisd(r.lateralTilt, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(-r.inclination, Eigen::Vector3d::UnitX()))
                                  .toRotationMatrix();
  const Eigen::Vector3d normal = rot.col(2);

  RibCurve c;
  c.height = r.height;
  c.thickness = r.thickness;
  for (int i = 0; i < kRibStations; ++i) {
    const double theta = r.endAngle * i / (kRibStations - 1);
    const Eigen::Vector2d p = ribPlanar(r, lateral, theta);
    c.centre.push_back(head + rot * Eigen::Vector3d(p.x(), p.y(), 0.0));
    c.normal.push_back(normal);
  }
  c.arc.push_back(0.0);
  for (int i = 1; i < kRibStations; ++i) {
    c.arc.push_back(
        c.arc.back() +
        (c.centre[static_cast<std::size_t>(i)] - c.centre[static_cast<std::size_t>(i - 1)]).norm());
  }
  // the curve turns counter-clockwise about the plane normal: inward = normal x tangent
  for (int i = 0; i < kRibStations; ++i)
    c.inward.push_back(normal.cross(c.tangent(c.arc[static_cast<std::size_t>(i)])).normalized());
  return c;
}

RibCurve mirrored(const RibCurve& c) {
  RibCurve m = c;
  for (auto* pts : {&m.centre, &m.inward, &m.normal}) {
    for (Eigen::Vector3d& p : *pts) p.x() = -p.x();
  }
  return m;
}

TriangleMesh ribMesh(const RibCurve& c) {
  std::vector<SweepStation> st;
  for (std::size_t i = 0; i < c.centre.size(); ++i) {
    // the neck near the head is slimmer
    const double taper = std::min(1.0, 0.6 + 0.4 * c.arc[i] / (0.12 * c.length()));
    st.push_back({c.centre[i], c.normal[i], 0.5 * c.height * taper, 0.5 * c.thickness});
  }
  return sweepTube(st, kAround, false);
}

/// Smallest distance between two rib centrelines [m].
double centrelineDistance(const RibCurve& a, const RibCurve& b) {
  double d = 1e9;
  for (const auto& p : a.centre) {
    for (const auto& q : b.centre) d = std::min(d, (p - q).norm());
  }
  return d;
}

}  // namespace

Eigen::Vector3d RibCurve::at(double s, double offsetIn, double offsetUp) const {
  s = std::clamp(s, 0.0, length());
  const std::size_t i = static_cast<std::size_t>(std::clamp<long>(
      std::upper_bound(arc.begin(), arc.end(), s) - arc.begin() - 1, 0, static_cast<long>(arc.size()) - 2));
  const double f = (s - arc[i]) / (arc[i + 1] - arc[i]);
  const Eigen::Vector3d p = (1 - f) * centre[i] + f * centre[i + 1];
  const Eigen::Vector3d in = ((1 - f) * inward[i] + f * inward[i + 1]).normalized();
  return p + offsetIn * in + offsetUp * normal[i];
}

Eigen::Vector3d RibCurve::tangent(double s) const {
  const double h = 0.25 * length() / static_cast<double>(centre.size());
  const double a = std::clamp(s - h, 0.0, length() - 2 * h);
  const std::size_t i = static_cast<std::size_t>(std::clamp<long>(
      std::upper_bound(arc.begin(), arc.end(), a) - arc.begin() - 1, 0, static_cast<long>(arc.size()) - 2));
  return (centre[i + 1] - centre[i]).normalized();
}

Skeleton buildSkeleton(const AnatomyParams& a) {
  Skeleton sk;
  const std::vector<Vertebra> vert = stackVertebrae(a.spine);
  auto thoracic = [&](int t) -> const Vertebra& {
    return vert[static_cast<std::size_t>(4 + 13 - t)];
  };  // T1..T12
  auto addBone = [&](const std::string& name, bool isFixed, TriangleMesh mesh) {
    sk.bones.push_back({name, isFixed, std::move(mesh), 0.0, false, std::nullopt});
    return static_cast<int>(sk.bones.size()) - 1;
  };

  // fixed lumbar spine L5..L1
  TriangleMesh lumbar;
  for (int i = 0; i < 5; ++i)
    lumbar.append(vertebraMesh(vert[static_cast<std::size_t>(i)], a.spine.spinousLength));
  sk.lumbar = addBone("lumbar_spine", true, lumbar);
  for (int i = 4; i >= 2; --i) {
    const Vertebra& v = vert[static_cast<std::size_t>(i)];
    sk.lumbarFront.emplace_back(0.0, v.y + 0.5 * v.depth, 0.5 * (v.zBottom + v.zTop));
  }

  // fixed pelvis: two iliac wings, the sacrum and the pubic arch (separate closed components)
  {
    const PelvisParams& p = a.pelvis;
    const double zc = 0.5 * p.height - 0.03;  // wing centre: crest near L4
    TriangleMesh pelvis;
    std::vector<SweepStation> wing;
    for (int i = 0; i <= 12; ++i) {
      const double t = M_PI * i / 12.0;  // sacroiliac joint (t = 0) to anterior superior iliac spine (t = pi)
      const Eigen::Vector3d c(0.055 + (0.5 * p.width - 0.07) * std::sin(t),
                              -0.04 + 0.5 * (p.depth + 0.04) * (1 - std::cos(t)), zc - 0.02 * std::sin(t));
      const Eigen::Vector3d up = Eigen::Vector3d(0.35 * std::sin(t), 0, 1).normalized();  // flared outward
      wing.push_back({c, up, 0.5 * p.height * (0.6 + 0.4 * std::sin(t)), 0.006});
    }
    TriangleMesh right = sweepTube(wing, kAround, false);
    pelvis.append(right);
    pelvis.append(right.mirroredX());
    std::vector<SweepStation> sacrum;
    for (int i = 0; i <= 4; ++i) {
      const double f = i / 4.0;
      sacrum.push_back({Eigen::Vector3d(0, -0.015 - 0.05 * f * f, -0.012 - 0.10 * f),
                        Eigen::Vector3d::UnitX(), 0.05 * (1 - 0.7 * f), 0.012});
    }
    pelvis.append(sweepTube(sacrum, kAround, false));
    std::vector<SweepStation> pubis;
    for (int i = 0; i <= 8; ++i) {
      const double t =
          -0.5 * M_PI + M_PI * i / 8.0;  // from the left ramus round the symphysis to the right one
      pubis.push_back({Eigen::Vector3d(0.09 * std::sin(t), p.depth - 0.03 + 0.03 * std::cos(t),
                                       a.abdomen.floorLevel - 0.01 + 0.03 * std::abs(std::sin(t))),
                       Eigen::Vector3d::UnitZ(), 0.012, 0.008});
    }
    pelvis.append(sweepTube(pubis, kAround, false));
    sk.pelvis = addBone("pelvis", true, pelvis);
  }

  // articulated thoracic segments; each holds its vertebrae
  sk.thoracicSegment.assign(12, -1);
  for (std::size_t s = 0; s < a.spine.thoracicSegments.size(); ++s) {
    const auto [first, last] = a.spine.thoracicSegments[s];
    TriangleMesh mesh;
    for (int t = first; t <= last; ++t) mesh.append(vertebraMesh(thoracic(t), a.spine.spinousLength));
    const int b = addBone("thoracic_T" + std::to_string(first) + "_T" + std::to_string(last), false, mesh);
    for (int t = first; t <= last; ++t) sk.thoracicSegment[static_cast<std::size_t>(t - 1)] = b;
  }
  for (int t = 1; t <= 12; ++t) {
    sk.vertebraTop.push_back(thoracic(t).zTop);
    sk.vertebraCentreY.push_back(thoracic(t).y);
    const Vertebra& v = thoracic(t);
    sk.thoracicFront.emplace_back(0.0, v.y + 0.5 * v.depth, 0.5 * (v.zBottom + v.zTop));
  }
  // spine joints at the disc centres, from the lumbar spine upward
  for (std::size_t s = a.spine.thoracicSegments.size(); s-- > 0;) {
    const int last = a.spine.thoracicSegments[s][1];
    const Vertebra& below = last == 12 ? vert[4] : thoracic(last + 1);
    const Vertebra& above = thoracic(last);
    const int parent = last == 12 ? sk.lumbar : sk.thoracicSegment[static_cast<std::size_t>(last)];
    const int child = sk.thoracicSegment[static_cast<std::size_t>(last - 1)];
    sk.joints.push_back({"spine_" + sk.bones[static_cast<std::size_t>(child)].name, parent, child,
                         Eigen::Vector3d(0, 0.5 * (below.y + above.y), 0.5 * (below.zTop + above.zBottom)),
                         kSpineJoint});
  }

  // sternum: manubrium, body and xiphoid swept down and forward from the jugular notch
  {
    const SternumParams& s = a.sternum;
    const int lo = std::clamp(static_cast<int>(std::floor(s.notchLevel)), 1, 11);
    const double f = s.notchLevel - lo;
    auto zc = [&](int t) { return 0.5 * (thoracic(t).zBottom + thoracic(t).zTop); };
    const Eigen::Vector3d notch(0, (1 - f) * thoracic(lo).y + f * thoracic(lo + 1).y + s.notchDepth,
                                (1 - f) * zc(lo) + f * zc(lo + 1));
    sk.sternumAxis = Eigen::Vector3d(0, std::sin(s.inclination), -std::cos(s.inclination));
    const double total = s.manubriumLength + s.bodyLength + s.xiphoidLength;
    auto widthAt = [&](double d) {
      if (d < s.manubriumLength)
        return s.manubriumWidth + (s.bodyWidth - s.manubriumWidth) * d / s.manubriumLength;
      if (d < s.manubriumLength + s.bodyLength) return s.bodyWidth;
      return s.bodyWidth * (0.55 - 0.35 * (d - s.manubriumLength - s.bodyLength) / s.xiphoidLength);
    };
    std::vector<SweepStation> st;
    constexpr int kStations = 24;
    for (int i = 0; i <= kStations; ++i) {
      const double d = total * i / kStations;
      const double thick = d > s.manubriumLength + s.bodyLength ? 0.5 * s.thickness : s.thickness;
      st.push_back({notch + d * sk.sternumAxis, Eigen::Vector3d::UnitX(), 0.5 * widthAt(d), 0.5 * thick});
      const Eigen::Vector3d back = sk.sternumAxis.cross(Eigen::Vector3d::UnitX()).normalized();  // posterior
      sk.sternumInner.push_back(notch + d * sk.sternumAxis + (0.5 * thick + 0.004) * back);
    }
    sk.sternum = addBone("sternum", false, sweepTube(st, kAround, false));
    sk.xiphoidTip = notch + total * sk.sternumAxis;
    sk.jugularNotch = notch;
    // costal notches: rib 1 on the manubrium, rib 2 at the sternal angle, 3-6 along the body, 7 at the
    // xiphisternal joint
    for (int r = 1; r <= 7; ++r) {
      const double d = r == 1 ? 0.35 * s.manubriumLength : s.manubriumLength + s.bodyLength * (r - 2) / 5.0;
      const Eigen::Vector3d c = notch + d * sk.sternumAxis;
      const double half = 0.5 * widthAt(d);
      sk.costalNotch.push_back({c + Eigen::Vector3d(half, 0, 0), c - Eigen::Vector3d(half, 0, 0)});
    }
  }

  // ribs: heads at the top of their thoracic vertebra, right side built, left side mirrored
  for (int level = 1; level <= 12; ++level) {
    const Vertebra& v = thoracic(level);
    const Eigen::Vector3d head(0.5 * v.width + 0.004, v.y - 0.25 * v.depth, v.zTop);
    const RibCurve right = ribCurve(a.ribs[static_cast<std::size_t>(level - 1)], head);
    const RibCurve left = mirrored(right);
    const bool isFixed = level > 10 && !a.areFloatingRibsMoving;
    const TriangleMesh mesh = ribMesh(right);
    const std::string n = "rib" + std::to_string(level);
    const int br = addBone(n + "_right", isFixed, mesh);
    const int bl = addBone(n + "_left", isFixed, mesh.mirroredX());
    sk.rib.push_back({br, bl});
    sk.ribCurve.push_back({right, left});
    if (!isFixed) {
      // the rib-neck axis runs from the head laterally and backward to the tubercle
      const double phi = a.ribs[static_cast<std::size_t>(level - 1)].neckAxis;
      const Eigen::Vector3d axisRight(std::cos(phi), -std::sin(phi), 0.0),
          axisLeft(-std::cos(phi), -std::sin(phi), 0.0);
      const int parent = sk.thoracicSegment[static_cast<std::size_t>(level - 1)];
      sk.joints.push_back({"costovertebral_" + n + "_right", parent, br, right.centre.front(),
                           kCostovertebralJoint, axisRight});
      sk.joints.push_back(
          {"costovertebral_" + n + "_left", parent, bl, left.centre.front(), kCostovertebralJoint, axisLeft});
    }
  }

  // neighbouring ribs must not touch
  for (int level = 1; level < 12; ++level) {
    const RibCurve& up = sk.ribCurve[static_cast<std::size_t>(level - 1)][kRight];
    const RibCurve& down = sk.ribCurve[static_cast<std::size_t>(level)][kRight];
    const double gap = centrelineDistance(up, down);
    const double need = 0.5 * (up.height + down.height);
    if (gap < need) {
      std::ostringstream s;
      s << a.source << ": ribs[" << level - 1 << "] and ribs[" << level
        << "] overlap: their centrelines come within " << gap * 1e3 << " mm, less than the mean rib height "
        << need * 1e3 << " mm";
      throw sim::Error(s.str());
    }
  }
  if (a.hasShoulderGirdle) addGirdle(a, sk);
  return sk;
}

}  // namespace pneuma::meshing

namespace pneuma::meshing {

namespace {

constexpr int kCervicalCount = 7;  // C7..C1
// the cervical spine in the skin mesh's neck, which is short and carries the head forward
constexpr double kCervicalHeight = 0.010;     // [m] cervical vertebral body height
constexpr double kCervicalDisc = 0.003;       // [m] cervical disc height
constexpr double kCervicalLordosis = 0.008;   // [m] anterior bulge of the cervical curve
constexpr double kCervicalLean = 0.045;       // [m] forward lean of C1 over C7
constexpr double kClavicleRetraction = 20.0;  // [deg] backward turn of the clavicle from the frontal plane
constexpr double kClavicleElevation = 10.0;   // [deg] upward tilt of the clavicle
constexpr double kScapulaClearance =
    0.012;  // [m] scapula blade behind the back of the ribs (serratus, fascia)

/// The posterior face of the rib cage behind (x, z): the back of the rib centreline point nearest in (x, z)
/// among the posterior halves of ribs 1-10 [m, y].
double backOfRibs(const Skeleton& sk, double x, double z) {
  double best = 1e9, y = 0.0;
  for (std::size_t level = 0; level < 10; ++level)
    for (const RibCurve& c : sk.ribCurve[level])
      for (std::size_t i = 0; i < c.centre.size() && c.arc[i] < 0.45 * c.length(); ++i) {
        const Eigen::Vector3d& p = c.centre[i];
        const double d = (p.x() - x) * (p.x() - x) + (p.z() - z) * (p.z() - z);
        if (d < best) {
          best = d;
          y = p.y() - 0.5 * c.thickness;
        }
      }
  return y;
}

Eigen::Vector3d sideX(int side, double x) { return Eigen::Vector3d(side == kRight ? x : -x, 0, 0); }

}  // namespace

void addGirdle(const AnatomyParams& a, Skeleton& sk) {
  const GirdleParams& g = a.girdle;
  auto addBone = [&](const std::string& name, bool isFixed, TriangleMesh mesh, double mass = 0.0) {
    sk.bones.push_back({name, isFixed, std::move(mesh), mass, !isFixed, std::nullopt});
    return static_cast<int>(sk.bones.size()) - 1;
  };
  sk.hasGirdle = true;

  // fixed cervical spine C7..C1 on T1, curving forward (lordosis), and the head on C1
  {
    const double t1Top = sk.vertebraTop.front();
    const double t1Y = sk.vertebraCentreY.front();
    TriangleMesh cervical;
    std::vector<Eigen::Vector3d> centre(kCervicalCount);
    for (int k = 0; k < kCervicalCount; ++k) {  // k = 0 is C7
      const double f = (k + 0.5) / kCervicalCount;
      Vertebra v;
      v.zBottom = t1Top + a.spine.thoracicDisc + k * (kCervicalHeight + kCervicalDisc);
      v.zTop = v.zBottom + kCervicalHeight;
      v.width = a.spine.thoracicBodyTop[0] * 0.85;
      v.depth = a.spine.thoracicBodyTop[1] * 0.9;
      v.y = t1Y + kCervicalLordosis * std::sin(M_PI * f) + kCervicalLean * f;
      cervical.append(vertebraMesh(v, k == 0 ? 0.02 : 0.01));
      centre[static_cast<std::size_t>(kCervicalCount - 1 - k)] =
          Eigen::Vector3d(0, v.y, 0.5 * (v.zBottom + v.zTop));
    }
    sk.cervicalCentre = centre;
    sk.cervical = addBone("cervical_spine", true, cervical);
    // the cranium: an ellipsoid 12 x 13 x 13.6 cm (breadth, length, height) above C1, placed from the jugular
    // notch by the proportions of the skin mesh (22.5 cm above the notch and 3.5 cm behind it), above and
    // behind the mesh's mouth cavity
    const Eigen::Vector3d headCentre = sk.jugularNotch + Eigen::Vector3d(0, -0.035, 0.225);
    std::vector<SweepStation> head;
    for (int i = 0; i <= 12; ++i) {
      const double t = M_PI * (0.06 + 0.88 * i / 12.0);
      head.push_back({headCentre + Eigen::Vector3d(0, 0, -0.068 * std::cos(t)), Eigen::Vector3d::UnitY(),
                      0.065 * std::sin(t), 0.06 * std::sin(t)});
    }
    sk.head = addBone("head", true, sweepTube(head, kAround, false));
    for (int side : {kRight, kLeft})
      sk.girdle[static_cast<std::size_t>(side)].mastoid =
          headCentre + Eigen::Vector3d(side == kRight ? 0.04 : -0.04, -0.01, -0.055);
  }

  // rib 8's lateral half-breadth sets the shoulders' breadth (acromion about 1.4 times it)
  double rib8 = 0.0;
  for (const Eigen::Vector3d& p : sk.ribCurve[7][kRight].centre) rib8 = std::max(rib8, p.x());
  const double kDeg = M_PI / 180.0;
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ(), forward = Eigen::Vector3d::UnitY();

  // joint centres and landmarks per side
  for (int side : {kRight, kLeft}) {
    GirdleSide& s = sk.girdle[static_cast<std::size_t>(side)];
    const double sx = side == kRight ? 1.0 : -1.0;
    // sternoclavicular joint at the manubrium's clavicular notch, behind its front face; the clavicle runs
    // laterally, back and up
    s.sternoclavicular = sk.jugularNotch + 0.1 * a.sternum.manubriumLength * sk.sternumAxis +
                         sideX(side, 0.5 * a.sternum.manubriumWidth + 0.003) - 0.008 * forward;
    const Eigen::Vector3d dir(sx * std::cos(kClavicleRetraction * kDeg) * std::cos(kClavicleElevation * kDeg),
                              -std::sin(kClavicleRetraction * kDeg) * std::cos(kClavicleElevation * kDeg),
                              std::sin(kClavicleElevation * kDeg));
    s.acromioclavicular = s.sternoclavicular + g.clavicleLength * dir;
    s.acromion = s.acromioclavicular + sideX(side, 0.015) + 0.004 * up - 0.005 * forward;
    // the humeral head under the acromion, slightly forward and lateral
    s.glenohumeral = s.acromioclavicular + sideX(side, 0.005) + 0.012 * forward - 0.038 * up;
    s.coracoid = s.glenohumeral + sideX(side, -0.025) + 0.028 * forward + 0.012 * up;
    // scapula: superior angle level with the top of T2, inferior angle with T7, on the back of the ribs
    const double zSup = sk.vertebraTop[1], zInf = sk.vertebraTop[6] - 0.01;
    s.superiorAngle = Eigen::Vector3d(sx * 0.07, backOfRibs(sk, sx * 0.07, zSup) - kScapulaClearance, zSup);
    s.inferiorAngle = Eigen::Vector3d(sx * 0.095, backOfRibs(sk, sx * 0.095, zInf) - kScapulaClearance, zInf);
    s.spineRoot = s.superiorAngle + 0.3 * (s.inferiorAngle - s.superiorAngle);
    // the arm in the skin's A-pose: abducted in the frontal plane, the elbow flexed forward
    const Eigen::Vector3d upperArm(sx * std::sin(g.abduction), 0.0, -std::cos(g.abduction));
    const Eigen::Vector3d forearm =
        (std::cos(g.elbowFlexion) * upperArm + std::sin(g.elbowFlexion) * forward).normalized();
    s.elbow = s.glenohumeral + g.upperArmLength * upperArm;
    s.wrist = s.elbow + g.forearmLength * forearm;
  }

  // bones, right then left (the left ones are mirrored when remeshed)
  const double armMass = g.bodyMass;
  std::array<TriangleMesh, 4> right;
  {
    const GirdleSide& s = sk.girdle[kRight];
    // clavicle: a tube between its joints
    const Eigen::Vector3d cl = s.acromioclavicular - s.sternoclavicular;
    std::vector<SweepStation> clavicle;
    for (double f : {0.04, 0.3, 0.7, 0.96})
      clavicle.push_back({s.sternoclavicular + f * cl, up, 0.006, 0.007 + 0.002 * (f < 0.2 || f > 0.8)});
    right[0] = sweepTube(clavicle, kAround, false);
    // scapula: a plate from the inferior angle up to its superior border (superior angle to acromion)
    const Eigen::Vector3d top = 0.5 * (s.superiorAngle + s.acromion);
    Eigen::Vector3d normal =
        (s.acromion - s.superiorAngle).cross(s.inferiorAngle - s.superiorAngle).normalized();
    if (normal.y() > 0) normal = -normal;  // posterior
    const double topHalf = 0.5 * (s.acromion - s.superiorAngle).norm();
    std::vector<SweepStation> blade;
    for (int i = 0; i <= 6; ++i) {
      const double f = i / 6.0;
      blade.push_back(
          {s.inferiorAngle + f * (top - s.inferiorAngle), normal, 0.0055, 0.006 + f * (topHalf - 0.006)});
    }
    right[1] = sweepTube(blade, kAround, false);
    // humerus: head, shaft and condyles
    const Eigen::Vector3d ua = s.elbow - s.glenohumeral;
    const double l = ua.norm();
    std::vector<SweepStation> humerus;
    for (const auto& [d, r] : std::initializer_list<std::pair<double, double>>{{-0.018, 0.010},
                                                                               {0.0, 0.022},
                                                                               {0.025, 0.016},
                                                                               {0.07, 0.011},
                                                                               {0.5 * l, 0.010},
                                                                               {l - 0.03, 0.012},
                                                                               {l, 0.016},
                                                                               {l + 0.012, 0.010}})
      humerus.push_back({s.glenohumeral + d / l * ua, forward, r, r});
    right[2] = sweepTube(humerus, kAround, false);
    // forearm and hand: one segment, the palm facing the thigh; the bone ends in the palm (the skin's fingers
    // follow it)
    const Eigen::Vector3d fa = (s.wrist - s.elbow).normalized();
    const Eigen::Vector3d palm = (Eigen::Vector3d::UnitX() - fa.x() * fa).normalized();
    std::vector<SweepStation> arm;
    for (const auto& [d, h, w] : std::initializer_list<std::tuple<double, double, double>>{
             {0.015, 0.011, 0.013},
             {0.3 * g.forearmLength, 0.012, 0.016},
             {g.forearmLength, 0.007, 0.015},
             {g.forearmLength + 0.3 * g.handLength, 0.006, 0.012},
             {g.forearmLength + 0.45 * g.handLength, 0.004, 0.006}})
      arm.push_back({s.elbow + d * fa, palm, h, w});
    right[3] = sweepTube(arm, kAround, false);
  }
  const double upperArmMass = g.upperArmMassFraction * armMass;
  const double forearmMass = (g.forearmMassFraction + g.handMassFraction) * armMass;
  for (int part = 0; part < 4; ++part) {
    static const char* kNames[4] = {"clavicle", "scapula", "humerus", "forearm"};
    const double mass = part == 2 ? upperArmMass : part == 3 ? forearmMass : 0.0;
    const int r =
        addBone(std::string(kNames[part]) + "_right", false, right[static_cast<std::size_t>(part)], mass);
    const int l = addBone(std::string(kNames[part]) + "_left", false,
                          right[static_cast<std::size_t>(part)].mirroredX(), mass);
    for (int side : {kRight, kLeft}) {
      GirdleSide& s = sk.girdle[static_cast<std::size_t>(side)];
      const int b = side == kRight ? r : l;
      (part == 0 ? s.clavicle : part == 1 ? s.scapula : part == 2 ? s.humerus : s.forearm) = b;
    }
  }

  // the arms hang from the shoulder joint: carried there, each segment turns back to its rest pose under its
  // weight as a pendulum from that joint would (sim::Bodies::supportHeight), so that a blade turning under an
  // arm in a deep breath does not swing it out
  for (const GirdleSide& s : sk.girdle)
    for (int part : {s.humerus, s.forearm})
      sk.bones[static_cast<std::size_t>(part)].hangsFrom = s.glenohumeral;

  // joints: sternum - clavicle - scapula - humerus - forearm
  for (int side : {kRight, kLeft}) {
    const GirdleSide& s = sk.girdle[static_cast<std::size_t>(side)];
    const std::string n = side == kRight ? "_right" : "_left";
    const Eigen::Vector3d upperArm = (s.elbow - s.glenohumeral).normalized();
    sk.joints.push_back(
        {"sternoclavicular" + n, sk.sternum, s.clavicle, s.sternoclavicular, kSternoclavicularJoint});
    sk.joints.push_back(
        {"acromioclavicular" + n, s.clavicle, s.scapula, s.acromioclavicular, kAcromioclavicularJoint});
    sk.joints.push_back({"glenohumeral" + n, s.scapula, s.humerus, s.glenohumeral, kGlenohumeralJoint});
    sk.joints.push_back({"elbow" + n, s.humerus, s.forearm, s.elbow, kElbowJoint,
                         upperArm.cross(Eigen::Vector3d::UnitY()).normalized()});
  }
}

}  // namespace pneuma::meshing
