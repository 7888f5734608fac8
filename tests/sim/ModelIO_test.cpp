// Model format: round trip and rejection of corrupted files (docs/model-format.md).
#include "pneuma/sim/Error.h"
#include "pneuma/sim/ModelIO.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <string>

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

  for (int i = 0; i < 4; ++i) m.cavity.vertices.addNodePoint(Eigen::Vector3i(i, -1, -1), Eigen::Vector3d(1, 0, 0));
  m.cavity.triangles = m.gut.triangles;

  for (const char* n : {"xiphoid", "umbilicus", "diaphragm_apex", "rib8_lateral_left", "rib8_lateral_right"}) {
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
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["version"] = 7; }),
            "model.json: version: unsupported version 7 (this build reads 1)");
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["landmarks"].erase(0); }),
            "model.json: landmarks: missing required landmark 'xiphoid'");
  // an inward-facing gut surface encloses negative volume
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) {
              for (auto& t : j["gut"]["triangles"]) std::swap(t[0], t[1]);
            }).rfind("model.json: gut.triangles: enclosed rest volume must be > 0", 0),
            0u);
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["bodies"][0]["inertia"][0][0] = -1.0; })
                .rfind("model.json: bodies[0].inertia: must be positive definite", 0),
            0u);
}

// gut.drag is optional: a model written before the visceral drag existed loads without it
TEST(ModelIO, ModelWithoutGutDragLoadsWithNone) {
  nlohmann::json j = nlohmann::json::parse(serializeModel(tinyModel()));
  EXPECT_DOUBLE_EQ(parseModel(j.dump()).gut.drag, 20.0);
  j["gut"].erase("drag");
  EXPECT_DOUBLE_EQ(parseModel(j.dump()).gut.drag, 0.0);
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
    EXPECT_NE(std::string(e.what()).find("/nonexistent/pneuma-model/model.json: cannot open"), std::string::npos);
  }
}
