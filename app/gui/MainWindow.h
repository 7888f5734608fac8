#pragma once
/// @file MainWindow.h
/// Pneuma's main window: the 3D view in the centre, the status bar below.

#include <QMainWindow>

#include <memory>

class QLabel;
class QVTKOpenGLNativeWidget;

namespace pneuma::viz {
class ModelScene;
}

namespace pneuma::app {

class MainWindow : public QMainWindow {
  Q_OBJECT

 public:
  explicit MainWindow(QWidget* parent = nullptr);
  ~MainWindow() override;

  /// Renders the 3D view now and returns a grab of the whole window (what the user sees).
  QImage grabWindow();
  /// Renders the 3D view now and returns a grab of the 3D view only.
  QImage grabView();

 private:
  std::unique_ptr<viz::ModelScene> m_scene;
  QVTKOpenGLNativeWidget* m_view = nullptr;
  QLabel* m_statusText = nullptr;
};

}  // namespace pneuma::app
