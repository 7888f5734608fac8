/// @file Morphs.cpp
#include "Morphs.h"

#include <cstdio>

#include "CliSupport.h"
#include "Progress.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/Resources.h"
#include "viz/AtomicFile.h"
#include "viz/GltfWriter.h"

namespace pneuma::app {

void checkHasSkin(const char* flag, const sim::Model& model) {
  if (model.skin.vertexCount() == 0)
    fail(kExitBadInput, std::string(flag) + ": model '" + model.name +
                            "' has no skin (rebuild it with pneuma-cli model build)");
}

sim::MorphTargets morphTargetsFor(const std::shared_ptr<const sim::Model>& model,
                                  const std::string& morphsFile) {
  if (!morphsFile.empty()) {
    try {
      sim::MorphTargets m = viz::readGltfMorphTargets(morphsFile);
      if (m.vertexCount() != model->skin.vertexCount())
        fail(kExitBadInput, "--morphs: " + morphsFile + " has " + std::to_string(m.vertexCount()) +
                                " skin vertices, model '" + model->name + "' " +
                                std::to_string(model->skin.vertexCount()));
      if (!m.bones.empty() && m.bones != model->bodies.name)
        fail(kExitBadInput, "--morphs: " + morphsFile + " has the bones of another model than '" +
                                model->name + "' (bake it again)");
      return m;
    } catch (const sim::Error& e) {
      fail(kExitBadInput, std::string("--morphs: ") + e.what());
    }
  }
  // bake: one progress line per run
  std::string stage;
  std::unique_ptr<ProgressBar> bar;
  try {
    sim::MorphTargets m = sim::bakeMorphTargets(
        model, sim::resourceDir(),
        [&](const std::string& s, double fraction) {
          if (s != stage) {
            if (bar) bar->finish();
            stage = s;
            std::fprintf(stderr, "baking morph targets: %s run\n", s.c_str());
            bar = std::make_unique<ProgressBar>("bake " + s, 1.0);
          }
          bar->update(fraction);
        },
        InterruptGuard::flag());
    if (bar) bar->finish();
    return m;
  } catch (const sim::Interrupted& e) {
    if (bar) bar->finish();
    fail(kExitInterrupted, e.what());
  } catch (const sim::Error& e) {
    if (bar) bar->finish();
    fail(kExitFailed, std::string("bake: ") + e.what());
  }
}

void checkGltfOutput(const char* flag, const std::string& path) {
  try {
    viz::AtomicFileWriter probe(path);  // removed again when it goes out of scope uncommitted
  } catch (const std::exception& e) {
    fail(kExitBadInput, std::string(flag) + ": " + e.what());
  }
}

}  // namespace pneuma::app
