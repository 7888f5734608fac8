#include "pneuma/sim/pattern/Pattern.h"

#include <gtest/gtest.h>

#include <string>

#include "pneuma/sim/Error.h"

using namespace pneuma::sim;
using namespace pneuma::sim::pattern;

namespace {

const std::string kResources = PNEUMA_RESOURCE_DIR;

// a valid two-layer pattern; `cycle` replaces the first layer's cycle
std::string patternWith(const std::string& cycle) {
  return R"({"format": "pneuma-pattern", "version": 1, "name": "t", "layers": [
    {"name": "first", "repeat": 2, "cycle": )" +
         cycle + R"(},
    {"name": "base", "repeat": "infinite", "cycle": {"kind": "linear", "rate_bpm": 15, "depth": [0.05, 0.25]}}]})";
}

// the Error message of parsing `text`, or "" when it parses
std::string parseError(const std::string& text) {
  try {
    parsePattern(text, "test.json", kResources);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(PatternFile, ParsesLayersInPlayOrder) {
  const Pattern p = parsePattern(
      patternWith(R"({"kind": "keyframe", "time": "absolute", "depth": [0.1, 0.6], "balance": 0.2,
                      "post_inspiratory_pause_s": 0.5, "keyframes": [[0, 0], [1.5, 1], [2.5, 0]]})"),
      "test.json", kResources);
  ASSERT_EQ(p.layers.size(), 2u);
  EXPECT_EQ(p.layers[0].name, "first");
  EXPECT_EQ(p.layers[0].repetitions, 2);
  EXPECT_EQ(p.layers[0].cycle.kind, CycleKind::Keyframe);
  EXPECT_FALSE(p.layers[0].cycle.isRelative);
  EXPECT_DOUBLE_EQ(p.layers[0].cycle.depthMax, 0.6);
  EXPECT_DOUBLE_EQ(p.layers[0].cycle.postInspiratoryPause, 0.5);
  EXPECT_EQ(p.layers[1].repetitions, kInfinite);
  // two 3 s breaths of the first layer, then the base layer
  LayerStack s = makeLayerStack(p, 0);
  s.sample(5.9);
  EXPECT_EQ(s.currentLayerName(), "first");
  s.sample(6.1);
  EXPECT_EQ(s.currentLayerName(), "base");
}

TEST(PatternFile, MalformedFilesNameTheField) {
  struct Case {
    std::string cycle, expected;
  };
  const Case cases[] = {
      {R"({"kind": "cubic", "rate_bpm": 15, "depth": [0.05, 0.25]})",
       "test.json: layers[0].cycle.kind: unknown cycle kind 'cubic'"},
      {R"({"kind": "keyframe", "rate_bpm": 15, "depth": [0.05, 0.25], "keyframes": [[0, 0], [0.7, 1], [0.5, 0.5], [1, 0]]})",
       "test.json: layers[0].cycle.keyframes[2].time: 0.5 is not after"},
      {R"({"kind": "linear", "rate_bpm": 15, "depth": [0.4, 0.2]})",
       "test.json: layers[0].cycle.depth: min 0.4 > max 0.2"},
      {R"({"kind": "linear", "rate_bpm": -5, "depth": [0.05, 0.25]})",
       "test.json: layers[0].cycle.rate_bpm: must be in [0.5, 200] breaths/min, got -5"},
      {R"({"kind": "linear", "depth": [0.05, 0.25]})", "test.json: layers[0].cycle.rate_bpm: missing"},
      {R"({"kind": "linear", "rate_bpm": 15, "depth": [0.05, 0.25], "rte": 3})",
       "test.json: layers[0].cycle.rte: unknown field"},
      {R"({"kind": "linear", "rate_bpm": 15, "depth": [0.05, 1.25]})",
       "test.json: layers[0].cycle.depth[1]: must be in [0, 1]"},
      {R"({"kind": "spline", "rate_bpm": 15, "depth": [0.05, 0.25], "ie_ratio": 1, "keyframes": [[0, 0], [1, 0]]})",
       "test.json: layers[0].cycle.ie_ratio: not allowed with keyframes"},
      {R"({"kind": "linear", "rate_bpm": 15, "depth": [0.05, 0.25], "inspiratory_balance": -0.2})",
       "test.json: layers[0].cycle.inspiratory_balance: must be in [0, 1]"},
  };
  for (const Case& c : cases) {
    const std::string msg = parseError(patternWith(c.cycle));
    EXPECT_EQ(msg.rfind(c.expected, 0), 0u) << "got: " << msg << "\nexpected: " << c.expected;
  }
}

TEST(PatternFile, MalformedHeadersAndTimelinesNameTheField) {
  EXPECT_EQ(parseError("{nope").rfind("test.json: invalid JSON", 0), 0u);
  EXPECT_EQ(parseError(R"({"format": "pneuma-pattern", "version": 2, "name": "x", "affect": "neutral"})")
                .rfind("test.json: version: unsupported version 2", 0),
            0u);
  EXPECT_EQ(parseError(R"({"format": "pneuma-pattern", "version": 1, "name": "x", "affect": "glee"})")
                .rfind("test.json: affect: unknown affect 'glee' (valid: anger, boredom,", 0),
            0u);
  EXPECT_EQ(parseError(R"({"format": "pneuma-pattern", "version": 1, "name": "x", "affect": "neutral",
                          "timeline": [{"time_s": 5, "switch": "later", "affect": "joy"}]})")
                .rfind("test.json: timeline[0].switch: must be", 0),
            0u);
  EXPECT_EQ(parseError(R"({"format": "pneuma-pattern", "version": 1, "name": "x", "affect": "neutral",
                          "timeline": [{"time_s": 5, "affect": "joy"}, {"time_s": 2, "affect": "joy"}]})")
                .rfind("test.json: timeline[1].time_s: events must be in time order", 0),
            0u);
  EXPECT_EQ(parseError(R"({"format": "pneuma-pattern", "version": 1, "name": "x"})")
                .rfind("test.json: (root): needs exactly one of", 0),
            0u);
  EXPECT_EQ(parseError(patternWith(R"({"kind": "linear", "rate_bpm": 15, "depth": [0.05, 0.25]})")), "");
}

