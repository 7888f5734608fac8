#include "pneuma/sim/pattern/Pattern.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "pneuma/sim/Error.h"
#include "pneuma/sim/JsonReader.h"

namespace pneuma::sim::pattern {

namespace {

constexpr const char* kFormatName = "pneuma-pattern";

using Node = sim::JsonReader;

CycleKind parseKind(const Node& n) {
  const std::string k = n.string();
  for (CycleKind kind : {CycleKind::Linear, CycleKind::Keyframe, CycleKind::Spline})
    if (k == cycleKindName(kind)) return kind;
  n.fail("unknown cycle kind '" + sim::excerptOf(k) + "' (valid: linear, keyframe, spline)");
}

CycleSpec parseCycle(const Node& n) {
  n.allowKeys({"kind", "time", "rate_bpm", "depth", "ie_ratio", "post_inspiratory_pause_s",
               "post_expiratory_pause_s", "irregularity", "balance", "inspiratory_balance", "keyframes"});
  CycleSpec c;
  c.kind = parseKind(n.at("kind"));

  // time base: relative cycles need a rate, absolute ones take it from the keyframes
  const std::string time = n.stringOr("time", "relative");
  if (time != "relative" && time != "absolute")
    n.at("time").fail("must be 'relative' or 'absolute', got '" + sim::excerptOf(time) + "'");
  c.isRelative = time == "relative";
  if (c.isRelative)
    c.rate = n.at("rate_bpm").number();
  else if (n.has("rate_bpm"))
    n.at("rate_bpm").fail("not allowed with absolute time (the keyframes set the rate)");

  // depth [min, max]
  const Node depth = n.at("depth");
  if (depth.size() != 2) depth.fail("must be [min, max]");
  c.depthMin = depth[0].number();
  c.depthMax = depth[1].number();

  // timing extras
  if (n.has("ie_ratio") && n.has("keyframes"))
    n.at("ie_ratio").fail("not allowed with keyframes (they set the shape)");
  c.ieRatio = n.numberOr("ie_ratio", c.ieRatio);
  c.postInspiratoryPause = n.numberOr("post_inspiratory_pause_s", 0.0);
  c.postExpiratoryPause = n.numberOr("post_expiratory_pause_s", 0.0);
  if (n.has("irregularity")) {
    const Node irr = n.at("irregularity");
    irr.allowKeys({"rate", "depth"});
    c.rateIrregularity = irr.numberOr("rate", 0.0);
    c.depthIrregularity = irr.numberOr("depth", 0.0);
  }
  c.balance = n.numberOr("balance", c.balance);
  if (n.has("inspiratory_balance")) c.inspiratoryBalance = n.at("inspiratory_balance").number();

  // keyframes as [time, volume] pairs
  if (n.has("keyframes")) {
    const Node k = n.at("keyframes");
    for (std::size_t i = 0; i < k.size(); ++i) {
      const Node pair = k[i];
      if (pair.size() != 2) pair.fail("must be [time, volume]");
      c.keyframes.push_back({pair[0].number(), pair[1].number()});
    }
  }

  // semantic checks, reported under this cycle's path
  try {
    validateCycle(c);
  } catch (const Error& e) {
    n.failBelow(e.what());
  }
  return c;
}

Layer parseLayer(const Node& n) {
  n.allowKeys({"name", "repeat", "cycle"});
  Layer l;
  l.name = n.at("name").string();
  const Node repeat = n.at("repeat");
  if (repeat.isString()) {
    if (repeat.string() != "infinite") repeat.fail("must be a count >= 1 or \"infinite\"");
    l.repetitions = kInfinite;
  } else {
    const double r = repeat.number();
    if (r < 1.0 || r != std::floor(r) || r > 1e6) repeat.fail("must be a count >= 1 or \"infinite\"");
    l.repetitions = static_cast<int>(r);
  }
  l.cycle = parseCycle(n.at("cycle"));
  return l;
}

std::string readText(const std::string& path) { return readInputFile(path); }

std::string affectPath(const std::string& resourceDir, const std::string& name) {
  return (std::filesystem::path(resourceDir) / "presets" / "affect" / (name + ".json")).string();
}

constexpr int kMaxAffectNesting = 4;  // "affect" references may nest this deep (guards against cycles)

Pattern parseAt(const std::string& jsonText, const std::string& sourceName, const std::string& resourceDir,
                int nesting);
Pattern loadAffectAt(const std::string& name, const std::string& resourceDir, int nesting);

// a layer source: inline "layers" or a reference "affect": NAME (exactly one of them)
std::vector<Layer> parseLayerSource(const Node& n, const std::string& resourceDir, int nesting,
                                    std::string* label) {
  if (n.has("layers") == n.has("affect")) n.fail("needs exactly one of \"layers\" or \"affect\"");
  if (n.has("affect")) {
    const Node a = n.at("affect");
    const std::string name = a.string();
    if (label) *label = name;
    try {
      if (nesting >= kMaxAffectNesting) throw Error("affect references nest too deep (a cycle?)");
      return loadAffectAt(name, resourceDir, nesting + 1).layers;
    } catch (const Error& e) {
      a.fail(e.what());
    }
  }
  const Node arr = n.at("layers");
  if (arr.size() == 0) arr.fail("must not be empty");
  std::vector<Layer> layers;
  for (std::size_t i = 0; i < arr.size(); ++i) layers.push_back(parseLayer(arr[i]));
  if (label && !layers.empty()) *label = layers.front().name;
  return layers;
}

Pattern parseAt(const std::string& jsonText, const std::string& sourceName, const std::string& resourceDir,
                int nesting) {
  const sim::JsonDocument doc = sim::JsonDocument::parse(jsonText, sourceName);
  const Node root = doc.root();
  root.allowKeys({"format", "version", "name", "description", "layers", "affect", "timeline"});

  root.checkHeader(kFormatName, kPatternFormatVersion);
  Pattern p;
  p.name = root.at("name").string();
  p.description = root.stringOr("description", "");
  p.layers = parseLayerSource(root, resourceDir, nesting, nullptr);

  // timeline of scheduled pushes, in time order
  if (root.has("timeline")) {
    const Node events = root.at("timeline");
    for (std::size_t i = 0; i < events.size(); ++i) {
      const Node e = events[i];
      e.allowKeys({"time_s", "switch", "label", "layers", "affect"});
      TimelineEvent ev;
      const Node time = e.at("time_s");
      ev.time = time.number();
      if (ev.time < 0.0) time.fail("must be >= 0");
      if (!p.timeline.empty() && ev.time < p.timeline.back().time)
        time.fail("events must be in time order (previous at " + std::to_string(p.timeline.back().time) +
                  " s)");
      const std::string mode = e.stringOr("switch", "immediate");
      if (!switchModeFromName(mode, ev.mode))
        e.at("switch").fail("must be \"immediate\" or \"end_of_cycle\", got \"" + sim::excerptOf(mode) +
                            "\"");
      ev.layers = parseLayerSource(e, resourceDir, nesting, &ev.label);
      ev.label = e.stringOr("label", ev.label);
      p.timeline.push_back(std::move(ev));
    }
  }
  return p;
}

Pattern loadAffectAt(const std::string& name, const std::string& resourceDir, int nesting) {
  const std::vector<std::string> valid = listAffects(resourceDir);
  if (std::find(valid.begin(), valid.end(), name) == valid.end()) {
    std::string list;
    for (const std::string& v : valid) list += (list.empty() ? "" : ", ") + v;
    throw Error("unknown affect '" + sim::excerptOf(name) +
                "' (valid: " + (list.empty() ? "none found in " + resourceDir : list) + ")");
  }
  const std::string path = affectPath(resourceDir, name);
  return parseAt(readText(path), std::filesystem::path(path).filename().string(), resourceDir, nesting);
}

}  // namespace

Pattern parsePattern(const std::string& jsonText, const std::string& sourceName,
                     const std::string& resourceDir) {
  return parseAt(jsonText, sourceName, resourceDir, 0);
}

Pattern loadPatternFile(const std::string& path, const std::string& resourceDir) {
  return parseAt(readText(path), path, resourceDir, 0);
}

std::vector<std::string> listAffects(const std::string& resourceDir) {
  std::vector<std::string> names;
  const std::filesystem::path dir = std::filesystem::path(resourceDir) / "presets" / "affect";
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec))
    if (entry.path().extension() == ".json") names.push_back(entry.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

Pattern loadAffect(const std::string& name, const std::string& resourceDir) {
  return loadAffectAt(name, resourceDir, 0);
}

LayerStack makeLayerStack(const Pattern& pattern, std::uint64_t seed) {
  LayerStack stack(seed);
  stack.push(pattern.layers, SwitchMode::EndOfCycle, 0.0);
  for (const TimelineEvent& e : pattern.timeline) stack.push(e.layers, e.mode, e.time);
  return stack;
}

}  // namespace pneuma::sim::pattern
