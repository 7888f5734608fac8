#pragma once
/// @file MainWindow.h
/// Pneuma's main window, laid out like ParaView / 3D Slicer: the 3D view with a timeline in the
/// centre, display and parameter panels on the left, the live plots on the right, transport and
/// style controls in the toolbar, and render fps and the simulation's real-time factor in the status bar.
///
/// The simulation runs in a SimWorker on its own QThread; the window only queues edits and draws
/// the snapshots the worker publishes (refreshed at 30 Hz).

#include <QElapsedTimer>
#include <QMainWindow>
#include <QThread>
#include <memory>
#include <utility>
#include <vector>

#include "gui/DocumentController.h"
#include "gui/ExportController.h"
#include "gui/SimWorker.h"
#include "viz/ModelScene.h"

class QAction;
class QCheckBox;
class QComboBox;
class QDockWidget;
class QLabel;
class QPushButton;
class QSlider;
class QTimer;
class QVTKOpenGLNativeWidget;

namespace pneuma::app {

class LivePlots;
class ParameterPanel;
class PlotView;

class MainWindow : public QMainWindow {
  Q_OBJECT

 public:
  explicit MainWindow(QWidget* parent = nullptr);
  ~MainWindow() override;

  /// The model directory used at start-up: sim::defaultModelDir() ($PNEUMA_MODEL_DIR, else
  /// <bindir>/../share/pneuma/models/default).
  static QString defaultModelDir();

  /// Loads a model directory and restarts the run on it. On failure the current model stays, the
  /// error is shown in a dialog (non-blocking) and returned. @return empty on success, else the error.
  QString openModel(const QString& dir);
  /// Loads a scenario file (model, style, parameters). Same failure behaviour as openModel().
  QString openScenario(const QString& path);
  /// Scenarios > Teaching: the teaching presets shipped in <resources>/scenarios/teaching, sorted by file
  /// name.
  static QStringList teachingPresets();
  /// Opens a teaching preset (openScenario()) and overlays calm upright breathing (<resources>/scenarios/
  /// calm.json) to compare with. @return empty or the error.
  QString openTeachingPreset(const QString& path);
  /// The opened scenario's name and description as shown in the Scenario panel (empty before one).
  QString scenarioExplanation() const;
  /// Runs the scenario at `path` on the window's model and draws it dashed over the volume, flow and
  /// pressure plots (RunOverlay.h), with a progress dialog whose Cancel leaves the plots as they were.
  /// A scenario of another model is refused with a message naming both. @return empty or the error.
  QString overlayScenario(const QString& path);
  /// Draws a recording (a pneuma-cli simulate folder or its timeseries.csv) dashed over the volume and flow
  /// plots; a recording of another model is refused with a message naming both. @return empty or the error.
  QString overlayRecording(const QString& path);
  /// Removes the overlaid run.
  void clearOverlay();
  /// File > Open trace: the open model's run follows the measured lung-volume trace at `path` (CSV,
  /// docs/patterns.md) from now on, through the pattern controller (its drive is calibrated first, a few
  /// simulated seconds in the worker); the volume plot draws the trace's target beside the simulated volume
  /// and its note the tracking RMS. A bad trace changes nothing: the error (file, line, column) is shown and
  /// returned. @return empty on success, else the error.
  QString openTrace(const QString& path);
  /// Writes the current model, style and parameters as a scenario file. @return empty or the error.
  QString saveScenario(const QString& path);
  /// Selects a breath style preset by name ("calm", "deep", "panting", "forced-exhale").
  QString setBreathStyle(const QString& name);
  /// Selects the posture by name (sim::postureNames()); a new posture restarts the run, which settles in it.
  /// @return empty, or the error (an unknown name lists the valid ones).
  QString setPosture(const QString& name);

  /// Sets the view's motion magnification (display only, viz::DisplayOptions::magnification).
  /// @return empty, or the error (outside [viz::kMinMagnification, viz::kMaxMagnification]).
  QString setMagnification(double factor);

  void play();
  void pause();
  /// Runs as fast as possible until simulated time `time` [s], then pauses and shows that instant.
  /// Blocks (processing events) at most `timeoutMs`. @return false on timeout or a sim error.
  bool runUntil(double time, int timeoutMs = 60000);
  /// Shows the recorded instant nearest to `time` [s] (pauses) and waits until it is on screen.
  bool scrubTo(double time, int timeoutMs = 5000);

