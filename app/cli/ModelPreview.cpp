#include "ModelPreview.h"

#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkWindowToImageFilter.h>

#include <cstdlib>
#include <filesystem>
#include <stdexcept>

#include "pneuma/sim/Error.h"
#include "pneuma/sim/ModelIO.h"
#include "viz/AtomicFile.h"
#include "viz/ModelScene.h"

namespace pneuma::app {

namespace {

namespace fs = std::filesystem;

/// Renders the window and writes it as a PNG through a temporary file and a rename.
void writePng(vtkRenderWindow* window, const fs::path& file) {
  window->Render();
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->ReadFrontBufferOff();
  grab->Update();
  const std::string tmp = viz::temporaryPathFor(file.string());
  vtkNew<vtkPNGWriter> writer;
  writer->SetFileName(tmp.c_str());
  writer->SetInputConnection(grab->GetOutputPort());
  writer->Write();
  try {
    viz::commitTemporary(tmp, file.string());
  } catch (const std::runtime_error& e) {
    throw sim::Error(file.string() + ": cannot write preview: " + e.what());
  }
}

}  // namespace

bool renderModelPreviews(const std::string& dir, std::string& why) {
  const char* display = std::getenv("DISPLAY");
  if (display == nullptr || *display == '\0') {
    why = "no X display (DISPLAY is not set); run under xvfb-run to render previews";
    return false;
  }
  const sim::Model model = sim::loadModel(dir);

  // the viewer's scene at rest: bones, elements coloured by group, the translucent gut
  viz::ModelScene scene;
  viz::DisplayOptions options;
  options.muscleColouring = viz::MuscleColouring::Group;
  options.gutColouring = viz::GutColouring::Plain;
  options.showLandmarks = false;
  scene.setOptions(options);
  scene.setModel(model, dir);

  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetSize(720, 960);
  window->AddRenderer(scene.renderer());

  // anterior and right lateral views
  scene.setCamera(viz::CameraPreset::Anterior);
  writePng(window, fs::path(dir) / "preview_front.png");
  scene.setCamera(viz::CameraPreset::Lateral);
  writePng(window, fs::path(dir) / "preview_side.png");
  return true;
}

}  // namespace pneuma::app
