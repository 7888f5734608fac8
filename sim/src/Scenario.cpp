#include "pneuma/sim/Scenario.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "pneuma/sim/BreathStyleController.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/JsonReader.h"
#include "pneuma/sim/Limits.h"
#include "pneuma/sim/pattern/PatternController.h"

namespace pneuma::sim {

using nlohmann::json;
namespace fs = std::filesystem;

namespace {

constexpr const char* kFormatName = "pneuma-scenario";

using Field = JsonReader;

std::string resolve(const std::string& path, const std::string& baseDir) {
  if (path.empty() || fs::path(path).is_absolute() || baseDir.empty()) return path;
  return (fs::path(baseDir) / path).lexically_normal().string();
}

// {"diaphragm": 1.2, ...} -> per-group scale factors (>= 0)
// the halves of the diaphragm an active gain scale may name besides the groups
// (StepOptions::hemidiaphragmActiveScale)
constexpr std::array<const char*, 2> kHemidiaphragmNames = {"diaphragm_left", "diaphragm_right"};

// `halves`: where "diaphragm_left" and "diaphragm_right" go, or null when the scale has no halves (passive)
void parseGroupScales(const Field& f, std::array<double, kElementGroupCount>& out,
                      std::array<double, 2>* halves) {
  if (!f.isObject()) f.fail("must be an object of group names to scale factors");
  for (const std::string& key : f.keys()) {
    if (halves && (key == kHemidiaphragmNames[0] || key == kHemidiaphragmNames[1])) {
      (*halves)[key == kHemidiaphragmNames[0] ? 0 : 1] = f.at(key).nonNegative();
      continue;
    }
    ElementGroup g;
    if (!groupFromName(key, g)) {
      std::string valid;
      for (int i = 0; i < kElementGroupCount; ++i)
        valid += std::string(i ? ", " : "") + groupName(static_cast<ElementGroup>(i));
      if (halves) valid += std::string(", ") + kHemidiaphragmNames[0] + ", " + kHemidiaphragmNames[1];
      f.at(key).fail("unknown muscle group (valid: " + valid + ")");
    }
    out[static_cast<std::size_t>(g)] = f.at(key).nonNegative();
  }
}

void parseController(const Field& c, const std::string& baseDir, Scenario& s) {
  c.allowKeys({"style", "affect", "pattern", "trace"});
  const int count = c.has("style") + c.has("affect") + c.has("pattern") + c.has("trace");
  if (count != 1) c.fail("needs exactly one of \"style\", \"affect\", \"pattern\" or \"trace\"");
  if (c.has("style")) {
    s.controller = ControllerKind::Style;
    s.controllerName = c.at("style").string();
  } else if (c.has("trace")) {
    s.controller = ControllerKind::Trace;
    s.controllerName = c.at("trace").string();
    if (!s.controllerName.empty()) s.controllerName = resolve(s.controllerName, baseDir);
  } else if (c.has("affect")) {
    s.controller = ControllerKind::Affect;
    s.controllerName = c.at("affect").string();
  } else {
    s.controller = ControllerKind::Pattern;
    const Field p = c.at("pattern");
    if (p.isString())
      s.controllerName = resolve(p.string(), baseDir);
    else if (p.isObject())
      s.patternText = p.dump(2);
    else
      p.fail("must be a pattern file path or an inline pattern object");
  }
  if (s.controller != ControllerKind::Pattern && s.controllerName.empty())
    c.at(controllerKindName(s.controller)).fail("must not be empty");
}

constexpr std::initializer_list<const char*> kOverrideKeys = {
    "integrator",           "dt_s",           "settle_time_s", "gravity",           "posture",
    "joint_friction_scale", "gut_drag_scale", "kappa_pa",      "active_gain_scale", "passive_gain_scale"};

void parseOverrides(const Field& o, SimulationOptions& opt) {
  o.allowKeys(kOverrideKeys);
  if (o.has("integrator")) {
    const std::string name = o.at("integrator").string();
    if (!integratorFromName(name, opt.step.integrator))
      o.at("integrator")
          .fail("unknown integrator '" + excerptOf(name) + "' (valid: " + integratorNames() + ")");
  }
  if (o.has("dt_s")) opt.dt = o.at("dt_s").numberIn(kTimeStepRange);
  if (o.has("settle_time_s")) opt.settleTime = o.at("settle_time_s").numberIn(kSettleTimeRange);
  if (o.has("gravity")) opt.step.gravity = o.at("gravity").boolean();
  if (o.has("posture")) {
    const std::string name = o.at("posture").string();
    if (!postureFromName(name, opt.step.posture))
      o.at("posture").fail("unknown posture '" + excerptOf(name) + "' (valid: " + postureNames() + ")");
  }
  if (o.has("joint_friction_scale")) opt.step.jointFrictionScale = o.at("joint_friction_scale").nonNegative();
  if (o.has("gut_drag_scale")) opt.step.gutDragScale = o.at("gut_drag_scale").nonNegative();
  if (o.has("kappa_pa")) opt.step.kappa = o.at("kappa_pa").positive();
  if (o.has("active_gain_scale"))
    parseGroupScales(o.at("active_gain_scale"), opt.step.activeGainScale, &opt.step.hemidiaphragmActiveScale);
  if (o.has("passive_gain_scale"))
    parseGroupScales(o.at("passive_gain_scale"), opt.step.passiveGainScale, nullptr);
}

void parseOutputs(const Field& o, ScenarioOutputs& out, SimulationOptions& opt) {
  o.allowKeys({"output_rate_hz", "csv", "plots", "vtk"});
  if (o.has("output_rate_hz")) opt.outputRate = o.at("output_rate_hz").numberIn(kOutputRateRange);
  if (o.has("csv")) out.csv = o.at("csv").boolean();
  if (o.has("plots")) out.plots = o.at("plots").boolean();
  if (o.has("vtk")) out.vtk = o.at("vtk").boolean();
}

json groupScalesJson(const std::array<double, kElementGroupCount>& scales) {
  json j = json::object();
  for (int i = 0; i < kElementGroupCount; ++i)
    j[groupName(static_cast<ElementGroup>(i))] = scales[static_cast<std::size_t>(i)];
  return j;
}

}  // namespace

const char* controllerKindName(ControllerKind k) {
  switch (k) {
    case ControllerKind::Style:
      return "style";
    case ControllerKind::Affect:
      return "affect";
    case ControllerKind::Pattern:
      return "pattern";
    case ControllerKind::Trace:
      return "trace";
  }
  return "style";
}

Scenario parseScenario(const std::string& jsonText, const std::string& sourceName,
                       const std::string& baseDir) {
  const JsonDocument doc = JsonDocument::parse(jsonText, sourceName);
  const Field root = doc.root();
  root.allowKeys({"format", "version", "name", "description", "model", "duration_s", "seed", "controller",
                  "overrides", "outputs"});

  root.checkHeader(kFormatName, kScenarioFormatVersion);

  Scenario s;
  s.name = root.has("name") ? root.at("name").string() : "";
  s.description = root.has("description") ? root.at("description").string() : "";
  if (root.has("model")) {
    s.model = root.at("model").string();
    if (s.model.empty()) root.at("model").fail("must not be empty (use \"default\" for the default model)");
    if (s.model != "default") s.model = resolve(s.model, baseDir);
  }
  s.duration = root.at("duration_s").numberIn(kDurationRange);
  if (root.has("seed")) s.seed = root.at("seed").unsignedInteger();
  parseController(root.at("controller"), baseDir, s);
  if (root.has("overrides")) parseOverrides(root.at("overrides"), s.options);
  if (root.has("outputs")) parseOutputs(root.at("outputs"), s.outputs, s.options);

  // cross-field checks the simulation would make later, reported against the file
  try {
    validateSimulationOptions(s.options);
  } catch (const Error& e) {
    throw Error(sourceName + ": overrides: " + e.what());
  }
  return s;
}

std::string overrideKeys() {
  std::string keys;
  for (const char* k : kOverrideKeys) {
    const bool isGroupScale = std::string(k).find("gain_scale") != std::string::npos;
    keys += std::string(keys.empty() ? "" : ", ") + k + (isGroupScale ? ".<group>" : "");
  }
  return keys;
}

void applyOverride(SimulationOptions& options, const std::string& key, const std::string& value,
                   const std::string& source) {
  // the value: JSON text when it is JSON, else a bare string (--set posture=supine)
  json v = json::parse(value, nullptr, /*allow_exceptions=*/false);
  if (v.is_discarded()) v = value;
  // "a.b.c" -> {"a": {"b": {"c": value}}}, read by the scenario file's own overrides parser
  json nested = std::move(v);
  std::string rest = key;
  for (std::size_t dot; (dot = rest.rfind('.')) != std::string::npos; rest.erase(dot))
    nested = json{{rest.substr(dot + 1), std::move(nested)}};
  if (rest.empty() || key.back() == '.')
    throw Error(source + ": '" + excerptOf(key) + "': not an override key");
  const JsonDocument doc = JsonDocument::parse(json{{rest, std::move(nested)}}.dump(), source);
  SimulationOptions changed = options;
  parseOverrides(doc.root(), changed);
  try {
    validateSimulationOptions(changed);
  } catch (const Error& e) {
    throw Error(source + ": " + key + ": " + e.what());
  }
  options = changed;
}

Scenario loadScenario(const std::string& path) {
  return parseScenario(readInputFile(path), path, fs::path(path).parent_path().string());
}

std::string serializeScenario(const Scenario& s) {
  json j;
  j["format"] = kFormatName;
  j["version"] = kScenarioFormatVersion;
  j["name"] = s.name;
  j["description"] = s.description;
  j["model"] = s.model;
  j["duration_s"] = s.duration;
  j["seed"] = s.seed;
  if (s.controller == ControllerKind::Pattern && !s.patternText.empty())
    j["controller"]["pattern"] = json::parse(s.patternText);
  else
    j["controller"][controllerKindName(s.controller)] = s.controllerName;
  const StepOptions& st = s.options.step;
  json& o = j["overrides"];
  o["integrator"] = integratorName(st.integrator);
  if (s.options.dt) o["dt_s"] = *s.options.dt;
  o["settle_time_s"] = s.options.settleTime;
  o["gravity"] = st.gravity;
  o["posture"] = postureName(st.posture);
  o["joint_friction_scale"] = st.jointFrictionScale;
  o["gut_drag_scale"] = st.gutDragScale;
  if (st.kappa) o["kappa_pa"] = *st.kappa;
  o["active_gain_scale"] = groupScalesJson(st.activeGainScale);
  for (std::size_t side = 0; side < 2; ++side)
    o["active_gain_scale"][kHemidiaphragmNames[side]] = st.hemidiaphragmActiveScale[side];
  o["passive_gain_scale"] = groupScalesJson(st.passiveGainScale);
  j["outputs"] = {{"output_rate_hz", s.options.outputRate},
                  {"csv", s.outputs.csv},
                  {"plots", s.outputs.plots},
                  {"vtk", s.outputs.vtk}};
  return j.dump(2) + "\n";
}

namespace {

// runs `load`, prefixing any error with the scenario field it came from
template <class F>
auto named(const Scenario& s, F&& load) {
  try {
    return load();
  } catch (const Error& e) {
    throw Error(std::string("controller.") + controllerKindName(s.controller) + ": " + e.what());
  }
}

BreathStyle styleOf(const Scenario& s, const std::string& resourceDir) {
  return named(
      s, [&] { return loadBreathStyle(s.controllerName, (fs::path(resourceDir) / "presets").string()); });
}

pattern::Pattern patternOf(const Scenario& s, const std::string& resourceDir) {
  if (s.controller == ControllerKind::Affect)
    return named(s, [&] { return pattern::loadAffect(s.controllerName, resourceDir); });
  if (s.patternText.empty())
    return named(s, [&] { return pattern::loadPatternFile(s.controllerName, resourceDir); });
  // inline: the pattern parser's message already carries the path below "controller.pattern"
  return pattern::parsePattern(s.patternText, "controller.pattern", resourceDir);
}

}  // namespace

void checkController(const Scenario& scenario, const std::string& resourceDir) {
  if (scenario.controller == ControllerKind::Trace)
    named(scenario, [&] { return pattern::loadVolumeTrace(scenario.controllerName); });
  else if (scenario.controller == ControllerKind::Style)
    validateBreathStyle(styleOf(scenario, resourceDir));
  else
    patternOf(scenario, resourceDir);
}

std::unique_ptr<Controller> makeController(const Scenario& scenario, std::shared_ptr<const Model> model,
                                           const std::string& resourceDir, const std::atomic<bool>* stop) {
  if (scenario.controller == ControllerKind::Style)
    return std::make_unique<BreathStyleController>(styleOf(scenario, resourceDir));
  // parse the pattern or trace first (cheap, reports bad names and fields), then calibrate the drive
  const auto calibrate = [&] {
    return pattern::calibrateDrive(std::move(model), scenario.options,
                                   pattern::DriveCalibration{}.contractionR, stop);
  };
  if (scenario.controller == ControllerKind::Trace) {
    pattern::VolumeTrace trace =
        named(scenario, [&] { return pattern::loadVolumeTrace(scenario.controllerName); });
    return std::make_unique<pattern::PatternController>(std::move(trace), calibrate());
  }
  const pattern::Pattern p = patternOf(scenario, resourceDir);
  return pattern::makePatternController(p, scenario.seed, calibrate());
}

void saveScenario(const Scenario& scenario, const std::string& path) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw Error("scenario file '" + path + "' cannot be written");
    out << serializeScenario(scenario);
    if (!out.flush()) throw Error("scenario file '" + path + "' cannot be written");
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) throw Error("scenario file '" + path + "' cannot be written: " + ec.message());
}

}  // namespace pneuma::sim