  /// Exports a plot by file suffix: .png, .svg, .pdf or .csv. @return empty or the error.
  QString exportPlot(const PlotView* plot, const QString& path);
  /// Writes a PNG of the 3D view. @return empty or the error.
  QString exportViewImage(const QString& path);
  /// Renders the recorded run over `options`' range, size and overlays (File > Export > Animation, the
  /// MovieDialog) as an MP4 (H.264 through ffmpeg), an Ogg Theora movie (.ogv) or a PNG sequence (any other
  /// suffix: <base>_0000.png, ...). @return empty or the error. A progress dialog shows the frames written;
  /// its Cancel leaves no file (returns ExportController::cancelled()).
  QString exportAnimation(const QString& path, const ExportController::MovieOptions& options);
  /// Writes the recorded frames `range` keeps (File > Export > Run as ParaView series, the SeriesDialog: a
  /// stretch, every n-th frame) as a ParaView series: `pvdPath` plus a folder of .vtp frames beside it, with
  /// a progress dialog whose Cancel removes what it wrote (returns ExportController::cancelled()). Blocks
  /// (processing events) until the worker has written it. @return empty or the error.
  QString exportRun(const QString& pvdPath, const viz::SeriesRange& range = {});
  /// File > Export > Run as glTF: the recording as a .glb (morph weights and bone poses); "" on success.
  QString exportGltf(const QString& path);
  /// File > Export > Baked morph targets: the model's morph targets as a .glb; "" on success.
  QString bakeMorphTargets(const QString& path);
  /// Pushes an affect preset (de Melo et al. 2010), at the end of the current breath or immediately.
  /// @return empty, or the error (an unknown name lists the valid ones; no model open).
  QString pushAffect(const QString& name, bool isImmediate);

  /// View > Morph playback (de Melo et al. 2010, docs/app.md): on, pauses the physics and shows the skin
  /// driven only by the morph targets (baked once per model by the SimWorker, blocking with events processed
  /// while it bakes) and the pattern of the toolbar's affect (sim::MorphPlayer), at every display refresh;
  /// bones, muscles, gut and lungs are hidden. Off, the physics' last instant is shown again.
  /// @return empty, or the error (no model, a model without a skin, a failed bake).
  QString setMorphPlayback(bool isOn);
  bool isMorphPlayback() const { return m_player != nullptr; }
  /// Shows the morph playback at pattern time `t` [s] from its start and holds it there (scripts and tests;
  /// the playback's clock resumes from `t`). Going back in time restarts the pattern.
  void showMorphPlaybackAt(double t);
  QAction* morphPlaybackAction() const { return m_playbackAction; }
  /// The morph targets the playback plays (null before its first start on the current model).
  std::shared_ptr<const sim::MorphTargets> morphTargets() const { return m_morphs; }

  /// Renders the 3D view now and returns a grab of the whole window (what the user sees).
  QImage grabWindow();
  /// Renders the 3D view now and returns a grab of the 3D view only.
  QImage grabView();

  viz::ModelScene& scene() { return *m_scene; }
  /// The worker running the simulation (null before a model is open).
  SimWorker* worker() const { return m_worker; }
  LivePlots* plots() const { return m_plots; }
  ParameterPanel* parameters() const { return m_params; }
  /// The toolbar's breath-style box (it names the affect, pattern or trace while one drives).
  QComboBox* styleBox() const { return m_styleCombo; }
  /// The Breathing read-out's text: the last breaths' figures in people's units (Snapshot::breathing).
  QString breathingReadout() const;
  /// The snapshot on screen (null before the first one).
  const Snapshot* shown() const { return m_shown.get(); }
  const sim::Model* model() const { return m_document.model().get(); }
  /// Applies display options and redraws.
  void setDisplayOptions(const viz::DisplayOptions& options);
  /// Selects what is under view pixel (x, y) (Qt widget coordinates), as a click would.
  void pickAt(const QPoint& viewPos);
  /// Render frames per second over the last full second.
  double renderFps() const { return m_fps; }
  /// Plot refreshes per second over the last full second.
  double plotRate() const { return m_plotHz; }
  /// Wall time [ms] of one scene update and render, smoothed.
  double renderMilliseconds() const { return m_renderMs; }
  /// The 3D view's size in pixels.
  QSize viewSize() const;
  /// The rates averaged since restartRates() (pneuma --measure): 3D frames and plot refreshes per second, the
  /// mean wall time of one scene update and render [ms], and the CPU time the display took per 3D frame [ms]
  /// (every thread but the simulation's: the GUI's, with the plots, and the OpenGL driver's; CpuClock.h) and
  /// the simulation thread's CPU as a share of one core [-].
  struct Rates {
    double fps = 0.0, plotHz = 0.0, renderMs = 0.0, displayCpuMsPerFrame = 0.0, simulationCpuShare = 0.0;
  };
  void restartRates();
  Rates rates() const;
  /// Sets the simulation speed: simulated seconds per wall second, 0 = as fast as possible.
  void setSpeed(double speed);
  /// Help > Quick guide: a lecturer's tasks and the keys, as rich text.
  static QString quickGuide();
  /// Help > About: version, sources, licence, as rich text.
  static QString aboutText();
  /// The last error reported to the user (model, scenario, export or simulation).
  QString lastError() const { return m_lastError; }

 protected:
  bool eventFilter(QObject* watched, QEvent* event) override;
  void closeEvent(QCloseEvent* event) override;