TEST(PatternFile, TimelineStartleAtTenSecondsThenNeutral) {
  const Pattern p = loadPatternFile(kResources + "/patterns/startle-at-10s.json", kResources);
  ASSERT_EQ(p.timeline.size(), 1u);
  EXPECT_EQ(p.timeline[0].label, "startle");
  LayerStack s = makeLayerStack(p, 1);
  s.sample(9.99);
  EXPECT_EQ(s.currentLayerName(), "neutral");
  s.sample(10.01);
  EXPECT_EQ(s.currentLayerName(), "startle");
  // quick inspiration 0.55 s and a 1 s suspension: the volume holds at the startle peak
  const double held = s.sample(10.6);
  for (double t = 10.6; t < 11.5; t += 0.05) EXPECT_NEAR(s.sample(t), held, 1e-12);
  // then 8 breaths at 35 b/m and back to neutral
  s.sample(13.0);
  EXPECT_EQ(s.currentLayerName(), "startled");
  s.sample(10.0 + 2.2 + 8 * 60.0 / 35.0 + 0.05);
  EXPECT_EQ(s.currentLayerName(), "neutral");
}

TEST(PatternFile, ExamplePatternsLoad) {
  for (const char* name : {"startle-at-10s.json", "calm-then-laugh.json"}) {
    SCOPED_TRACE(name);
    const Pattern p = loadPatternFile(kResources + std::string("/patterns/") + name, kResources);
    LayerStack s = makeLayerStack(p, 7);
    for (double t = 0.0; t < 40.0; t += 0.01) {
      const double v = s.sample(t);
      ASSERT_GE(v, 0.0);
      ASSERT_LE(v, 1.0);
    }
  }
  EXPECT_THROW(loadPatternFile(kResources + "/patterns/missing.json", kResources), Error);
}
