/// @file MorphCommands.cpp
/// `pneuma-cli bake`: morph targets baked from physics runs, written as a .glb.
/// `pneuma-cli play`: an affect or pattern played straight on the morph targets, without physics
/// (de Melo et al. 2010), written as a .glb animation.

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <memory>

#include "CliSupport.h"
#include "Commands.h"
#include "Morphs.h"
#include "Progress.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/ModelIO.h"
#include "pneuma/sim/Resources.h"
#include "pneuma/sim/pattern/Pattern.h"
#include "pneuma/sim/pattern/PatternController.h"
#include "viz/GltfWriter.h"

namespace pneuma::app {

namespace {

std::shared_ptr<const sim::Model> loadModelOrFail(const std::string& requested) {
  const std::string dir = resolveModelDir(requested);
  try {
    return std::make_shared<const sim::Model>(sim::loadModel(dir));
  } catch (const sim::Error& e) {
    fail(kExitBadInput, e.what());
  }
}

/// Writes the .glb or fails with kExitFailed naming the flag (nothing is left under `path`).
void writeGltfOrFail(const char* flag, const std::string& path, const sim::Model& model,
                     const std::string& modelDir, const sim::MorphTargets& targets,
                     const std::vector<viz::GltfAnimation>& animations) {
  try {
    viz::writeGltf(path, model, modelDir, targets, animations);
  } catch (const std::exception& e) {
    fail(kExitFailed, std::string(flag) + ": " + e.what());
  }
}

struct BakeArgs {
  std::string model, out;
};

void runBake(const BakeArgs& a) {
  const std::shared_ptr<const sim::Model> model = loadModelOrFail(a.model);
  checkHasSkin("--model", *model);
  checkGltfOutput("--out", a.out);
  InterruptGuard guard;
  const sim::MorphTargets m = morphTargetsFor(model, "");

  writeGltfOrFail("--out", a.out, *model, resolveModelDir(a.model), m, {viz::breathingDemo(m)});

  std::printf("morph targets of model '%s' (%d skin vertices), scaled to the deep breath's %.0f mL:\n",
              model->name.c_str(), m.vertexCount(), (m.targetVolume - m.baseVolume) * 1e6);
  for (const sim::MorphTarget& t : m.targets)
    std::printf("  %-9s largest displacement %5.1f mm, rib cage %3.0f %% of the tidal volume\n",
                t.name.c_str(), t.displacement.colwise().norm().maxCoeff() * 1e3, t.ribCageShare * 100.0);
  std::printf("  base at %.0f mL, rest %.0f mL; %.3f weight per litre above the base\n", m.baseVolume * 1e6,
              m.restVolume * 1e6, m.weightPerVolume * 1e-3);
  std::printf("  wrote %s\n", a.out.c_str());
}

struct PlayArgs {
  std::string model, affect, pattern, gltf, morphs;
  double duration = 60.0;    // [s]
  double outputRate = 30.0;  // [Hz]
  std::uint64_t seed = 0;
};

void runPlay(const PlayArgs& a) {
  if (a.affect.empty() == a.pattern.empty()) fail(kExitBadInput, "give exactly one of --affect or --pattern");
  checkOption(sim::kDurationRange, "--duration", a.duration);
  checkOption(sim::kOutputRateRange, "--output-rate", a.outputRate);
  sim::pattern::Pattern pattern;
  try {
    pattern = a.affect.empty() ? sim::pattern::loadPatternFile(a.pattern, sim::resourceDir())
                               : sim::pattern::loadAffect(a.affect, sim::resourceDir());
  } catch (const sim::Error& e) {
    fail(kExitBadInput, std::string(a.affect.empty() ? "--pattern: " : "--affect: ") + e.what());
  }
  const std::shared_ptr<const sim::Model> model = loadModelOrFail(a.model);
  checkHasSkin("--model", *model);
  checkGltfOutput("--gltf", a.gltf);
  InterruptGuard guard;
  const sim::MorphTargets m = morphTargetsFor(model, a.morphs);

  // the playback: pattern volume and balance -> weights, per frame (sim::MorphPlayer), and the bones posed by
  // the same weights (sim::blendBones)
  const std::clock_t start = std::clock();
  sim::MorphPlayer player(pattern, a.seed);
  const long long frames = static_cast<long long>(std::floor(a.duration * a.outputRate)) + 1;
  viz::GltfAnimation animation;
  animation.name = a.affect.empty() ? pattern.name : a.affect;
  animation.weights.resize(static_cast<Eigen::Index>(m.targets.size()), frames);
  for (long long f = 0; f < frames; ++f) {
    const double t = static_cast<double>(f) / a.outputRate;  // [s]
    animation.time.push_back(t);
    animation.weights.col(f) = player.weightsAt(m, t);
    if (!m.bones.empty()) animation.bodies.push_back(sim::blendBones(m, animation.weights.col(f)));
  }
  const double cpu = static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC;  // [s]
  writeGltfOrFail("--gltf", a.gltf, *model, resolveModelDir(a.model), m, {animation});
  std::printf("%s: %.0f s at %.0f frames/s played on the morph targets in %.1f ms of CPU; wrote %s\n",
              animation.name.c_str(), a.duration, a.outputRate, cpu * 1e3, a.gltf.c_str());
}

}  // namespace

void addBakeCommand(CLI::App& app) {
  auto args = std::make_shared<BakeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "bake",
      "Bake breathing morph targets (base, breathing, chest, belly; shoulders with a shoulder girdle) from "
      "physics runs; write a .glb");
  addModelOption(*cmd, args->model);
  cmd->add_option("--out", args->out, "Output .glb file (replaced when it exists)")->required();
  cmd->callback([args] { runBake(*args); });
}

void addPlayCommand(CLI::App& app) {
  auto args = std::make_shared<PlayArgs>();
  CLI::App* cmd = app.add_subcommand(
      "play", "Play an affect or pattern on the morph targets without physics (de Melo 2010); write a .glb");
  addModelOption(*cmd, args->model);
  auto* affect =
      cmd->add_option("--affect", args->affect, "Affect preset (neutral, panic, ... docs/patterns.md)");
  auto* pattern = cmd->add_option("--pattern", args->pattern, "Pattern file (JSON, docs/patterns.md)");
  affect->excludes(pattern);
  cmd->add_option("--gltf", args->gltf, "Output .glb file (replaced when it exists)")->required();
  cmd->add_option("--morphs", args->morphs, "Morph targets baked by pneuma-cli bake (default: bake now)");
  cmd->add_option("--duration", args->duration, "Seconds to play (default 60)");
  cmd->add_option("--output-rate", args->outputRate, "Animation frames per second [Hz] (default 30)");
  addSeedOption(*cmd, args->seed);
  cmd->callback([args] { runPlay(*args); });
}

}  // namespace pneuma::app
