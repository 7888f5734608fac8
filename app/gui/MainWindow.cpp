#include "gui/MainWindow.h"

#include "viz/ModelScene.h"

#include <QLabel>
#include <QStatusBar>
#include <QVTKOpenGLNativeWidget.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkRenderer.h>

namespace pneuma::app {

MainWindow::MainWindow(QWidget* parent) : QMainWindow(parent), m_scene(std::make_unique<viz::ModelScene>()) {
  setWindowTitle("Pneuma");
  resize(1280, 800);

  // 3D view
  m_view = new QVTKOpenGLNativeWidget(this);
  vtkNew<vtkGenericOpenGLRenderWindow> window;
  m_view->setRenderWindow(window);
  window->AddRenderer(m_scene->renderer());
  m_scene->installOrientationMarker(m_view->interactor());
  setCentralWidget(m_view);

  // status bar
  m_statusText = new QLabel("Ready", this);
  statusBar()->addWidget(m_statusText, 1);
}

MainWindow::~MainWindow() = default;

QImage MainWindow::grabView() {
  m_view->renderWindow()->Render();
  return m_view->grabFramebuffer();
}

QImage MainWindow::grabWindow() {
  m_view->renderWindow()->Render();
  return grab().toImage();
}

}  // namespace pneuma::app
