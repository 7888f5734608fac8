// Scenario files: parsing, defaults, round trip, and errors that name the failing JSON path.
#include "pneuma/sim/Scenario.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "pneuma/sim/Error.h"

using namespace pneuma::sim;
namespace fs = std::filesystem;

namespace {

const char* kMinimal =
    R"({"format": "pneuma-scenario", "version": 1, "duration_s": 5, "controller": {"style": "calm"}})";

// parses `text` expecting an Error whose message contains every string of `mentions`
void expectError(const std::string& text, const std::vector<std::string>& mentions) {
  try {
    parseScenario(text, "bad.json", "/base");
    ADD_FAILURE() << "no error for " << text;
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("bad.json: ", 0), 0u) << what;
    for (const std::string& m : mentions)
      EXPECT_NE(what.find(m), std::string::npos) << "'" << m << "' not in: " << what;
  }
}

// kMinimal with one top-level member replaced or added
std::string with(const std::string& member) {
  std::string t =
      R"({"format": "pneuma-scenario", "version": 1, "duration_s": 5, "controller": {"style": "calm"}, )";
  return t + member + "}";
}

}  // namespace

TEST(Scenario, MinimalFileGetsDocumentedDefaults) {
  const Scenario s = parseScenario(kMinimal, "min.json", "/base");
  EXPECT_EQ(s.controller, ControllerKind::Style);
  EXPECT_EQ(s.controllerName, "calm");
  EXPECT_EQ(s.duration, 5.0);
  EXPECT_EQ(s.model, "default");
  EXPECT_EQ(s.seed, 0u);
  EXPECT_EQ(s.options.outputRate, 60.0);
  EXPECT_TRUE(s.outputs.csv);
  EXPECT_FALSE(s.outputs.vtk);
  EXPECT_EQ(s.options.settleTime, SimulationOptions{}.settleTime);
  EXPECT_EQ(s.options.step.integrator, StepOptions{}.integrator);
  EXPECT_EQ(s.options.step.posture, Posture::Upright);
}

TEST(Scenario, RelativePathsResolveAgainstTheScenarioDirectory) {
  const Scenario s = parseScenario(with(R"("model": "models/small")"), "x.json", "/data/runs");
  EXPECT_EQ(s.model, "/data/runs/models/small");
  const Scenario p = parseScenario(
      R"({"format": "pneuma-scenario", "version": 1, "duration_s": 5, "controller": {"pattern": "p/sigh.json"}})",
      "x.json", "/data/runs");
  EXPECT_EQ(p.controller, ControllerKind::Pattern);
  EXPECT_EQ(p.controllerName, "/data/runs/p/sigh.json");
}

TEST(Scenario, OverridesReachTheSimulationOptions) {
  const Scenario s = parseScenario(
      with(
          R"("overrides": {"integrator": "symplectic-euler", "dt_s": 0.0002, "settle_time_s": 0.5, "gravity": false,
              "posture": "supine",
              "joint_friction_scale": 0, "gut_drag_scale": 0.5, "kappa_pa": 40000, "active_gain_scale": {"rectus": 1.5},
              "passive_gain_scale": {"cartilage": 2}}, "outputs": {"output_rate_hz": 25, "vtk": true})"),
      "o.json", "");
  EXPECT_EQ(s.options.step.integrator, IntegratorKind::SymplecticEuler);
  EXPECT_EQ(s.options.dt, 0.0002);
  EXPECT_EQ(s.options.settleTime, 0.5);
  EXPECT_FALSE(s.options.step.gravity);
  EXPECT_EQ(s.options.step.posture, Posture::Supine);
  EXPECT_EQ(s.options.step.jointFrictionScale, 0.0);
  EXPECT_EQ(s.options.step.gutDragScale, 0.5);
  EXPECT_EQ(s.options.step.kappa, 40000.0);
  EXPECT_EQ(s.options.step.activeGainScale[static_cast<int>(ElementGroup::Rectus)], 1.5);
  EXPECT_EQ(s.options.step.activeGainScale[static_cast<int>(ElementGroup::Diaphragm)], 1.0);
  EXPECT_EQ(s.options.step.passiveGainScale[static_cast<int>(ElementGroup::Cartilage)], 2.0);
  EXPECT_EQ(s.options.outputRate, 25.0);
  EXPECT_TRUE(s.outputs.vtk);
}

