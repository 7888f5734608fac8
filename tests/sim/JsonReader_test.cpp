// The one JSON reading layer through the real loaders (scenario, pattern, breath style, model): deep nesting,
// numbers beyond double range, wrapped integers, duplicate and unknown keys give a clear Error naming the
// file and JSON path, quote a short excerpt and never crash.
#include "pneuma/sim/JsonReader.h"

#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "pneuma/sim/BreathStyleController.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/ModelIO.h"
#include "pneuma/sim/Scenario.h"
#include "pneuma/sim/pattern/Pattern.h"

using namespace pneuma::sim;

namespace {

const std::string kScenario =
    R"({"format": "pneuma-scenario", "version": 1, "duration_s": 5, "controller": {"style": "calm"}})";
const std::string kPattern = R"({"format": "pneuma-pattern", "version": 1, "name": "t", "layers": [
    {"name": "a", "repeat": "infinite", "cycle": {"kind": "linear", "rate_bpm": 12, "depth": [0.1, 0.2]}}]})";
const std::string kStyle =
    R"({"name": "s", "breaths_per_minute": 12, "diaphragm_r": 0.8, "intercostal_mean": 0.2, "intercostal_amplitude": 0.1})";

// every loader under test, by name, reading text
const std::vector<std::pair<std::string, std::function<void(const std::string&)>>> kLoaders = {
    {"scenario", [](const std::string& t) { parseScenario(t, "x.json", ""); }},
    {"pattern", [](const std::string& t) { pattern::parsePattern(t, "x.json", ""); }},
    {"style", [](const std::string& t) { parseBreathStyle(t, "x.json"); }},
    {"model", [](const std::string& t) { parseModel(t, "x.json"); }},
};

std::string errorOf(const std::function<void(const std::string&)>& load, const std::string& text) {
  try {
    load(text);
  } catch (const Error& e) {
    return e.what();
  }
  return "accepted";
}

// `text` with the first occurrence of `what` replaced by `with`
std::string edited(std::string text, const std::string& what, const std::string& with) {
  return text.replace(text.find(what), what.size(), with);
}

}  // namespace

TEST(JsonLoaders, DeepNestingIsAnErrorNotAStackOverflow) {
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  for (const auto& [name, load] : kLoaders) {
    const std::string e = errorOf(load, deep);
    EXPECT_NE(e.find("x.json: "), std::string::npos) << name << ": " << e;
    EXPECT_NE(e.find("nesting deeper than 64 levels"), std::string::npos) << name << ": " << e;
    EXPECT_LT(e.size(), 600u) << name;
  }
  // 64 levels still parse
  EXPECT_NO_THROW(JsonDocument::parse(std::string(64, '[') + std::string(64, ']'), "ok.json"));
}

TEST(JsonLoaders, NumberBeyondDoubleRangeNamesThePath) {
  EXPECT_EQ(errorOf(kLoaders[0].second, "1e400"),
            "x.json: (root): number 1e400 is beyond the range of a double");
  EXPECT_EQ(errorOf(kLoaders[0].second, edited(kScenario, "\"duration_s\": 5", "\"duration_s\": 1e400")),
            "x.json: duration_s: number 1e400 is beyond the range of a double");
  EXPECT_EQ(errorOf(kLoaders[1].second, edited(kPattern, "[0.1, 0.2]", "[0.1, -2e999]")),
            "x.json: layers[0].cycle.depth[1]: number -2e999 is beyond the range of a double");
  EXPECT_EQ(errorOf(kLoaders[2].second, edited(kStyle, "0.8", "1" + std::string(400, '0')))
                .rfind("x.json: diaphragm_r: number 1000", 0),
            0u);
}

TEST(JsonLoaders, IntegersDoNotWrap) {
  EXPECT_EQ(errorOf(kLoaders[0].second, edited(kScenario, "\"version\": 1", "\"version\": 4294967297")),
            "x.json: version: must be an integer in [0, 2147483647], got 4294967297");
  EXPECT_EQ(errorOf(kLoaders[1].second, edited(kPattern, "\"version\": 1", "\"version\": 4294967297")),
            "x.json: version: must be an integer in [0, 2147483647], got 4294967297");
  EXPECT_EQ(errorOf(kLoaders[2].second, edited(kStyle, "}", ", \"cycles\": -1}")),
            "x.json: cycles: must be an integer in [0, 2147483647], got -1");
  EXPECT_EQ(errorOf(kLoaders[0].second, edited(kScenario, "}}", "}, \"seed\": -1}")),
            "x.json: seed: must be a non-negative integer, got -1");
}

TEST(JsonLoaders, DuplicateKeysAreRejected) {
  // the first duplicate is found while parsing, before any field is read
  for (const auto& [name, load] : kLoaders)
    EXPECT_EQ(errorOf(load, edited(kScenario, "{", "{\"z\": 1, \"z\": 2, ")), "x.json: z: duplicate key")
        << name;
  EXPECT_EQ(
      errorOf(kLoaders[1].second, edited(kPattern, "\"rate_bpm\": 12", "\"rate_bpm\": 12, \"rate_bpm\": 30")),
      "x.json: layers[0].cycle.rate_bpm: duplicate key");
}

TEST(JsonLoaders, UnknownKeysInStylesAreRejectedWithASuggestion) {
  EXPECT_EQ(errorOf(kLoaders[2].second, edited(kStyle, "}", ", \"diaphragm_rr\": 1}")),
            "x.json: diaphragm_rr: unknown field (did you mean diaphragm_r?)");
  EXPECT_EQ(errorOf(kLoaders[2].second, edited(kStyle, "}", ", \"colour\": 1}")),
            "x.json: colour: unknown field");
}

