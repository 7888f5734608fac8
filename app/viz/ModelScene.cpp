#include "viz/ModelScene.h"

#include <vtkAxesActor.h>
#include <vtkCaptionActor2D.h>
#include <vtkOrientationMarkerWidget.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkTextProperty.h>

namespace pneuma::viz {

ModelScene::ModelScene() : m_renderer(vtkSmartPointer<vtkRenderer>::New()) {
  // paraview-like blue-grey gradient
  m_renderer->GradientBackgroundOn();
  m_renderer->SetBackground(0.11, 0.12, 0.16);
  m_renderer->SetBackground2(0.36, 0.39, 0.47);
}

ModelScene::~ModelScene() = default;

vtkRenderer* ModelScene::renderer() const { return m_renderer; }

void ModelScene::installOrientationMarker(vtkRenderWindowInteractor* interactor) {
  // axes labelled with the anatomical directions of the RAS world frame
  vtkNew<vtkAxesActor> axes;
  axes->SetXAxisLabelText("R");
  axes->SetYAxisLabelText("A");
  axes->SetZAxisLabelText("S");
  for (vtkCaptionActor2D* caption : {axes->GetXAxisCaptionActor2D(), axes->GetYAxisCaptionActor2D(),
                                     axes->GetZAxisCaptionActor2D()}) {
    caption->GetCaptionTextProperty()->SetFontSize(14);
    caption->GetCaptionTextProperty()->ShadowOff();
    caption->GetCaptionTextProperty()->ItalicOff();
  }
  m_marker = vtkSmartPointer<vtkOrientationMarkerWidget>::New();
  m_marker->SetOrientationMarker(axes);
  m_marker->SetInteractor(interactor);
  m_marker->SetDefaultRenderer(m_renderer);
  m_marker->SetViewport(0.0, 0.0, 0.16, 0.22);
  m_marker->SetEnabled(1);
  m_marker->InteractiveOff();
}

}  // namespace pneuma::viz