// the halves of the diaphragm are scaled on their own (a paralysed hemidiaphragm), for the active gain only,
// and survive a save
TEST(Scenario, HemidiaphragmScalesAreReadAndSaved) {
  const Scenario s =
      parseScenario(with(R"("overrides": {"active_gain_scale": {"diaphragm_left": 0}})"), "h.json", "");
  EXPECT_EQ(s.options.step.hemidiaphragmActiveScale[0], 0.0);
  EXPECT_EQ(s.options.step.hemidiaphragmActiveScale[1], 1.0);
  EXPECT_EQ(s.options.step.activeGainScale[static_cast<int>(ElementGroup::Diaphragm)], 1.0);
  const Scenario back = parseScenario(serializeScenario(s), "h.json", "");
  EXPECT_EQ(back.options.step.hemidiaphragmActiveScale, s.options.step.hemidiaphragmActiveScale);
  expectError(with(R"("overrides": {"passive_gain_scale": {"diaphragm_right": 0}})"),
              {"overrides.passive_gain_scale.diaphragm_right: unknown muscle group"});
  expectError(with(R"("overrides": {"active_gain_scale": {"diaphragm_right": -1}})"),
              {"overrides.active_gain_scale.diaphragm_right"});
}

TEST(Scenario, SerializeThenParseIsTheIdentity) {
  for (const auto& entry :
       fs::recursive_directory_iterator(std::string(PNEUMA_RESOURCE_DIR) + "/scenarios")) {
    if (!entry.is_regular_file()) continue;
    const Scenario a = loadScenario(entry.path().string());
    const std::string text = serializeScenario(a);
    const Scenario b = parseScenario(text, "round.json", entry.path().parent_path().string());
    EXPECT_EQ(serializeScenario(b), text) << entry.path();
    EXPECT_EQ(b.controller, a.controller);
    EXPECT_EQ(b.duration, a.duration);
    EXPECT_EQ(b.seed, a.seed);
    EXPECT_EQ(b.options.step.posture, a.options.step.posture);
  }
  // the lying example keeps its posture through a save
  const Scenario supine = loadScenario(std::string(PNEUMA_RESOURCE_DIR) + "/scenarios/calm-supine.json");
  EXPECT_EQ(supine.options.step.posture, Posture::Supine);
  EXPECT_NE(serializeScenario(supine).find(R"("posture": "supine")"), std::string::npos);
}

TEST(Scenario, ExampleTimelineIsNeutralThenStartleAtTenSeconds) {
  const Scenario s = loadScenario(std::string(PNEUMA_RESOURCE_DIR) + "/scenarios/startle-at-10s.json");
  EXPECT_EQ(s.controller, ControllerKind::Pattern);
  EXPECT_NE(s.patternText.find("\"startle\""), std::string::npos);
  EXPECT_NO_THROW(checkController(s, PNEUMA_RESOURCE_DIR));
}

TEST(Scenario, BadFieldsAreNamedByTheirJsonPath) {
  expectError("{", {"invalid JSON"});
  expectError(
      R"({"format": "pneuma-pattern", "version": 1, "duration_s": 5, "controller": {"style": "calm"}})",
      {"format", "pneuma-scenario"});
  expectError(
      R"({"format": "pneuma-scenario", "version": 2, "duration_s": 5, "controller": {"style": "calm"}})",
      {"version", "unsupported"});
  expectError(R"({"format": "pneuma-scenario", "version": 1, "controller": {"style": "calm"}})",
              {"duration_s: missing"});
  expectError(
      R"({"format": "pneuma-scenario", "version": 1, "duration_s": -2, "controller": {"style": "calm"}})",
      {"duration_s: must be in [0.001, 86400] s, got -2"});
  expectError(
      R"({"format": "pneuma-scenario", "version": 1, "duration_s": "long", "controller": {"style": "calm"}})",
      {"duration_s: must be a number"});
  expectError(with(R"("seed": -1)"), {"seed: must be a non-negative integer"});
  expectError(with(R"("sead": 1)"), {"sead: unknown field"});
  expectError(
      R"({"format": "pneuma-scenario", "version": 1, "duration_s": 5, "controller": {"style": "calm", "affect": "joy"}})",
      {"controller: needs exactly one"});
  expectError(R"({"format": "pneuma-scenario", "version": 1, "duration_s": 5, "controller": {"pattern": 3}})",
              {"controller.pattern: must be a pattern file path"});
  expectError(with(R"("overrides": {"dt_s": 0})"), {"overrides.dt_s: must be in [1e-06, 0.05] s, got 0"});
  expectError(with(R"("overrides": {"integrator": "rk4"})"),
              {"overrides.integrator", "rk4", "implicit-euler-joints"});
  expectError(with(R"("overrides": {"active_gain_scale": {"diaphram": 2}})"),
              {"overrides.active_gain_scale.diaphram: unknown muscle group", "diaphragm"});
  expectError(with(R"("overrides": {"passive_gain_scale": {"rectus": -1}})"),
              {"overrides.passive_gain_scale.rectus: must be >= 0"});
  expectError(with(R"("overrides": {"gravity": "yes"})"), {"overrides.gravity: must be true or false"});
  expectError(with(R"("overrides": {"posture": "sitting"})"),
              {"overrides.posture: unknown posture 'sitting' (valid: upright, supine, prone, left-lateral, "
               "right-lateral)"});
  expectError(with(R"("overrides": {"posture": 1})"), {"overrides.posture"});
  expectError(with(R"("outputs": {"output_rate_hz": 0})"),
              {"outputs.output_rate_hz: must be in [0.01, 10000] Hz, got 0"});
  expectError(with(R"("outputs": {"png": true})"), {"outputs.png: unknown field"});
}

