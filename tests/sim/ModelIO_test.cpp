// Model format: round trip and rejection of corrupted files (docs/model-format.md).
#include "pneuma/sim/ModelIO.h"

#include <gtest/gtest.h>

#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "ToyTorso.h"
#include "pneuma/sim/BreathStyleController.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/Simulation.h"
#include "pneuma/sim/Ties.h"

using namespace pneuma::sim;

namespace {

// a minimal valid model: a fixed spine, one rib on a ball joint, a tetrahedral gut with one moving
// node, a muscle from the rib to that node, a tetrahedral cavity and the five required landmarks
Model tinyModel() {
  Model m;
  m.name = "tiny";
  m.anatomy = "inline";
  for (int i = 0; i < 2; ++i) {
    m.bodies.name.push_back(i == 0 ? "spine" : "rib1_left");
    m.bodies.isFixed.push_back(i == 0 ? 1 : 0);
    m.bodies.inertia.push_back(Eigen::Matrix3d::Identity() * 1e-3);
    m.bodies.mesh.push_back("");
  }
  m.bodies.mass = Eigen::Vector2d(1.0, 0.1);
  m.bodies.com.resize(3, 2);
  m.bodies.com << 0.0, 0.1, 0.0, 0.0, 0.0, 0.0;

  m.joints.name = {"costovertebral_rib1_left"};
  m.joints.parent = {0};
  m.joints.child = {1};
  m.joints.anchor = Eigen::Vector3d(0.05, 0.0, 0.0);
  m.joints.friction = Eigen::VectorXd::Constant(1, 0.01);
  m.joints.stiffness = Eigen::VectorXd::Zero(1);
  m.joints.axis = Eigen::Vector3d(-0.6, -0.8, 0.0);
  m.joints.lockStiffness = Eigen::VectorXd::Constant(1, 50.0);

  m.nodes.rest.resize(3, 4);
  m.nodes.rest << 0, 1, 0, 0,  //
      0, 0, 1, 0,              //
      0, 0, 0, 1;
  m.nodes.rest *= 0.1;
  m.nodes.mass = Eigen::Vector4d(0.0, 0.0, 0.0, 8.0);
  m.nodes.region = {NodeRegion::Fixed, NodeRegion::Fixed, NodeRegion::Fixed, NodeRegion::Wall};
  m.gut.kappa = 1e4;
  m.gut.drag = 20.0;
  m.gut.wallToneUpright = 0.03;
  m.gut.triangles.resize(3, 4);
  m.gut.triangles << 0, 0, 0, 1,  //
      2, 1, 3, 2,                 //
      1, 3, 2, 3;

  m.elements.group = {ElementGroup::Diaphragm};
  m.elements.endA.addBodyPoint(1, Eigen::Vector3d(0.01, 0.0, 0.0));
  m.elements.endB.addNodePoint(Eigen::Vector3i(3, -1, -1), Eigen::Vector3d(1, 0, 0));
  m.elements.restLength = Eigen::VectorXd::Constant(1, 0.12);
  m.elements.kac = Eigen::VectorXd::Constant(1, 100.0);
  m.elements.kpe = Eigen::VectorXd::Constant(1, 10.0);
  m.elements.damping = Eigen::VectorXd::Constant(1, 0.5);

  for (int i = 0; i < 4; ++i)
    m.cavity.vertices.addNodePoint(Eigen::Vector3i(i, -1, -1), Eigen::Vector3d(1, 0, 0));
  m.cavity.triangles = m.gut.triangles;

  // two lungs: the cavity tetrahedron shrunk by half towards its centroid (each vertex 5/8 its own corner and
  // 1/8 each other corner), and a mediastinum of a tenth of the cavity
  for (LungSurface* lung : {&m.lungs.right, &m.lungs.left}) {
    lung->cavityVertex.setConstant(kLungVertexSlots, 4, -1);
    lung->weights.setZero(kLungVertexSlots, 4);
    for (int v = 0; v < 4; ++v)
      for (int k = 0; k < 4; ++k) lung->cavityVertex(k, v) = k, lung->weights(k, v) = k == v ? 0.625 : 0.125;
    lung->triangles = m.cavity.triangles;
  }
  m.lungs.mediastinumVolume = 0.1 * 1e-3 / 6.0;

  for (const char* n :
       {"xiphoid", "umbilicus", "diaphragm_apex", "rib8_lateral_left", "rib8_lateral_right"}) {
    m.landmarks.name.push_back(n);
    m.landmarks.points.addNodePoint(Eigen::Vector3i(1, 2, -1), Eigen::Vector3d(0.25, 0.75, 0));
  }
  return m;
}

// serialise, apply an edit to the JSON, and return the message of the error the parser raises
std::string rejectionOf(void (*edit)(nlohmann::json&)) {
  nlohmann::json j = nlohmann::json::parse(serializeModel(tinyModel()));
  edit(j);
  try {
    parseModel(j.dump(), "model.json");
  } catch (const Error& e) {
    return e.what();
  }
  return "accepted";
}

}  // namespace

