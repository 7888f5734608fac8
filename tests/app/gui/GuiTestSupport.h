#pragma once
// Shared set-up of the gui tests: one QApplication per process, the toy torso written as a model
// directory, and pixel counting on grabs.

#include <QVTKOpenGLNativeWidget.h>

#include <QApplication>
#include <QColor>
#include <QFile>
#include <QImage>
#include <QSurfaceFormat>
#include <QTemporaryDir>
#include <set>

#include "../../sim/ToyTorso.h"
#include "pneuma/sim/ModelIO.h"

namespace pneuma::app::test {

// one QApplication per test process, created on first use (test discovery never creates it)
inline QApplication& application() {
  static int argc = 1;
  static char name[] = "pneuma_gui_tests";
  static char* argv[] = {name, nullptr};
  static QApplication* instance = [] {
    QSurfaceFormat::setDefaultFormat(QVTKOpenGLNativeWidget::defaultFormat());
    return new QApplication(argc, argv);
  }();
  return *instance;
}

// the toy torso of the sim tests as a model directory inside `dir`
inline QString writeToyModel(const QTemporaryDir& dir) {
  const QString path = dir.filePath("toy");
  QDir().mkpath(path);
  sim::saveModel(sim::test::makeToyTorso(2), path.toStdString());
  return path;
}

inline int distinctColours(const QImage& image) {
  std::set<QRgb> colours;
  for (int y = 0; y < image.height(); y += 2)
    for (int x = 0; x < image.width(); x += 2) colours.insert(image.pixel(x, y));
  return static_cast<int>(colours.size());
}

// pixels in the hue range of the contractive-force colour map (pale orange to deep red), saturated;
// grey (slack), ivory (bones), blue (gut, background) and green (landmarks) do not count
inline bool isForceColoured(QRgb rgb) {
  const QColor c = QColor::fromRgb(rgb).toHsv();
  const int hue = c.hue();
  return c.saturationF() > 0.45 && c.valueF() > 0.3 && hue >= 0 && (hue <= 45 || hue >= 340);
}

// force-coloured pixels of a 3D-view grab, left of the colour legends (the right 14 % of the view)
inline int forceColouredPixels(const QImage& image) {
  int n = 0;
  const int right = static_cast<int>(0.86 * image.width());
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < right; ++x) n += isForceColoured(image.pixel(x, y)) ? 1 : 0;
  return n;
}

// the default model built with the project, when it exists
inline QString defaultModelDir() {
  const QString dir = PNEUMA_DEFAULT_MODEL_DIR;
  return QFile::exists(dir + "/model.json") ? dir : QString();
}

}  // namespace pneuma::app::test
