// Soft-tissue volume bodies (Model::volumes, VolumeBodies): closed surfaces over their own nodes that keep
// their volume by the gut's pressure law (Eq. 4, 5). On the toy torso with one lens of tissue over a rib
// (addToyTissueBody()): a muscle pressing on it changes its volume by less than the stated tolerance, while
// the same press on a body with a hundredth of the bulk modulus squeezes it by far more; the implicit step's
// preconditioner carries each body's rank-one pressure stiffness exactly; the model file round-trips the
// block, a model without it loads unchanged, and bad values are refused naming the field. Their forces and
// stiffness against finite differences are in Stiffness_test.
#include <gtest/gtest.h>

#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "ToyTorso.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/ModelIO.h"
#include "pneuma/sim/Step.h"

namespace pneuma::sim {
namespace {

using Eigen::Vector3d;

constexpr double kVolumeTolerance = 0.01;  // [-] |V - V0| / V0 under the press (the gut's is 2 %, Section 6.2)

// the toy torso with a tissue lens and three muscle strands (rectus group) from its apex to the rib behind
// it: activating the rectus presses the lens against the rib
Model pressedLens(double kappa) {
  Model m = test::makeToyTorso(2);
  const int apex = test::addToyTissueBody(m, kappa);
  int rib = -1;
  for (int b = 0; b < m.bodies.size(); ++b)
    if (m.bodies.name[static_cast<std::size_t>(b)] == "rib3_right") rib = b;
  const Vector3d p = m.nodes.rest.col(apex);
  const Vector3d inward = -Vector3d(0.75, 0.66, 0.0).normalized();
  for (const Vector3d& off : {Vector3d(0.0, 0.0, 0.01), Vector3d(0.0, 0.0, -0.01), Vector3d(0.01, -0.01, 0.0)})
    test::addElement(m, ElementGroup::Rectus, test::End{-1, apex, {}},
                     test::End{rib, -1, Vector3d(p + 0.05 * inward + off)}, 600.0, 0.0, 0.5);
  return m;
}

// largest |V - V0| / V0 of the lens over 2 s of a rectus contraction (r = 0.3) whose activation alpha rises
// from 0 to 1 over the first 0.5 s, at the default implicit step
double maxLensError(const Model& m) {
  State s = makeInitialState(m);
  StepWork w = makeStepWork(m);
  StepOptions o;
  o.gravity = false;
  Activations act{};
  const double dt = defaultTimeStep(o.integrator);
  double worst = 0.0;
  Metrics metrics;
  for (int i = 0; i < 120; ++i) {
    act[static_cast<std::size_t>(ElementGroup::Rectus)] = {0.3, std::min(1.0, s.time / 0.5)};
    step(m, s, dt, act, o, w);
    checkState(m, s, w, dt);
    computeMetrics(m, s, act, o, w, metrics);
    worst = std::max(worst, std::abs(metrics.volumeBodyError(0)));
  }
  return worst;
}

TEST(VolumeBodies, APressedBodyKeepsItsVolumeWithinTheTolerance) {
  const double stiff = maxLensError(pressedLens(2e6));
  const double soft = maxLensError(pressedLens(2e4));
  EXPECT_LT(stiff, kVolumeTolerance);
  // the press is real: a body with a hundredth of the bulk modulus gives way
  EXPECT_GT(soft, 5.0 * kVolumeTolerance);
  EXPECT_GT(soft, 20.0 * stiff);
}

// the state after one implicit step from `s` with solver memory `w` (copied)
State stepFrom(const Model& m, const State& s, StepWork w, const StepOptions& o, const Activations& act) {
  State out = s;
  step(m, out, defaultTimeStep(o.integrator), act, o, w);
  return out;
}

// right after a refactorization the step takes the preconditioner's solution without a CG iteration, which
// is exact only if the preconditioner holds every term of the system: the volume bodies' rank-one pressure
// stiffness included. Against the same step solved by CG to 1e-12 from a factorization a step old
TEST(VolumeBodies, PreconditionerHoldsTheirPressureStiffness) {
  const Model m = pressedLens(2e6);
  Activations act{};
  act[static_cast<std::size_t>(ElementGroup::Rectus)] = {0.3, 1.0};
  StepOptions o;
  o.gravity = false;
  State s = makeInitialState(m);
  StepWork w = makeStepWork(m);
  for (int i = 0; i < 6; ++i) step(m, s, defaultTimeStep(o.integrator), act, o, w);
  ASSERT_GT(w.outputs.volumeBodyPressure(0), 100.0) << "the pressed body pushes";

  StepWork fresh = w;
  fresh.memory.hasFactorization = false;  // factor at this state: no CG iteration
  const State direct = stepFrom(m, s, fresh, o, act);

  StepOptions iterate = o;  // keep the old factorization and iterate to convergence
  iterate.cgTolerance = 1e-12;
  iterate.cgMaxIterations = 1000;
  iterate.preconditionerRefresh = 1000;
  iterate.refactorIterations = 1000;
  iterate.refactorElementChanges = 1000000;
  const State converged = stepFrom(m, s, w, iterate, act);

  const Eigen::Matrix3Xd dvDirect = direct.nodeVelocity - s.nodeVelocity,
                         dvConverged = converged.nodeVelocity - s.nodeVelocity;
  EXPECT_LT((dvDirect - dvConverged).norm(), 1e-6 * dvConverged.norm());
}

// the model file: the block round-trips; without it a model loads with none; bad values name the field
std::string rejectionOf(const std::function<void(nlohmann::json&)>& edit) {
  Model m = test::makeToyTorso(1);
  test::addToyTissueBody(m);
  nlohmann::json j = nlohmann::json::parse(serializeModel(m));
  edit(j);
  try {
    parseModel(j.dump());
  } catch (const Error& e) {
    return e.what();
  }
  return "accepted";
}

TEST(VolumeBodies, ModelFileRoundTripsTheBlockAndOlderModelsLoadWithout) {
  Model m = test::makeToyTorso(1);
  test::addToyTissueBody(m, 3e5);
  const std::string text = serializeModel(m);
  const Model back = parseModel(text);
  ASSERT_EQ(back.volumes.size(), 1);
  EXPECT_EQ(back.volumes.name[0], "toy_tissue_0");
  EXPECT_EQ(back.volumes.kappa(0), 3e5);
  EXPECT_EQ(back.volumes.triangles[0], m.volumes.triangles[0]);
  EXPECT_EQ(back.nodes.region.back(), NodeRegion::Tissue);
  EXPECT_EQ(serializeModel(back), text);

  const std::string plain = serializeModel(test::makeToyTorso(1));
  EXPECT_EQ(plain.find("volume_bodies"), std::string::npos) << "a model without bodies writes no block";
  EXPECT_EQ(parseModel(plain).volumes.size(), 0);
}

TEST(VolumeBodies, BadValuesAreRefusedNamingTheField) {
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["volume_bodies"][0]["kappa"] = 0.0; }),
            "model.json: volume_bodies[0].kappa: must be > 0, got 0");
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["volume_bodies"][0]["name"] = ""; }),
            "model.json: volume_bodies[0].name: must not be empty");
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["volume_bodies"].push_back(j["volume_bodies"][0]); }),
            "model.json: volume_bodies[1].name: duplicate name 'toy_tissue_0'");
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["volume_bodies"][0]["triangles"][0][0] = 0; }),
            "model.json: volume_bodies[0].triangles[0]: node 0 is not a tissue node (region \"tissue\")");
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["volume_bodies"][0]["triangles"].erase(0); })
                .rfind("model.json: volume_bodies[0].triangles[", 0),
            0u);
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) {
              for (auto& t : j["volume_bodies"][0]["triangles"]) std::swap(t[0], t[1]);
            }).rfind("model.json: volume_bodies[0].triangles: enclosed rest volume must be > 0", 0),
            0u);
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["volume_bodies"][0]["density"] = 1.0; })
                .rfind("model.json: volume_bodies[0]", 0),
            0u);
  EXPECT_EQ(rejectionOf([](nlohmann::json& j) { j["nodes"][0]["region"] = "bone"; }),
            "model.json: nodes[0].region: unknown region 'bone' (expected wall, diaphragm, fixed or tissue)");
}

}  // namespace
}  // namespace pneuma::sim