TEST(ModelIO, RoundTripIsByteIdentical) {
  const std::string first = serializeModel(tinyModel());
  const Model back = parseModel(first);
  EXPECT_EQ(serializeModel(back), first);
  EXPECT_EQ(back.elements.endB.nodes(0, 0), 3);
  EXPECT_DOUBLE_EQ(back.elements.restLength[0], 0.12);
  EXPECT_EQ(back.landmarks.find("umbilicus"), 1);
}

TEST(ModelIO, RejectsCorruptedFilesNamingTheField) {
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["elements"][0]["rest_length"] = 0.0; }),
            "model.json: elements[0].rest_length: must be > 0, got 0");
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["bodies"][1]["mass"] = -2.0; }),
            "model.json: bodies[1].mass: must be > 0, got -2");
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["elements"][0]["b"]["nodes"][0] = 9; }),
            "model.json: elements.b[0].nodes: index 9 out of range [0, 4)");
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["joints"][0].erase("anchor"); }),
            "model.json: joints[0].anchor: missing");
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["elements"][0]["group"] = "biceps"; }),
            "model.json: elements[0].group: unknown group 'biceps'");
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["gut"]["drag"] = -1.0; }),
            "model.json: gut.drag: must be >= 0, got -1");
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["gut"]["wall_tone_upright"] = 0.9; }),
            "model.json: gut.wall_tone_upright: must be in [0, 0.5], got 0.9");
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["version"] = 7; }),
            "model.json: version: unsupported version 7 (this build reads 1)");
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["landmarks"].erase(0); }),
            "model.json: landmarks: missing required landmark 'xiphoid'");
  // an inward-facing gut surface encloses negative volume
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) {
              for (auto& t : j["gut"]["triangles"]) std::swap(t[0], t[1]);
            }).rfind("model.json: gut.triangles: enclosed rest volume must be > 0", 0),
            0u);
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) {
              j["bodies"][0]["inertia"][0][0] = -1.0;
            }).rfind("model.json: bodies[0].inertia: must be positive definite", 0),
            0u);
}

