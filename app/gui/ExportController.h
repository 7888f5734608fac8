#pragma once
/// @file ExportController.h
/// The app's exports: a plot as PNG, SVG, PDF or CSV; the 3D view as PNG; the recording as an Ogg Theora
/// movie or a PNG sequence (viz::MovieWriter); the run as a ParaView series or a glTF 2.0 .glb, and the baked
/// morph targets as a .glb (written by the SimWorker). Each
/// returns an empty string on success, else the error, and announces it with failed() or done(); every file
/// is written through a temporary name, so a failed export leaves nothing.

#include <QObject>
#include <QString>
#include <functional>

class QImage;

namespace pneuma::app {

class PlotView;
class SimWorker;

class ExportController : public QObject {
  Q_OBJECT

 public:
  /// What the exports need of the window: a grab of the 3D view as shown now, and a scrub of the recording to
  /// a time [s] that returns once that instant is on screen (false when it did not come).
  struct View {
    std::function<QImage()> grab;
    std::function<bool(double)> scrubTo;
  };

  ExportController(View view, QObject* parent = nullptr);

  /// Writes `plot` by the file suffix: .png, .svg, .pdf or .csv.
  QString exportPlot(const PlotView* plot, const QString& path);
  /// Writes a PNG of the 3D view.
  QString exportViewImage(const QString& path);
  /// Renders the recording from `from` to `to` [s] at `fps` [1/s]: an .ogv movie or a PNG sequence, with a
  /// progress dialog (parented to `dialogParent`, may be null) whose Cancel stops it and leaves no file
  /// (the result is then kCancelled, and nothing is reported as failed).
  QString exportAnimation(const QString& path, double from, double to, double fps,
                          class QWidget* dialogParent = nullptr);
  /// What exportAnimation() returns when its Cancel was pressed.
  static QString cancelled() { return "cancelled"; }
  /// Has `worker` write its recording as `pvdPath` plus a folder of .vtp frames (body meshes from
  /// `modelDir`); blocks, processing events, until it is written.
  QString exportRun(SimWorker* worker, const QString& modelDir, const QString& pvdPath);
  /// Has `worker` write its recording as a glTF 2.0 .glb (skin morph weights and bone poses), or with
  /// `isBakeOnly` the model's baked morph targets alone; blocks, processing events, until it is written.
  QString exportGltf(SimWorker* worker, const QString& modelDir, const QString& path, bool isBakeOnly);

 signals:
  /// An export failed: a title and the message (naming the file).
  void failed(const QString& title, const QString& message);
  /// An export was written: a line for the status bar.
  void done(const QString& message);

 private:
  QString fail(const QString& message);
  /// Calls `request` and waits, processing events, for `worker`'s exportDone(); returns its error.
  QString waitForWorker(SimWorker* worker, const std::function<void()>& request);
  View m_view;
};

}  // namespace pneuma::app
