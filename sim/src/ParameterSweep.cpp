#include "pneuma/sim/ParameterSweep.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>

#include "pneuma/sim/Error.h"
#include "pneuma/sim/JsonReader.h"
#include "pneuma/sim/pattern/SplitMix64.h"

namespace pneuma::sim {

using nlohmann::json;
namespace fs = std::filesystem;

namespace {

constexpr const char* kFormatName = "pneuma-sweep";

// a number as the JSON text the variant records and the table prints: the shortest that reads back the same
// ("1", not "1.0", as in the file's own lists)
std::string numberText(double v) {
  char buf[32];
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  return buf;
}

// the values of one grid or list parameter: [v, ...] (any JSON values) or {"from", "to", "steps"}
std::vector<std::string> valuesOf(const JsonReader& p) {
  std::vector<std::string> values;
  if (p.isArray()) {
    if (p.size() == 0) p.fail("must list at least one value");
    for (std::size_t i = 0; i < p.size(); ++i) values.push_back(p[i].dump());
    return values;
  }
  if (!p.isObject()) p.fail("must be a list of values or {\"from\", \"to\", \"steps\"}");
  p.allowKeys({"from", "to", "steps"});
  const double from = p.at("from").number(), to = p.at("to").number();
  const auto steps = static_cast<int>(p.at("steps").integerIn(1, 10000));
  if (steps == 1 && from != to) p.at("steps").fail("must be >= 2 when from != to");
  for (int i = 0; i < steps; ++i) {
    const double t = steps == 1 ? 0.0 : static_cast<double>(i) / (steps - 1);
    values.push_back(numberText(from * (1.0 - t) + to * t));  // exact at both ends
  }
  return values;
}

}  // namespace

Sweep parseSweep(const std::string& jsonText, const std::string& sourceName, const std::string& baseDir) {
  const JsonDocument doc = JsonDocument::parse(jsonText, sourceName);
  const JsonReader root = doc.root();
  root.allowKeys({"format", "version", "name", "description", "scenario", "design", "parameters", "samples",
                  "seed", "outputs"});
  root.checkHeader(kFormatName, kSweepFormatVersion);

  Sweep sweep;
  sweep.name = root.has("name") ? root.at("name").string() : "";

  // the base scenario: a file beside the sweep file, or inline
  const JsonReader sc = root.at("scenario");
  Scenario base;
  if (sc.isString()) {
    std::string path = sc.string();
    if (!fs::path(path).is_absolute() && !baseDir.empty()) path = (fs::path(baseDir) / path).string();
    base = loadScenario(path);
  } else if (sc.isObject()) {
    base = parseScenario(sc.dump(), sourceName + ": scenario", baseDir);
  } else {
    sc.fail("must be a scenario file path or an inline scenario object");
  }
  if (sweep.name.empty()) sweep.name = base.name.empty() ? "sweep" : base.name;

  const std::string design = root.has("design") ? root.at("design").string() : "grid";
  if (design == "grid")
    sweep.design = SweepDesign::Grid;
  else if (design == "list")
    sweep.design = SweepDesign::List;
  else if (design == "random")
    sweep.design = SweepDesign::Random;
  else
    root.at("design").fail("unknown design '" + excerptOf(design) + "' (valid: grid, list, random)");
  if (sweep.design != SweepDesign::Random)
    for (const char* key : {"samples", "seed"})
      if (root.has(key)) root.at(key).fail("only a \"random\" design takes it");

  // the parameters, each checked by the overrides rule on the base scenario's options
  const JsonReader params = root.at("parameters");
  if (params.keys().empty()) params.fail("must vary at least one override");
  const std::string where = sourceName + ": parameters";
  auto checked = [&](const std::string& key, const std::string& value) {
    SimulationOptions probe = base.options;
    applyOverride(probe, key, value, where);
  };
  std::vector<std::vector<std::string>> values;   // per parameter
  std::vector<std::pair<double, double>> ranges;  // random design: [from, to] per parameter
  for (const std::string& key : params.keys()) {
    sweep.parameters.push_back(key);
    const JsonReader p = params.at(key);
    if (sweep.design == SweepDesign::Random) {
      if (!p.isObject()) p.fail("must be {\"from\", \"to\"} in a random design");
      p.allowKeys({"from", "to"});
      const double from = p.at("from").number(), to = p.at("to").number();
      if (from > to) p.fail("from " + numberText(from) + " > to " + numberText(to));
      checked(key, numberText(from));
      checked(key, numberText(to));
      ranges.emplace_back(from, to);
    } else {
      values.push_back(valuesOf(p));
      for (const std::string& v : values.back()) checked(key, v);
    }
  }

  // the variants' settings
  std::vector<std::vector<std::pair<std::string, std::string>>> settings;
  const std::size_t n = sweep.parameters.size();
  if (sweep.design == SweepDesign::Grid) {
    std::size_t count = 1;
    for (const auto& v : values) {
      if (count > kMaxSweepVariants / v.size())
        params.fail("a grid of more than " + std::to_string(kMaxSweepVariants) + " variants");
      count *= v.size();
    }
    for (std::size_t i = 0; i < count; ++i) {
      std::vector<std::pair<std::string, std::string>> s(n);
      for (std::size_t k = n, rest = i; k-- > 0; rest /= values[k].size())
        s[k] = {sweep.parameters[k], values[k][rest % values[k].size()]};
      settings.push_back(std::move(s));
    }
  } else if (sweep.design == SweepDesign::List) {
    for (std::size_t k = 1; k < n; ++k)
      if (values[k].size() != values[0].size())
        params.at(sweep.parameters[k])
            .fail("has " + std::to_string(values[k].size()) + " values, " + sweep.parameters[0] + " has " +
                  std::to_string(values[0].size()) + " (a list design pairs them one to one)");
    for (std::size_t i = 0; i < values[0].size(); ++i) {
      std::vector<std::pair<std::string, std::string>> s;
      for (std::size_t k = 0; k < n; ++k) s.emplace_back(sweep.parameters[k], values[k][i]);
      settings.push_back(std::move(s));
    }
  } else {
    const auto samples = static_cast<std::size_t>(
        root.at("samples").integerIn(1, static_cast<std::int64_t>(kMaxSweepVariants)));
    sweep.seed = root.has("seed") ? root.at("seed").unsignedInteger() : 0;
    pattern::SplitMix64 rng(sweep.seed);
    for (std::size_t i = 0; i < samples; ++i) {
      std::vector<std::pair<std::string, std::string>> s;
      for (std::size_t k = 0; k < n; ++k) {
        const double u = 0.5 * (rng.symmetric() + 1.0);  // [0, 1)
        s.emplace_back(sweep.parameters[k],
                       numberText(ranges[k].first + u * (ranges[k].second - ranges[k].first)));
      }
      settings.push_back(std::move(s));
    }
  }

  // each variant: the base scenario with its settings
  for (auto& s : settings) {
    SweepVariant v;
    v.scenario = base;
    for (const auto& [key, value] : s) applyOverride(v.scenario.options, key, value, where);
    v.settings = std::move(s);
    sweep.variants.push_back(std::move(v));
  }

  if (root.has("outputs")) {
    const JsonReader o = root.at("outputs");
    if (!o.isArray()) o.fail("must be a list of summary.json figure names");
    for (std::size_t i = 0; i < o.size(); ++i) sweep.outputs.push_back(o[i].string());
  } else {
    sweep.outputs = {"tidal_volume_ml", "breaths_per_minute"};
  }
  return sweep;
}

Sweep loadSweep(const std::string& path) {
  return parseSweep(readInputFile(path), path, fs::path(path).parent_path().string());
}

}  // namespace pneuma::sim
