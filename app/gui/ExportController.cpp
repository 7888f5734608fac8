#include "gui/ExportController.h"

#include <QEventLoop>
#include <QFile>
#include <QFileInfo>
#include <QImage>
#include <QPainter>
#include <QPdfWriter>
#include <QProgressDialog>
#include <QSvgRenderer>
#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <vector>

#include "gui/PlotView.h"
#include "gui/SimWorker.h"
#include "viz/AtomicFile.h"
#include "viz/MovieWriter.h"
#include "viz/OffscreenView.h"

namespace pneuma::app {

ExportController::ExportController(View view, QObject* parent) : QObject(parent), m_view(std::move(view)) {}

QString ExportController::fail(const QString& message) {
  emit failed("Export failed", message);
  return message;
}

QString ExportController::exportPlot(const PlotView* plot, const QString& path) {
  const QString suffix = QFileInfo(path).suffix().toLower();
  try {
    const viz::Plot chart = plot->toPlot();
    if (suffix == "png") {
      chart.writePng(path.toStdString());
    } else if (suffix == "svg") {
      chart.writeSvg(path.toStdString());
    } else if (suffix == "csv") {
      viz::writeFileAtomically(path.toStdString(), plot->toCsv());
    } else if (suffix == "pdf") {
      // the SVG drawn into a PDF page of the same aspect, through a temporary file
      QSvgRenderer svg(QByteArray::fromStdString(chart.toSvg()));
      const std::string temp = viz::temporaryPathFor(path.toStdString());
      {
        QPdfWriter pdf(QString::fromStdString(temp));
        pdf.setTitle(plot->title());
        pdf.setCreator("Pneuma");
        pdf.setResolution(96);
        pdf.setPageSize(QPageSize(QSizeF(svg.defaultSize()), QPageSize::Point));
        pdf.setPageMargins(QMarginsF(0, 0, 0, 0));
        QPainter painter;
        if (!painter.begin(&pdf)) throw std::runtime_error("cannot write " + temp);
        svg.render(&painter);
        painter.end();
      }
      if (QFileInfo(QString::fromStdString(temp)).size() == 0) {
        QFile::remove(QString::fromStdString(temp));
        throw std::runtime_error("cannot write " + path.toStdString());
      }
      viz::commitTemporary(temp, path.toStdString());
    } else {
      throw std::runtime_error("unknown plot format '." + suffix.toStdString() +
                               "' (use .png, .svg, .pdf or .csv)");
    }
  } catch (const std::exception& e) {
    return fail(QString("Cannot export plot to '%1': %2").arg(path, e.what()));
  }
  emit done(QString("Plot exported to %1").arg(path));
  return {};
}

QString ExportController::exportViewImage(const QString& path) {
  const std::string temp = viz::temporaryPathFor(path.toStdString());
  try {
    if (!m_view.grab().save(QString::fromStdString(temp), "PNG")) {
      QFile::remove(QString::fromStdString(temp));
      throw std::runtime_error("cannot write " + path.toStdString());
    }
    viz::commitTemporary(temp, path.toStdString());
  } catch (const std::exception& e) {
    return fail(QString("Cannot export the 3D view: %1").arg(e.what()));
  }
  emit done(QString("3D view saved to %1").arg(path));
  return {};
}

int ExportController::frameCount(const MovieOptions& options) {
  if (!(options.to > options.from) || !(options.fps > 0.0)) return 0;
  return static_cast<int>(std::floor((options.to - options.from) * options.fps + 1e-6)) + 1;
}

namespace {

// what is drawn over each frame of a movie: the time stamp (top centre) and the volume panel (bottom left)
// (the volume plot over the exported span, its cursor at the frame's instant), sized for the frame
class MovieOverlay {
 public:
  MovieOverlay(const ExportController::MovieOptions& options, const PlotView* volume) : m_options(options) {
    if (!options.hasVolumePanel || !volume || volume->series().empty()) return;
    // the lung volume over the exported span (the panel keeps the plot's title, unit and colour)
    const std::vector<double>& t = volume->time();
    const PlotView::Series& lung = volume->series().front();
    std::vector<double> time, y;
    for (std::size_t k = 0; k < t.size(); ++k)
      if (t[k] >= options.from - 1e-9 && t[k] <= options.to + 1e-9)
        time.push_back(t[k]), y.push_back(lung.y[k]);
    m_panel = std::make_unique<PlotView>(volume->title(), volume->yLabel());
    m_panel->setWindow(options.to - options.from);
    m_panel->setViewEnd(options.to);
    m_panel->setData(std::move(time), {{lung.name, lung.colour, false, std::move(y), QString()}});
  }

