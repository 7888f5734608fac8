// What the user sees in the main window, asserted on grabs under Xvfb.

#include "gui/MainWindow.h"

#include <QApplication>
#include <QImage>
#include <QSurfaceFormat>
#include <QVTKOpenGLNativeWidget.h>
#include <gtest/gtest.h>

#include <set>

namespace {

// one QApplication per test process, created on first use (test discovery never creates it)
QApplication& app() {
  static int argc = 1;
  static char name[] = "pneuma_gui_tests";
  static char* argv[] = {name, nullptr};
  static QApplication* instance = [] {
    QSurfaceFormat::setDefaultFormat(QVTKOpenGLNativeWidget::defaultFormat());
    return new QApplication(argc, argv);
  }();
  return *instance;
}

int distinctColours(const QImage& image) {
  std::set<QRgb> colours;
  for (int y = 0; y < image.height(); y += 2)
    for (int x = 0; x < image.width(); x += 2) colours.insert(image.pixel(x, y));
  return static_cast<int>(colours.size());
}

}  // namespace

TEST(MainWindow, ViewRendersBackdropAndAxes) {
  app();
  pneuma::app::MainWindow window;
  window.show();
  QApplication::processEvents();

  // the gradient backdrop alone gives dozens of shades; a blank or failed GL view gives one or two
  const QImage view = window.grabView();
  ASSERT_FALSE(view.isNull());
  EXPECT_GT(view.width(), 200);
  EXPECT_GT(distinctColours(view), 20);

  // the whole-window grab includes the view, not a black hole where GL should be
  const QImage whole = window.grabWindow();
  EXPECT_GT(distinctColours(whole), 20);
}
