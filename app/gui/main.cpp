// pneuma: the desktop app. `pneuma --screenshot FILE [--after SECONDS] [--style NAME] [--model DIR]`
// starts, simulates for the given time, saves a grab of the whole window and exits.

#include "gui/MainWindow.h"

#include <QApplication>
#include <QCommandLineParser>
#include <QImage>
#include <QSurfaceFormat>
#include <QTimer>
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
  const QCommandLineOption screenshot("screenshot", "Save a grab of the whole window to FILE (PNG) and exit.", "FILE");
  parser.addOption(screenshot);
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

  pneuma::app::MainWindow window;
  window.show();

  if (parser.isSet(screenshot)) {
    // grab once the window is mapped and painted
    const QString file = parser.value(screenshot);
    int status = 0;
    QTimer::singleShot(0, [&] {
      QApplication::processEvents();
      if (!window.grabWindow().save(file, "PNG")) {
        std::fprintf(stderr, "pneuma: cannot write screenshot '%s'\n", qPrintable(file));
        status = 1;
      }
      QApplication::exit(status);
    });
  }
  return QApplication::exec();
}
