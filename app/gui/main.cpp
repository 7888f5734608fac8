// pneuma: the desktop app. `pneuma --screenshot FILE [--after SECONDS] [--style NAME] [--trace CSV]
// [--magnify N]
// [--model DIR]` starts, simulates for the given time, saves a grab of the whole window and exits.
// `pneuma --movie FILE [--from S] [--to S] [--size WxH] [--overlay time,volume]` simulates until --to and
// writes the recording from --from to --to as a movie (File > Export > Animation), then exits.

#include <QVTKOpenGLNativeWidget.h>

#include <QApplication>
#include <QCommandLineParser>
#include <QImage>
#include <QSurfaceFormat>
#include <QTimer>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "gui/ExportController.h"
#include "gui/LivePlots.h"
#include "gui/MainWindow.h"

int main(int argc, char** argv) {
  // our --style names a breath style: parse the full command line ourselves and keep Qt from
  // taking it as its widget style (QApplication would consume it and warn)
  QStringList arguments;
  std::vector<char*> qtArgv;
  for (int i = 0; i < argc; ++i) {
    const std::string arg = argv[i];
    arguments << QString::fromLocal8Bit(argv[i]);
    if ((arg == "--style" || arg == "-style") && i + 1 < argc) {
      arguments << QString::fromLocal8Bit(argv[++i]);
      continue;
    }
    if (arg.rfind("--style=", 0) == 0 || arg.rfind("-style=", 0) == 0) continue;
    qtArgv.push_back(argv[i]);
  }
  int qtArgc = static_cast<int>(qtArgv.size());
  qtArgv.push_back(nullptr);

  // --help and --version need no display (help2man writes the man page from them at build time)
  const bool isInfoOnly = std::any_of(qtArgv.begin(), qtArgv.end() - 1, [](const char* a) {
    const std::string arg = a;
    return arg == "--help" || arg == "-h" || arg == "-?" || arg == "--help-all" || arg == "--version" ||
           arg == "-v";
  });

  // without a display Qt would abort with a plugin message: say what to do instead
  const bool hasPlatformArg = std::any_of(qtArgv.begin(), qtArgv.end() - 1, [](const char* a) {
    return std::string(a) == "-platform" || std::string(a) == "--platform";
  });
  const auto isSet = [](const char* name) { return std::getenv(name) && *std::getenv(name); };
  if (!isInfoOnly && !isSet("DISPLAY") && !isSet("WAYLAND_DISPLAY") && !isSet("QT_QPA_PLATFORM") &&
      !hasPlatformArg) {
    std::fprintf(stderr,
                 "pneuma: no display (DISPLAY is not set): run it in a desktop session or under "
                 "'xvfb-run -a -s \"-screen 0 1280x800x24\" pneuma ...'; for headless runs use pneuma-cli\n");
    return 2;
  }

  QSurfaceFormat::setDefaultFormat(QVTKOpenGLNativeWidget::defaultFormat());
  const std::unique_ptr<QCoreApplication> app =
      isInfoOnly ? std::make_unique<QCoreApplication>(qtArgc, qtArgv.data())
                 : std::make_unique<QApplication>(qtArgc, qtArgv.data());
  QApplication::setApplicationName("Pneuma");
  QApplication::setApplicationVersion(PNEUMA_VERSION);

  QCommandLineParser parser;
  parser.setApplicationDescription("Pneuma: a simulated human torso breathing (Zordan et al. 2004).");
  parser.addHelpOption();
  parser.addVersionOption();
  const QCommandLineOption model(
      "model", "Model directory (default: $PNEUMA_MODEL_DIR or <bindir>/../share/pneuma/models/default).",
      "DIR");
  const QCommandLineOption style("style", "Breath style: calm, deep, panting or forced-exhale.", "NAME");
  const QCommandLineOption affect(
      "affect", "Start with an affective state (neutral, panic, relief, ...; de Melo et al. 2010).", "NAME");
  const QCommandLineOption volumeTrace(
      "trace", "Follow a measured lung-volume trace (CSV: time [s], volume [L] or [mL]; docs/patterns.md).",
      "FILE");
  const QCommandLineOption posture(
      "posture",
      QString::fromStdString("Gravity relative to the body: " + pneuma::sim::postureNames() + " (default " +
                             pneuma::sim::postureName(pneuma::sim::StepOptions{}.posture) + ")."),
      "NAME");
  const QCommandLineOption screenshot("screenshot", "Save a grab of the whole window to FILE (PNG) and exit.",
                                      "FILE");
  const QCommandLineOption after("after", "With --screenshot: simulated seconds before the grab (default 6).",
                                 "SECONDS", "6");
  const QCommandLineOption exportGltf(
      "export-gltf", "With --screenshot: export the recording as a glTF 2.0 .glb to FILE before the grab.",
      "FILE");
  const QCommandLineOption camera(
      "camera", "Camera preset: anterior, lateral, superior, posterior or oblique (default).", "NAME",
      "oblique");
  const QCommandLineOption labels("labels",
                                  "Show the anatomical labels and the lung cavity (teaching view).");
  const QCommandLineOption skin("skin", "The skin: translucent (default), opaque or hidden.", "MODE",
                                "translucent");
  const QCommandLineOption magnify(
      "magnify",
      QString("Motion magnification of the view, display only (%1 to %2, default %3).")
          .arg(pneuma::viz::kMinMagnification)
          .arg(pneuma::viz::kMaxMagnification)
          .arg(pneuma::viz::kDefaultMagnification),
      "N", QString::number(pneuma::viz::kDefaultMagnification));
  const QCommandLineOption physiology(
      "physiology", "Show the Physiology plots (flow, flow-volume loop, pressures) in front.");
  const QCommandLineOption speed("speed", "Simulated seconds per wall second, or 'max' (default 1).", "X",
                                 "1");
  const QCommandLineOption measure(
      "measure", "Run for SECONDS of wall time, print render fps and real-time factor, exit.", "SECONDS");
  const QCommandLineOption morphPlayback(
      "morph-playback",
      "Show the morph playback of the --affect (default neutral) instead of the physics: the skin on its "
      "baked morph targets, no physics (de Melo et al. 2010). With --screenshot, --after is the pattern "
      "time.");
  const QCommandLineOption scenario(
      "scenario", "Open a scenario file (e.g. a teaching preset in resources/scenarios/teaching) at start.",
      "FILE");
  const QCommandLineOption compare(
      "compare",
      "Draw a second run dashed over the plots: a scenario (.json) run on the same model, or a recording "
      "(a pneuma-cli simulate folder or its timeseries.csv).",
      "FILE");
  const QCommandLineOption movie(
      "movie",
      "Simulate until --to, write the recording from --from to --to as a movie to FILE (.mp4: H.264 through "
      "ffmpeg; .ogv: Ogg Theora; else a PNG sequence) at 25 frames per second, and exit.",
      "FILE");
  const QCommandLineOption movieFrom(
      "from", "With --movie: first instant [s] (default: the recording's start).", "S");
  const QCommandLineOption movieTo("to", "With --movie: last instant [s] (default 6).", "S", "6");
  const QCommandLineOption movieSize(
      "size", "With --movie: frame size WxH in pixels, e.g. 1280x720 (default: the 3D view as shown).",
      "WxH");
  const QCommandLineOption overlay(
      "overlay",
      "With --movie: overlays drawn on each frame, comma-separated: time (a time stamp), volume (the "
      "volume plot with a cursor).",
      "LIST");
  parser.addOptions({model,    style,      affect, volumeTrace, posture, camera,     labels,  skin,
                     magnify,  physiology, speed,  screenshot,  after,   exportGltf, measure, morphPlayback,
                     scenario, compare,    movie,  movieFrom,   movieTo, movieSize,  overlay});
  if (!parser.parse(arguments)) {
    std::fprintf(stderr, "pneuma: %s\n%s", qPrintable(parser.errorText()), qPrintable(parser.helpText()));
    return 2;
  }
  if (parser.isSet("help")) parser.showHelp(0);
  if (parser.isSet("version")) parser.showVersion();
  if (isInfoOnly) parser.showHelp(2);  // "--help" was an option's value: no widgets without a QApplication
  if (!parser.positionalArguments().isEmpty()) {
    std::fprintf(stderr, "pneuma: unexpected argument '%s'\n%s",
                 qPrintable(parser.positionalArguments().first()), qPrintable(parser.helpText()));
    return 2;
  }
  bool isNumber = false;
  const double afterSeconds = parser.value(after).toDouble(&isNumber);
  if (!isNumber || !(afterSeconds >= 0.0)) {
    std::fprintf(stderr, "pneuma: --after: expected seconds >= 0, got '%s'\n",
                 qPrintable(parser.value(after)));
    return 2;
  }

  const double speedValue = parser.value(speed) == "max" ? 0.0 : parser.value(speed).toDouble(&isNumber);
  if (parser.value(speed) != "max" && (!isNumber || !(speedValue > 0.0))) {
    std::fprintf(stderr, "pneuma: --speed: expected a positive number or 'max', got '%s'\n",
                 qPrintable(parser.value(speed)));
    return 2;
  }
  const double measureSeconds = parser.isSet(measure) ? parser.value(measure).toDouble(&isNumber) : 0.0;
  if (parser.isSet(measure) && (!isNumber || !(measureSeconds > 0.0))) {
    std::fprintf(stderr, "pneuma: --measure: expected seconds > 0, got '%s'\n",
                 qPrintable(parser.value(measure)));
    return 2;
  }

  const double magnification = parser.value(magnify).toDouble(&isNumber);
  const std::string magnifyError =
      isNumber ? pneuma::viz::magnificationError(magnification)
               : "motion magnification: '" + parser.value(magnify).toStdString() + "' is not a number";
  if (!magnifyError.empty()) {
    std::fprintf(stderr, "pneuma: --magnify: %s\n", magnifyError.c_str());
    return 2;
  }

  // the movie: range, size and overlays, checked before anything is simulated
  pneuma::app::ExportController::MovieOptions movieOptions;
  const bool isMovie = parser.isSet(movie);
  if (isMovie) {
    movieOptions.to = parser.value(movieTo).toDouble(&isNumber);
    if (!isNumber || !(movieOptions.to > 0.0)) {
      std::fprintf(stderr, "pneuma: --to: expected seconds > 0, got '%s'\n",
                   qPrintable(parser.value(movieTo)));
      return 2;
    }
    if (parser.isSet(movieFrom)) {
      movieOptions.from = parser.value(movieFrom).toDouble(&isNumber);
      if (!isNumber || !(movieOptions.from >= 0.0) || !(movieOptions.from < movieOptions.to)) {
        std::fprintf(stderr, "pneuma: --from: expected seconds >= 0 and before --to (%g s), got '%s'\n",
                     movieOptions.to, qPrintable(parser.value(movieFrom)));
        return 2;
      }
    }
    if (parser.isSet(movieSize)) {
      const QStringList wh = parser.value(movieSize).toLower().split('x');
      bool isWidth = false, isHeight = false;
      const int w = wh.size() == 2 ? wh[0].toInt(&isWidth) : 0;
      const int h = wh.size() == 2 ? wh[1].toInt(&isHeight) : 0;
      if (!isWidth || !isHeight || w < 16 || h < 16 || w > 7680 || h > 4320) {
        std::fprintf(stderr,
                     "pneuma: --size: expected WxH in pixels from 16x16 to 7680x4320 (e.g. 1280x720), got "
                     "'%s'\n",
                     qPrintable(parser.value(movieSize)));
        return 2;
      }
      movieOptions.size = QSize(w, h);
    }
    if (parser.isSet(overlay)) {
      for (const QString& name : parser.value(overlay).split(',')) {
        if (name.trimmed() == "time") {
          movieOptions.hasTimeStamp = true;
        } else if (name.trimmed() == "volume") {
          movieOptions.hasVolumePanel = true;
        } else {
          std::fprintf(stderr, "pneuma: --overlay: unknown overlay '%s' (valid: time, volume)\n",
                       qPrintable(name));
          return 2;
        }
      }
    }
  } else {
    for (const QCommandLineOption* o : {&movieFrom, &movieTo, &movieSize, &overlay})
      if (parser.isSet(*o)) {
        std::fprintf(stderr, "pneuma: --%s needs --movie FILE\n", qPrintable(o->names().first()));
        return 2;
      }
  }

  const auto& presets = pneuma::viz::cameraPresets();
  const auto preset = std::find_if(presets.begin(), presets.end(), [&](const auto& p) {
    return QString::fromStdString(p.first) == parser.value(camera);
  });
  if (preset == presets.end()) {
    QStringList valid;
    for (const auto& p : presets) valid << QString::fromStdString(p.first);
    std::fprintf(stderr, "pneuma: --camera: unknown preset '%s' (valid: %s)\n",
                 qPrintable(parser.value(camera)), qPrintable(valid.join(", ")));
    return 2;
  }

  const std::map<QString, pneuma::viz::SkinDisplay> skinModes{
      {"translucent", pneuma::viz::SkinDisplay::Translucent},
      {"opaque", pneuma::viz::SkinDisplay::Opaque},
      {"hidden", pneuma::viz::SkinDisplay::Hidden}};
  const auto skinMode = skinModes.find(parser.value(skin));
  if (skinMode == skinModes.end()) {
    std::fprintf(stderr, "pneuma: --skin: unknown mode '%s' (valid: translucent, opaque, hidden)\n",
                 qPrintable(parser.value(skin)));
    return 2;
  }

  pneuma::app::MainWindow window;
  window.setSpeed(speedValue);
  window.show();
  QApplication::processEvents();
  const bool isScripted = parser.isSet(screenshot) || isMovie;
  if (parser.isSet(style) && !window.setBreathStyle(parser.value(style)).isEmpty() && isScripted) return 2;
  if (parser.isSet(posture) && !window.setPosture(parser.value(posture)).isEmpty() && isScripted) return 2;
  const QString modelDir =
      parser.isSet(model) ? parser.value(model) : pneuma::app::MainWindow::defaultModelDir();
  const bool hasModel = window.openModel(modelDir).isEmpty();
  if (hasModel && parser.isSet(affect)) {
    // an unknown name is reported by the window (dialog, or stderr when scripted)
    if (!window.pushAffect(parser.value(affect), true).isEmpty() && isScripted) return 2;
  }
  if (hasModel && parser.isSet(scenario) && !window.openScenario(parser.value(scenario)).isEmpty() &&
      isScripted)
    return 2;
  if (hasModel && parser.isSet(compare)) {
    const QString path = parser.value(compare);
    const QString error =
        path.endsWith(".json") ? window.overlayScenario(path) : window.overlayRecording(path);
    if (!error.isEmpty() && isScripted) return 2;
  }
  if (hasModel && parser.isSet(volumeTrace)) {
    // a bad trace is reported by the window (dialog, or stderr when scripted)
    if (!window.openTrace(parser.value(volumeTrace)).isEmpty() && isScripted) return 2;
  }
  window.scene().setCamera(preset->second);
  {
    pneuma::viz::DisplayOptions options = window.scene().options();
    options.skin = skinMode->second;
    options.magnification = magnification;
    window.plots()->showPhysiology(parser.isSet(physiology));
    if (parser.isSet(labels)) {
      options.showLabels = true;
      options.showCavity = true;
    }
    window.setDisplayOptions(options);
  }

  const bool isPlayback = parser.isSet(morphPlayback);
  if (isPlayback && hasModel) {
    const QString error = window.setMorphPlayback(true);
    if (!error.isEmpty()) {
      std::fprintf(stderr, "pneuma: --morph-playback: %s\n", qPrintable(error));
      return 1;
    }
  }

  // grab what the user would see
  const auto saveScreenshot = [&] {
    QApplication::processEvents();
    const QString file = parser.value(screenshot);
    if (window.grabWindow().save(file, "PNG")) return 0;
    std::fprintf(stderr, "pneuma: cannot write screenshot '%s'\n", qPrintable(file));
    return 1;
  };
  if (isScripted && isPlayback) {
    // the playback at pattern time --after, grabbed as the user would see it
    if (!hasModel) return 1;
    window.showMorphPlaybackAt(afterSeconds);
    return saveScreenshot();
  }
  if (isMovie) {
    // simulate until the movie's end, then replay its span through the export (progress dialog included)
    if (!hasModel) return 1;
    if (!window.runUntil(movieOptions.to)) {
      std::fprintf(stderr, "pneuma: simulation did not reach t = %g s: %s\n", movieOptions.to,
                   qPrintable(window.lastError()));
      return 1;
    }
    const double recordedFrom = window.shown()->recordedFrom;  // [s]
    if (!parser.isSet(movieFrom)) {
      movieOptions.from = recordedFrom;
    } else if (movieOptions.from < recordedFrom - 1e-9) {
      std::fprintf(stderr, "pneuma: --from: %g s is before the recording's start (%g s)\n", movieOptions.from,
                   recordedFrom);
      return 2;
    }
    const QString file = parser.value(movie);
    if (!window.exportAnimation(file, movieOptions).isEmpty()) return 1;  // the error is on stderr
    std::printf("pneuma: wrote %s (%d frames, %.2f s to %.2f s)\n", qPrintable(file),
                pneuma::app::ExportController::frameCount(movieOptions), movieOptions.from, movieOptions.to);
    return 0;
  }
  if (isScripted) {
    // simulate, show that instant, grab what the user would see
    if (!hasModel) return 1;
    if (!window.runUntil(afterSeconds)) {
      std::fprintf(stderr, "pneuma: simulation did not reach t = %g s: %s\n", afterSeconds,
                   qPrintable(window.lastError()));
      return 1;
    }
    if (parser.isSet(exportGltf) && !window.exportGltf(parser.value(exportGltf)).isEmpty()) return 1;
    return saveScreenshot();
  }
  if (hasModel && !isPlayback) window.play();
  if (parser.isSet(measure)) {
    // the rates averaged over the given wall time after a warm-up (the first quarter, at most 2 s: the first
    // renders compile the shaders)
    const double warmUp = std::min(2.0, 0.25 * measureSeconds);  // [s]
    QTimer::singleShot(static_cast<int>(1000.0 * warmUp), &window, [&window] { window.restartRates(); });
    QTimer::singleShot(static_cast<int>(1000.0 * measureSeconds), &window, [&window] {
      const auto* shown = window.shown();
      const pneuma::app::MainWindow::Rates rates = window.rates();
      const QSize view = window.viewSize();
      if (window.isMorphPlayback()) {
        std::printf("morph playback: 3D view %.1f fps (%.1f ms per render, %dx%d px), no physics\n",
                    rates.fps, rates.renderMs, view.width(), view.height());
        QApplication::exit(0);
        return;
      }
      std::printf(
          "3D view %.1f fps (%.1f ms per render, %dx%d px), plots %.1f Hz, real-time factor %.2f, simulated "
          "%.2f s\n"
          "CPU: display %.1f ms per 3D frame (GUI, plots and OpenGL threads), simulation %.0f %% of a core\n",
          rates.fps, rates.renderMs, view.width(), view.height(), rates.plotHz,
          shown ? shown->realTimeFactor : 0.0, shown ? shown->state.time : 0.0, rates.displayCpuMsPerFrame,
          100.0 * rates.simulationCpuShare);
      QApplication::exit(shown ? 0 : 1);
    });
  }
  return QApplication::exec();
}
