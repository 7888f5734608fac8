/// @file SimulateCommand.cpp
/// `pneuma-cli simulate`: one run of a breath style, an affect, a pattern file or a scenario file.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <vector>

#include "CliSupport.h"
#include "Commands.h"
#include "Morphs.h"
#include "Progress.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/ModelIO.h"
#include "pneuma/sim/Resources.h"
#include "pneuma/sim/Scenario.h"
#include "pneuma/sim/Simulation.h"
#include "pneuma/sim/pattern/PatternController.h"
#include "viz/AtomicFile.h"
#include "viz/GltfWriter.h"
#include "viz/RunRecord.h"
#include "viz/RunSummary.h"
#include "viz/VtkSeriesWriter.h"

namespace pneuma::app {

namespace {

namespace fs = std::filesystem;

/// Command-line settings; `isGiven` tells which numeric ones were on the command line (the others keep
/// the scenario's or the default value).
struct SimulateArgs {
  std::string model;
  std::string style, affect, scenario, pattern, trace;
  double duration = 0.0;  // [s]
  std::string out;
  std::string gltf;         // .glb of the run (skin morph weights and bones), "" for none
  std::string morphs;       // morph targets baked by `pneuma-cli bake`, "" to bake them now
  double outputRate = 0.0;  // [Hz]
  bool vtk = false;
  viz::SeriesRange vtkRange;  // --vtk-from, --vtk-to, --vtk-stride
  bool force = false;         // replace an earlier run's results in `out`
  std::uint64_t seed = 0;
  std::string integrator;
  std::string posture;
  double dt = 0.0;                // [s]
  double settle = 0.0;            // [s]
  std::vector<std::string> sets;  // --set KEY=VALUE, scenario overrides
  std::function<bool(const char*)> isGiven;
};

/// Applies each --set KEY=VALUE by the scenario file's overrides rule (sim::applyOverride()).
void applySets(const std::vector<std::string>& sets, sim::SimulationOptions& options) {
  for (const std::string& kv : sets) {
    const std::size_t eq = kv.find('=');
    if (eq == std::string::npos)
      fail(kExitBadInput,
           "--set: expected KEY=VALUE, got '" + kv.substr(0, 60) + "' (keys: " + sim::overrideKeys() + ")");
    try {
      sim::applyOverride(options, kv.substr(0, eq), kv.substr(eq + 1));
    } catch (const sim::Error& e) {
      fail(kExitBadInput, e.what());
    }
  }
}

/// The scenario to run: the --scenario file (if any) with the command-line settings applied on top.
sim::Scenario scenarioFromArgs(const SimulateArgs& a) {
  sim::Scenario s;
  if (!a.scenario.empty()) {
    try {
      s = sim::loadScenario(a.scenario);
    } catch (const sim::Error& e) {
      fail(kExitBadInput, e.what());
    }
  }
  const int given =
      !a.style.empty() + !a.affect.empty() + !a.pattern.empty() + !a.trace.empty() + !a.scenario.empty();
  if (given != 1)
    fail(kExitBadInput, "give exactly one of --style, --affect, --pattern, --trace or --scenario");
  if (!a.style.empty()) s.controller = sim::ControllerKind::Style, s.controllerName = a.style;
  if (!a.affect.empty()) s.controller = sim::ControllerKind::Affect, s.controllerName = a.affect;
  if (!a.pattern.empty()) s.controller = sim::ControllerKind::Pattern, s.controllerName = a.pattern;
  if (!a.trace.empty()) s.controller = sim::ControllerKind::Trace, s.controllerName = a.trace;
  if (s.name.empty()) s.name = s.controllerName.empty() ? "run" : fs::path(s.controllerName).stem().string();
  applySets(a.sets, s.options);

  if (a.isGiven("--duration")) {
    checkOption(sim::kDurationRange, "--duration", a.duration);
    s.duration = a.duration;
  }
  // a trace runs for its own length unless told otherwise
  if (!a.trace.empty() && !a.isGiven("--duration")) {
    try {
      s.duration = std::max(sim::pattern::loadVolumeTrace(a.trace).duration(), sim::kDurationRange.lo);
    } catch (const sim::Error& e) {
      fail(kExitBadInput, std::string("--trace: ") + e.what());
    }
  } else if (a.scenario.empty() && !a.isGiven("--duration"))
    fail(kExitBadInput, "--duration is required (simulated seconds)");
  if (a.isGiven("--output-rate")) {
    checkOption(sim::kOutputRateRange, "--output-rate", a.outputRate);
    s.options.outputRate = a.outputRate;
  }
  if (a.vtk) s.outputs.vtk = true;
  const std::string vtkRangeError = a.vtkRange.error("--vtk-from", "--vtk-to", "--vtk-stride");
  if (!vtkRangeError.empty()) fail(kExitBadInput, vtkRangeError);
  if (a.isGiven("--seed")) s.seed = a.seed;
  applyIntegrator(a.integrator, s.options.step.integrator);
  applyPosture(a.posture, s.options.step.posture);
  if (a.isGiven("--dt")) {
    checkOption(sim::kTimeStepRange, "--dt", a.dt);
    s.options.dt = a.dt;
  }
  if (a.isGiven("--settle")) {
    checkOption(sim::kSettleTimeRange, "--settle", a.settle);
    s.options.settleTime = a.settle;
  }
  try {
    sim::validateSimulationOptions(s.options);
  } catch (const sim::Error& e) {
    fail(kExitBadInput, e.what());
  }
  return s;
}

void runSimulate(const SimulateArgs& args) {
  const sim::Scenario scenario = scenarioFromArgs(args);
  const std::string modelDir = resolveModelDir(!args.model.empty()           ? args.model
                                               : scenario.model == "default" ? ""
                                                                             : scenario.model);
  prepareOutputDir(args.out, "simulate",
                   {"summary.json", "timeseries.csv", "frames.pvd", "frames", "*.png", "*.svg"}, args.force);

  // Ctrl-C from here on: the first stops within one step (the drive calibration too) and the outputs are
  // still written; a second ends the process at once (InterruptGuard)
  InterruptGuard guard;

  // model, controller and simulation: any bad input is reported by name before anything runs
  std::shared_ptr<const sim::Model> model;
  std::unique_ptr<sim::Simulation> simulation;
  bool isInterrupted = false;
  try {
    model = std::make_shared<const sim::Model>(sim::loadModel(modelDir));
    sim::checkController(scenario, sim::resourceDir());
    if (scenario.controller != sim::ControllerKind::Style)
      std::fprintf(stderr, "calibrating the pattern controller's muscle drive on the model...\n");
    std::unique_ptr<sim::Controller> controller =
        sim::makeController(scenario, model, sim::resourceDir(), InterruptGuard::flag());
    // the CLI writes the trace; the recorder's timeline is for the app's scrubbing
    sim::SimulationOptions options = scenario.options;
    options.recordSeconds = sim::kTraceOnlyRecordSeconds;
    simulation = std::make_unique<sim::Simulation>(model, std::move(controller), options);
    simulation->setStopFlag(InterruptGuard::flag());
    sim::checkStepCount(args.isGiven("--duration") ? "--duration" : "duration_s",
                        scenario.options.settleTime + scenario.duration, simulation->dt());
  } catch (const sim::Interrupted&) {
    isInterrupted = true;  // Ctrl-C during the calibration: nothing ran, the summary says so
  } catch (const sim::Error& e) {
    // a controller given on the command line is named by its flag, not by its scenario-file path
    std::string message = e.what();
    const std::string field =
        std::string("controller.") + sim::controllerKindName(scenario.controller) + ": ";
    if (args.scenario.empty() && message.rfind(field, 0) == 0)
      message = std::string("--") + sim::controllerKindName(scenario.controller) + ": " +
                message.substr(field.size());
    fail(kExitBadInput, message);
  }
  // the glTF export: a skinned model, a writable path and the morph targets, before anything runs
  std::unique_ptr<sim::MorphTargets> morphs;
  std::unique_ptr<viz::GltfAnimationBuilder> gltf;
  if (!args.gltf.empty() && model) {
    checkHasSkin("--gltf", *model);
    checkGltfOutput("--gltf", args.gltf);
    morphs = std::make_unique<sim::MorphTargets>(morphTargetsFor(model, args.morphs));
    gltf = std::make_unique<viz::GltfAnimationBuilder>(*model, *morphs);
  }

  const bool hasTarget = scenario.controller != sim::ControllerKind::Style;
  const std::string controllerText =
      simulation ? simulation->controller().describe()
                 : std::string(sim::controllerKindName(scenario.controller)) + " " + scenario.controllerName;

  // run, recording every output frame; a blow-up or an output that cannot be written (a full disk) ends the
  // run with what was computed so far
  // outputs that cannot even be started are refused before the run
  std::unique_ptr<viz::RunRecord> recordOwner;
  try {
    recordOwner = std::make_unique<viz::RunRecord>(
        *model, hasTarget, scenario.outputs.csv ? args.out + "/timeseries.csv" : std::string());
  } catch (const std::exception& e) {
    fail(kExitBadInput, std::string("--out: ") + e.what());
  }
  viz::RunRecord& record = *recordOwner;
  std::unique_ptr<viz::VtkSeriesWriter> vtk;
  viz::SeriesSelector vtkFrames(args.vtkRange);
  int vtkFrameCount = 0;  // the series' frames, said before the run
  if (simulation && scenario.outputs.vtk) {
    try {
      vtk = std::make_unique<viz::VtkSeriesWriter>(*model, modelDir, args.out, "frames");
      // what the series will hold, before the run: its frames (their size once the first is written)
      const double total = scenario.options.settleTime + scenario.duration;  // [s] the output frames' span
      const double rate = simulation->options().outputRate;                  // [1/s]
      const auto frames = static_cast<std::size_t>(std::floor(total * rate + 1e-9)) + 1;
      vtkFrameCount = args.vtkRange.count(frames, 0.0, static_cast<double>(frames - 1) / rate);
      std::printf("ParaView series: %d frames (one in %d of the %g output frames per second, %g s to %g s)\n",
                  vtkFrameCount, args.vtkRange.stride, rate, args.vtkRange.from,
                  std::min(args.vtkRange.to, total));
      std::fflush(stdout);
    } catch (const std::exception& e) {
      fail(kExitBadInput, std::string("--vtk: ") + e.what());
    }
  }
  std::string failure;
  if (simulation) {
    const double total = scenario.options.settleTime + scenario.duration;  // [s]
    ProgressBar bar(scenario.name, total);
    try {
      simulation->advance(total, [&](const sim::Simulation& s) {
        if (s.controller().tracksVolume())
          record.append(s.latestMetrics(), s.controller().targetFraction(),
                        s.controller().measuredFraction());
        else
          record.append(s.latestMetrics());
        if (vtk && vtkFrames.take(s.state().time)) {
          vtk->writeFrame(s.state(), s.latestMetrics());
          // the size, from the first frame's files (a frame at rest would compress better than the others)
          if (vtk->frameCount() == 1) {
            const double bytes = static_cast<double>(vtk->bytesWritten());  // [bytes]
            std::printf("ParaView series: about %.1f MB (%.2f MB a frame)\n", bytes * vtkFrameCount / 1e6,
                        bytes / 1e6);
            std::fflush(stdout);
          }
        }
        // the glTF animation starts with the controller; each frame's skin fitted onto the morph targets
        const double t = s.state().time - scenario.options.settleTime;  // [s]
        if (gltf && t >= 0.0) gltf->add(t, s.state());
        bar.update(s.state().time);
        return true;
      });
    } catch (const std::exception& e) {
      failure = e.what();  // sim::Error (blow-up) or std::runtime_error from a writer
    }
    bar.finish();
    isInterrupted = simulation->wasStopped();
  }

  // outputs, each through a temporary file and a rename; one that cannot be written does not stop the others
  std::vector<std::string> files;
  std::vector<std::string> writeErrors;
  auto attempt = [&](const std::function<void()>& write) {
    try {
      write();
    } catch (const std::exception& e) {
      writeErrors.push_back(e.what());
    }
  };
  if (scenario.outputs.csv)
    attempt([&] {
      record.commitCsv();
      files.push_back("timeseries.csv");
    });
  if (scenario.outputs.plots && record.size() > 0)
    attempt([&] {
      for (const std::string& f : record.writePlots(args.out, scenario.name)) files.push_back(f);
    });
  if (vtk) attempt([&] { files.push_back(vtk->finish()); });
  if (gltf && gltf->frames() >= 2)
    attempt([&] {
      viz::writeGltf(args.gltf, *model, modelDir, *morphs, {gltf->animation(scenario.name)});
      files.push_back(args.gltf);
    });
  if (failure.empty() && !writeErrors.empty()) failure = writeErrors.front();

  const sim::Summary sum = simulation ? simulation->summary() : sim::Summary{};
  const bool ran = simulation && record.size() > 0;
  const bool breathed = ran && sum.cycles > 0;
  const bool blended = gltf && gltf->frames() > 0;
  const sim::BlendError blend = blended ? gltf->error() : sim::BlendError{};
  const nlohmann::json j =
      viz::runSummary(*model, scenario, simulation.get(),
                      {modelDir, controllerText, isInterrupted, failure, record.size(), files,
                       blended ? blend.rms : sim::kNaN, blended ? blend.max : sim::kNaN});
  bool hasSummary = false;
  attempt([&] {
    viz::writeFileAtomically(args.out + "/summary.json", j.dump(2) + "\n");
    hasSummary = true;
  });

  // a short human-readable report on stdout
  std::printf("%s: %s%s\n", scenario.name.c_str(), controllerText.c_str(),
              isInterrupted ? " (interrupted, partial results)" : "");
  if (breathed)
    std::printf("  tidal volume %.0f mL, %.1f breaths/min", sum.tidalVolume * 1e6, sum.breathsPerMinute);
  else if (ran)
    std::printf("  no full breath found");
  if (ran)
    std::printf(", max gut volume error %.3f %%, real-time factor %.2f\n", sum.maxGutVolumeError * 100.0,
                sum.realTimeFactor);
  if (blended)
    std::printf("  morph blend error over the skin: RMS %.2f mm, max %.2f mm (%zu frames)\n", blend.rms * 1e3,
                blend.max * 1e3, gltf->frames());
  if (blended && !morphs->bones.empty()) {
    const sim::BoneBlendError bone = gltf->boneError();
    std::printf(
        "  morph blend error of the bones: rib tips RMS %.2f mm, max %.2f mm; rotations RMS %.2f deg, "
        "max %.2f deg\n",
        bone.tipRms * 1e3, bone.tipMax * 1e3, bone.angleRms * 180.0 / M_PI, bone.angleMax * 180.0 / M_PI);
  }
  std::printf("  wrote %s%zu files in %s\n", hasSummary ? "summary.json and " : "", files.size(),
              args.out.c_str());
  if (!failure.empty() || !writeErrors.empty()) {
    // one line: the run's failure, then every output that could not be written
    std::string message = failure;
    for (const std::string& w : writeErrors)
      if (w != failure) message += "; " + w;
    if (!hasSummary) message += " (no summary.json)";
    fail(kExitFailed, message);
  }
  if (isInterrupted) throw CLI::RuntimeError(kExitInterrupted);
}

}  // namespace

void addSimulateCommand(CLI::App& app) {
  auto args = std::make_shared<SimulateArgs>();
  CLI::App* cmd =
      app.add_subcommand("simulate", "Simulate breathing; write timeseries.csv, summary.json and plots");
  addModelOption(*cmd, args->model);
  auto* style =
      cmd->add_option("--style", args->style, "Breath style preset (calm, deep, panting, forced-exhale)");
  auto* affect =
      cmd->add_option("--affect", args->affect, "Affect preset (neutral, startle, ... see docs/cli.md)");
  cmd->add_option("--scenario", args->scenario, "Scenario file (JSON); other options override it");
  auto* pattern = cmd->add_option("--pattern", args->pattern, "Pattern file (JSON, docs/patterns.md)");
  auto* trace = cmd->add_option("--trace", args->trace,
                                "Volume-against-time CSV to follow ('time [s],volume [L]' or [mL]; "
                                "docs/patterns.md); --duration defaults to its length");
  style->excludes(affect)->excludes(pattern)->excludes(trace);
  affect->excludes(pattern)->excludes(trace);
  pattern->excludes(trace);
  cmd->add_option("--duration", args->duration, "Simulated seconds after the settling phase (> 0)");
  cmd->add_option("--out", args->out, "Output directory (created if missing)")->required();
  cmd->add_flag("--force", args->force, "Replace the results of an earlier run in --out");
  cmd->add_option("--output-rate", args->outputRate,
                  "Frames per simulated second in CSV, plots and VTK [Hz] (default 60)");
  auto* vtk = cmd->add_flag("--vtk", args->vtk, "Also write a ParaView .pvd series of .vtp frames");
  cmd->add_option("--vtk-from", args->vtkRange.from,
                  "First instant of the ParaView series [s], on timeseries.csv's clock (default 0)")
      ->needs(vtk);
  cmd->add_option("--vtk-to", args->vtkRange.to, "Last instant of the ParaView series [s] (default: the end)")
      ->needs(vtk);
  cmd->add_option("--vtk-stride", args->vtkRange.stride,
                  "Keep every N-th output frame in the ParaView series (default 1: all)")
      ->needs(vtk);
  auto* gltf = cmd->add_option(
      "--gltf", args->gltf,
      "Also write the run as a glTF 2.0 .glb: skin morph weights and bone poses (needs a skin)");
  cmd->add_option("--morphs", args->morphs,
                  "Morph targets for --gltf, baked by pneuma-cli bake (default: bake now)")
      ->needs(gltf);
  addSeedOption(*cmd, args->seed);
  addIntegratorOption(*cmd, args->integrator);
  addPostureOption(*cmd, args->posture);
  cmd->add_option(
      "--dt", args->dt,
      "Time step [s] (default: the integrator's, 1/60 s for implicit-euler-joints; 10 ms for affect and "
      "pattern runs)");
  cmd->add_option("--settle", args->settle, "Settling time before the controller starts [s] (default 2)");
  cmd->add_option("--set", args->sets,
                  "Override KEY=VALUE, as in a scenario's \"overrides\" (repeatable; e.g. dt_s=0.005, "
                  "posture=supine, active_gain_scale.diaphragm=1.2; docs/cli.md)")
      ->allow_extra_args(false);
  args->isGiven = [cmd](const char* flag) { return cmd->count(flag) > 0; };
  cmd->callback([args] { runSimulate(*args); });
}

}  // namespace pneuma::app
