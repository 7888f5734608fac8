#include "pneuma/sim/Elements.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace pneuma::sim {

double enclosedVolume(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xi& triangles) {
  // tetrahedra from the vertex centroid to each face (exact for a closed surface; the centroid only
  // reduces round-off)
  return coneVolume(x, triangles, x.rowwise().mean());
}

double coneVolume(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xi& triangles,
                  const Eigen::Vector3d& origin) {
  double sixV = 0.0;
  for (Eigen::Index f = 0; f < triangles.cols(); ++f) {
    const Eigen::Vector3d a = x.col(triangles(0, f)) - origin;
    const Eigen::Vector3d b = x.col(triangles(1, f)) - origin;
    const Eigen::Vector3d e = x.col(triangles(2, f)) - origin;
    sixV += a.dot(b.cross(e));
  }
  return sixV / 6.0;
}

double gutPressure(double kappa, double restVolume, double volume) {
  return kappa * (restVolume / volume - 1.0);
}

double gutEnergy(double kappa, double restVolume, double volume) {
  if (volume >= restVolume) return 0.0;
  return kappa * (volume - restVolume - restVolume * std::log(volume / restVolume));
}

void addVolumeGradient(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xi& triangles, double scale,
                       Eigen::Matrix3Xd& out) {
  if (scale == 0.0) return;
  // A n / 3 = (b - a) x (e - a) / 6 for each of the face's three vertices
  for (Eigen::Index f = 0; f < triangles.cols(); ++f) {
    const int ia = triangles(0, f), ib = triangles(1, f), ie = triangles(2, f);
    const Eigen::Vector3d an = (x.col(ib) - x.col(ia)).cross(x.col(ie) - x.col(ia));
    const Eigen::Vector3d share = (scale / 6.0) * an;
    out.col(ia) += share;
    out.col(ib) += share;
    out.col(ie) += share;
  }
}

}  // namespace pneuma::sim