TEST(JsonLoaders, MessagesQuoteAShortExcerpt) {
  std::string big = "[";
  for (int i = 0; i < 100000; ++i) big += (i ? ", " : "") + std::to_string(i);
  big += "]";
  const std::string e =
      errorOf(kLoaders[0].second, edited(kScenario, "\"duration_s\": 5", "\"duration_s\": " + big));
  EXPECT_EQ(e.rfind("x.json: duration_s: must be a number, got [0, 1, 2, ", 0), 0u) << e.substr(0, 200);
  EXPECT_LT(e.size(), 120u);
  const std::string s =
      errorOf(kLoaders[2].second, edited(kStyle, "\"s\"", "\"" + std::string(1 << 20, 'x') + "\"}"));
  EXPECT_LT(s.size(), 300u) << s.substr(0, 300);
  // strings from the file quoted in semantic messages are cut too
  const std::string huge(1 << 20, 'y');
  const std::vector<std::string> messages = {
      errorOf(kLoaders[2].second, edited(edited(kStyle, "\"s\"", "\"" + huge + "\""), "12", "-3")),
      errorOf(kLoaders[1].second, edited(kPattern, "\"linear\"", "\"" + huge + "\"")),
      errorOf(kLoaders[0].second,
              edited(kScenario, "}}", "}, \"overrides\": {\"integrator\": \"" + huge + "\"}}")),
      errorOf(kLoaders[0].second,
              edited(kScenario, "}}", "}, \"overrides\": {\"active_gain_scale\": {\"" + huge + "\": 1}}}")),
  };
  for (const std::string& m : messages) {
    EXPECT_NE(m.find("yyy..."), std::string::npos) << m.substr(0, 200);
    EXPECT_LT(m.size(), 300u) << m.substr(0, 300);
  }
}

TEST(JsonLoaders, ModelRejectsUnknownDuplicateAndWrappedKeys) {
  const std::string text = serializeModel(parseModel(
      R"({"format": "pneuma-model", "version": 1, "name": "m", "gravity": [0, 0, -9.81],
          "bodies": [{"name": "spine", "fixed": true, "mass": 1, "com": [0, 0, 0],
                      "inertia": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}],
          "joints": [], "nodes": [{"x": [0, 0, 0], "mass": 1, "region": "wall"}, {"x": [0.1, 0, 0], "mass": 1, "region": "wall"},
                                  {"x": [0, 0.1, 0], "mass": 1, "region": "wall"}, {"x": [0, 0, 0.1], "mass": 1, "region": "wall"}],
          "gut": {"kappa": 1, "triangles": []},
          "elements": [{"group": "cartilage", "a": {"nodes": [0], "weights": [1]}, "b": {"nodes": [1], "weights": [1]},
                        "rest_length": 0.1, "kac": 0, "kpe": 10, "damping": 0}],
          "cavity": {"vertices": [{"nodes": [0], "weights": [1]}, {"nodes": [1], "weights": [1]},
                                  {"nodes": [2], "weights": [1]}, {"nodes": [3], "weights": [1]}],
                     "triangles": [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]},
          "lungs": {"mediastinum_volume": 0, "right": {"vertices": [], "triangles": []},
                    "left": {"vertices": [], "triangles": []}},
          "landmarks": [{"name": "xiphoid", "body": 0, "local": [0, 0, 0]},
                        {"name": "umbilicus", "body": 0, "local": [0, 0, 0]},
                        {"name": "diaphragm_apex", "body": 0, "local": [0, 0, 0]},
                        {"name": "rib8_lateral_left", "body": 0, "local": [0, 0, 0]},
                        {"name": "rib8_lateral_right", "body": 0, "local": [0, 0, 0]}]})",
      "m.json"));
  const auto& load = kLoaders[3].second;
  EXPECT_EQ(errorOf(load, edited(text, "\"mass\"", "\"mas\"")),
            "x.json: bodies[0].mas: unknown field (did you mean mass?)");
  EXPECT_EQ(errorOf(load, edited(text, "\"kappa\"", "\"kappa\": 2, \"kappa\"")),
            "x.json: gut.kappa: duplicate key");
  EXPECT_EQ(errorOf(load, edited(text, "\"body\": 0", "\"body\": 4294967296")),
            "x.json: landmarks[0].body: must be an integer in [-2147483648, 2147483647], got 4294967296");
  EXPECT_EQ(errorOf(load, edited(text, "\"version\": 1", "\"version\": 4294967297")),
            "x.json: version: must be an integer in [-2147483648, 2147483647], got 4294967297");
  EXPECT_EQ(errorOf(load, edited(text, "\"format\"", "\"fromat\": 1, \"format\"")),
            "x.json: fromat: unknown field (did you mean format?)");
}

// a loader given a device, a directory or a missing file fails at once, naming the path: /dev/zero used to be
// read until memory ran out
TEST(ReadInputFile, RefusesWhatIsNotARegularFile) {
  const auto message = [](const std::function<void()>& load) {
    try {
      load();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_NE(message([] { readInputFile("/dev/zero"); }).find("/dev/zero: not a regular file"),
            std::string::npos);
  EXPECT_NE(message([] { loadScenario("/dev/zero"); }).find("not a regular file"), std::string::npos);
  EXPECT_NE(message([] { loadBreathStyle("/dev/zero.json"); }).find("/dev/zero.json: cannot open"),
            std::string::npos);
  EXPECT_NE(
      message([] { loadModel("/tmp"); }).find("/tmp/model.json: cannot open (is '/tmp' a model directory?)"),
      std::string::npos);
  EXPECT_NE(message([] { readInputFile("/"); }).find("/: not a regular file"), std::string::npos);
  const std::string text = readInputFile(std::string(PNEUMA_RESOURCE_DIR) + "/presets/calm.json");
  EXPECT_NE(text.find("\"calm\""), std::string::npos);
}