 private:
  void buildActions();
  void buildDocks();
  void buildTimeline(QWidget* centre);
  void syncDisplayWidgets();
  void startRun(std::shared_ptr<const sim::Model> model, const QString& modelDir,
                const RunSettings& settings);
  void refresh();
  void showSnapshot(std::shared_ptr<const Snapshot> snapshot);
  void report(const QString& title, const QString& message);
  /// Shows `text` in the status bar for a while, then the model line again.
  void showMessage(const QString& text, int milliseconds);
  /// The status bar's model text with the run's posture ("Model: ... , posture supine").
  QString modelStatus() const;
  /// Shows modelStatus() now unless a message is on show (it comes back when the message ends).
  void showPosture();
  void select(const viz::Pick& pick);
  void exportPlotInteractive(const PlotView* plot);
  void updateTimeline();
  /// The style box and the parameter panel show what drives the breathing: the breath style, or the affect,
  /// pattern or trace of m_drive (a disabled entry in the style box; the style's fields disabled).
  void showDriver();
  /// Enables View > Morph playback for a model with a skin, else disables it with the reason as tooltip.
  void updatePlaybackAction();

  std::unique_ptr<viz::ModelScene> m_scene;
  QVTKOpenGLNativeWidget* m_view = nullptr;
  LivePlots* m_plots = nullptr;
  ParameterPanel* m_params = nullptr;

  DocumentController m_document;         // the open model and its directory; scenario files
  ExportController* m_export = nullptr;  // plots, the 3D view, movies and ParaView series
  RunSettings m_settings;
  QThread m_thread;
  SimWorker* m_worker = nullptr;
  std::shared_ptr<const Snapshot> m_shown;
  // what drives the run besides the breath style: a pushed affect or an opened affect or pattern scenario
  // (saved with the scenario); null while a breath style plays
  std::shared_ptr<const sim::Scenario> m_drive;
  long long m_generation = -1;
  viz::Pick m_selected;

  QTimer* m_refresh = nullptr;
  // morph playback: the action, the model's targets (shared with the SimWorker's glTF export), the player
  // (null: the physics is shown), its clock and the pattern time it started from
  QAction* m_playbackAction = nullptr;
  std::shared_ptr<const sim::MorphTargets> m_morphs;
  std::unique_ptr<sim::MorphPlayer> m_player;
  QElapsedTimer m_playbackClock;
  double m_playbackFrom = 0.0;  // [s]
  double m_playbackTime = 0.0;  // [s] pattern time shown last
  QAction* m_playAction = nullptr;
  QComboBox* m_styleCombo = nullptr;
  QComboBox* m_speedCombo = nullptr;
  QComboBox* m_affectCombo = nullptr;
  QComboBox* m_affectMode = nullptr;
  QComboBox* m_muscleColour = nullptr;
  QComboBox* m_gutColour = nullptr;
  QComboBox* m_skinDisplay = nullptr;  // the skin: translucent, opaque or hidden
  QComboBox* m_skinColour = nullptr;   // the skin: plain or displacement
  std::vector<std::pair<QCheckBox*, bool viz::DisplayOptions::*>> m_structureChecks;  // each with its option
  std::vector<QCheckBox*> m_groupChecks;
  std::vector<QPushButton*> m_cameraButtons;  // viz::cameraPresets(), in order
  QLabel* m_selection = nullptr;
  QLabel* m_breathing = nullptr;          // Snapshot::breathing, in people's units
  QLabel* m_scenarioNote = nullptr;       // the opened scenario's name and description
  QDockWidget* m_scenarioDock = nullptr;  // holds m_scenarioNote, shown once a scenario is opened
  QSlider* m_timeline = nullptr;
  QLabel* m_timeLabel = nullptr;
  QLabel* m_statusModel = nullptr;
  QString m_modelText = "No model";
  QTimer* m_messageTimer = nullptr;
  QLabel* m_statusTime = nullptr;
  QLabel* m_statusFps = nullptr;
  QLabel* m_statusRtf = nullptr;
  QPoint m_pressPos;
  int m_framesRendered = 0;
  double m_fps = 0.0;
  double m_renderMs = 0.0;  // [ms]
  double m_plotHz = 0.0;    // [1/s] plot refreshes
  int m_plotFrames = 0;
  // since restartRates(): frames, plot refreshes, render time [ms]
  QElapsedTimer m_ratesClock;
  int m_totalFrames = 0, m_totalPlotFrames = 0;
  double m_totalRenderMs = 0.0;
  double m_processCpuAtStart = 0.0, m_simulationCpuAtStart = 0.0;  // [s] CPU clocks at restartRates()
  void countRender(qint64 nanoseconds);
  /// Moves the 3D scene to `s` (when it is of the open model), with the compared run's ghost at its time.
  void poseScene(const Snapshot& s);
  QElapsedTimer m_sinceRender;
  qint64 m_fpsWindowStart = 0;  // [ms]
  QString m_lastError;
};

}  // namespace pneuma::app
