// All TetGen code of pneuma::meshing.
#include "pneuma/meshing/Tetrahedralizer.h"

#include <tetgen.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "pneuma/sim/Error.h"

namespace pneuma::meshing {

namespace {

// [-] smallest triangle quality handed to TetGen (the default model's gut: 0.24). TetGen 1.5 crashes in its
// own clean-up (SIGSEGV, no exception to catch) on nearly flat surfaces, e.g. an abdomen 1e-12 mm wide.
constexpr double kMinTetgenQuality = 0.01;

// TetGen on the piecewise-linear complex of `surface` with the `interior` points added as vertices
TetMesh run(const TriangleMesh& surface, const Eigen::Matrix3Xd& interior, const char* options,
            const std::string& part) {
  for (int f = 0; f < surface.triangleCount(); ++f) {
    const double q = triangleQuality(surface.vertices.col(surface.triangles(0, f)),
                                     surface.vertices.col(surface.triangles(1, f)),
                                     surface.vertices.col(surface.triangles(2, f)));
    if (!(q >= kMinTetgenQuality)) {
      std::ostringstream s;
      s << part << ": surface triangle " << f << " is degenerate (quality " << q
        << ", TetGen needs >= " << kMinTetgenQuality << "): check the anatomy's dimensions";
      throw sim::Error(s.str());
    }
  }
  // the surface as a piecewise-linear complex of triangular facets (tetgenio frees these arrays)
  tetgenio in;
  in.firstnumber = 0;
  const int nSurface = surface.vertexCount();
  in.numberofpoints = nSurface + static_cast<int>(interior.cols());
  in.pointlist = new REAL[static_cast<std::size_t>(3 * in.numberofpoints)];
  for (int i = 0; i < in.numberofpoints; ++i) {
    for (int k = 0; k < 3; ++k)
      in.pointlist[3 * i + k] = i < nSurface ? surface.vertices(k, i) : interior(k, i - nSurface);
  }
  in.numberoffacets = surface.triangleCount();
  in.facetlist = new tetgenio::facet[static_cast<std::size_t>(in.numberoffacets)];
  for (int f = 0; f < in.numberoffacets; ++f) {
    tetgenio::facet& facet = in.facetlist[f];
    facet.numberofpolygons = 1;
    facet.polygonlist = new tetgenio::polygon[1];
    facet.numberofholes = 0;
    facet.holelist = nullptr;
    facet.polygonlist[0].numberofvertices = 3;
    facet.polygonlist[0].vertexlist = new int[3];
    for (int k = 0; k < 3; ++k) facet.polygonlist[0].vertexlist[k] = surface.triangles(k, f);
  }

  tetgenio out;
  std::string switches = options;
  try {
    ::tetrahedralize(switches.data(), &in, &out);
  } catch (int code) {
    throw sim::Error(part + ": TetGen failed to tetrahedralise the surface (error " + std::to_string(code) +
                     ")");
  }

  // copy the result and sum the tetrahedra volumes
  TetMesh t;
  t.vertices.resize(3, out.numberofpoints);
  for (int i = 0; i < out.numberofpoints; ++i) {
    for (int k = 0; k < 3; ++k) t.vertices(k, i) = out.pointlist[3 * i + k];
  }
  t.tets.resize(4, out.numberoftetrahedra);
  for (int e = 0; e < out.numberoftetrahedra; ++e) {
    for (int k = 0; k < 4; ++k) t.tets(k, e) = out.tetrahedronlist[e * out.numberofcorners + k];
    const Eigen::Vector3d a = t.vertices.col(t.tets(0, e));
    t.volume +=
        std::abs((t.vertices.col(t.tets(1, e)) - a)
                     .dot((t.vertices.col(t.tets(2, e)) - a).cross(t.vertices.col(t.tets(3, e)) - a))) /
        6.0;
  }
  t.boundaryTriangles = out.numberoftrifaces;
  if (out.numberoftetrahedra == 0) throw sim::Error(part + ": TetGen produced no tetrahedra");
  // the input points keep their indices (TetGen numbers its output points from the input's)
  for (int i = 0; i < std::min(in.numberofpoints, out.numberofpoints); ++i) {
    for (int k = 0; k < 3; ++k)
      if (out.pointlist[3 * i + k] != in.pointlist[3 * i + k])
        throw sim::Error(part + ": TetGen renumbered the input points");
  }
  return t;
}

}  // namespace

TetMesh tetrahedralize(const TriangleMesh& surface, const std::string& part) {
  return run(surface, Eigen::Matrix3Xd(3, 0), "pq1.5YQ", part);
}

TetMesh tetrahedralizeAround(const TriangleMesh& surface, const Eigen::Matrix3Xd& interior,
                             const std::string& part) {
  return run(surface, interior, "pYQ", part);
}

}  // namespace pneuma::meshing
