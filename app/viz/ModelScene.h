#pragma once
/// @file ModelScene.h
/// The 3D scene of a Pneuma model: a VTK renderer with a ParaView-like backdrop and an RAS
/// orientation marker, into which the model's bodies, muscle elements, gut, cavity and landmarks are drawn.

#include <vtkSmartPointer.h>

class vtkRenderer;
class vtkRenderWindowInteractor;
class vtkOrientationMarkerWidget;

namespace pneuma::viz {

/// Owns the renderer of one 3D view. Qt-free: the GUI puts the renderer into a QVTKOpenGLNativeWidget,
/// the CLI into an off-screen render window.
class ModelScene {
 public:
  ModelScene();
  ~ModelScene();
  ModelScene(const ModelScene&) = delete;
  ModelScene& operator=(const ModelScene&) = delete;

  /// The renderer to add to a render window.
  vtkRenderer* renderer() const;

  /// Shows the RAS axes (x right, y anterior, z superior) in the lower-left corner of the view
  /// driven by `interactor` (the marker is a widget, so it needs the window's interactor).
  void installOrientationMarker(vtkRenderWindowInteractor* interactor);

 private:
  vtkSmartPointer<vtkRenderer> m_renderer;
  vtkSmartPointer<vtkOrientationMarkerWidget> m_marker;
};

}  // namespace pneuma::viz
