#pragma once
/// @file OffscreenView.h
/// A scene rendered at a chosen size, independent of the window that shows it: for movies of 1280 x 720 or
/// 1920 x 1080 pixels from a 3D view of another shape. While it exists, the renderer is moved from its render
/// window into an off-screen one of the given size (the window on screen draws nothing meanwhile); destroyed,
/// it moves the renderer back. Actors, cameras and 2D captions are the renderer's own, so the frames show
/// what the view shows, laid out for the new size (the camera keeps its view angle: a wider frame shows
/// more at the sides).

#include <vtkNew.h>
#include <vtkSmartPointer.h>

#include <vector>

class vtkRenderWindow;
class vtkRenderer;

namespace pneuma::viz {

class OffscreenView {
 public:
  /// @param renderer the scene's renderer (ModelScene::renderer());  @param width, height the frame [px].
  OffscreenView(vtkRenderer* renderer, int width, int height);
  ~OffscreenView();
  OffscreenView(const OffscreenView&) = delete;
  OffscreenView& operator=(const OffscreenView&) = delete;

  /// Renders the scene and returns its pixels: 3 bytes (RGB) per pixel, rows from the top, width x height.
  std::vector<unsigned char> render();
  int width() const { return m_width; }
  int height() const { return m_height; }

 private:
  vtkRenderer* m_renderer;
  vtkSmartPointer<vtkRenderWindow> m_home;  // the window the renderer came from (may be null)
  vtkSmartPointer<vtkRenderWindow> m_window;
  int m_width, m_height;
};

}  // namespace pneuma::viz
