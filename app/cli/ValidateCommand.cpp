/// @file ValidateCommand.cpp
/// `pneuma-cli validate`: reruns the papers' experiments (sim/Experiments.h) on a model and writes
/// report.html (self-contained, plots embedded), report.md and report.json. Exit 0 iff every check passes.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "CliSupport.h"
#include "Commands.h"
#include "Silhouettes.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/Experiments.h"
#include "pneuma/sim/ModelIO.h"
#include "pneuma/sim/Resources.h"
#include "viz/AtomicFile.h"
#include "viz/Plot.h"

namespace pneuma::app {

namespace {

namespace fs = std::filesystem;

struct ValidateArgs {
  std::string model;
  std::string out = "validation";
  bool isQuick = false;
  bool force = false;  // replace an earlier report in `out`
  std::string integrator;
  std::optional<double> dt;  // [s] unset: sim::resolveOptions() picks it
};

/// A figure of the report: its plot and a caption.
struct Figure {
  std::string stem;  // file name without extension
  std::string caption;
  viz::Plot plot;
};

std::string base64(const std::vector<unsigned char>& bytes) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const unsigned v = (bytes[i] << 16) | (i + 1 < bytes.size() ? bytes[i + 1] << 8 : 0) |
                       (i + 2 < bytes.size() ? bytes[i + 2] : 0);
    out += table[(v >> 18) & 63];
    out += table[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? table[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? table[v & 63] : '=';
  }
  return out;
}

std::string htmlEscape(const std::string& s) {
  std::string out;
  for (char c : s) out += c == '<' ? "&lt;" : c == '>' ? "&gt;" : c == '&' ? "&amp;" : std::string(1, c);
  return out;
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

/// Figure 6 of Zordan et al. 2004: lung-cavity volume of every style, relative to calm end-expiration,
/// with the 500 mL calm tidal volume as a dashed reference.
viz::Plot figure6(const std::vector<sim::StyleRun>& runs) {
  double base = 0.0;
  for (const sim::StyleRun& r : runs)
    if (r.style.name == "calm") base = r.summary.endExpiratoryVolume;
  viz::Plot plot("Lung volume of the breath styles (cf. Zordan et al. 2004, Fig. 6)",
                 "time since settling [s]", "volume above calm end-expiration [mL]");
  for (const sim::StyleRun& r : runs) {
    std::vector<double> t, v;
    for (std::size_t i = 0; i < r.trace.size(); ++i)
      if (r.trace.time[i] >= r.settleTime) {
        t.push_back(r.trace.time[i] - r.settleTime);
        v.push_back((r.trace.lungVolume[i] - base) * 1e6);
      }
    plot.addSeries(r.style.name, t, v);
  }
  plot.addReferenceLine("500 mL (calm tidal volume, textbook)", 500.0);
  return plot;
}

constexpr double kDegPerRad = 180.0 / M_PI;   // [deg/rad]
constexpr double kSilhouetteSpacing = 0.002;  // [m] outline grid of the report's silhouettes

void runValidate(const ValidateArgs& args) {
  const std::string modelDir = resolveModelDir(args.model);
  prepareOutputDir(args.out, "validate",
                   {"report.json", "report.md", "report.html", "*.png", "*.svg", "*.csv"}, args.force);
  sim::ExperimentSettings settings =
      args.isQuick ? sim::ExperimentSettings::quick() : sim::ExperimentSettings();
  applyIntegrator(args.integrator, settings.simulation.step.integrator);
  if (args.dt) checkOption(sim::kTimeStepRange, "--dt", *args.dt);
  settings.simulation.dt = args.dt;
  std::shared_ptr<const sim::Model> model;
  std::vector<sim::BreathStyle> styles;
  try {
    model = std::make_shared<const sim::Model>(sim::loadModel(modelDir));
    for (const char* name : {"calm", "deep", "panting", "forced-exhale"})
      styles.push_back(sim::loadBreathStyle(name, sim::resourceDir() + "/presets"));
  } catch (const sim::Error& e) {
    fail(kExitBadInput, e.what());
  }

  // the experiments; a blow-up fails the run (exit 1) with the simulator's diagnosis
  const auto wallStart = std::chrono::steady_clock::now();
  auto progress = [](const std::string& what) { std::fprintf(stderr, "validate: %s\n", what.c_str()); };
  // an experiment that blows up becomes a failing check carrying the simulator's diagnosis; the others still
  // run
  std::vector<sim::StyleRun> runs;
  std::vector<sim::Check> blowUps;
  auto attempt = [&](const std::string& id, const std::string& what, auto&& experiment) {
    progress(what);
    try {
      experiment();
      return true;
    } catch (const sim::Error& e) {
      sim::Check c;
      c.id = id + ".completed";
      c.what = what + " stopped: " + e.what();
      c.target = "no blow-up";
      c.source = "pneuma (numerical stability)";
      c.unit = "-";
      c.measured = 0.0;
      c.lower = 1.0;
      c.upper = 1.0;
      blowUps.push_back(c);
      return false;
    }
  };
  for (const sim::BreathStyle& s : styles)
    attempt(s.name, "breath style '" + s.name + "'",
            [&] { runs.push_back(sim::runBreathStyle(model, s, settings)); });
  sim::StyleRun deepFrictionless;
  const sim::StyleRun* deep = nullptr;
  for (const sim::StyleRun& r : runs) deep = r.style.name == "deep" ? &r : deep;
  const bool hasSway =
      deep != nullptr && attempt("sway", "deep breathing without joint friction (spine sway)", [&] {
        deepFrictionless = sim::runBreathStyle(model, deep->style, settings, 0.0);
      });
  sim::ImpactRun impact;
  const bool hasImpact =
      attempt("impact", "heavy impact", [&] { impact = sim::runHeavyImpact(model, settings); });
  // the teaching presets against calm upright breathing (docs/app.md "Teaching presets")
  std::vector<sim::TeachingRun> teachingRuns;
  for (const std::string& scenario : sim::teachingScenarios())
    attempt("teaching." + std::filesystem::path(scenario).stem().string(),
            "teaching scenario '" + scenario + "'",
            [&] { teachingRuns.push_back(sim::runTeachingScenario(model, scenario, sim::resourceDir())); });
  const double wallSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wallStart).count();

  std::vector<sim::Check> checks = blowUps;
  for (const sim::Check& c : sim::breathStyleChecks(runs)) checks.push_back(c);
  if (hasSway)
    for (const sim::Check& c : sim::swayChecks(*deep, deepFrictionless)) checks.push_back(c);
  if (hasImpact)
    for (const sim::Check& c : sim::impactChecks(impact)) checks.push_back(c);
  int failed = 0;
  for (const sim::Check& c : checks) failed += !c.isPassed();
  // physiology: the motion against published ranges, reported beside the papers' checks (not in the exit
  // status)
  const std::vector<sim::Check> physiology = sim::physiologyChecks(runs);
  int within = 0;
  for (const sim::Check& c : physiology) within += c.isPassed();

  // the silhouette: the skin seen from the side and the front at end-expiration and end-inspiration of each
  // style, its AP change against published chest-wall motion (reported like the physiology)
  std::vector<sim::SilhouetteBreath> breaths;
  std::string silhouetteProblem;
  if (model->skin.vertexCount() == 0) silhouetteProblem = "the model has no skin";
  for (const sim::StyleRun& r : runs) {
    if (!silhouetteProblem.empty()) break;
    try {
      breaths.push_back(sim::silhouetteBreath(r));
    } catch (const sim::Error& e) {
      silhouetteProblem = e.what();
    }
  }
  const std::vector<sim::Check> silhouette = sim::silhouetteChecks(breaths);
  const std::vector<sim::Check> teaching = sim::teachingChecks(teachingRuns);
  int teachingWithin = 0;
  for (const sim::Check& c : teaching) teachingWithin += c.isPassed();
  int silhouetteWithin = 0;
  for (const sim::Check& c : silhouette) silhouetteWithin += c.isPassed();
  std::vector<BreathOutlines> outlines;
  for (const sim::SilhouetteBreath& b : breaths) {
    outlines.push_back(traceBreath(b, model->skin.triangles, kSilhouetteSpacing));
    writeSilhouettes(outlines.back(), args.out, "silhouette_");
  }

  // figures
  std::vector<Figure> figures;
  figures.push_back(
      {"figure6_lung_volume",
       "Lung volume of the four breath styles; dashed: the 500 mL calm tidal volume of Figure 6.",
       figure6(runs)});
  if (hasSway) {
    viz::Plot p("Spine sway during deep breathing (cf. Sec. 5)", "time [s]",
                "anterior position of " + deep->spineBody + " [mm]");
    for (const sim::StyleRun* r : {deep, static_cast<const sim::StyleRun*>(&deepFrictionless)}) {
      std::vector<double> y;
      for (const Eigen::Vector3d& p3 : r->spineTop) y.push_back((p3.y() - r->spineTop.front().y()) * 1e3);
      p.addSeries(r->frictionScale > 0.0 ? "with rib-joint friction" : "frictionless", r->trace.time, y);
    }
    figures.push_back({"spine_sway",
                       "Anterior-posterior position of the top thoracic segment during deep breathing, with "
                       "and without rib-joint friction (Eq. 3), relative to the start.",
                       p});
  }
  if (hasImpact) {
    viz::Plot p("Gut volume error after a heavy impact (cf. Fig. 4)", "time after impact [s]",
                "gut volume error [%]");
    std::vector<double> e;
    for (double v : impact.gutVolumeError) e.push_back(v * 100.0);
    p.addSeries("gut volume error", impact.time, e);
    p.addReferenceLine("+0.5 % (Fig. 4)", 0.5);
    p.addReferenceLine("-0.5 %", -0.5, viz::Color{0.5, 0.5, 0.5});
    figures.push_back({"impact_gut_volume_error",
                       "Signed gut volume error after " + std::to_string(impact.struckNodes) +
                           " wall nodes around the umbilicus are struck at " + number(settings.impactSpeed) +
                           " m/s.",
                       p});
  }
  for (const Figure& f : figures) {
    f.plot.writePng(args.out + "/" + f.stem + ".png");
    f.plot.writeSvg(args.out + "/" + f.stem + ".svg");
  }

  // report.json
  nlohmann::json j;
  j["pneuma_version"] = PNEUMA_VERSION;
  j["model"] = modelDir;
  j["model_name"] = model->name;
  j["integrator"] = sim::integratorName(settings.simulation.step.integrator);
  j["quick"] = args.isQuick;
  j["wall_seconds"] = wallSeconds;
  j["passed"] = failed == 0;
  j["failed_count"] = failed;
  using CheckList = std::pair<const char*, const std::vector<sim::Check>*>;
  for (const auto& [key, list] : {CheckList{"checks", &checks}, CheckList{"physiology", &physiology},
                                  CheckList{"silhouette", &silhouette}, CheckList{"teaching", &teaching}})
    for (const sim::Check& c : *list)
      j[key].push_back(
          {{"id", c.id},
           {"what", c.what},
           {"target", c.target},
           {"measured", std::isfinite(c.measured) ? nlohmann::json(c.measured) : nlohmann::json(nullptr)},
           {"unit", c.unit},
           {"lower", std::isfinite(c.lower) ? nlohmann::json(c.lower) : nlohmann::json(nullptr)},
           {"upper", std::isfinite(c.upper) ? nlohmann::json(c.upper) : nlohmann::json(nullptr)},
           {"passed", c.isPassed()},
           {"source", c.source}});
  j["physiology_within"] = within;
  j["silhouette_within"] = silhouetteWithin;
  j["teaching_within"] = teachingWithin;
  for (const sim::StyleRun& r : runs) {
    nlohmann::json& style = j["styles"][r.style.name];
    // as in summary.json, the breath figures are null when no full breath was found (a forced exhale)
    const auto breath = [&](double v) {
      return r.summary.cycles > 0 ? jsonNumber(v) : nlohmann::json(nullptr);
    };
    style = {{"tidal_volume_ml", breath(r.summary.tidalVolume * 1e6)},
             {"breaths_per_minute", breath(r.summary.breathsPerMinute)},
             {"end_expiratory_volume_ml", breath(r.summary.endExpiratoryVolume * 1e6)},
             {"max_gut_volume_error_pct", r.summary.maxGutVolumeError * 100.0},
             {"real_time_factor", r.summary.realTimeFactor}};
    writeMotion(r.summary.motion, style);
    for (const sim::RibMotion& rm : sim::ribMotions(r))
      style["rib_motion"].push_back(
          {{"rib", rm.rib},
           {"turn_deg", rm.turn * kDegPerRad},
           {"axis_from_midsagittal_deg", rm.axisFromMidsagittal * kDegPerRad},
           {"about_neck_deg", rm.aboutNeck * kDegPerRad},
           {"com_motion_mm", {rm.comMotion.x() * 1e3, rm.comMotion.y() * 1e3, rm.comMotion.z() * 1e3}}});
    for (const sim::SilhouetteBreath& b : breaths)
      if (b.style == r.style.name) style["silhouette"] = silhouetteJson(b);
  }
  for (const Figure& f : figures) j["figures"].push_back(f.stem + ".png");
  viz::writeFileAtomically(args.out + "/report.json", j.dump(2) + "\n");

  // report.md and report.html share the table rows
  std::ostringstream md, html, table;
  const std::string verdict =
      failed == 0 ? "all " + std::to_string(checks.size()) + " checks pass"
                  : std::to_string(failed) + " of " + std::to_string(checks.size()) + " checks fail";
  md << "# Pneuma validation report\n\nModel `" << modelDir << "` (" << model->name << "), integrator "
     << sim::integratorName(settings.simulation.step.integrator) << (args.isQuick ? ", quick settings" : "")
     << ", pneuma " << PNEUMA_VERSION << ". Result: **" << verdict << "**.\n\n"
     << "| check | what | target | measured | result | source |\n|---|---|---|---|---|---|\n";
  for (const sim::Check& c : checks) {
    md << "| " << c.id << " | " << c.what << " | " << c.target << " | " << number(c.measured) << " " << c.unit
       << " | " << (c.isPassed() ? "pass" : "**FAIL**") << " | " << c.source << " |\n";
    table << "<tr class=\"" << (c.isPassed() ? "pass" : "fail") << "\"><td>" << htmlEscape(c.id)
          << "</td><td>" << htmlEscape(c.what) << "</td><td>" << htmlEscape(c.target) << "</td><td>"
          << number(c.measured) << " " << htmlEscape(c.unit) << "</td><td>"
          << (c.isPassed() ? "pass" : "FAIL") << "</td><td>" << htmlEscape(c.source) << "</td></tr>\n";
  }
  md << "\n";

  // physiology and silhouette: the motion next to published ranges
  const auto rangeRows = [](const std::vector<sim::Check>& list, std::ostringstream& rowsMd,
                            std::ostringstream& rowsHtml) {
    for (const sim::Check& c : list) {
      const std::string verdictText = !std::isfinite(c.measured) ? "n/a"
                                      : c.isPassed()             ? "within"
                                                                 : "**outside**";
      rowsMd << "| " << c.id << " | " << c.what << " | " << number(c.measured) << " " << c.unit << " | "
             << c.target << " | " << verdictText << " | " << c.source << " |\n";
      rowsHtml << "<tr class=\"" << (c.isPassed() ? "pass" : "fail") << "\"><td>" << htmlEscape(c.id)
               << "</td><td>" << htmlEscape(c.what) << "</td><td>" << number(c.measured) << " "
               << htmlEscape(c.unit) << "</td><td>" << htmlEscape(c.target) << "</td><td>"
               << (c.isPassed() ? "within" : "outside") << "</td><td>" << htmlEscape(c.source)
               << "</td></tr>\n";
    }
  };
  // the calm breath's rib motion, rib by rib (the figures behind physiology.calm.rib_axis_angle)
  std::ostringstream ribMd, ribHtml;
  for (const sim::StyleRun& r : runs) {
    if (r.style.name != "calm" || r.frictionScale != 1.0) continue;
    for (const sim::RibMotion& rm : sim::ribMotions(r)) {
      const double outward =
          rm.rib.find("_left") != std::string::npos ? -1.0 : 1.0;  // lateral: away from x = 0
      const std::string cells[] = {
          rm.rib, number(rm.turn * kDegPerRad), number(rm.axisFromMidsagittal * kDegPerRad),
          number(rm.aboutNeck * kDegPerRad),
          number(outward * rm.comMotion.x() * 1e3) + " / " + number(rm.comMotion.y() * 1e3) + " / " +
              number(rm.comMotion.z() * 1e3)};
      ribMd << "|";
      ribHtml << "<tr>";
      for (const std::string& c : cells) {
        ribMd << " " << c << " |";
        ribHtml << "<td>" << htmlEscape(c) << "</td>";
      }
      ribMd << "\n";
      ribHtml << "</tr>\n";
    }
  }
  const std::string ribIntro =
      "Each rib's turn from end-expiration to end-inspiration of the calm breath, from the bones' poses: its "
      "angle, the angle between its axis and the midsagittal plane (0 deg: an anteroposterior axis, the "
      "bucket "
      "handle; 90 deg: a left-right axis, the pump handle; about 35 deg for ribs 3-7 by CT, Wilson et al. "
      "1987, "
      "J Appl Physiol 62:1872), its part about the rib's neck axis (> 0 lifts the rib), and the motion of "
      "its "
      "centre of mass outward / forward / up.";
  const char* ribHeader =
      "| rib | turn [deg] | axis from midsagittal [deg] | about the neck axis [deg] | centre of mass, out / "
      "forward / up [mm] |\n|---|---|---|---|---|\n";
  std::ostringstream physMd, physHtml, silMd, silHtml, teachMd, teachHtml;
  rangeRows(physiology, physMd, physHtml);
  rangeRows(silhouette, silMd, silHtml);
  rangeRows(teaching, teachMd, teachHtml);
  const std::string teachIntro =
      "The teaching presets (resources/scenarios/teaching/), each run for " + number(sim::kTeachingSeconds) +
      " s against calm upright breathing (calm.json): the figure each preset's description names, in the "
      "direction the physiology it cites gives. " +
      std::to_string(teachingWithin) + " of " + std::to_string(teaching.size()) +
      " as published; not part of the exit status.";
  const std::string silIntro =
      silhouetteProblem.empty()
          ? "The body's silhouette seen from the side at end-inspiration and end-expiration of each style "
            "(the last full breath; the forced exhale's one manoeuvre): its anteroposterior depth along the "
            "chest line (4th intercostal space) and the belly line (umbilicus), held at their end-expiration "
            "heights. " +
                std::to_string(silhouetteWithin) + " of " + std::to_string(silhouette.size()) +
                " within range; not part of the exit status. Outlines: silhouette_<style>_<view>.csv, "
                "overlays "
                "silhouette_<style>_<view>.svg and .png."
          : "No silhouette: " + silhouetteProblem + ".";
  const std::string physIntro =
      "The breath's motion in anatomical axes (summary.json's motion fields) next to published "
      "physiology: " +
      std::to_string(within) + " of " + std::to_string(physiology.size()) +
      " within range. Reported beside the papers' checks; not part of the exit status.";
  const char* rangeHeader = "| check | what | measured | published | | source |\n|---|---|---|---|---|---|\n";
  md << "## Physiology\n\n" << physIntro << "\n\n" << rangeHeader << physMd.str() << "\n";
  if (!ribMd.str().empty())
    md << "## Rib motion, calm\n\n" << ribIntro << "\n\n" << ribHeader << ribMd.str() << "\n";
  md << "## Silhouette\n\n" << silIntro << "\n\n";
  if (!silhouette.empty()) md << rangeHeader << silMd.str() << "\n";
  md << "## Teaching presets\n\n" << teachIntro << "\n\n" << rangeHeader << teachMd.str() << "\n";
  for (const BreathOutlines& b : outlines)
    md << "![" << b.breath.style << "](silhouette_" << b.breath.style << "_lateral.png)\n\n";
  for (const Figure& f : figures)
    md << "![" << f.caption << "](" << f.stem << ".png)\n\n" << f.caption << "\n\n";
  html << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>Pneuma validation "
          "report</title>\n<style>"
       << "body{font-family:sans-serif;max-width:1000px;margin:2em "
          "auto}table{border-collapse:collapse;font-size:14px}"
       << "td,th{border:1px solid #ccc;padding:4px 8px;text-align:left}tr.pass td:nth-child(5){color:#1a7f37}"
       << "tr.fail td:nth-child(5){color:#c00;font-weight:bold}img{max-width:100%}</style></head><body>\n"
       << "<h1>Pneuma validation report</h1>\n<p>Model <code>" << htmlEscape(modelDir) << "</code> ("
       << htmlEscape(model->name) << "), integrator "
       << sim::integratorName(settings.simulation.step.integrator) << (args.isQuick ? ", quick settings" : "")
       << ", pneuma " << PNEUMA_VERSION << ". Result: <b>" << verdict << "</b>.</p>\n"
       << "<table><tr><th>check</th><th>what</th><th>target</th><th>measured</th><th>result</th><th>source</"
          "th></tr>\n"
       << table.str() << "</table>\n"
       << "<h2>Physiology</h2>\n<p>" << htmlEscape(physIntro)
       << "</p>\n<table><tr><th>check</th><th>what</th><th>measured</th>"
       << "<th>published</th><th></th><th>source</th></tr>\n"
       << physHtml.str() << "</table>\n";
  if (!ribHtml.str().empty())
    html << "<h2>Rib motion, calm</h2>\n<p>" << htmlEscape(ribIntro)
         << "</p>\n<table><tr><th>rib</th><th>turn [deg]</th><th>axis from midsagittal [deg]</th><th>about "
            "the "
            "neck axis [deg]</th><th>centre of mass, out / forward / up [mm]</th></tr>\n"
         << ribHtml.str() << "</table>\n";
  html << "<h2>Silhouette</h2>\n<p>" << htmlEscape(silIntro) << "</p>\n";
  if (!silhouette.empty())
    html << "<table><tr><th>check</th><th>what</th><th>measured</th><th>published</th><th></th><th>source</"
            "th></tr>\n"
         << silHtml.str() << "</table>\n";
  for (const BreathOutlines& b : outlines)
    html << "<img alt=\"silhouette " << htmlEscape(b.breath.style)
         << "\" style=\"width:49%\" src=\"data:image/png;base64,"
         << base64(silhouettePlot(b, sim::SilhouetteView::Lateral).toPng()) << "\">";
  html << "<h2>Teaching presets</h2>\n<p>" << htmlEscape(teachIntro)
       << "</p>\n<table><tr><th>check</th><th>what</th><th>measured</th><th>published</th><th></"
          "th><th>source</"
          "th></tr>\n"
       << teachHtml.str() << "</table>\n";
  if (!outlines.empty())
    html << "\n<p>Lateral silhouettes of the trunk, to scale (mm): end-expiration blue, end-inspiration red; "
            "dashed, the chest and belly lines.</p>\n";
  for (const Figure& f : figures)
    html << "<figure><img alt=\"" << htmlEscape(f.stem) << "\" src=\"data:image/png;base64,"
         << base64(f.plot.toPng()) << "\"><figcaption>" << htmlEscape(f.caption)
         << "</figcaption></figure>\n";
  html << "</body></html>\n";
  viz::writeFileAtomically(args.out + "/report.md", md.str());
  viz::writeFileAtomically(args.out + "/report.html", html.str());

  // the table on stdout
  std::printf("%-32s %-8s %-14s %s\n", "check", "result", "measured", "target");
  for (const sim::Check& c : checks)
    std::printf("%-32s %-8s %-14s %s\n", c.id.c_str(), c.isPassed() ? "pass" : "FAIL",
                (number(c.measured) + " " + c.unit).c_str(), c.target.c_str());
  for (const sim::Check& c : blowUps) std::printf("  %s: %s\n", c.id.c_str(), c.what.c_str());
  // a table of checks against published ranges, the ids without their section prefix, padded to the longest
  const auto rangeTable = [](const char* section, const std::vector<sim::Check>& list) {
    const std::size_t prefix = std::strlen(section) + 1;
    int width = 36;
    for (const sim::Check& c : list) width = std::max(width, static_cast<int>(c.id.size() - prefix));
    std::printf("\n%-*s %-8s %-14s %s\n", width, section, "range", "measured", "published");
    for (const sim::Check& c : list)
      std::printf("%-*s %-8s %-14s %s\n", width, c.id.c_str() + prefix, c.isPassed() ? "within" : "OUTSIDE",
                  (number(c.measured) + " " + c.unit).c_str(), c.target.c_str());
  };
  rangeTable("physiology", physiology);
  if (!silhouette.empty()) rangeTable("silhouette", silhouette);
  if (!silhouetteProblem.empty()) std::printf("silhouette: none (%s)\n", silhouetteProblem.c_str());
  rangeTable("teaching", teaching);
  std::printf(
      "%s; physiology: %d of %zu within published ranges; silhouette: %d of %zu; teaching: %d of %zu; "
      "report: "
      "%s/report.html (%.0f s)\n",
      verdict.c_str(), within, physiology.size(), silhouetteWithin, silhouette.size(), teachingWithin,
      teaching.size(), args.out.c_str(), wallSeconds);
  if (failed > 0) throw CLI::RuntimeError(kExitFailed);
}

}  // namespace

void addValidateCommand(CLI::App& app) {
  auto args = std::make_shared<ValidateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "validate", "Rerun the papers' experiments; write report.html, report.md, report.json");
  addModelOption(*cmd, args->model);
  cmd->add_option("--out", args->out, "Output directory (default: ./validation; created if missing)");
  cmd->add_flag("--force", args->force, "Replace an earlier report in --out");
  cmd->add_flag("--quick", args->isQuick, "Shorter runs (same checks), for tests and quick looks");
  addIntegratorOption(*cmd, args->integrator);
  cmd->add_option_function<double>(
      "--dt", [args](double dt) { args->dt = dt; }, "Time step [s] (default: the integrator's default)");
  cmd->callback([args] { runValidate(*args); });
}

}  // namespace pneuma::app