  // draws the overlays for the instant `t` [s] onto `frame`
  void paint(QImage& frame, double t) const {
    if (!m_options.hasTimeStamp && !m_panel) return;
    QPainter painter(&frame);
    painter.setRenderHint(QPainter::Antialiasing);
    const int h = frame.height(), w = frame.width();
    if (m_options.hasTimeStamp) {
      QFont font = painter.font();
      font.setPixelSize(std::max(12, h / 24));
      font.setBold(true);
      painter.setFont(font);
      const QString text = QString("t = %1 s").arg(t, 0, 'f', 2);
      // at the top centre: the view's own caption ("motion x5") keeps the top left
      const QRect box = painter.fontMetrics().boundingRect(text).adjusted(-8, -4, 8, 4);
      const QRect placed = box.translated(QPoint((w - box.width()) / 2, h / 40) - box.topLeft());
      painter.fillRect(placed, QColor(0, 0, 0, 150));
      painter.setPen(Qt::white);
      painter.drawText(placed, Qt::AlignCenter, text);
    }
    if (m_panel) {
      m_panel->setCursor(t);
      // laid out once at its 1280x720 size and scaled to 42 % of the width and 30 % of the height, so that
      // its labels and axes keep their proportions at every frame size
      const QSize layout(538, 216);
      const double scale = std::min(0.42 * w / layout.width(), 0.3 * h / layout.height());
      m_panel->resize(layout);
      painter.save();
      painter.setOpacity(0.92);
      painter.translate(h / 40, h - scale * layout.height() - h / 40);
      painter.scale(scale, scale);
      m_panel->render(&painter, QPoint(0, 0));
      painter.restore();
    }
  }

