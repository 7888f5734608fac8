// The one posing function (sim::poseGeometry) on the toy torso, and the skin block it poses: a skin vertex is
// a fixed affine combination of bone-frame points and gut nodes (Model.h, Skin), so under a rigid motion of
// its bone it moves rigidly, and bound to nodes it moves by their weighted displacement. Older model files
// without the block load without a skin; a bad block is refused naming the field.
#include "pneuma/sim/PosedGeometry.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "ToyTorso.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/ModelIO.h"

namespace pneuma::sim {
namespace {

using Eigen::Vector3d;

// the toy torso with a tetrahedral skin round the sternum: vertex 0 rigid on the sternum, 1 on a gut node, 2
// half and half, 3 on the fixed lumbar spine
struct SkinnedToy {
  Model m = test::makeToyTorso();
  int sternum = -1, node = -1, lumbar = -1;
  Eigen::Matrix3Xd rest{3, 4};

  SkinnedToy() {
    for (int b = 0; b < m.bodies.size(); ++b) {
      if (m.bodies.name[static_cast<std::size_t>(b)] == "sternum") sternum = b;
      if (m.bodies.name[static_cast<std::size_t>(b)] == "lumbar") lumbar = b;
    }
    for (int i = 0; i < m.nodes.size() && node < 0; ++i)
      if (!m.nodes.isFixed(i)) node = i;
    const Vector3d c = m.bodies.com.col(sternum) + Vector3d(0, 0.05, 0);
    rest << c + Vector3d(0, 0, 0.03), c + Vector3d(0.03, 0, -0.02), c + Vector3d(-0.03, 0, -0.02),
        c + Vector3d(0, -0.03, 0);
    Skin& s = m.skin;
    s.anchors.addBodyPoint(sternum, rest.col(0) - m.bodies.com.col(sternum));  // anchor 0
    s.anchors.addNodePoint({node, -1, -1}, {1, 0, 0});                         // anchor 1
    s.anchors.addBodyPoint(sternum, Vector3d::Zero());                         // anchor 2: the com
    s.anchors.addBodyPoint(lumbar, rest.col(3) - m.bodies.com.col(lumbar));    // anchor 3
    s.anchor.setConstant(kSkinVertexSlots, 4, -1);
    s.weights.setZero(kSkinVertexSlots, 4);
    s.offset.setZero(3, 4);
    s.anchor(0, 0) = 0, s.weights(0, 0) = 1.0;
    s.anchor(0, 1) = 1, s.weights(0, 1) = 1.0;
    s.offset.col(1) = rest.col(1) - m.nodes.rest.col(node);
    s.anchor(0, 2) = 2, s.anchor(1, 2) = 1, s.weights(0, 2) = 0.5, s.weights(1, 2) = 0.5;
    s.offset.col(2) = rest.col(2) - 0.5 * (m.bodies.com.col(sternum) + m.nodes.rest.col(node));
    s.anchor(0, 3) = 3, s.weights(0, 3) = 1.0;
    s.triangles.resize(3, 4);  // a consistently wound tetrahedron, turned outward below
    s.triangles.row(0) << 0, 0, 0, 1;
    s.triangles.row(1) << 1, 3, 2, 3;
    s.triangles.row(2) << 2, 1, 3, 2;
    if (enclosedVolume() < 0) s.triangles.row(1).swap(s.triangles.row(2));
    s.tetrahedra = 1;
  }
  double enclosedVolume() const {
    double v = 0.0;
    for (int f = 0; f < m.skin.triangles.cols(); ++f)
      v += rest.col(m.skin.triangles(0, f))
               .dot(rest.col(m.skin.triangles(1, f)).cross(rest.col(m.skin.triangles(2, f))));
    return v / 6.0;
  }
};

TEST(PosedGeometry, SkinFollowsItsBonesRigidlyAndItsNodesByTheirDisplacement) {
  const SkinnedToy t;
  validateModel(t.m);
  PosedGeometry p;
  State s = makeInitialState(t.m);
  poseGeometry(t.m, s, p);
  EXPECT_LT((p.skin - t.rest).norm(), 1e-12) << "the rest pose gives the rest positions";

  // a rigid motion of the sternum and a displaced gut node
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.3, Vector3d(1, 2, -1).normalized()));
  const Vector3d move(0.004, -0.01, 0.02), dn(0.003, 0.007, -0.002);
  s.bodyOrientation[static_cast<std::size_t>(t.sternum)] = q;
  s.bodyPosition.col(t.sternum) += move;
  s.nodePosition.col(t.node) += dn;
  poseGeometry(t.m, s, p);
  const Vector3d com = t.m.bodies.com.col(t.sternum);
  EXPECT_LT((p.skin.col(0) - (q * (t.rest.col(0) - com) + com + move)).norm(), 1e-12) << "rigid on its bone";
  EXPECT_LT((p.skin.col(1) - (t.rest.col(1) + dn)).norm(), 1e-12) << "translates with its node";
  EXPECT_LT((p.skin.col(2) - (t.rest.col(2) + 0.5 * move + 0.5 * dn)).norm(), 1e-12) << "half of each";
  EXPECT_LT((p.skin.col(3) - t.rest.col(3)).norm(), 1e-12) << "still on the fixed spine";
  // the other parts are the anchors' and the state's
  EXPECT_LT((p.gut - s.nodePosition).norm(), 1e-15);
  EXPECT_LT(
      (p.body[static_cast<std::size_t>(t.sternum)].translation() - s.bodyPosition.col(t.sternum)).norm(),
      1e-15);
}

