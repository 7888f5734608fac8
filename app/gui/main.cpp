// pneuma: the desktop app. `pneuma --screenshot FILE [--after SECONDS] [--style NAME] [--model DIR]`
// starts, simulates for the given time, saves a grab of the whole window and exits.

#include "gui/MainWindow.h"

#include <QApplication>
#include <QCommandLineParser>
#include <QImage>
#include <QSurfaceFormat>
#include <QVTKOpenGLNativeWidget.h>

#include <cstdio>

int main(int argc, char** argv) {
  QSurfaceFormat::setDefaultFormat(QVTKOpenGLNativeWidget::defaultFormat());
  QApplication app(argc, argv);
  QApplication::setApplicationName("Pneuma");
  QApplication::setApplicationVersion(PNEUMA_VERSION);

  QCommandLineParser parser;
  parser.setApplicationDescription("Pneuma: a simulated human torso breathing (Zordan et al. 2004).");
  parser.addHelpOption();
  parser.addVersionOption();
  const QCommandLineOption model("model", "Model directory (default: $PNEUMA_MODEL_DIR or <bindir>/../models/default).",
                                 "DIR");
  const QCommandLineOption style("style", "Breath style: calm, deep, panting or forced-exhale.", "NAME");
  const QCommandLineOption screenshot("screenshot", "Save a grab of the whole window to FILE (PNG) and exit.", "FILE");
  const QCommandLineOption after("after", "With --screenshot: simulated seconds before the grab (default 6).",
                                 "SECONDS", "6");
  parser.addOptions({model, style, screenshot, after});
  if (!parser.parse(QApplication::arguments())) {
    std::fprintf(stderr, "pneuma: %s\n%s", qPrintable(parser.errorText()), qPrintable(parser.helpText()));
    return 2;
  }
  if (parser.isSet("help")) parser.showHelp(0);
  if (parser.isSet("version")) parser.showVersion();
  if (!parser.positionalArguments().isEmpty()) {
    std::fprintf(stderr, "pneuma: unexpected argument '%s'\n%s", qPrintable(parser.positionalArguments().first()),
                 qPrintable(parser.helpText()));
    return 2;
  }
  bool isNumber = false;
  const double afterSeconds = parser.value(after).toDouble(&isNumber);
  if (!isNumber || !(afterSeconds >= 0.0)) {
    std::fprintf(stderr, "pneuma: --after: expected seconds >= 0, got '%s'\n", qPrintable(parser.value(after)));
    return 2;
  }

  pneuma::app::MainWindow window;
  window.show();
  QApplication::processEvents();
  const bool isScripted = parser.isSet(screenshot);
  if (parser.isSet(style) && !window.setBreathStyle(parser.value(style)).isEmpty() && isScripted) return 2;
  const QString modelDir = parser.isSet(model) ? parser.value(model) : pneuma::app::MainWindow::defaultModelDir();
  const bool hasModel = window.openModel(modelDir).isEmpty();

  if (isScripted) {
    // simulate, show that instant, grab what the user would see
    if (!hasModel) return 1;
    if (!window.runUntil(afterSeconds)) {
      std::fprintf(stderr, "pneuma: simulation did not reach t = %g s: %s\n", afterSeconds,
                   qPrintable(window.lastError()));
      return 1;
    }
    QApplication::processEvents();
    const QString file = parser.value(screenshot);
    if (!window.grabWindow().save(file, "PNG")) {
      std::fprintf(stderr, "pneuma: cannot write screenshot '%s'\n", qPrintable(file));
      return 1;
    }
    return 0;
  }
  if (hasModel) window.play();
  return QApplication::exec();
}