 private:
  ExportController::MovieOptions m_options;
  std::unique_ptr<PlotView> m_panel;
};

}  // namespace

QString ExportController::exportAnimation(const QString& path, const MovieOptions& options,
                                          QWidget* dialogParent) {
  try {
    const int frames = frameCount(options);
    if (frames == 0) throw std::runtime_error("nothing recorded to export");
    if (options.size.isValid() && (options.size.width() < 16 || options.size.height() < 16))
      throw std::runtime_error("a frame of " + std::to_string(options.size.width()) + " x " +
                               std::to_string(options.size.height()) + " pixels is too small");
    viz::MovieWriter writer(path.toStdString(), options.fps);
    const MovieOverlay overlay(options, m_view.volumePlot ? m_view.volumePlot() : nullptr);
    // a chosen size is rendered off screen (the view on screen stays blank meanwhile)
    std::unique_ptr<viz::OffscreenView> offscreen;
    if (options.size.isValid())
      offscreen = std::make_unique<viz::OffscreenView>(m_view.renderer(), options.size.width(),
                                                       options.size.height());
    QProgressDialog progress(QString("Rendering %1 frames of %2 s to %3 s\u2026")
                                 .arg(frames)
                                 .arg(options.from, 0, 'f', 1)
                                 .arg(options.to, 0, 'f', 1),
                             "Cancel", 0, frames, dialogParent);
    progress.setWindowTitle("Export animation");
    progress.setWindowModality(Qt::WindowModal);
    progress.setMinimumDuration(0);
    for (int k = 0; k < frames; ++k) {
      progress.setValue(k);
      // the writer, destroyed unfinished, stops ffmpeg and removes every file it began
      if (progress.wasCanceled()) {
        emit done(QString("Animation export cancelled; nothing written"));
        return cancelled();
      }
      const double shownTime = m_view.scrubTo(options.from + k / options.fps);  // [s]
      if (!std::isfinite(shownTime)) throw std::runtime_error("the recording did not answer");
      QImage shot;
      if (offscreen) {
        const std::vector<unsigned char> rgb = offscreen->render();
        shot = QImage(rgb.data(), offscreen->width(), offscreen->height(), 3 * offscreen->width(),
                      QImage::Format_RGB888)
                   .copy();
      } else {
        shot = m_view.grab().convertToFormat(QImage::Format_RGB888);
      }
      overlay.paint(shot, shownTime);
      // QImage pads its rows to 4 bytes: hand the writer packed rows
      QByteArray rows(3 * shot.width() * shot.height(), Qt::Uninitialized);
      for (int y = 0; y < shot.height(); ++y)
        std::copy_n(shot.constScanLine(y), 3 * shot.width(), rows.data() + 3 * shot.width() * y);
      writer.writeFrame(reinterpret_cast<const unsigned char*>(rows.constData()), shot.width(),
                        shot.height());
    }
    progress.setLabelText("Finishing " + path + "\u2026");
    writer.finish();
  } catch (const std::exception& e) {
    return fail(QString("Cannot export the animation: %1").arg(e.what()));
  }
  emit done(QString("Animation saved to %1").arg(path));
  return {};
}

QString ExportController::waitForWorker(SimWorker* worker, const std::function<void()>& request) {
  QEventLoop loop;
  QString error = "the export did not finish";
  auto finished = connect(worker, &SimWorker::exportDone, &loop, [&](const QString& e) {
    error = e;
    loop.quit();
  });
  request();
  loop.exec();
  disconnect(finished);
  return error;
}

QString ExportController::exportGltf(SimWorker* worker, const QString& modelDir, const QString& path,
                                     bool isBakeOnly) {
  if (!worker) return fail("no model loaded");
  const QString error = waitForWorker(
      worker, [&] { worker->requestExportGltf(modelDir.toStdString(), path.toStdString(), isBakeOnly); });
  const QString what = isBakeOnly ? "the morph targets" : "the run";
  if (!error.isEmpty()) return fail(QString("Cannot export %1 to '%2': %3").arg(what, path, error));
  emit done(QString("%1 saved as %2").arg(isBakeOnly ? "Morph targets" : "glTF of the run", path));
  return {};
}

QString ExportController::exportRun(SimWorker* worker, const QString& modelDir, const QString& pvdPath,
                                    const viz::SeriesRange& range, QWidget* dialogParent) {
  if (!worker) return "no model loaded";
  const std::string rangeError = range.error("from", "to", "stride");
  if (!rangeError.empty())
    return fail(
        QString("Cannot export the run to '%1': %2").arg(pvdPath, QString::fromStdString(rangeError)));
  const QFileInfo info(pvdPath);
  // the frames are written in the worker's thread; the dialog follows them and its Cancel stops them
  QProgressDialog progress(QString("Writing the ParaView series %1\u2026").arg(pvdPath), "Cancel", 0, 1,
                           dialogParent);
  progress.setWindowTitle("Export run");
  progress.setWindowModality(Qt::WindowModal);
  progress.setMinimumDuration(0);
  progress.setValue(0);
  progress.show();  // at once: the worker's frames can keep the event loop too busy for its show timer
  auto advanced =
      connect(worker, &SimWorker::exportProgress, &progress, [&progress, worker](int written, int total) {
        if (progress.wasCanceled()) return worker->cancelExport();  // cancel() called without the button
        progress.setMaximum(total);
        progress.setValue(written);
      });
  auto canceller = connect(
      &progress, &QProgressDialog::canceled, worker, [worker] { worker->cancelExport(); },
      Qt::DirectConnection);
  const QString error = waitForWorker(worker, [&] {
    worker->requestExportRun(modelDir.toStdString(), info.absolutePath().toStdString(),
                             info.completeBaseName().toStdString(), range);
  });
  disconnect(advanced);
  disconnect(canceller);
  if (error == SimWorker::kCancelled) {
    emit done("Series export cancelled; nothing written");
    return ExportController::cancelled();
  }
  if (!error.isEmpty()) return fail(QString("Cannot export the run to '%1': %2").arg(pvdPath, error));
  emit done(QString("Run saved as %1").arg(pvdPath));
  return {};
}

}  // namespace pneuma::app
