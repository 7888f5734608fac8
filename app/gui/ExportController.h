#pragma once
/// @file ExportController.h
/// The app's exports: a plot as PNG, SVG, PDF or CSV; the 3D view as PNG; the recording as an MP4 (H.264,
/// through ffmpeg) or Ogg Theora movie or a PNG sequence (viz::MovieWriter), at the view's size or a chosen
/// one, optionally with a time stamp and a volume panel drawn over each frame; the run as a ParaView series
/// or a glTF 2.0 .glb, and the baked morph targets as a .glb (written by the SimWorker). Each returns an
/// empty string on success, else the error, and announces it with failed() or done(); every file is written
/// through a temporary name, so a failed export leaves nothing.

#include <QObject>
#include <QSize>
#include <QString>
#include <functional>

#include "viz/VtkSeriesWriter.h"

class QImage;
class vtkRenderer;

namespace pneuma::app {

class PlotView;
class SimWorker;

class ExportController : public QObject {
  Q_OBJECT

 public:
  /// What the exports need of the window: a grab of the 3D view as shown now; a scrub of the recording to a
  /// time [s] that returns the recorded instant's time once it is on screen (NaN when it did not come); the
  /// scene's renderer (rendered off screen for a chosen movie size); the volume plot (the movie's panel).
  struct View {
    std::function<QImage()> grab;
    std::function<double(double)> scrubTo;
    std::function<vtkRenderer*()> renderer;
    std::function<const PlotView*()> volumePlot;
  };

  /// What a movie shows and at what size.
  struct MovieOptions {
    double from = 0.0;  ///< [s] first instant
    double to = 0.0;    ///< [s] last instant
    double fps = 25.0;  ///< [1/s] frames per second, of the recording's time (the movie plays in real time)
    QSize size;         ///< frame size [px]; empty: the 3D view's size as shown
    bool hasTimeStamp = false;    ///< "t = 12.40 s" at the top centre of each frame
    bool hasVolumePanel = false;  ///< the volume plot over [from, to] at the bottom left, cursor at the frame
  };
  /// Frames of a movie: every 1/fps from `from` to `to`, both included.
  static int frameCount(const MovieOptions& options);

  ExportController(View view, QObject* parent = nullptr);

  /// Writes `plot` by the file suffix: .png, .svg, .pdf or .csv.
  QString exportPlot(const PlotView* plot, const QString& path);
  /// Writes a PNG of the 3D view.
  QString exportViewImage(const QString& path);
  /// Renders the recording as `options` say: an .mp4 or .ogv movie or a PNG sequence (by the suffix), with a
  /// progress dialog (parented to `dialogParent`, may be null) whose Cancel stops it (and ffmpeg) and leaves
  /// no file (the result is then cancelled(), and nothing is reported as failed).
  QString exportAnimation(const QString& path, const MovieOptions& options,
                          class QWidget* dialogParent = nullptr);
  /// What exportAnimation() returns when its Cancel was pressed.
  static QString cancelled() { return "cancelled"; }
  /// Has `worker` write the recorded frames `range` keeps as `pvdPath` plus a folder of .vtp frames (body
  /// meshes from `modelDir`), with a progress dialog (parented to `dialogParent`, may be null) whose Cancel
  /// stops it and removes what it wrote, nothing else (the result is then cancelled()); blocks, processing
  /// events, until it is written.
  QString exportRun(SimWorker* worker, const QString& modelDir, const QString& pvdPath,
                    const viz::SeriesRange& range = {}, class QWidget* dialogParent = nullptr);
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
