#include "MuscleNetwork.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <tuple>
#include <utility>

#include "Anchors.h"
#include "pneuma/sim/Error.h"

namespace pneuma::meshing {

namespace {

using sim::ElementGroup;

constexpr double kObliqueShift = 0.018;  // [m] arc offset along the lower rib that makes intercostals oblique
constexpr double kMaxIntercostalGap = 0.06;  // [m] no intercostal where neighbouring ribs are farther apart
// [m] how far beyond the rib point an apposition spring is anchored (in the rib's frame), along the line from
// the dome node: a spring this long holds the node at its distance from the rib face and lets it slide along
// the face
constexpr double kAppositionSlide = 0.2;
// [m] an apposition spring is as stiff as one reaching this far when its node lies closer to the face: the
// stiffness grows as 1 / reach, and a node 11 mm in front of a vertebral body got a spring stiff enough for
// the first linearly implicit step to gain energy (Integrators_test, StrongRibFriction)
constexpr double kAppositionStiffReach = 0.015;
constexpr double kVertebralFrontHalfWidth =
    0.015;  // [m] lateral reach of the apposition points on a vertebral body's front
constexpr double kCostalSample = 0.01;     // [m] spacing of candidate costal-margin points on the lower ribs
constexpr int kRectusHalfColumns = 4;      // rectus columns on each side of the linea alba
constexpr double kScaleneLength = 0.06;    // [m] rib 1 to the scalene anchors above it (no cervical spine)
constexpr double kScaleneNeckRise = 0.10;  // [m] rib 1 to the scalenes' cervical anchors, craniocaudal
constexpr double kScaleneNeckOffset = 0.035;     // [m] the scalenes' cervical anchors off the midline
constexpr double kScapulothoracicLength = 0.10;  // [m] the scapulothoracic springs, blade to their rib points

/// Angle of `p` round the ribcage's vertical axis through (0, axisY), from the posterior midline
/// toward the sternum on either side [rad].
double aroundAxis(const Eigen::Vector3d& p, double axisY) {
  return std::atan2(std::abs(p.x()), axisY - p.y());
}

/// Arc length of the point of `c` at the same angle round the ribcage axis as `p`.
double sameAngleArc(const RibCurve& c, const Eigen::Vector3d& p, double axisY) {
  const double target = aroundAxis(p, axisY);
  std::size_t best = 0;
  for (std::size_t i = 1; i < c.centre.size(); ++i) {
    if (std::abs(aroundAxis(c.centre[i], axisY) - target) <
        std::abs(aroundAxis(c.centre[best], axisY) - target))
      best = i;
  }
  return c.arc[best];
}

/// External (down and forward) and internal (down and backward) intercostals between each rib pair.
void addIntercostals(const AnatomyParams& a, const Skeleton& sk, ElementSink& sink) {
  const int n = a.resolution.intercostalSamples;
  // the ribcage axis: mean depth of all rib centrelines
  double axisY = 0.0;
  int count = 0;
  for (const auto& pair : sk.ribCurve) {
    for (const RibCurve& c : pair) {
      for (const Eigen::Vector3d& p : c.centre) axisY += p.y();
      count += static_cast<int>(c.centre.size());
    }
  }
  axisY /= count;
  for (int side : {kRight, kLeft}) {
    for (int level = 1; level < 12; ++level) {
      const RibCurve& up = sk.ribCurve[static_cast<std::size_t>(level - 1)][static_cast<std::size_t>(side)];
      const RibCurve& low = sk.ribCurve[static_cast<std::size_t>(level)][static_cast<std::size_t>(side)];
      const int bUp = sk.rib[static_cast<std::size_t>(level - 1)][static_cast<std::size_t>(side)];
      const int bLow = sk.rib[static_cast<std::size_t>(level)][static_cast<std::size_t>(side)];
      // external layer: tubercle to costochondral junction, outside, its drive graded by space; internal: rib
      // angle to the front, inside
      const double externalScale = a.gains.externalIntercostalSpaceScale[static_cast<std::size_t>(level - 1)];
      for (const auto& [group, from, to, shift, inward] :
           {std::tuple{ElementGroup::IntercostalExternal, 0.08, 0.92, kObliqueShift, -1.0},
            std::tuple{ElementGroup::IntercostalInternal, 0.25, 0.99, -kObliqueShift, 1.0}}) {
        for (int k = 0; k < n; ++k) {
          const double s = up.length() * (from + (to - from) * (k + 0.5) / n);
          const Eigen::Vector3d top = up.at(s, 0.5 * inward * up.thickness, -0.5 * up.height);
          // the lower rib's point straight below, shifted forward (external) or backward (internal) along it
          const double sLow = sameAngleArc(low, top, axisY);
          if ((low.at(sLow) - top).norm() > kMaxIntercostalGap) continue;
          sink.add(
              group, Endpoint::onBody(bUp, top),
              Endpoint::onBody(bLow, low.at(sLow + shift, 0.5 * inward * low.thickness, 0.5 * low.height)),
              group == ElementGroup::IntercostalExternal ? externalScale : 1.0);
        }
      }
    }
  }
}

/// The candidate nearest to `p` (the first of equals); `candidates` must not be empty.
const Endpoint& nearest(const std::vector<Endpoint>& candidates, const Eigen::Vector3d& p) {
  const Endpoint* best = &candidates.front();
  for (const Endpoint& e : candidates)
    if ((e.world - p).squaredNorm() < (best->world - p).squaredNorm()) best = &e;
  return *best;
}

/// Candidate costal-margin attachments of the diaphragm: lower ribs 7-12, the xiphoid and the crura.
std::vector<Endpoint> costalMargin(const Skeleton& sk) {
  std::vector<Endpoint> c;
  for (int level = 7; level <= 12; ++level) {
    for (int side : {kRight, kLeft}) {
      const RibCurve& r = sk.ribCurve[static_cast<std::size_t>(level - 1)][static_cast<std::size_t>(side)];
      const int b = sk.rib[static_cast<std::size_t>(level - 1)][static_cast<std::size_t>(side)];
      for (double s = 0.3 * r.length(); s <= r.length(); s += kCostalSample) {
        c.push_back(Endpoint::onBody(b, r.at(s, 0.5 * r.thickness, -0.3 * r.height)));
      }
    }
  }
  c.push_back(Endpoint::onBody(sk.sternum, sk.xiphoidTip));
  for (const Eigen::Vector3d& p : sk.lumbarFront) c.push_back(Endpoint::onBody(sk.lumbar, p));
  return c;
}

/// Radial diaphragm strands: from the apex through the central tendon and out to the costal margin,
/// tied together by passive hoops.
void addDiaphragm(const Skeleton& sk, const GutSurface& gut, ElementSink& sink) {
  // between consecutive dome rings: each outer node to the inner node nearest in angle
  for (std::size_t r = 0; r < gut.domeRing.size(); ++r) {
    const std::vector<int>& outer = gut.domeRing[r];
    const bool isLast = r + 1 == gut.domeRing.size();
    const std::size_t nIn = isLast ? 1 : gut.domeRing[r + 1].size();
    for (std::size_t j = 0; j < outer.size(); ++j) {
      const std::size_t jIn =
          static_cast<std::size_t>(std::lround(static_cast<double>(j) * nIn / outer.size())) % nIn;
      const int inner = isLast ? gut.apex : gut.domeRing[r + 1][jIn];
      sink.add(ElementGroup::Diaphragm, Endpoint::atNode(outer[j], gut.rest),
               Endpoint::atNode(inner, gut.rest));
    }
  }
  // passive hoops round every inner ring keep neighbouring strands together (connective tissue, kac = 0)
  for (std::size_t r = 1; r < gut.domeRing.size(); ++r) {
    const std::vector<int>& ring = gut.domeRing[r];
    for (std::size_t j = 0; j < ring.size(); ++j) {
      sink.add(ElementGroup::Diaphragm, Endpoint::atNode(ring[j], gut.rest),
               Endpoint::atNode(ring[(j + 1) % ring.size()], gut.rest), 0.0);
    }
  }
  // rim to the nearest point of the costal margin, xiphoid or crura
  const std::vector<Endpoint> margin = costalMargin(sk);
  for (int node : gut.domeRing.front()) {
    sink.add(ElementGroup::Diaphragm, Endpoint::atNode(node, gut.rest), nearest(margin, gut.rest.col(node)));
  }
}

/// Apposition: the outer dome lies on the inner face of the lower rib cage (the zone of apposition), held
/// there by the pleural fluid, so that the abdominal pressure of an inspiration pushes on the lower ribs
/// rather than bulging the dome out between them (Loring & Mead 1982, J Appl Physiol 53:756; De Troyer &
/// Wilson 2016, J Appl Physiol 121:391). The pleural fluid holds the dome against the ribs but lets it slide
/// along them: the apposed dome shortens and descends like a piston while the ribs rise past it. The zone
/// begins at the rim, where the costal fibres leave the costal margin, and takes in the dome rings whose rise
/// above the costal margin's mean level (GutSurface::domeRingRise) is at most the zone's height
/// `a.abdomen.appositionHeight`. Unheld, the rim followed its insertions on the rising lower ribs past the
/// first ring at the biggest inspirations (a yawn, a sigh, a laugh: the tip of rib 8 rises 27 mm in the
/// female preset's yawn) and the dome folded on itself between them. Each of their moving nodes gets a
/// two-sided spring (Cartilage group) toward the nearest point of the inner face of ribs 6-12, or of the
/// front of the vertebral bodies T10-L1 beside the crura (where the dome lies on the spine; without it the
/// dome's rings over the spine fold backward on themselves while the model settles), within
/// `a.abdomen.appositionReach`, anchored kAppositionSlide beyond that point on the same line: a long spring
/// resists a change of the node's distance to the face and hardly a slide across it (a slide s lengthens it
/// by about s^2 / 2 l). Its stiffness and damping along the line are those of a spring reaching only the rib
/// point, the cartilage group's times `a.gains.appositionFraction`.
void addApposition(const AnatomyParams& a, const Skeleton& sk, const GutSurface& gut, ElementSink& sink) {
  const double fraction = a.gains.appositionFraction;
  if (fraction <= 0.0) return;
  std::vector<Endpoint> face;
  for (int level = 6; level <= 12; ++level) {
    for (int side : {kRight, kLeft}) {
      const RibCurve& r = sk.ribCurve[static_cast<std::size_t>(level - 1)][static_cast<std::size_t>(side)];
      const int b = sk.rib[static_cast<std::size_t>(level - 1)][static_cast<std::size_t>(side)];
      for (double s = 0.0; s <= r.length(); s += kCostalSample)
        face.push_back(Endpoint::onBody(b, r.at(s, 0.5 * r.thickness)));
    }
  }
  // the front of the vertebral bodies T10-L1, on which the dome lies beside the crura: held in the frame of
  // the fixed lumbar spine (the thoracic segments' sway, about a millimetre, neglected; anchored on those
  // moving segments, the springs' 0.2 m lever let the linearly implicit step gain energy, Integrators_test)
  std::vector<Eigen::Vector3d> spineFront(sk.thoracicFront.begin() + 9, sk.thoracicFront.end());
  spineFront.push_back(sk.lumbarFront.front());
  for (const Eigen::Vector3d& c : spineFront)
    for (double x : {-kVertebralFrontHalfWidth, 0.0, kVertebralFrontHalfWidth})
      face.push_back(Endpoint::onBody(sk.lumbar, c + Eigen::Vector3d(x, 0, 0)));
  for (std::size_t ring = 0; ring < gut.domeRing.size(); ++ring) {
    if (gut.domeRingRise[ring] > a.abdomen.appositionHeight) break;
    for (int node : gut.domeRing[ring]) {
      // the rim's crural arc is fixed to the spine
      if (gut.region[static_cast<std::size_t>(node)] == sim::NodeRegion::Fixed) continue;
      const Eigen::Vector3d p = gut.rest.col(node);
      const Endpoint& rib = nearest(face, p);
      const double reach = (rib.world - p).norm();
      if (reach > a.abdomen.appositionReach || reach < 1e-6) continue;
      const Endpoint anchor =
          Endpoint::onBody(rib.body, rib.world + kAppositionSlide * (rib.world - p) / reach);
      sink.add(ElementGroup::Cartilage, Endpoint::atNode(node, gut.rest), anchor, 0.0,
               fraction * (reach + kAppositionSlide) / std::max(reach, kAppositionStiffReach));
    }
  }
}

/// Rectus: vertical strands on the anterior wall from the pubis (floor ring) to the xiphoid and ribs 5-7.
void addRectus(const Skeleton& sk, const GutSurface& gut, ElementSink& sink) {
  const int m = static_cast<int>(gut.wallRing.front().size());
  for (int c = -kRectusHalfColumns; c <= kRectusHalfColumns; ++c) {
    const std::size_t j = static_cast<std::size_t>((c + m) % m);
    for (std::size_t k = 0; k + 1 < gut.wallRing.size(); ++k) {
      sink.add(ElementGroup::Rectus, Endpoint::atNode(gut.wallRing[k][j], gut.rest),
               Endpoint::atNode(gut.wallRing[k + 1][j], gut.rest));
    }
    // top insertion: the xiphoid on the midline, costal cartilages 7, 6 and 5 going outward
    Endpoint top = Endpoint::onBody(sk.sternum, sk.xiphoidTip);
    if (c != 0) {
      const std::size_t level = static_cast<std::size_t>(std::max(5, 8 - std::abs(c)));
      const std::size_t side = c > 0 ? kRight : kLeft;
      const RibCurve& r = sk.ribCurve[level - 1][side];
      top = Endpoint::onBody(sk.rib[level - 1][side], r.at(r.length()));
    }
    sink.add(ElementGroup::Rectus, Endpoint::atNode(gut.wallRing.back()[j], gut.rest), top);
  }
}

/// Transversus (hoops round each wall ring) and obliques (diagonals between rings, alternating external
/// oblique "down and forward" and internal oblique "up and forward", and from the top ring up to the
/// costal margin); only where the wall moves.
void addTransversusObliques(const GutSurface& gut, ElementSink& sink) {
  const int m = static_cast<int>(gut.wallRing.front().size());
  auto moving = [&](int node) {
    return gut.region[static_cast<std::size_t>(node)] != sim::NodeRegion::Fixed;
  };
  auto node = [&](std::size_t k, int j) { return gut.wallRing[k][static_cast<std::size_t>((j + m) % m)]; };
  for (std::size_t k = 1; k < gut.wallRing.size(); ++k) {
    for (int j = 0; j < m; ++j) {
      if (moving(node(k, j)) || moving(node(k, j + 1))) {
        sink.add(ElementGroup::TransversusObliques, Endpoint::atNode(node(k, j), gut.rest),
                 Endpoint::atNode(node(k, j + 1), gut.rest));
      }
    }
  }
  for (std::size_t k = 0; k + 1 < gut.wallRing.size(); ++k) {
    const bool isExternal = k % 2 == 0;
    for (int j = 0; j < m; ++j) {
      const int q[4] = {node(k, j), node(k, j + 1), node(k + 1, j), node(k + 1, j + 1)};
      if (!(moving(q[0]) || moving(q[1]) || moving(q[2]) || moving(q[3]))) continue;
      // j grows from the anterior midline round the right side: "forward" is -j on the right, +j on the left
      const bool isRight = std::sin(2.0 * M_PI * (j + 0.5) / m) > 0.0;
      const bool lowerIsAtJ = isRight == isExternal;
      const int upper = lowerIsAtJ ? q[3] : q[2];
      const int lower = lowerIsAtJ ? q[0] : q[1];
      sink.add(ElementGroup::TransversusObliques, Endpoint::atNode(upper, gut.rest),
               Endpoint::atNode(lower, gut.rest));
    }
  }
  const std::vector<int>& rim = gut.domeRing.front();
  const std::size_t nRim = rim.size();
  for (int j = 0; j < m; ++j) {
    const int top = node(gut.wallRing.size() - 1, j);
    if (!moving(top)) continue;
    const std::size_t jRim = static_cast<std::size_t>(std::lround(static_cast<double>(j) * nRim / m)) % nRim;
    sink.add(ElementGroup::TransversusObliques, Endpoint::atNode(top, gut.rest),
             Endpoint::atNode(rim[jRim], gut.rest));
  }
}

/// Three attachment points around `p`: above and below along `up`, and one `back` from it.
std::array<Eigen::Vector3d, 3> triad(const Eigen::Vector3d& p, const Eigen::Vector3d& up,
                                     const Eigen::Vector3d& back) {
  return {p + 0.007 * up, p - 0.007 * up, p + 0.008 * back};
}

/// Costal cartilage: a 3 x 3 bipartite spring truss (structurally stable) from each rib tip to the
/// sternum (ribs 1-7) or to the tip of the rib above (ribs 8-10); rib 1's (the synchondrosis with the
/// manubrium) `a.gains.firstCartilageScale` times stiffer.
void addCartilage(const AnatomyParams& a, const Skeleton& sk, ElementSink& sink) {
  for (int level = 1; level <= 10; ++level) {
    for (int side : {kRight, kLeft}) {
      const RibCurve& r = sk.ribCurve[static_cast<std::size_t>(level - 1)][static_cast<std::size_t>(side)];
      const int b = sk.rib[static_cast<std::size_t>(level - 1)][static_cast<std::size_t>(side)];
      const double s = r.length();
      const auto ribPts = triad(r.at(s), r.normal.back(), -r.tangent(s));
      int other = sk.sternum;
      std::array<Eigen::Vector3d, 3> otherPts;
      if (level <= 7) {
        const Eigen::Vector3d notch =
            sk.costalNotch[static_cast<std::size_t>(level - 1)][static_cast<std::size_t>(side)];
        otherPts = triad(notch, -sk.sternumAxis, sk.sternumAxis.cross(Eigen::Vector3d::UnitX()).normalized());
      } else {
        const RibCurve& above =
            sk.ribCurve[static_cast<std::size_t>(level - 2)][static_cast<std::size_t>(side)];
        other = sk.rib[static_cast<std::size_t>(level - 2)][static_cast<std::size_t>(side)];
        const double sa = above.length() - 0.01;
        otherPts = triad(above.at(sa), above.normal.back(), -above.tangent(sa));
      }
      const double stiffness = level == 1 ? a.gains.firstCartilageScale : 1.0;
      for (const Eigen::Vector3d& p : ribPts) {
        for (const Eigen::Vector3d& q : otherPts) {
          sink.add(ElementGroup::Cartilage, Endpoint::onBody(b, p), Endpoint::onBody(other, q), 1.0,
                   stiffness);
        }
      }
    }
  }
}

/// One scalene from `neck` to `rib` (on rib 1) with the gains `a.gains.scalenes`: an inspiratory muscle of
/// the external intercostal group (driven with them) when it has a kac, else a passive spring.
void addScalene(const AnatomyParams& a, const Endpoint& neck, const Endpoint& rib, ElementSink& sink) {
  const GroupGains& g = a.gains.scalenes;
  sink.add(g.kac > 0.0 ? ElementGroup::IntercostalExternal : ElementGroup::Cartilage, neck, rib, g);
}

/// Scalenes: rib 1 hangs from the cervical spine (scalenus anterior, medius, posterior), which holds it
/// while the intercostals act; without this reference the external intercostals crowd the free ribs
/// together instead of lifting them (Hamberger's lever needs rib 1 held; De Troyer et al. 2005,
/// Physiol Rev 85:717). The model has no cervical spine, so three scalenes per side (addScalene()) run from
/// rib 1 up by kScaleneLength to anchors on the fixed lumbar-spine body (a fixed world point).
void addScalenes(const AnatomyParams& a, const Skeleton& sk, ElementSink& sink) {
  if (sk.hasGirdle) return;  // addNeckAndShoulders() hangs rib 1 from the cervical spine
  for (int side : {kRight, kLeft}) {
    const RibCurve& r = sk.ribCurve[0][static_cast<std::size_t>(side)];
    const int b = sk.rib[0][static_cast<std::size_t>(side)];
    for (double f : {0.3, 0.5, 0.7}) {
      const Eigen::Vector3d p = r.at(f * r.length());
      addScalene(a, Endpoint::onBody(sk.lumbar, p + kScaleneLength * Eigen::Vector3d::UnitZ()),
                 Endpoint::onBody(b, p), sink);
    }
  }
}

/// The neck and the shoulder girdle (AnatomyParams::hasShoulderGirdle), per side:
///  - scalenes: from the cervical transverse processes (kScaleneNeckOffset off the midline, kScaleneNeckRise
///    above rib 1, C3-C4) to the front half of rib 1 (scalenus anterior, medius; the posterior to rib 2 is
///    folded into them), with the gains of the model's scalenes without a neck (addScalene()). Each runs in
///    its rib point's sagittal plane, tilted inwards only: a fore-aft tilt braces rib 1, and with it the
///    upper thoracic spine, against the fixed neck. From C3-C5 (2.8 cm off the midline, level with the
///    vertebral bodies, up to 12 deg forward) the backward sway of the spine in a deep inhale was -0.10 mm
///    (validate's sway.backward, male, --quick; -0.71 mm without the girdle, -0.14 mm without scalenes), in
///    the sagittal plane -0.15 mm. Vertical springs on the middle of rib 1 (the model without the girdle)
///    give -0.73 mm but leave the skin at the base of the neck. On the back half of rib 1 they pulled rib 1
///    and T1 forward and the spine swayed forward on a deep inhale. In a calm breath T1-T3 moves 3.0 mm
///    forward (1.3 mm without the girdle); added to these, 6 cm vertical springs on the middle of rib 1
///    gave 1.1 mm but leave the skin, 2.5 cm ones (inside it, and stiffer) pulled T1-T3 1.1 mm back, and ones
///    to the transverse processes of C5 2.3-3.6 mm forward;
///  - sternocleidomastoid: from the mastoid process to the manubrium (sternal head) and the medial clavicle
///    (clavicular head);
///  - Breathe Easy's 26 shoulder elements (Zordan et al. 2004, Table 1: 52 in all), passive at the shoulder
///    gains (kpe 10, b 1): upper (3), middle (2) and lower (2) trapezius, levator scapulae (2), rhomboids
///    (3), serratus anterior (5), pectoralis minor (3) and major (3), subclavius (1) and deltoid (2).
///  - scapulothoracic gliding springs (muscle_gains.json `scapulothoracic`): six per blade, from its medial
///    border and a line 40 % of the way to its lateral border along the blade's normal into the chest, to a
///    point on the rib under them kScapulothoracicLength deep, so that the blade slides over the ribs and
///    does not sink into them: without them it followed the clavicle, whose sternal end the sternum pushes
///    forward, 8.1 mm forward in a calm breath, and the back's skin with it.
/// Two-sided springs of the cartilage group, except the accessory inspiratory muscles (the
/// sternocleidomastoids and the upper trapezius: 5 per side): muscles of the external intercostal group (the
/// rib cage's inspiratory drive) with the shoulder gains' kpe and b, muscle_gains.json's `accessory_muscles`
/// kac and a recruitment threshold above calm demand (sim::recruitedActivation()), so that a deep breath
/// lifts the shoulders and a calm one barely (Hudson, Gandevia & Butler 2007, J Physiol 584:261; Raper et al.
/// 1966, J Appl Physiol 21:497). The springs that hang the girdle from the neck (levator scapulae, the
/// rhomboid from C7, and the upper trapezius' passive part) take the suspension's kpe
/// (Gains::shoulderSuspension), the tone that holds the shoulders' height: the postural support cancels the
/// girdle's weight, and without it the chest, expanding under the blades, lifted the acromion 5.6 mm in a
/// calm breath (3.2 mm with it, male, validate --quick).
void addNeckAndShoulders(const AnatomyParams& a, const Skeleton& sk, ElementSink& sink) {
  if (!sk.hasGirdle) return;
  const GroupGains& shoulder = a.gains.shoulder;
  // a point on the spinous process of thoracic vertebra t (1..12) and its body
  auto spinous = [&](int t) {
    const std::size_t i = static_cast<std::size_t>(t - 1);
    const double y = sk.vertebraCentreY[i];
    const Eigen::Vector3d p(0, 2 * y - sk.thoracicFront[i].y() - 0.02, sk.thoracicFront[i].z());
    return Endpoint::onBody(sk.thoracicSegment[i], p);
  };
  // cervical vertebra c (1..7): its spinous process (side 0) or transverse process on a side
  auto cervical = [&](int c, double x) {
    const Eigen::Vector3d& p = sk.cervicalCentre[static_cast<std::size_t>(c - 1)];
    return Endpoint::onBody(sk.cervical, x == 0.0 ? Eigen::Vector3d(p + Eigen::Vector3d(0, -0.035, 0))
                                                  : Eigen::Vector3d(p + Eigen::Vector3d(x, -0.004, 0)));
  };
  auto ribAt = [&](int level, int side, double f) {
    const RibCurve& r = sk.ribCurve[static_cast<std::size_t>(level - 1)][static_cast<std::size_t>(side)];
    return Endpoint::onBody(sk.rib[static_cast<std::size_t>(level - 1)][static_cast<std::size_t>(side)],
                            r.at(f * r.length()));
  };
  for (int side : {kRight, kLeft}) {
    const GirdleSide& s = sk.girdle[static_cast<std::size_t>(side)];
    const double sx = side == kRight ? 1.0 : -1.0;
    auto clavicle = [&](double f) {
      return Endpoint::onBody(s.clavicle,
                              s.sternoclavicular + f * (s.acromioclavicular - s.sternoclavicular));
    };
    auto scapula = [&](const Eigen::Vector3d& p) { return Endpoint::onBody(s.scapula, p); };
    auto medialBorder = [&](double f) {
      return scapula(s.superiorAngle + f * (s.inferiorAngle - s.superiorAngle));
    };
    auto superiorBorder = [&](double f) {
      return scapula(s.superiorAngle + f * (s.acromion - s.superiorAngle));
    };
    auto humerus = [&](double f) {
      return Endpoint::onBody(s.humerus, s.glenohumeral + f * (s.elbow - s.glenohumeral));
    };
    auto spring = [&](const Endpoint& p, const Endpoint& q) {
      sink.add(ElementGroup::Cartilage, p, q, shoulder, 0.0);
    };
    // the girdle's suspension from the neck (levator scapulae, the rhomboid from C7): the tone that holds the
    // shoulders' height, kpe AnatomyParams::Gains::shoulderSuspension
    const GroupGains suspension{0.0, a.gains.shoulderSuspension, shoulder.damping};
    auto suspend = [&](const Endpoint& p, const Endpoint& q) {
      sink.add(ElementGroup::Cartilage, p, q, suspension, 0.0);
    };
    // an accessory inspiratory muscle, driven with the external intercostals above its recruitment threshold,
    // with the passive gains `passive` (passive springs when muscle_gains.json has no accessory_muscles
    // block)
    auto accessory = [&](const Endpoint& p, const Endpoint& q, const GroupGains& passive) {
      if (!(a.gains.accessory.kac > 0.0)) return sink.add(ElementGroup::Cartilage, p, q, passive, 0.0);
      const GroupGains g{a.gains.accessory.kac, passive.kpe, passive.damping};
      sink.add(ElementGroup::IntercostalExternal, p, q, g, 1.0, 1.0, a.gains.accessory.recruitment);
    };

    // scalenes, each in its rib point's sagittal plane, and sternocleidomastoid
    for (double f : {0.8, 0.88, 0.96}) {
      const Endpoint rib = ribAt(1, side, f);
      addScalene(a,
                 Endpoint::onBody(sk.cervical, Eigen::Vector3d(sx * kScaleneNeckOffset, rib.world.y(),
                                                               rib.world.z() + kScaleneNeckRise)),
                 rib, sink);
    }
    const Endpoint mastoid = Endpoint::onBody(sk.head, s.mastoid);
    accessory(mastoid,
              Endpoint::onBody(sk.sternum,
                               sk.jugularNotch + Eigen::Vector3d(sx * 0.012, 0, 0) + 0.01 * sk.sternumAxis),
              shoulder);
    accessory(mastoid, clavicle(0.08), shoulder);

    // trapezius: upper (accessory) from the neck to the clavicle and acromion, middle and lower from T1-T7
    // to the scapular spine
    accessory(cervical(2, 0.0), clavicle(0.75), suspension);
    accessory(cervical(4, 0.0), scapula(s.acromion), suspension);
    accessory(cervical(7, 0.0), superiorBorder(0.8), suspension);
    spring(spinous(1), superiorBorder(0.3));
    spring(spinous(3), superiorBorder(0.5));
    spring(spinous(5), scapula(s.spineRoot));
    spring(spinous(7), medialBorder(0.2));
    // levator scapulae: C1 and C3 transverse processes to the superior angle
    suspend(cervical(1, sx * 0.03), scapula(s.superiorAngle));
    suspend(cervical(3, sx * 0.03), medialBorder(0.1));
    // rhomboids: C7-T4 to the medial border
    suspend(cervical(7, 0.0), medialBorder(0.1));
    spring(spinous(2), medialBorder(0.5));
    spring(spinous(4), medialBorder(0.9));
    // serratus anterior: the medial border round the chest wall to ribs 2-8 laterally
    for (const auto& [f, level] :
         {std::pair{0.1, 2}, std::pair{0.3, 3}, std::pair{0.5, 4}, std::pair{0.7, 6}, std::pair{0.9, 8}})
      spring(medialBorder(f), ribAt(level, side, 0.5));
    // pectoralis minor: coracoid to ribs 3-5 in front
    for (int level : {3, 4, 5}) spring(scapula(s.coracoid), ribAt(level, side, 0.85));
    // pectoralis major: humerus to the clavicle, the sternum and rib 6's cartilage
    spring(humerus(0.2), clavicle(0.4));
    spring(humerus(0.2), Endpoint::onBody(sk.sternum, sk.jugularNotch + 0.08 * sk.sternumAxis));
    spring(humerus(0.2), ribAt(6, side, 0.95));
    // subclavius: clavicle to rib 1's front
    spring(clavicle(0.5), ribAt(1, side, 1.0));
    // deltoid: acromion and lateral clavicle to the deltoid tuberosity
    spring(scapula(s.acromion), humerus(0.45));
    spring(clavicle(0.85), humerus(0.45));
    // scapulothoracic gliding: springs from the blade along its normal to points on the rib under it (the
    // nearest), kScapulothoracicLength deep, hold the blade off the ribs while it slides over them (the
    // springs' length changes by the normal motion only; a tangential slide d lengthens them by
    // d^2 / (2 kScapulothoracicLength), 1 mm for 15 mm)
    if (a.gains.scapulothoracic.kpe > 0.0) {
      Eigen::Vector3d inward =
          (s.acromion - s.superiorAngle).cross(s.inferiorAngle - s.superiorAngle).normalized();
      if (inward.y() < 0) inward = -inward;  // the blade's normal, into the chest
      // the centrelines of ribs 2-8 on this side, every 2 mm: the nearest is the rib under a blade point
      std::vector<Endpoint> ribs;
      for (int level = 2; level <= 8; ++level) {
        const RibCurve& r = sk.ribCurve[static_cast<std::size_t>(level - 1)][static_cast<std::size_t>(side)];
        for (double t = 0.0; t <= r.length(); t += 0.002)
          ribs.push_back(Endpoint::onBody(
              sk.rib[static_cast<std::size_t>(level - 1)][static_cast<std::size_t>(side)], r.at(t)));
      }
      for (double f : {0.15, 0.5, 0.85}) {
        const Eigen::Vector3d medial = s.superiorAngle + f * (s.inferiorAngle - s.superiorAngle);
        const Eigen::Vector3d lateral = s.acromion + f * (s.inferiorAngle - s.acromion);
        for (double w : {0.0, 0.4}) {
          const Eigen::Vector3d p = medial + w * (lateral - medial);
          sink.add(ElementGroup::Cartilage, scapula(p),
                   Endpoint::onBody(nearest(ribs, p).body, p + kScapulothoracicLength * inward),
                   a.gains.scapulothoracic, 0.0);
          sink.markGliding();
        }
      }
    }
  }
}

}  // namespace

void buildElements(const AnatomyParams& a, const Skeleton& sk, const GutSurface& gut, sim::Model& model) {
  ElementSink sink(a.gains, model);
  addIntercostals(a, sk, sink);
  addDiaphragm(sk, gut, sink);
  addApposition(a, sk, gut, sink);
  addRectus(sk, gut, sink);
  addTransversusObliques(gut, sink);
  addCartilage(a, sk, sink);
  addScalenes(a, sk, sink);
  addNeckAndShoulders(a, sk, sink);
}

}  // namespace pneuma::meshing