// a model.json written before the lungs is refused in one line that names the missing block; a malformed lung
// block names its field
TEST(ModelIO, LungBlockIsRequiredAndChecked) {
  EXPECT_EQ(
      rejectionOf([](nlohmann::json& j) { j.erase("lungs"); }),
      "model.json: lungs: missing (a model written before the two lungs; rebuild it with 'pneuma-cli model "
      "build')");
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["lungs"].erase("left"); }),
            "model.json: lungs.left: missing");
  EXPECT_EQ(
      rejectionOf([](nlohmann::json& j) { j["lungs"]["right"]["vertices"][2]["cavity_vertices"][1] = 4; }),
      "model.json: lungs.right.vertices[2].cavity_vertices: index 4 out of range [0, 4)");
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["lungs"]["left"]["vertices"][0]["weights"][1] = -0.125; }),
            "model.json: lungs.left.vertices[0].weights: must be finite and >= 0, got -0.125");
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["lungs"]["left"]["vertices"][0]["weights"][1] = 0.5; }),
            "model.json: lungs.left.vertices[0].weights: must sum to 1, got 1.375");
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["lungs"]["right"]["vertices"][1]["weights"].erase(0); }),
            "model.json: lungs.right.vertices[1].weights: must have as many entries as cavity_vertices (4)");
  EXPECT_EQ(
      rejectionOf([](nlohmann::json& j) { j["lungs"]["mediastinum_volume"] = 1.0; }),
      "model.json: lungs.mediastinum_volume: must be smaller than the cavity's rest volume 0.000166667 m^3, "
      "got 1");
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["lungs"]["right"]["triangles"].erase(3); }),
            "model.json: lungs.right.triangles: must be a closed surface of at least 4 triangles, got 3");
  EXPECT_NE(rejectionOf([](nlohmann::json& j) {
              std::swap(j["lungs"]["left"]["triangles"][1][0], j["lungs"]["left"]["triangles"][1][1]);
            }).find("model.json: lungs.left.triangles[1]: edge"),
            std::string::npos);
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) {
              for (auto& t : j["lungs"]["left"]["triangles"]) std::swap(t[0], t[1]);
            }).rfind("model.json: lungs.left.triangles: enclosed rest volume must be > 0", 0),
            0u);
  EXPECT_EQ(
      rejectionOf([](nlohmann::json& j) {
        j["lungs"]["left"] = {{"vertices", nlohmann::json::array()}, {"triangles", nlohmann::json::array()}};
      }),
      "model.json: lungs.left: must be given with the other lung");
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) {
              j["lungs"]["right"]["vertices"][0]["bones"] = 1;
            }).rfind("model.json: lungs.right.vertices[0].bones: unknown field", 0),
            0u);
}

// the lungs' volume is the cavity's minus the constant mediastinum, so its swing is the cavity's; the right
// and left lungs split it as their surfaces do (here two equal surfaces: half each)
TEST(ModelIO, LungVolumeIsTheCavityMinusTheMediastinum) {
  auto model = std::make_shared<const Model>(tinyModel());
  SimulationOptions o;
  o.settleTime = 0.0;
  Simulation sim(model, std::make_unique<BreathStyleController>(loadBreathStyle("calm")), o);
  sim.advance(0.1);
  const Metrics& m = sim.latestMetrics();
  EXPECT_GT(m.thoracicCavityVolume, 0.0);
  EXPECT_DOUBLE_EQ(m.lungVolume, m.thoracicCavityVolume - model->lungs.mediastinumVolume);
  EXPECT_DOUBLE_EQ(m.rightLungVolume, 0.5 * m.lungVolume);
  EXPECT_DOUBLE_EQ(m.rightLungVolume + m.leftLungVolume, m.lungVolume);
  // a lung vertex follows its cavity corners: the lung is the cavity shrunk by half about its centroid
  Eigen::Matrix3Xd cavity, x;
  anchorPositions(model->cavity.vertices, sim.state(), cavity);
  lungPositions(model->lungs.left, cavity, x);
  const Eigen::Vector3d centroid = cavity.rowwise().mean();
  for (int v = 0; v < 4; ++v)
    EXPECT_LT((x.col(v) - (centroid + 0.5 * (cavity.col(v) - centroid))).norm(), 1e-15);
}

// gut.drag is optional: a model written before the visceral drag existed loads without it
TEST(ModelIO, ModelWithoutGutDragLoadsWithNone) {
  nlohmann::json j = nlohmann::json::parse(serializeModel(tinyModel()));
  EXPECT_DOUBLE_EQ(parseModel(j.dump()).gut.drag, 20.0);
  j["gut"].erase("drag");
  EXPECT_DOUBLE_EQ(parseModel(j.dump()).gut.drag, 0.0);
}