TEST(Scenario, BadControllerContentsAreNamedByTheirPath) {
  Scenario s = parseScenario(
      R"({"format": "pneuma-scenario", "version": 1, "duration_s": 5, "controller": {"affect": "ennui"}})",
      "a.json", "");
  try {
    checkController(s, PNEUMA_RESOURCE_DIR);
    ADD_FAILURE() << "unknown affect accepted";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("controller.affect"), std::string::npos) << what;
    EXPECT_NE(what.find("ennui"), std::string::npos) << what;
    EXPECT_NE(what.find("startle"), std::string::npos) << what;  // lists the valid names
  }
  s = parseScenario(R"({"format": "pneuma-scenario", "version": 1, "duration_s": 5, "controller": {"pattern":
      {"format": "pneuma-pattern", "version": 1, "name": "x", "affect": "neutral",
       "timeline": [{"time_s": -1, "affect": "startle"}]}}})",
                    "p.json", "");
  try {
    checkController(s, PNEUMA_RESOURCE_DIR);
    ADD_FAILURE() << "negative timeline time accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("controller.pattern: timeline[0].time_s"), std::string::npos)
        << e.what();
  }
}

// `simulate --set` and sweeps go through the overrides' own parser: the same keys, bounds and messages
TEST(Scenario, OverrideKeyValueGivesTheSameOptionsAsTheFile) {
  const Scenario file = parseScenario(
      with(R"("overrides": {"dt_s": 0.005, "posture": "supine", "active_gain_scale": {"diaphragm": 1.2},
                             "gravity": false})"),
      "run.json", "");
  SimulationOptions o;
  applyOverride(o, "dt_s", "0.005");
  applyOverride(o, "posture", "supine");  // a bare string
  applyOverride(o, "active_gain_scale.diaphragm", "1.2");
  applyOverride(o, "gravity", "false");
  ASSERT_TRUE(o.dt.has_value());
  EXPECT_EQ(*o.dt, *file.options.dt);
  EXPECT_EQ(o.step.posture, file.options.step.posture);
  EXPECT_EQ(o.step.gravity, file.options.step.gravity);
  EXPECT_EQ(o.step.activeGainScale, file.options.step.activeGainScale);
  EXPECT_EQ(o.step.activeGainScale[static_cast<std::size_t>(ElementGroup::Diaphragm)], 1.2);
  // one group's scale leaves the others alone
  EXPECT_EQ(o.step.activeGainScale[static_cast<std::size_t>(ElementGroup::Rectus)], 1.0);
}

TEST(Scenario, BadOverrideKeyOrValueIsOneLineNamingTheKeyAndChangesNothing) {
  auto message = [](const std::string& key, const std::string& value) {
    SimulationOptions o;
    const SimulationOptions before = o;
    try {
      applyOverride(o, key, value);
    } catch (const Error& e) {
      EXPECT_EQ(o.dt, before.dt);
      EXPECT_EQ(o.step.activeGainScale, before.step.activeGainScale);
      return std::string(e.what());
    }
    return std::string("no error");
  };
  // the file's message for the same value, with "--set" for the file name
  std::string fileMessage;
  try {
    parseScenario(with(R"("overrides": {"dt_s": -1})"), "run.json", "");
  } catch (const Error& e) {
    fileMessage = e.what();
  }
  EXPECT_EQ(fileMessage, "run.json: overrides.dt_s: must be in [1e-06, 0.05] s, got -1");
  EXPECT_EQ(message("dt_s", "-1"), "--set: dt_s: must be in [1e-06, 0.05] s, got -1");
  EXPECT_EQ(message("dt", "0.01"), "--set: dt: unknown field (did you mean dt_s?)");
  EXPECT_NE(
      message("active_gain_scale.diaphram", "1").find("active_gain_scale.diaphram: unknown muscle group"),
      std::string::npos);
  EXPECT_EQ(message("active_gain_scale.diaphragm", "-0.5"),
            "--set: active_gain_scale.diaphragm: must be >= 0, got -0.5");
  EXPECT_NE(message("posture", "sideways").find("--set: posture: unknown posture 'sideways'"),
            std::string::npos);
  EXPECT_NE(message("settle_time_s", "1e9").find("--set: settle_time_s: must be in [0, 600] s"),
            std::string::npos);
  EXPECT_NE(message("gravity", "maybe").find("--set: gravity:"), std::string::npos);
  EXPECT_NE(message("", "1").find("not an override key"), std::string::npos);
  EXPECT_NE(message("dt_s.", "1").find("not an override key"), std::string::npos);
}
