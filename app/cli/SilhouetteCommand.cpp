/// @file SilhouetteCommand.cpp
/// `pneuma-cli silhouette`: plays breath styles on a model with a skin and writes the body's lateral and
/// frontal silhouettes at end-expiration and end-inspiration (CSV outlines, SVG and PNG overlays) and
/// silhouette.json with the anteroposterior changes at the chest and belly lines and their published ranges.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "CliSupport.h"
#include "Commands.h"
#include "Silhouettes.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/ModelIO.h"
#include "pneuma/sim/Resources.h"
#include "viz/AtomicFile.h"

namespace pneuma::app {

namespace {

struct SilhouetteArgs {
  std::string model;
  std::string out = "silhouette";
  std::vector<std::string> styles{"calm", "deep", "panting", "forced-exhale"};
  double spacing = 2.0;  // [mm]
  bool isQuick = false;
  bool force = false;
  std::string integrator;
};

const sim::Range kSpacingRange{0.5, 20.0, "mm"};  // outline grid

void runSilhouette(const SilhouetteArgs& args) {
  checkOption(kSpacingRange, "--spacing", args.spacing);
  const std::string modelDir = resolveModelDir(args.model);
  std::shared_ptr<const sim::Model> model;
  std::vector<sim::BreathStyle> styles;
  try {
    model = std::make_shared<const sim::Model>(sim::loadModel(modelDir));
    for (const std::string& name : args.styles)
      styles.push_back(sim::loadBreathStyle(name, sim::resourceDir() + "/presets"));
  } catch (const sim::Error& e) {
    fail(kExitBadInput, e.what());
  }
  if (model->skin.vertexCount() == 0)
    fail(kExitBadInput, "--model: '" + modelDir + "' has no skin; rebuild it with pneuma-cli model build");
  prepareOutputDir(args.out, "silhouette", {"silhouette.json", "*.csv", "*.svg", "*.png"}, args.force);
  sim::ExperimentSettings settings =
      args.isQuick ? sim::ExperimentSettings::quick() : sim::ExperimentSettings();
  applyIntegrator(args.integrator, settings.simulation.step.integrator);

  // play each style and trace its breath; a blow-up ends the command (exit 1) with the simulator's diagnosis
  std::vector<sim::SilhouetteBreath> breaths;
  nlohmann::json j;
  j["pneuma_version"] = PNEUMA_VERSION;
  j["model"] = modelDir;
  j["quick"] = args.isQuick;
  j["spacing_mm"] = args.spacing;
  for (const sim::BreathStyle& style : styles) {
    std::fprintf(stderr, "silhouette: breath style '%s'\n", style.name.c_str());
    try {
      const sim::StyleRun run = sim::runBreathStyle(model, style, settings);
      breaths.push_back(sim::silhouetteBreath(run));
    } catch (const sim::Error& e) {
      fail(kExitFailed, e.what());
    }
    const BreathOutlines b = traceBreath(breaths.back(), model->skin.triangles, args.spacing * 1e-3);
    nlohmann::json& s = j["styles"][style.name];
    s = silhouetteJson(b.breath);
    s["files"] = writeSilhouettes(b, args.out, "");
  }

  // the figures against their published ranges (the styles given)
  const std::vector<sim::Check> checks = sim::silhouetteChecks(breaths);
  for (const sim::Check& c : checks)
    j["checks"].push_back({{"id", c.id},
                           {"what", c.what},
                           {"measured", jsonNumber(c.measured)},
                           {"unit", c.unit},
                           {"lower", jsonNumber(c.lower)},
                           {"upper", jsonNumber(c.upper)},
                           {"target", c.target},
                           {"within", c.isPassed()},
                           {"source", c.source}});
  viz::writeFileAtomically(args.out + "/silhouette.json", j.dump(2) + "\n");

  std::printf("%-16s %14s %14s %12s\n", "style", "chest AP [mm]", "belly AP [mm]", "lung [mL]");
  for (const sim::SilhouetteBreath& b : breaths)
    std::printf("%-16s %+14.1f %+14.1f %+12.0f\n", b.style.c_str(), b.chestChange * 1e3, b.bellyChange * 1e3,
                b.lungChange * 1e6);
  for (const sim::Check& c : checks)
    std::printf("%-32s %-8s %8.1f %s  %s\n", c.id.c_str(), c.isPassed() ? "within" : "OUTSIDE", c.measured,
                c.unit.c_str(), c.target.c_str());
  std::printf("outlines and overlays: %s/\n", args.out.c_str());
}

}  // namespace

void addSilhouetteCommand(CLI::App& app) {
  auto args = std::make_shared<SilhouetteArgs>();
  CLI::App* cmd = app.add_subcommand("silhouette",
                                     "Body silhouettes (lateral, frontal) at end-expiration and "
                                     "end-inspiration per breath style: CSV, SVG, PNG");
  addModelOption(*cmd, args->model);
  cmd->add_option("--out", args->out, "Output directory (default: ./silhouette; created if missing)");
  cmd->add_option(
      "--style", args->styles,
      "Breath styles, by name or preset file (repeatable; default: calm deep panting forced-exhale)");
  cmd->add_option("--spacing", args->spacing, "Outline grid spacing [mm] (default: 2; 0.5 - 20)");
  cmd->add_flag("--force", args->force, "Replace an earlier run in --out");
  cmd->add_flag("--quick", args->isQuick,
                "Shorter runs (1 s settling, 10 s per style), for tests and quick looks");
  addIntegratorOption(*cmd, args->integrator);
  cmd->callback([args] { runSilhouette(*args); });
}

}  // namespace pneuma::app