// gut.wall_tone_upright is optional too: a model written before the postural tone has none
TEST(ModelIO, ModelWithoutWallToneLoadsWithNone) {
  nlohmann::json j = nlohmann::json::parse(serializeModel(tinyModel()));
  EXPECT_DOUBLE_EQ(parseModel(j.dump()).gut.wallToneUpright, 0.03);
  j["gut"].erase("wall_tone_upright");
  EXPECT_DOUBLE_EQ(parseModel(j.dump()).gut.wallToneUpright, 0.0);
}

// a recruitment threshold (sim::Elements::recruitment) is written only for an element that has one: a model
// without any reads back without the array and writes no key; a bad value or a recruited spring is named
TEST(ModelIO, RecruitmentIsOptionalAndChecked) {
  const std::string plain = serializeModel(tinyModel());
  EXPECT_EQ(plain.find("recruitment"), std::string::npos);
  EXPECT_EQ(parseModel(plain).elements.recruitment.size(), 0);
  Model m = tinyModel();
  m.elements.recruitment = Eigen::VectorXd::Constant(1, 0.2);
  const std::string text = serializeModel(m);
  const Model back = parseModel(text);
  ASSERT_EQ(back.elements.recruitment.size(), 1);
  EXPECT_EQ(back.elements.recruitment(0), 0.2);
  EXPECT_EQ(serializeModel(back), text);
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["elements"][0]["recruitment"] = 1.0; }),
            "model.json: elements[0].recruitment: must be in [0, 1), got 1");
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["elements"][0]["recruitment"] = -0.1; }),
            "model.json: elements[0].recruitment: must be in [0, 1), got -0.1");
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) {
              j["elements"][0]["group"] = "cartilage";
              j["elements"][0]["recruitment"] = 0.2;
            }),
            "model.json: elements[0].recruitment: only a muscle is recruited; a cartilage spring is passive");
}

// a gliding spring (sim::Elements::isGliding) is marked only where there is one, read back and drawn by no
// view; only a cartilage spring glides
TEST(ModelIO, GlidingIsOptionalAndChecked) {
  const std::string plain = serializeModel(tinyModel());
  EXPECT_EQ(plain.find("gliding"), std::string::npos);
  EXPECT_TRUE(parseModel(plain).elements.isGliding.empty());
  nlohmann::json j = nlohmann::json::parse(plain);
  j["elements"][0]["group"] = "cartilage";
  const Model spring = parseModel(j.dump());
  EXPECT_FALSE(spring.elements.glides(0));
  j["elements"][0]["gliding"] = true;
  const Model back = parseModel(j.dump());
  ASSERT_EQ(back.elements.isGliding.size(), 1u);
  EXPECT_TRUE(back.elements.glides(0));
  EXPECT_TRUE(isDrawn(parseModel(plain), 0));
  EXPECT_FALSE(isDrawn(back, 0));
  EXPECT_EQ(parseModel(serializeModel(back)).elements.isGliding, back.elements.isGliding);
  EXPECT_EQ(rejectionOf([](nlohmann::json& m) { m["elements"][0]["gliding"] = true; }),
            "model.json: elements[0].gliding: only a cartilage spring glides; a muscle pulls its two bones "
            "together");
}

// a body's support height (bodies[i].support_height [m]): optional, written only where set, kept through a
// round trip, and only in (0, 2] m on a supported body
TEST(ModelIO, SupportHeightIsOptionalAndChecked) {
  const std::string plain = serializeModel(tinyModel());
  EXPECT_EQ(plain.find("support_height"), std::string::npos);
  EXPECT_EQ(parseModel(plain).bodies.supportHeight.size(), 0);
  nlohmann::json j = nlohmann::json::parse(plain);
  j["bodies"][1]["supported"] = true;
  j["bodies"][1]["support_height"] = 0.25;
  const Model hanging = parseModel(j.dump());
  EXPECT_EQ(hanging.bodies.supportHeightOf(1), 0.25);
  EXPECT_EQ(hanging.bodies.supportHeightOf(0), 0.0);
  EXPECT_EQ(parseModel(serializeModel(hanging)).bodies.supportHeight, hanging.bodies.supportHeight);
  EXPECT_EQ(rejectionOf([](nlohmann::json& m) { m["bodies"][1]["support_height"] = 0.25; }),
            "model.json: bodies[1].support_height: needs \"supported\": true");
  EXPECT_EQ(rejectionOf([](nlohmann::json& m) {
              m["bodies"][1]["supported"] = true;
              m["bodies"][1]["support_height"] = -0.1;
            }),
            "model.json: bodies[1].support_height: must be in (0, 2] m, got -0.1");
}

