#pragma once
/// @file Elements.h
/// Element kernels: small pure functions of one spring element or of the gut surface, testable alone
/// (in the manner of PositionBasedDynamics' XPBD.h). Sign convention: a scalar element force F < 0
/// pulls the endpoints together (tension); the force on endpoint A is -F d and on B is +F d, with
/// d = (xB - xA) / l the unit direction from A to B.

#include <Eigen/Core>
#include <algorithm>

namespace pneuma::sim {

/// Parameters of one muscle element under a given activation (Eq. 2).
struct MuscleParams {
  double restLength = 0.0;  ///< [m] l0 > 0
  double kac = 0.0;         ///< [N/m] active gain
  double kpe = 0.0;         ///< [N/m] passive gain
  double damping = 0.0;     ///< [N s/m] b
  double alpha = 0.0;       ///< [-] activation in [0, 1]
  double r = 1.0;           ///< [-] contraction ratio
};

/// Muscle force, Zordan et al. 2004 Eq. 2:
///   F = min[-alpha kac (l - r l0) - kpe (l - l0) - b ldot, 0]            [N]
/// Tension only; the damping term may be "virtually positive" (resist shortening) as long as the
/// total stays <= 0. @param l length [m], @param ldot lengthening rate [m/s].
inline double muscleForce(double l, double ldot, const MuscleParams& p) {
  const double elastic = -p.alpha * p.kac * (l - p.r * p.restLength) - p.kpe * (l - p.restLength);
  return std::min(elastic - p.damping * ldot, 0.0);
}

/// [-] activation of a muscle recruited above a threshold of its group's drive. The group's command is its
/// active tension at rest length per kac l0, c = alpha (1 - r) (Eq. 2 at l = l0); the element takes the
/// command left above its threshold c0 at the group's r:
///   alpha_e = max(0, alpha (1 - r) - c0) / (1 - r)  for r < 1,  0 for r >= 1 (a lengthening command),
/// so that alpha_e kac (1 - r) l0 = kac l0 max(0, c - c0) and alpha_e <= alpha. Motor units are recruited in
/// order of size as the drive grows, and a muscle with a small mechanical advantage is recruited late: the
/// scalenes fire in every quiet breath, the sternocleidomastoids only at larger efforts (Hudson, Gandevia &
/// Butler 2007, J Physiol 584:261; Raper et al. 1966, J Appl Physiol 21:497; De Troyer & Estenne 1984, J
/// Appl Physiol 57:899). @param alpha the group's activation [-] in [0, 1], @param r its contraction ratio
/// [-], @param c0 the element's threshold [-] in [0, 1).
inline double recruitedActivation(double alpha, double r, double c0) {
  if (r >= 1.0) return 0.0;
  return std::max(0.0, alpha * (1.0 - r) - c0) / (1.0 - r);
}

/// Slack length [m] of a muscle: the length at which its elastic part, -alpha kac (l - r l0) - kpe (l - l0),
/// is zero: l_s = (alpha kac r + kpe) l0 / (alpha kac + kpe); l0 when alpha kac + kpe = 0.
inline double muscleSlackLength(const MuscleParams& p) {
  const double k = p.alpha * p.kac + p.kpe;
  if (k <= 0.0) return p.restLength;
  return (p.alpha * p.kac * p.r + p.kpe) * p.restLength / k;
}

/// Elastic energy [J] of a muscle (the potential of Eq. 2 without damping): 1/2 (alpha kac + kpe) (l - l_s)^2
/// for l > l_s, else 0.
inline double muscleEnergy(double l, const MuscleParams& p) {
  const double stretch = l - muscleSlackLength(p);
  return stretch > 0.0 ? 0.5 * (p.alpha * p.kac + p.kpe) * stretch * stretch : 0.0;
}

/// Structural (cartilage) spring force, two-sided and damped: F = -k (l - l0) - b ldot   [N].
inline double springForce(double l, double ldot, double restLength, double k, double damping) {
  return -k * (l - restLength) - damping * ldot;
}

/// Elastic energy [J] of a structural spring: 1/2 k (l - l0)^2.
inline double springEnergy(double l, double restLength, double k) {
  const double stretch = l - restLength;
  return 0.5 * k * stretch * stretch;
}

/// Volume [m^3] enclosed by a closed triangle surface with outward normals: the sum over faces of the
/// signed tetrahedra from the vertex centroid c to each face (Section 6.2),
///   V = sum_f (a - c) . ((b - c) x (e - c)) / 6.
/// @param x  3 x #V vertex positions [m];  @param triangles 3 x #F vertex indices.
double enclosedVolume(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xi& triangles);

/// Volume [m^3] of the cone from `origin` over the faces `triangles` (an open patch allowed):
///   V = sum_f (a - o) . ((b - o) x (e - o)) / 6.
/// For a closed surface it is enclosedVolume() for any origin; for a patch whose rim hardly moves, its change
/// is the volume the patch sweeps (the abdominal wall's displacement of Konno & Mead 1967).
/// @param x  3 x #V vertex positions [m];  @param triangles 3 x #F vertex indices;  @param origin [m].
double coneVolume(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xi& triangles,
                  const Eigen::Vector3d& origin);

/// Gut pressure, Eq. 4: P = kappa (V0 / V - 1) [Pa], with kappa [Pa], V0 and V [m^3].
double gutPressure(double kappa, double restVolume, double volume);

/// Elastic energy [J] stored by the gut pressure: the potential whose negative gradient is the
/// max(0, P) face force of Eq. 5,  E = kappa (V - V0 - V0 ln(V / V0)) for V < V0, else 0.
double gutEnergy(double kappa, double restVolume, double volume);

/// Adds `scale` times the volume gradient dV/dx to `out` (3 x #V, not cleared): every face i adds
/// scale A_i n_i / 3 to each of its three vertices (A_i n_i = (b - a) x (e - a) / 2). On a closed
/// surface this is the exact gradient of enclosedVolume(). With scale = max(0, P) it is the gut
/// pressure force of Eq. 5 [N]; with scale = 1 it is dV/dx [m^2].
void addVolumeGradient(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xi& triangles, double scale,
                       Eigen::Matrix3Xd& out);

}  // namespace pneuma::sim
