#include "ModelPreview.h"

#include "pneuma/meshing/ModelSummary.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/ModelIO.h"

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkTransform.h>
#include <vtkUnsignedCharArray.h>
#include <vtkWindowToImageFilter.h>
#include <vtkXMLPolyDataReader.h>

#include <array>
#include <cstdlib>
#include <filesystem>

namespace pneuma::app {

namespace {

namespace fs = std::filesystem;

// group colours, in sim::ElementGroup order
constexpr std::array<std::array<unsigned char, 3>, sim::kElementGroupCount> kGroupColour = {{
    {200, 60, 50},    // intercostal_external
    {230, 150, 40},   // intercostal_internal
    {170, 20, 60},    // diaphragm
    {220, 90, 140},   // rectus
    {190, 110, 90},   // transversus_obliques
    {120, 200, 230},  // cartilage
}};

vtkSmartPointer<vtkActor> boneActor(const sim::Model& m, int b, const fs::path& dir) {
  const fs::path file = dir / m.bodies.mesh[static_cast<std::size_t>(b)];
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName(file.string().c_str());
  reader->Update();
  if (reader->GetOutput()->GetNumberOfPoints() == 0) {
    throw sim::Error(m.bodies.name[static_cast<std::size_t>(b)] + ": cannot read render mesh " + file.string());
  }
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(reader->GetOutputPort());
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  vtkNew<vtkTransform> t;
  t->Translate(m.bodies.com(0, b), m.bodies.com(1, b), m.bodies.com(2, b));
  actor->SetUserTransform(t);
  actor->GetProperty()->SetColor(0.93, 0.89, 0.80);
  actor->GetProperty()->SetSpecular(0.2);
  return actor;
}

vtkSmartPointer<vtkActor> elementActor(const sim::Model& m) {
  const Eigen::Matrix3Xd a = meshing::restPoints(m.elements.endA, m);
  const Eigen::Matrix3Xd b = meshing::restPoints(m.elements.endB, m);
  vtkNew<vtkPoints> pts;
  vtkNew<vtkCellArray> lines;
  vtkNew<vtkUnsignedCharArray> colours;
  colours->SetNumberOfComponents(3);
  for (int e = 0; e < m.elements.size(); ++e) {
    const vtkIdType i0 = pts->InsertNextPoint(a(0, e), a(1, e), a(2, e));
    const vtkIdType i1 = pts->InsertNextPoint(b(0, e), b(1, e), b(2, e));
    const vtkIdType ids[2] = {i0, i1};
    lines->InsertNextCell(2, ids);
    const auto& c = kGroupColour[static_cast<std::size_t>(m.elements.group[static_cast<std::size_t>(e)])];
    colours->InsertNextTuple3(c[0], c[1], c[2]);
  }
  vtkNew<vtkPolyData> poly;
  poly->SetPoints(pts);
  poly->SetLines(lines);
  poly->GetCellData()->SetScalars(colours);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(poly);
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  actor->GetProperty()->SetLineWidth(2.0);
  actor->GetProperty()->SetLighting(false);
  return actor;
}

vtkSmartPointer<vtkActor> gutActor(const sim::Model& m) {
  vtkNew<vtkPoints> pts;
  vtkNew<vtkUnsignedCharArray> colours;
  colours->SetNumberOfComponents(3);
  for (int i = 0; i < m.nodes.size(); ++i) {
    pts->InsertNextPoint(m.nodes.rest(0, i), m.nodes.rest(1, i), m.nodes.rest(2, i));
    switch (m.nodes.region[static_cast<std::size_t>(i)]) {
      case sim::NodeRegion::Diaphragm: colours->InsertNextTuple3(190, 40, 50); break;
      case sim::NodeRegion::Wall: colours->InsertNextTuple3(235, 170, 150); break;
      case sim::NodeRegion::Fixed: colours->InsertNextTuple3(150, 150, 160); break;
    }
  }
  vtkNew<vtkCellArray> tris;
  for (int f = 0; f < m.gut.triangles.cols(); ++f) {
    const vtkIdType ids[3] = {m.gut.triangles(0, f), m.gut.triangles(1, f), m.gut.triangles(2, f)};
    tris->InsertNextCell(3, ids);
  }
  vtkNew<vtkPolyData> poly;
  poly->SetPoints(pts);
  poly->SetPolys(tris);
  poly->GetPointData()->SetScalars(colours);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(poly);
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  actor->GetProperty()->SetOpacity(0.35);
  return actor;
}

void writePng(vtkRenderWindow* window, const fs::path& file) {
  window->Render();
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->ReadFrontBufferOff();
  grab->Update();
  const fs::path tmp = file.string() + ".tmp.png";
  vtkNew<vtkPNGWriter> writer;
  writer->SetFileName(tmp.string().c_str());
  writer->SetInputConnection(grab->GetOutputPort());
  writer->Write();
  std::error_code ec;
  fs::rename(tmp, file, ec);
  if (ec) throw sim::Error(file.string() + ": cannot write preview: " + ec.message());
}

}  // namespace

bool renderModelPreviews(const std::string& dir, std::string& why) {
  const char* display = std::getenv("DISPLAY");
  if (display == nullptr || *display == '\0') {
    why = "no X display (DISPLAY is not set); run under xvfb-run to render previews";
    return false;
  }
  const sim::Model m = sim::loadModel(dir);

  // scene: bones, elements, translucent gut
  vtkNew<vtkRenderer> renderer;
  renderer->SetBackground(1.0, 1.0, 1.0);
  for (int b = 0; b < m.bodies.size(); ++b) renderer->AddActor(boneActor(m, b, dir));
  renderer->AddActor(elementActor(m));
  renderer->AddActor(gutActor(m));

  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetSize(720, 960);
  window->AddRenderer(renderer);

  // anterior and right lateral views of the whole torso
  double bounds[6];
  renderer->ComputeVisiblePropBounds(bounds);
  const double c[3] = {0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3]), 0.5 * (bounds[4] + bounds[5])};
  vtkCamera* cam = renderer->GetActiveCamera();
  cam->SetFocalPoint(c);
  cam->SetViewUp(0, 0, 1);
  cam->SetPosition(c[0], c[1] + 3.0, c[2]);
  renderer->ResetCamera();
  writePng(window, fs::path(dir) / "preview_front.png");
  cam->SetPosition(c[0] + 3.0, c[1], c[2]);
  cam->SetViewUp(0, 0, 1);
  renderer->ResetCamera();
  writePng(window, fs::path(dir) / "preview_side.png");
  return true;
}

}  // namespace pneuma::app
