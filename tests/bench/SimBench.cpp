// Speed of the simulation core (Google Benchmark): the real-time factor per breath style on the
// default model (simulated seconds per wall-clock second, one thread), the cost of one step as the
// gut mesh is refined 4x per level (synthetic toy torso, 162 -> 642 -> 2562 gut nodes), and de Melo's
// morph playback of every affect (no physics: `pneuma-cli play` and the app's morph playback).
#include <benchmark/benchmark.h>

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "DefaultModel.h"
#include "ToyTorso.h"
#include "pneuma/sim/BreathStyleController.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/MorphTargets.h"
#include "pneuma/sim/Resources.h"
#include "pneuma/sim/Simulation.h"
#include "pneuma/sim/pattern/Pattern.h"

namespace pneuma::sim {
namespace {

using test::defaultModel;

// real-time factor of a breath style on the default model at time step dt [s] (unset: the integrator's
// default), after 100 settling steps (rtf is a rate over the CPU time of the loop, i.e. wall time on an idle
// core; stepping, metrics and recording at 60 Hz are all included); one iteration is 25 steps. The recorder
// keeps 1 s, as in `pneuma-cli bench`: its memory is then reused, the steady state of any run. While a fresh
// 300 s timeline fills, each frame also touches new memory (14 KB; about 50 us per frame in page faults on
// the build machine).
void realTimeFactor(benchmark::State& state, const std::string& style, IntegratorKind integrator,
                    std::optional<double> dt) {
  const auto model = defaultModel();
  if (!model) {
    state.SkipWithError("default model missing: build it with 'pneuma-cli model build'");
    return;
  }
  SimulationOptions o;
  o.step.integrator = integrator;
  o.dt = dt;
  o.recordSeconds = kTraceOnlyRecordSeconds;
  auto controller = std::make_unique<BreathStyleController>(loadBreathStyle(style));
  o.settleTime = 100.0 * resolveOptions(*model, o, controller->maxTimeStep()).dt;
  Simulation sim(model, std::move(controller), o);
  const double chunk = 25.0 * sim.dt();     // [s] simulated per iteration
  double cgIterations = 0.0, frames = 0.0;  // CG iterations of the step before each output frame
  const auto sample = [&](const Simulation& s) {
    cgIterations += s.stepWork().memory.cgIterations;
    frames += 1.0;
    return true;
  };
  try {
    sim.advance(o.settleTime);
    for (auto _ : state) sim.advance(chunk, sample);
  } catch (const Error& e) {
    state.SkipWithError(e.what());
    return;
  }
  state.counters["rtf"] =
      benchmark::Counter(chunk * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["dt_ms"] = sim.dt() * 1e3;
  state.counters["cg_iterations"] = frames > 0.0 ? cgIterations / frames : 0.0;
}

// wall time of one step() with the gut refined to `subdivisions`
void stepTime(benchmark::State& state) {
  const Model model = test::makeToyTorso(static_cast<int>(state.range(0)));
  const BreathStyle calm = loadBreathStyle("calm");
  BreathStyleController controller(calm);
  StepOptions o;
  State s = makeInitialState(model);
  StepWork w = makeStepWork(model);
  const double dt = test::toyTimeStep(o.integrator);
  double cgIterations = 0.0;
  for (auto _ : state) {
    step(model, s, dt, controller.activations(s.time, Metrics{}), o, w);
    cgIterations += w.memory.cgIterations;
    benchmark::DoNotOptimize(s.nodePosition.data());
  }
  state.counters["cg_iterations"] = cgIterations / static_cast<double>(state.iterations());
  state.counters["nodes"] = model.nodes.size();
  state.counters["elements"] = model.elements.size();
  state.counters["gut_faces"] = static_cast<double>(model.gut.triangles.cols());
}

// 60 s of an affect at 30 frames/s played on morph targets the size of the default model's (its skin and its
// bodies, random shapes: the cost does not depend on them) as `pneuma-cli play` and the app do it: each
// frame's weights (sim::MorphPlayer), bone poses (sim::blendBones) and skin (MorphFit::blend, what a renderer
// draws). One iteration is the 60 s; the bound is 1 s of CPU (the counter cpu_s_per_60s).
void morphPlay(benchmark::State& state, const std::string& affect) {
  const auto model = defaultModel();
  if (!model || model->skin.vertexCount() == 0) {
    state.SkipWithError("default model missing: build it with 'pneuma-cli model build'");
    return;
  }
  const int nV = model->skin.vertexCount(), nB = model->bodies.size();
  MorphTargets m;
  m.base = Eigen::Matrix3Xd::Random(3, nV);
  m.bones = model->bodies.name;
  m.boneBase = {Eigen::Matrix3Xd::Random(3, nB), Eigen::Matrix4Xd::Random(4, nB)};
  for (const char* name : {"breathing", "chest", "belly"})
    m.targets.push_back({name,
                         Eigen::Matrix3Xd::Random(3, nV) * 0.01,
                         m.targets.size() * 0.4,
                         {Eigen::Matrix3Xd::Random(3, nB) * 0.01, Eigen::Matrix4Xd::Random(4, nB) * 0.01}});
  m.restVolume = 3.0e-3;
  m.baseVolume = 2.9e-3;
  m.targetVolume = 4.0e-3;
  m.weightPerVolume = 1.0 / 1.1e-3;
  const MorphFit fit(m);
  const pattern::Pattern p = pattern::loadAffect(affect, resourceDir());
  for (auto _ : state) {
    MorphPlayer player(p, 0);
    for (int f = 0; f <= 1800; ++f) {
      const Eigen::VectorXd w = player.weightsAt(m, f / 30.0);
      benchmark::DoNotOptimize(blendBones(m, w).data());
      benchmark::DoNotOptimize(fit.blend(w).data());
    }
  }
  state.counters["cpu_s_per_60s"] = benchmark::Counter(
      static_cast<double>(state.iterations()), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

const bool kRegistered = [] {
  // every breath style with the default integrator at its default dt (1/60 s) and at 10 ms; calm with
  // symplectic Euler
  struct Run {
    IntegratorKind integrator;
    std::optional<double> dt;  // [s], unset: the integrator's default
    const char* style;
  };
  std::vector<Run> runs;
  for (const char* style : {"calm", "deep", "panting", "forced-exhale"}) {
    runs.push_back({IntegratorKind::ImplicitEulerJoints, std::nullopt, style});
    runs.push_back({IntegratorKind::ImplicitEulerJoints, 0.01, style});
  }
  runs.push_back({IntegratorKind::SymplecticEuler, std::nullopt, "calm"});
  for (const Run& run : runs) {
    const std::string dtName =
        run.dt ? "/dt_ms:" + std::to_string(static_cast<int>(*run.dt * 1e3 + 0.5)) : "";
    benchmark::RegisterBenchmark(
        (std::string("RealTimeFactor/") + integratorName(run.integrator) + dtName + "/" + run.style).c_str(),
        [run](benchmark::State& st) { realTimeFactor(st, run.style, run.integrator, run.dt); })
        ->Unit(benchmark::kMillisecond);
  }
  benchmark::RegisterBenchmark("StepTime/gut_subdivisions", stepTime)
      ->DenseRange(2, 4)
      ->Unit(benchmark::kMicrosecond);
  for (const std::string& affect : pattern::listAffects(resourceDir()))
    benchmark::RegisterBenchmark(("MorphPlay/" + affect).c_str(), [affect](benchmark::State& st) {
      morphPlay(st, affect);
    })->Unit(benchmark::kMillisecond);
  return true;
}();

}  // namespace
}  // namespace pneuma::sim

BENCHMARK_MAIN();
