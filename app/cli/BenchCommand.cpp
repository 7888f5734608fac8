/// @file BenchCommand.cpp
/// `pneuma-cli bench`: the real-time factor (simulated seconds per wall second) of every breath style,
/// and the wall time of one step against the number of spring elements (the model with every k-th
/// element kept, k = 8, 4, 2, 1). Prints a table; with --out also writes bench.json.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "CliSupport.h"
#include "Commands.h"
#include "pneuma/sim/BreathStyleController.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/ModelIO.h"
#include "pneuma/sim/Resources.h"
#include "pneuma/sim/Simulation.h"
#include "viz/AtomicFile.h"

namespace pneuma::app {

namespace {

struct BenchArgs {
  std::string model;
  std::string out;
  bool force = false;    // replace an earlier bench.json in `out`
  double seconds = 4.0;  // [s] simulated per measurement
  std::string integrator;
  std::string posture;
};

/// Keeps the points `keep` of an anchor set.
sim::AnchorSet subset(const sim::AnchorSet& a, const std::vector<int>& keep) {
  sim::AnchorSet out;
  for (int i : keep) {
    if (a.body[static_cast<std::size_t>(i)] >= 0)
      out.addBodyPoint(a.body[static_cast<std::size_t>(i)], a.local.col(i));
    else
      out.addNodePoint(a.nodes.col(i), a.weights.col(i));
  }
  return out;
}

/// `model` with every `stride`-th element of each group kept (cartilage always kept: it holds the ribcage).
sim::Model thinned(const sim::Model& model, int stride) {
  std::vector<int> keep;
  std::array<int, sim::kElementGroupCount> seen{};
  for (int e = 0; e < model.elements.size(); ++e) {
    const sim::ElementGroup g = model.elements.group[static_cast<std::size_t>(e)];
    if (g == sim::ElementGroup::Cartilage || seen[static_cast<std::size_t>(g)]++ % stride == 0)
      keep.push_back(e);
  }
  sim::Model m = model;
  sim::Elements& el = m.elements;
  const sim::Elements& src = model.elements;
  el.group.clear();
  el.restLength.resize(static_cast<Eigen::Index>(keep.size()));
  el.kac.resize(el.restLength.size());
  el.kpe.resize(el.restLength.size());
  el.damping.resize(el.restLength.size());
  if (src.recruitment.size() > 0) el.recruitment.resize(el.restLength.size());
  el.isGliding.clear();
  for (std::size_t k = 0; k < keep.size(); ++k) {
    const int e = keep[k];
    const auto i = static_cast<Eigen::Index>(k);
    el.group.push_back(src.group[static_cast<std::size_t>(e)]);
    el.restLength(i) = src.restLength(e);
    el.kac(i) = src.kac(e);
    el.kpe(i) = src.kpe(e);
    el.damping(i) = src.damping(e);
    if (src.recruitment.size() > 0) el.recruitment(i) = src.recruitment(e);
    if (!src.isGliding.empty()) el.isGliding.push_back(src.isGliding[static_cast<std::size_t>(e)]);
  }
  el.endA = subset(src.endA, keep);
  el.endB = subset(src.endB, keep);
  return m;
}

/// Runs `style` on `model` for `seconds` after a 0.5 s settle; returns (real-time factor, wall seconds per
/// step).
std::pair<double, double> measure(std::shared_ptr<const sim::Model> model, const sim::BreathStyle& style,
                                  const sim::SimulationOptions& options, double seconds) {
  sim::Simulation simulation(std::move(model), std::make_unique<sim::BreathStyleController>(style), options);
  simulation.advance(0.5);
  const long long steps0 = simulation.state().steps;
  const auto start = std::chrono::steady_clock::now();
  simulation.advance(seconds);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const long long steps = simulation.state().steps - steps0;
  return {seconds / wall, wall / static_cast<double>(std::max(1LL, steps))};
}

void runBench(const BenchArgs& args) {
  const std::string modelDir = resolveModelDir(args.model);
  checkOption(sim::kDurationRange, "--seconds", args.seconds);
  if (!args.out.empty()) prepareOutputDir(args.out, "bench", {"bench.json"}, args.force);
  sim::SimulationOptions options;
  options.settleTime = 0.0;
  options.recordSeconds = sim::kTraceOnlyRecordSeconds;
  applyIntegrator(args.integrator, options.step.integrator);
  applyPosture(args.posture, options.step.posture);
  std::shared_ptr<const sim::Model> model;
  std::vector<sim::BreathStyle> styles;
  try {
    model = std::make_shared<const sim::Model>(sim::loadModel(modelDir));
    for (const std::string& name : sim::breathStyleNames(sim::resourceDir() + "/presets"))
      styles.push_back(sim::loadBreathStyle(name, sim::resourceDir() + "/presets"));
  } catch (const sim::Error& e) {
    fail(kExitBadInput, e.what());
  }
  if (styles.empty()) fail(kExitBadInput, "no breath-style presets in " + sim::resourceDir() + "/presets");
  const double dt =
      sim::resolveOptions(*model, options, sim::BreathStyleController(styles.front()).maxTimeStep()).dt;
  nlohmann::json j;
  j["pneuma_version"] = PNEUMA_VERSION;
  j["model"] = modelDir;
  j["integrator"] = sim::integratorName(options.step.integrator);
  j["posture"] = sim::postureName(options.step.posture);
  j["dt_s"] = dt;
  j["simulated_seconds"] = args.seconds;
  std::printf("model %s: %d bodies, %d nodes, %d elements; %s, %s, dt = %g s, %g s simulated per row\n\n",
              model->name.c_str(), model->bodies.size(), model->nodes.size(), model->elements.size(),
              sim::integratorName(options.step.integrator), sim::postureName(options.step.posture), dt,
              args.seconds);

  // real-time factor per breath style
  std::printf("%-16s %18s %16s\n", "breath style", "real-time factor", "step time [ms]");
  try {
    for (const sim::BreathStyle& s : styles) {
      const auto [rtf, stepTime] = measure(model, s, options, args.seconds);
      std::printf("%-16s %18.2f %16.3f\n", s.name.c_str(), rtf, stepTime * 1e3);
      j["styles"].push_back({{"style", s.name}, {"real_time_factor", rtf}, {"step_time_ms", stepTime * 1e3}});
    }

  } catch (const sim::Error& e) {
    fail(kExitFailed, e.what());
  }

  // step time against element count (calm breathing); a thinned model keeps every 8th, 4th or 2nd strand of
  // its abdominal wall, so the gut pressure bulges it and it may blow up within seconds: measure a fixed 2 s
  // and report a blow-up in its row
  constexpr double kThinnedSeconds = 2.0;  // [s]
  const auto calm =
      std::find_if(styles.begin(), styles.end(), [](const sim::BreathStyle& s) { return s.name == "calm"; });
  std::printf("\n%-16s %18s %16s   (%g s each)\n", "elements", "real-time factor", "step time [ms]",
              kThinnedSeconds);
  for (int stride : {8, 4, 2, 1}) {
    auto m = std::make_shared<const sim::Model>(thinned(*model, stride));
    try {
      const auto [rtf, stepTime] =
          measure(m, calm != styles.end() ? *calm : styles.front(), options, kThinnedSeconds);
      std::printf("%-16d %18.2f %16.3f\n", m->elements.size(), rtf, stepTime * 1e3);
      j["elements"].push_back(
          {{"elements", m->elements.size()}, {"real_time_factor", rtf}, {"step_time_ms", stepTime * 1e3}});
    } catch (const sim::Error& e) {
      std::printf("%-16d %s\n", m->elements.size(), e.what());
      j["elements"].push_back({{"elements", m->elements.size()}, {"error", e.what()}});
    }
  }
  if (!args.out.empty()) {
    viz::writeFileAtomically(args.out + "/bench.json", j.dump(2) + "\n");
    std::printf("\nwrote %s/bench.json\n", args.out.c_str());
  }
}

}  // namespace

void addBenchCommand(CLI::App& app) {
  auto args = std::make_shared<BenchArgs>();
  CLI::App* cmd =
      app.add_subcommand("bench", "Real-time factor per breath style and step time per element count");
  addModelOption(*cmd, args->model);
  cmd->add_option("--out", args->out, "Also write bench.json into this directory (created if missing)");
  cmd->add_flag("--force", args->force, "Replace an earlier bench.json in --out");
  cmd->add_option("--seconds", args->seconds, "Simulated seconds per measurement (default 4)");
  addIntegratorOption(*cmd, args->integrator);
  addPostureOption(*cmd, args->posture);
  cmd->callback([args] { runBench(*args); });
}

}  // namespace pneuma::app