TEST(PosedGeometry, SkinBlockRoundTripsOlderFilesLoadWithoutItAndBadWeightsAreRefused) {
  const SkinnedToy t;
  const std::string text = serializeModel(t.m);
  EXPECT_EQ(serializeModel(parseModel(text)), text);

  nlohmann::json j = nlohmann::json::parse(text);
  j.erase("skin");
  EXPECT_EQ(parseModel(j.dump()).skin.vertexCount(), 0) << "a model written before the skin has none";

  j = nlohmann::json::parse(text);
  j["skin"]["vertices"][2]["weights"] = {0.5, 0.6};
  try {
    parseModel(j.dump(), "model.json");
    ADD_FAILURE() << "weights summing to 1.1 were accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("model.json: skin.vertices[2].weights: must sum to 1, got 1.1"),
              std::string::npos)
        << e.what();
  }
}

// motion magnification (display only): every posed point moves k times as far from the reference pose, to
// first order in the motion; bones stay rigid and the rotation's angle is k times the real one
TEST(PosedGeometry, MagnifiedMotionMovesEveryPosedPointByTheFactor) {
  const SkinnedToy t;
  const State reference = makeInitialState(t.m);
  State s = reference;
  // a small breath-sized motion: every free body turned 2 mrad and shifted 0.4 mm, every free node moved
  for (int b = 0; b < t.m.bodies.size(); ++b) {
    if (t.m.bodies.isFixed[static_cast<std::size_t>(b)]) continue;
    s.bodyOrientation[static_cast<std::size_t>(b)] =
        Eigen::Quaterniond(Eigen::AngleAxisd(0.002, Vector3d(1, 0.3 * b, 0.2).normalized()));
    s.bodyPosition.col(b) += Vector3d(0.0001 * b, 0.0004, -0.0002);
  }
  for (int n = 0; n < t.m.nodes.size(); ++n)
    if (!t.m.nodes.isFixed(n)) s.nodePosition.col(n) += Vector3d(0.0003, -0.0001 * (n % 3), 0.0004);

  PosedGeometry rest, real, shown;
  poseGeometry(t.m, reference, rest);
  poseGeometry(t.m, s, real);
  const double k = 5.0;
  poseGeometry(t.m, magnifyMotion(reference, s, k), shown);
  for (const auto& [name, part] : std::vector<std::pair<const char*, Eigen::Matrix3Xd PosedGeometry::*>>{
           {"elementA", &PosedGeometry::elementA},
           {"elementB", &PosedGeometry::elementB},
           {"gut", &PosedGeometry::gut},
           {"cavity", &PosedGeometry::cavity},
           {"landmarks", &PosedGeometry::landmarks},
           {"skin", &PosedGeometry::skin}}) {
    const Eigen::Matrix3Xd d1 = real.*part - rest.*part, dk = shown.*part - rest.*part;
    ASSERT_GT(d1.norm(), 1e-6) << name << " moved";
    // second-order terms of the turned bones: (k theta)^2 r ~ 1e-4 of k times the motion
    EXPECT_LT((dk - k * d1).norm(), 0.01 * k * d1.norm()) << name;
  }
  for (int b = 0; b < t.m.bodies.size(); ++b) {
    const Eigen::AngleAxisd turn(shown.body[static_cast<std::size_t>(b)].linear());
    const Eigen::AngleAxisd realTurn(real.body[static_cast<std::size_t>(b)].linear());
    EXPECT_NEAR(turn.angle(), k * realTurn.angle(), 1e-9) << "body " << b;
    EXPECT_NEAR((shown.body[static_cast<std::size_t>(b)].linear().transpose() *
                     shown.body[static_cast<std::size_t>(b)].linear() -
                 Eigen::Matrix3d::Identity())
                    .norm(),
                0.0, 1e-12)
        << "a bone stays rigid";
  }
  // factor 1 is the state itself
  poseGeometry(t.m, magnifyMotion(reference, s, 1.0), shown);
  EXPECT_LT((shown.skin - real.skin).norm(), 1e-15);
}

}  // namespace
}  // namespace pneuma::sim
