// What one frame of the app's 3D view costs (Google Benchmark, `pneuma-scene-bench`; run it under
// `xvfb-run -a -s "-screen 0 1280x800x24"`, the software OpenGL the frame-rate target is stated for, issue
// 18): the default model's scene (viz::ModelScene, default display options: translucent skin and lungs, gut,
// bones, force-coloured muscles, landmarks, motion x5) posed and rendered in an off-screen window of the
// 3D view's size in the 1280 x 800 window (575 x 683 px), then finished (glFinish). The time column is the
// wall time of one frame, the CPU column the process's CPU time (every thread: the renderer's own and Mesa
// llvmpipe's rasterizer threads), the one less sensitive to a shared machine's load. The variants each drop
// one structure from the default view, so the difference names what that structure costs.
#include <benchmark/benchmark.h>
#include <vtkNew.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>

#include <string>
#include <vector>

#include "DefaultModel.h"
#include "pneuma/sim/Metrics.h"
#include "pneuma/sim/State.h"
#include "viz/ModelScene.h"

namespace pneuma::viz {
namespace {

constexpr int kViewWidth = 575, kViewHeight = 683;  // [px] the 3D view in a 1280 x 800 window

void sceneFrame(benchmark::State& state, const DisplayOptions& options) {
  const auto model = sim::test::defaultModel();
  if (!model) {
    state.SkipWithError("default model missing: build it with 'pneuma-cli model build'");
    return;
  }
  ModelScene scene;
  scene.setModel(*model, PNEUMA_DEFAULT_MODEL_DIR);
  scene.setOptions(options);
  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetMultiSamples(0);
  window->SetSize(kViewWidth, kViewHeight);
  window->AddRenderer(scene.renderer());

  // the rest pose as the end-expiration and a pose a few millimetres off it, alternated so that every frame
  // uploads new points, as the live view does
  const sim::State rest = sim::makeInitialState(*model);
  sim::State moved = rest;
  moved.bodyPosition.array() += 0.002;  // [m]
  moved.nodePosition.array() += 0.002;  // [m]
  sim::Metrics metrics;
  metrics.elementForce = Eigen::VectorXd::LinSpaced(model->elements.size(), -4.0, 0.0);  // [N] tension
  metrics.isSlack.assign(static_cast<std::size_t>(model->elements.size()), 0);
  metrics.gutPressure = 200.0;  // [Pa]
  scene.update(rest, metrics, &rest);
  window->Render();  // compiles the shaders
  window->WaitForCompletion();
  bool odd = false;
  for (auto _ : state) {
    scene.update(odd ? moved : rest, metrics, &rest);
    window->Render();
    window->WaitForCompletion();
    odd = !odd;
  }
  window->RemoveRenderer(scene.renderer());
}

const bool kRegistered = [] {
  const DisplayOptions defaults;
  std::vector<std::pair<std::string, DisplayOptions>> variants{{"default", defaults}};
  const auto variant = [&](const std::string& name, auto change) {
    DisplayOptions o = defaults;
    change(o);
    variants.emplace_back(name, o);
  };
  variant("skin_opaque", [](DisplayOptions& o) { o.skin = SkinDisplay::Opaque; });
  variant("no_skin", [](DisplayOptions& o) { o.skin = SkinDisplay::Hidden; });
  variant("no_lungs", [](DisplayOptions& o) { o.showLungs = false; });
  variant("no_gut", [](DisplayOptions& o) { o.showGut = false; });
  variant("no_bones", [](DisplayOptions& o) { o.showBones = false; });
  variant("no_muscles", [](DisplayOptions& o) { o.showGroup.fill(false); });
  variant("no_landmarks", [](DisplayOptions& o) { o.showLandmarks = false; });
  for (const auto& [name, options] : variants)
    benchmark::RegisterBenchmark(("SceneFrame/" + name).c_str(),
                                 [o = options](benchmark::State& st) { sceneFrame(st, o); })
        ->Unit(benchmark::kMillisecond)
        ->MeasureProcessCPUTime()
        ->UseRealTime();
  return true;
}();

}  // namespace
}  // namespace pneuma::viz

BENCHMARK_MAIN();
