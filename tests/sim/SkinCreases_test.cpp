// Creases of the skin under motion magnification (the app's default 5x): over a calm breath on the default
// model, the skin at 5x magnified end-inspiration (sim::magnifyMotion) against the end-expiration it is
// magnified from. A crease is where neighbouring triangles turn against each other: the change of the fold
// angle across an edge (the angle between the two triangles' normals, signed by the fold's sense) between the
// two poses. Smooth binding weights keep it small; a seam where a vertex bound to a bone meets one bound to
// gut nodes makes it large. The bounds are on the 99th percentile and on the count of self-crossings: a few
// edges in the source mesh's own fold under the pectoral muscles (the inframammary fold), whose skin is bound
// to the diaphragm's dome through the lungs, still close through each other at 5x.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <vector>

#include "DefaultModel.h"
#include "SurfaceCrossings.h"
#include "pneuma/sim/BreathStyleController.h"
#include "pneuma/sim/PosedGeometry.h"
#include "pneuma/sim/Simulation.h"

namespace pneuma::sim {
namespace {

// the signed fold angle [rad] across every interior edge: the angle between the normals of its two triangles,
// positive where the surface is convex (outward normals turning away from each other)
struct Edge {
  int a, b;  // the edge's vertices
  int c, d;  // the opposite vertices of its two triangles
};

std::vector<Edge> interiorEdges(const Eigen::Matrix3Xi& t) {
  std::map<std::pair<int, int>, Edge> open;
  std::vector<Edge> edges;
  for (int f = 0; f < t.cols(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = t(k, f), b = t((k + 1) % 3, f), c = t((k + 2) % 3, f);
      const auto reverse = open.find({b, a});
      if (reverse != open.end()) {
        edges.push_back({b, a, reverse->second.c, c});
        open.erase(reverse);
      } else {
        open[{a, b}] = {a, b, c, -1};
      }
    }
  return edges;
}

double foldAngle(const Eigen::Matrix3Xd& x, const Edge& e) {
  const Eigen::Vector3d a = x.col(e.a), b = x.col(e.b);
  const Eigen::Vector3d n1 = (b - a).cross(x.col(e.c) - a), n2 = (a - b).cross(x.col(e.d) - b);
  const double angle = std::atan2(n1.cross(n2).norm(), n1.dot(n2));
  // convex when the second triangle's far vertex lies below the first triangle's plane
  return n1.dot(x.col(e.d) - a) <= 0.0 ? angle : -angle;
}

// the skin's vertex binding as text: each anchor's body name or "gut", with its weight
std::string binding(const Model& m, int v) {
  std::string s;
  for (int k = 0; k < kSkinVertexSlots; ++k) {
    const int a = m.skin.anchor(k, v);
    if (a < 0) continue;
    const int b = m.skin.anchors.body[static_cast<std::size_t>(a)];
    char w[16];
    std::snprintf(w, sizeof w, " %.2f ", m.skin.weights(k, v));
    const int node = b >= 0 ? -1 : m.skin.anchors.nodes(0, a);
    const std::string what = b >= 0 ? m.bodies.name[static_cast<std::size_t>(b)]
                             : m.nodes.region[static_cast<std::size_t>(node)] == NodeRegion::Diaphragm
                                 ? "dome"
                             : m.nodes.region[static_cast<std::size_t>(node)] == NodeRegion::Wall ? "wall"
                                                                                                  : "fixed";
    s += what + w;
  }
  return s;
}

TEST(SkinCreases, CalmBreathAtFiveTimesMagnificationFoldsFewEdgesSharply) {
  REQUIRE_DEFAULT_MODEL();
  const std::shared_ptr<const Model> model = test::defaultModel();
  ASSERT_GT(model->skin.vertexCount(), 0);

  // a calm breath after settling: its end-expiration and end-inspiration
  SimulationOptions o;
  o.recordSeconds = kTraceOnlyRecordSeconds;
  Simulation sim(model, std::make_unique<BreathStyleController>(loadBreathStyle("calm")), o);
  State low, high;
  double vLow = 1e9, vHigh = -1e9;
  sim.advance(o.settleTime + 10.0, [&](const Simulation& s) {
    const double v = s.latestMetrics().lungVolume;  // [m^3]
    if (s.state().time < o.settleTime) return true;
    if (v < vLow) vLow = v, low = s.state();
    if (v > vHigh) vHigh = v, high = s.state();
    return true;
  });
  ASSERT_GT(vHigh - vLow, 0.3e-3) << "a breath";

  PosedGeometry rest, magnified;
  poseGeometry(*model, low, rest);
  poseGeometry(*model, magnifyMotion(low, high, 5.0), magnified);
  const Eigen::Matrix3Xi& t = model->skin.triangles;
  const std::vector<Edge> edges = interiorEdges(t);
  ASSERT_EQ(edges.size() * 2, static_cast<std::size_t>(3 * t.cols())) << "a closed skin";

  // the change of every edge's fold angle [deg]
  std::vector<std::pair<double, int>> change(edges.size());
  for (std::size_t i = 0; i < edges.size(); ++i)
    change[i] = {
        std::abs(foldAngle(magnified.skin, edges[i]) - foldAngle(rest.skin, edges[i])) * 180.0 / M_PI,
        static_cast<int>(i)};
  std::sort(change.begin(), change.end(), std::greater<>());
  const double p99 = change[change.size() / 100].first;
  int over20 = 0;
  for (const auto& c : change) over20 += c.first > 20.0;
  const int crossings = pneuma::test::countCrossings(magnified.skin, t, magnified.skin, t, true);
  std::printf(
      "calm breath %.0f mL at 5x: fold-angle change max %.1f deg, 99th percentile %.2f deg, %d of %zu "
      "edges over 20 deg; %d self-crossings\n",
      (vHigh - vLow) * 1e6, change.front().first, p99, over20, edges.size(), crossings);
  for (int k = 0; k < 4; ++k) {
    const Edge& e = edges[static_cast<std::size_t>(change[static_cast<std::size_t>(k)].second)];
    const Eigen::Vector3d mid = 0.5 * (rest.skin.col(e.a) + rest.skin.col(e.b));
    std::printf("  %5.1f deg at (%.3f, %.3f, %.3f) m: [%s] - [%s]\n",
                change[static_cast<std::size_t>(k)].first, mid.x(), mid.y(), mid.z(),
                binding(*model, e.a).c_str(), binding(*model, e.b).c_str());
  }
  // measured after the binding's 60 smoothing passes (meshing/src/Skin.cpp): 99th percentile 27.4 deg, 574
  // edges over 20 deg, 16 self-crossings, all in the fold under the pectorals; with 10 passes 48.3 deg, 1029
  // edges and 66 crossings
  EXPECT_LT(p99, 32.0);
  EXPECT_LT(crossings, 25);
}

}  // namespace
}  // namespace pneuma::sim