TEST(ModelIO, RejectsTruncatedJson) {
  const std::string text = serializeModel(tinyModel());
  try {
    parseModel(text.substr(0, text.size() / 2), "m.json");
    FAIL() << "truncated JSON was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("m.json: invalid JSON", 0), 0u) << e.what();
  }
}

TEST(ModelIO, MissingDirectoryNamesThePath) {
  try {
    loadModel("/nonexistent/pneuma-model");
    FAIL() << "missing directory was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/pneuma-model/model.json: cannot open"),
              std::string::npos);
  }
}

// ---------------------------------------------------------------------------------------------
// structure (issue 15, class 7): models that load but describe no body

namespace {

std::string invalidOf(const Model& m) {
  try {
    validateModel(m);
  } catch (const Error& e) {
    return e.what();
  }
  return "accepted";
}

// tinyModel() with a second moving rib, "rib2_left" (body 2), not yet on a joint
Model tinyModelWithSecondRib() {
  Model m = tinyModel();
  m.bodies.name.push_back("rib2_left");
  m.bodies.isFixed.push_back(0);
  m.bodies.inertia.push_back(Eigen::Matrix3d::Identity() * 1e-3);
  m.bodies.mesh.push_back("");
  m.bodies.mass.conservativeResize(3);
  m.bodies.mass[2] = 0.1;
  m.bodies.com.conservativeResize(3, 3);
  m.bodies.com.col(2) = Eigen::Vector3d(0.0, -0.1, 0.0);
  return m;
}

void addJoint(Model& m, int parent, int child) {
  const int i = m.joints.size();
  m.joints.name.push_back("j" + std::to_string(i));
  m.joints.parent.push_back(parent);
  m.joints.child.push_back(child);
  m.joints.anchor.conservativeResize(3, i + 1);
  m.joints.anchor.col(i).setZero();
  for (Eigen::VectorXd* v : {&m.joints.friction, &m.joints.stiffness, &m.joints.lockStiffness}) {
    v->conservativeResize(i + 1);
    (*v)[i] = 0.0;
  }
  m.joints.axis.conservativeResize(3, i + 1);
  m.joints.axis.col(i) = Eigen::Vector3d::UnitX();
}

}  // namespace

TEST(ModelStructure, TheValidModelsPass) {
  EXPECT_EQ(invalidOf(tinyModel()), "accepted");
  Model chain = tinyModelWithSecondRib();
  addJoint(chain, 1, 2);  // spine -> rib1 -> rib2: a tree
  EXPECT_EQ(invalidOf(chain), "accepted");
}

TEST(ModelStructure, JointsMustFormATree) {
  // rib1 and rib2 each other's parent: a joint cycle, each body its own ancestor
  Model cycle = tinyModelWithSecondRib();
  cycle.joints.parent[0] = 2;
  addJoint(cycle, 1, 2);
  EXPECT_EQ(invalidOf(cycle), "joints[1].parent: joint cycle: body 'rib1_left' is its own ancestor");
  // a body hanging below a cycle is checked first: the search ends, naming a body of the cycle
  Model below = tinyModelWithSecondRib();
  below.bodies.isFixed[0] = 0;
  below.joints.parent[0] = 1;  // body 0 hangs from rib1 ...
  below.joints.child[0] = 0;
  addJoint(below, 2, 1);  // ... which hangs from rib2, which hangs from rib1
  addJoint(below, 1, 2);
  EXPECT_EQ(invalidOf(below), "joints[2].parent: joint cycle: body 'rib1_left' is its own ancestor");
  // two joints on one child
  Model twice = tinyModelWithSecondRib();
  addJoint(twice, 0, 1);
  EXPECT_EQ(
      invalidOf(twice),
      "joints[1].child: body 'rib1_left' is already the child of joints[0]: a body has one parent joint");
}

