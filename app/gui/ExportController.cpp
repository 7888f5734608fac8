#include "gui/ExportController.h"

#include <QEventLoop>
#include <QFile>
#include <QFileInfo>
#include <QImage>
#include <QPainter>
#include <QPdfWriter>
#include <QProgressDialog>
#include <QSvgRenderer>
#include <cmath>
#include <stdexcept>

#include "gui/PlotView.h"
#include "gui/SimWorker.h"
#include "viz/AtomicFile.h"
#include "viz/MovieWriter.h"

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

QString ExportController::exportAnimation(const QString& path, double from, double to, double fps,
                                          QWidget* dialogParent) {
  try {
    if (!(to > from) || !(fps > 0.0)) throw std::runtime_error("nothing recorded to export");
    viz::MovieWriter writer(path.toStdString(), fps);
    const int frames = static_cast<int>(std::floor((to - from) * fps + 1e-6)) + 1;
    QProgressDialog progress(QString("Rendering %1 frames of %2 s to %3 s\u2026")
                                 .arg(frames)
                                 .arg(from, 0, 'f', 1)
                                 .arg(to, 0, 'f', 1),
                             "Cancel", 0, frames, dialogParent);
    progress.setWindowTitle("Export animation");
    progress.setWindowModality(Qt::WindowModal);
    progress.setMinimumDuration(0);
    for (int k = 0; k < frames; ++k) {
      progress.setValue(k);
      // the writer, destroyed unfinished, removes every file it began
      if (progress.wasCanceled()) {
        emit done(QString("Animation export cancelled; nothing written"));
        return cancelled();
      }
      if (!m_view.scrubTo(from + k / fps)) throw std::runtime_error("the recording did not answer");
      const QImage shot = m_view.grab().convertToFormat(QImage::Format_RGB888);
      // QImage pads its rows to 4 bytes: hand the writer packed rows
      QByteArray rows(3 * shot.width() * shot.height(), Qt::Uninitialized);
      for (int y = 0; y < shot.height(); ++y)
        std::copy_n(shot.constScanLine(y), 3 * shot.width(), rows.data() + 3 * shot.width() * y);
      writer.writeFrame(reinterpret_cast<const unsigned char*>(rows.constData()), shot.width(),
                        shot.height());
    }
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

QString ExportController::exportRun(SimWorker* worker, const QString& modelDir, const QString& pvdPath) {
  if (!worker) return "no model loaded";
  const QFileInfo info(pvdPath);
  const QString error = waitForWorker(worker, [&] {
    worker->requestExportRun(modelDir.toStdString(), info.absolutePath().toStdString(),
                             info.completeBaseName().toStdString());
  });
  if (!error.isEmpty()) return fail(QString("Cannot export the run to '%1': %2").arg(pvdPath, error));
  emit done(QString("Run saved as %1").arg(pvdPath));
  return {};
}

}  // namespace pneuma::app