TEST(ModelStructure, SurfacesMustBeClosedAndConsistentlyOriented) {
  // the toy torso's icosphere gut with one triangle taken out: an open surface
  Model open = test::makeToyTorso(1);
  ASSERT_EQ(invalidOf(open), "accepted");
  open.gut.triangles = open.gut.triangles.leftCols(open.gut.triangles.cols() - 1).eval();
  EXPECT_NE(invalidOf(open).find("has no neighbouring triangle: the surface is open"), std::string::npos)
      << invalidOf(open);
  EXPECT_EQ(invalidOf(open).rfind("gut.triangles[", 0), 0u) << invalidOf(open);

  // a cavity of zero or one triangle
  Model none = tinyModel();
  none.cavity.triangles.resize(3, 0);
  EXPECT_EQ(invalidOf(none), "cavity.triangles: must be a closed surface of at least 4 triangles, got 0");
  Model one = tinyModel();
  one.cavity.triangles = tinyModel().cavity.triangles.leftCols(1).eval();
  EXPECT_EQ(invalidOf(one), "cavity.triangles: must be a closed surface of at least 4 triangles, got 1");

  // one flipped cavity triangle
  Model flipped = tinyModel();
  std::swap(flipped.cavity.triangles(0, 2), flipped.cavity.triangles(1, 2));
  EXPECT_NE(invalidOf(flipped).find("runs the same way as in cavity.triangles["), std::string::npos)
      << invalidOf(flipped);
  // every cavity triangle flipped: consistent, but inside out
  Model inverted = tinyModel();
  for (int i = 0; i < inverted.cavity.triangles.cols(); ++i)
    std::swap(inverted.cavity.triangles(0, i), inverted.cavity.triangles(1, i));
  EXPECT_EQ(invalidOf(inverted).rfind("cavity.triangles: enclosed rest volume must be > 0", 0), 0u)
      << invalidOf(inverted);
}

TEST(ModelStructure, ElementsMustExistHoldAndEndOnTheModel) {
  Model none = tinyModel();
  none.elements = Elements{};
  EXPECT_EQ(invalidOf(none),
            "elements: must not be empty: no muscle or cartilage holds the rib cage and the gut");
  Model slack = tinyModel();
  slack.elements.kpe.setZero();
  EXPECT_EQ(invalidOf(slack),
            "elements.kpe: all 1 passive gains are 0: nothing holds the rib cage, and the lungs would turn "
            "inside out");
  Model outside = tinyModel();
  outside.elements.endA.body[0] = 5;
  EXPECT_EQ(invalidOf(outside), "elements.a[0].body: index 5 out of range [0, 2)");
  Model node = tinyModel();
  node.elements.endB.nodes(0, 0) = 4;
  EXPECT_EQ(invalidOf(node), "elements.b[0].nodes: index 4 out of range [0, 4)");
}

// a model that loads but cannot hold itself (every passive gain scaled to 0): the lungs turn inside out, and
// the run stops with that as its error instead of going on with a negative volume (issue 15, class 7)
TEST(ModelStructure, ARunWhoseLungsTurnInsideOutStopsNamingIt) {
  SimulationOptions o;
  for (double& s : o.step.passiveGainScale) s = 0.0;
  Simulation sim(std::make_shared<const Model>(test::makeToyTorso(1)),
                 std::make_unique<BreathStyleController>(loadBreathStyle("calm")), o);
  try {
    sim.advance(10.0);
    FAIL() << "ran 10 s without passive gains";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("mL is not positive (the rib cage collapsed through itself"),
              std::string::npos)
        << e.what();
  }
}
