#include "gui/MainWindow.h"

#include <QVTKOpenGLNativeWidget.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkRenderer.h>

#include <QAction>
#include <QApplication>
#include <QCheckBox>
#include <QCloseEvent>
#include <QComboBox>
#include <QDateTime>
#include <QDir>
#include <QDockWidget>
#include <QElapsedTimer>
#include <QEventLoop>
#include <QFileDialog>
#include <QFileInfo>
#include <QFormLayout>
#include <QGridLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QMenu>
#include <QMenuBar>
#include <QMessageBox>
#include <QMouseEvent>
#include <QProgressDialog>
#include <QPushButton>
#include <QScrollArea>
#include <QSlider>
#include <QStandardItemModel>
#include <QStatusBar>
#include <QStyle>
#include <QTabWidget>
#include <QTimer>
#include <QToolBar>
#include <QVBoxLayout>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "gui/CpuClock.h"
#include "gui/DocumentController.h"
#include "gui/ExportController.h"
#include "gui/LivePlots.h"
#include "gui/MovieDialog.h"
#include "gui/ParameterPanel.h"
#include "gui/PlotView.h"
#include "gui/SeriesDialog.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/Resources.h"
#include "pneuma/sim/pattern/Pattern.h"

namespace pneuma::app {

namespace {

constexpr int kRefreshMs = 33;  // [ms] display refresh: 30 Hz
// [ms] a 3D render at most this long is drawn at every refresh: with the plots' few milliseconds both stay
// above 20 Hz (50 ms per refresh); a slower one waits its turn so that it cannot starve the plots
constexpr double kRenderEveryRefreshMs = 36.0;
constexpr double kRecordSeconds = 60.0;        // [s] recorded for the timeline
constexpr const char* kDriverItem = "driver";  // item data of the style box's entry for an affect or pattern
constexpr const char* kSimulationThread = "pneuma-sim";  // the simulation thread's name (CpuClock.h)

const std::vector<std::pair<QString, double>> kSpeeds{
    {"0.1\u00d7 real time", 0.1}, {"0.25\u00d7 real time", 0.25}, {"0.5\u00d7 real time", 0.5},
    {"1\u00d7 real time", 1.0},   {"2\u00d7 real time", 2.0},     {"As fast as possible", 0.0}};

// display options the window offers: the check boxes of the structures and the colourings, each tied to its
// option here (not by position)
const std::vector<std::pair<const char*, bool viz::DisplayOptions::*>> kStructures{
    {"Bones", &viz::DisplayOptions::showBones},
    {"Gut", &viz::DisplayOptions::showGut},
    {"Translucent gut", &viz::DisplayOptions::isGutTranslucent},
    {"Pectorals and shoulders", &viz::DisplayOptions::showTissue},
    {"Lung cavity", &viz::DisplayOptions::showCavity},
    {"Lungs", &viz::DisplayOptions::showLungs},
    {"Landmarks", &viz::DisplayOptions::showLandmarks},
    {"Anatomical labels", &viz::DisplayOptions::showLabels},
    {"Ghost of the compared run", &viz::DisplayOptions::showGhost}};
const std::vector<std::pair<const char*, viz::MuscleColouring>> kMuscleColourings{
    {"Tension [N]", viz::MuscleColouring::Force},
    {"Activation \u03b1 [0-1]", viz::MuscleColouring::Activation},
    {"Muscle group", viz::MuscleColouring::Group}};
const std::vector<std::pair<const char*, viz::GutColouring>> kGutColourings{
    {"Plain", viz::GutColouring::Plain},
    {"Pressure [cmH2O]", viz::GutColouring::Pressure},
    {"Displacement [mm]", viz::GutColouring::Displacement}};
const std::vector<std::pair<const char*, viz::SkinDisplay>> kSkinDisplays{
    {"Translucent", viz::SkinDisplay::Translucent},
    {"Opaque", viz::SkinDisplay::Opaque},
    {"Hidden", viz::SkinDisplay::Hidden}};
const std::vector<std::pair<const char*, viz::SkinColouring>> kSkinColourings{
    {"Plain", viz::SkinColouring::Plain}, {"Displacement [mm]", viz::SkinColouring::Displacement}};
const std::vector<std::pair<const char*, sim::pattern::SwitchMode>> kAffectModes{
    {"at end of cycle", sim::pattern::SwitchMode::EndOfCycle},
    {"immediately", sim::pattern::SwitchMode::Immediate}};

// the Breathing read-out: the last breaths' figures (sim::Summary, SI) in people's units, one per line; a
// figure the breath does not define (a landmark the model lacks) reads "n/a"
QString breathingText(const sim::Summary* b) {
  if (!b) return "Measured after the first full breath.";
  auto value = [](double v, double scale, int decimals, const char* unit) {
    return std::isfinite(v) ? QString("%1 %2").arg(v * scale, 0, 'f', decimals).arg(unit) : QString("n/a");
  };
  const sim::Motion& m = b->motion;
  return QStringList{
      QString("Tidal volume %1 at %2")
          .arg(value(b->tidalVolume, 1e6, 0, "mL"), value(b->breathsPerMinute, 1.0, 1, "b/min")),
      "Dome descent " + value(m.domeDescent, 1e3, 1, "mm"),
      "Rib 8 widening " + value(m.lowerRibExpansion, 1e3, 1, "mm"),
      "Sternum forward " + value(m.sternumAnterior, 1e3, 1, "mm"),
      "Sternum upward " + value(m.sternumCranial, 1e3, 1, "mm"),
      "Belly forward " + value(m.umbilicusAnterior, 1e3, 1, "mm"),
      "Rib cage share " + value(m.ribCageShare(), 100.0, 0, "%"),
      "Rib cage-abdomen phase " + value(m.phaseAngle, 180.0 / M_PI, 0, "\u00b0")}
      .join('\n');
}

}  // namespace

MainWindow::MainWindow(QWidget* parent) : QMainWindow(parent), m_scene(std::make_unique<viz::ModelScene>()) {
  setWindowTitle("Pneuma");
  resize(1280, 800);
  m_export = new ExportController(
      {[this] { return grabView(); },
       [this](double t) {
         return scrubTo(t) ? m_shown->state.time : std::numeric_limits<double>::quiet_NaN();
       },
       [this] { return m_scene->renderer(); }, [this]() -> const PlotView* { return m_plots->volumePlot(); }},
      this);
  connect(m_export, &ExportController::failed, this, &MainWindow::report);
  connect(m_export, &ExportController::done, this,
          [this](const QString& message) { showMessage(message, 5000); });

  // centre: the 3D view over the timeline
  auto* centre = new QWidget(this);
  auto* centreLayout = new QVBoxLayout(centre);
  centreLayout->setContentsMargins(0, 0, 0, 0);
  centreLayout->setSpacing(0);
  m_view = new QVTKOpenGLNativeWidget(centre);
  vtkNew<vtkGenericOpenGLRenderWindow> window;
  window->SetMultiSamples(0);  // multisampling costs more than it gives in software GL
  m_view->setRenderWindow(window);
  window->AddRenderer(m_scene->renderer());
  m_scene->installOrientationMarker(m_view->interactor());
  m_view->installEventFilter(this);
  centreLayout->addWidget(m_view, 1);
  buildTimeline(centre);
  setCentralWidget(centre);

  buildDocks();
  buildActions();
  updatePlaybackAction();

  // status bar: model, time, fps and real-time factor
  m_statusModel = new QLabel("No model", this);
  m_statusTime = new QLabel(this);
  m_statusFps = new QLabel(this);
  m_statusRtf = new QLabel(this);
  statusBar()->addWidget(m_statusModel, 1);
  statusBar()->addPermanentWidget(m_statusTime);
  statusBar()->addPermanentWidget(m_statusFps);
  statusBar()->addPermanentWidget(m_statusRtf);

  m_messageTimer = new QTimer(this);
  m_messageTimer->setSingleShot(true);
  connect(m_messageTimer, &QTimer::timeout, this, [this] { m_statusModel->setText(modelStatus()); });

  m_refresh = new QTimer(this);
  m_refresh->setInterval(kRefreshMs);
  connect(m_refresh, &QTimer::timeout, this, &MainWindow::refresh);
  m_refresh->start();
  m_fpsWindowStart = QDateTime::currentMSecsSinceEpoch();
  m_sinceRender.start();

  // default run settings: the calm style when its preset exists
  const std::vector<std::string> styles = sim::breathStyleNames();
  for (const std::string& s : styles) m_styleCombo->addItem(QString::fromStdString(s));
  m_settings.options.recordSeconds = kRecordSeconds;
  try {
    m_settings.style = sim::loadBreathStyle(
        styles.empty() || std::find(styles.begin(), styles.end(), "calm") != styles.end() ? "calm"
                                                                                          : styles.front());
  } catch (const sim::Error& e) {
    m_settings.style.name = "default";
    showMessage(QString("Breath-style presets not found (%1); using built-in defaults").arg(e.what()), 10000);
  }
  {
    const QSignalBlocker block(m_styleCombo);
    m_styleCombo->setCurrentText(QString::fromStdString(m_settings.style.name));
  }
  m_params->setSettings(m_settings, nullptr);
}

MainWindow::~MainWindow() {
  m_thread.quit();
  m_thread.wait();
}

QString MainWindow::defaultModelDir() { return DocumentController::defaultModelDir(); }

void MainWindow::buildTimeline(QWidget* centre) {
  auto* bar = new QWidget(centre);
  auto* layout = new QHBoxLayout(bar);
  layout->setContentsMargins(8, 4, 8, 4);
  auto* title = new QLabel("Timeline", bar);
  m_timeline = new QSlider(Qt::Horizontal, bar);
  m_timeline->setRange(0, 1000);
  m_timeline->setToolTip("Drag to scrub back through the recorded states (pauses the run)");
  m_timeLabel = new QLabel("t = 0.00 s", bar);
  m_timeLabel->setMinimumWidth(170);
  auto* live = new QPushButton("Live", bar);
  live->setToolTip("Return to the running simulation");
  layout->addWidget(title);
  layout->addWidget(m_timeline, 1);
  layout->addWidget(m_timeLabel);
  layout->addWidget(live);
  centre->layout()->addWidget(bar);

  connect(m_timeline, &QSlider::sliderMoved, this, [this](int value) {
    if (!m_shown || !m_worker) return;
    const double t = m_shown->recordedFrom + (m_shown->recordedTo - m_shown->recordedFrom) * value / 1000.0;
    m_playAction->setChecked(false);
    m_worker->requestScrub(t);
  });
  connect(live, &QPushButton::clicked, this, &MainWindow::play);
}

void MainWindow::buildActions() {
  // file menu
  QMenu* file = menuBar()->addMenu("&File");
  file->addAction(
      "&Open model directory\u2026", this,
      [this] {
        const QString dir =
            QFileDialog::getExistingDirectory(this, "Open model directory", m_document.modelDir());
        if (!dir.isEmpty()) openModel(dir);
      },
      QKeySequence::Open);
  file->addAction("Open &scenario\u2026", this, [this] {
    const QString path = QFileDialog::getOpenFileName(this, "Open scenario", QString(), "Scenario (*.json)");
    if (!path.isEmpty()) openScenario(path);
  });
  file->addAction("Open &trace\u2026", this, [this] {
    const QString path = QFileDialog::getOpenFileName(this, "Open volume trace", QString(),
                                                      "Volume trace (*.csv);;All files (*)");
    if (!path.isEmpty()) openTrace(path);
  });
  file->addAction(
      "Sa&ve scenario\u2026", this,
      [this] {
        const QString path =
            QFileDialog::getSaveFileName(this, "Save scenario", "scenario.json", "Scenario (*.json)");
        if (!path.isEmpty()) saveScenario(path);
      },
      QKeySequence::Save);
  file->addSeparator();
  QMenu* exportMenu = file->addMenu("&Export");
  for (PlotView* plot : m_plots->plots())
    exportMenu->addAction(QString("Plot \u201c%1\u201d\u2026").arg(plot->title()), this,
                          [this, plot] { exportPlotInteractive(plot); });
  exportMenu->addSeparator();
  exportMenu->addAction("3D view as PNG\u2026", this, [this] {
    const QString path =
        QFileDialog::getSaveFileName(this, "Export 3D view", "view.png", "PNG image (*.png)");
    if (!path.isEmpty()) exportViewImage(path);
  });
  exportMenu->addAction("Animation of the recording\u2026", this, [this] {
    if (!m_shown) return;
    MovieDialog dialog(m_shown->recordedFrom, m_shown->recordedTo, viewSize(), this);
    if (dialog.exec() == QDialog::Accepted) exportAnimation(dialog.path(), dialog.options());
  });
  exportMenu->addAction("Run as ParaView series (.pvd)\u2026", this, [this] {
    if (!m_shown || !model()) return;
    // one frame encoded now gives the size of the series before it is written
    double frameBytes = 0.0;  // [bytes]
    try {
      QApplication::setOverrideCursor(Qt::WaitCursor);
      frameBytes = static_cast<double>(viz::VtkSeriesWriter::frameBytes(
          *model(), m_document.modelDir().toStdString(), m_shown->state, m_shown->metrics));
      QApplication::restoreOverrideCursor();
    } catch (const std::exception& e) {
      QApplication::restoreOverrideCursor();
      report("Export failed", QString("Cannot export the run: %1").arg(e.what()));
      return;
    }
    SeriesDialog dialog(m_shown->recordedFrom, m_shown->recordedTo, m_shown->recordedFrames, frameBytes,
                        this);
    if (dialog.exec() == QDialog::Accepted) exportRun(dialog.path(), dialog.range());
  });
  exportMenu->addAction("Run as glTF 2.0 (.glb)\u2026", this, [this] {
    const QString path =
        QFileDialog::getSaveFileName(this, "Export run as glTF", "breathing.glb", "glTF 2.0 binary (*.glb)");
    if (!path.isEmpty()) exportGltf(path);
  });
  exportMenu->addAction("Baked morph targets (.glb)\u2026", this, [this] {
    const QString path =
        QFileDialog::getSaveFileName(this, "Bake morph targets", "morphs.glb", "glTF 2.0 binary (*.glb)");
    if (!path.isEmpty()) bakeMorphTargets(path);
  });
  file->addSeparator();
  file->addAction("&Quit", this, &QWidget::close, QKeySequence::Quit);

  // simulation toolbar and menu
  QToolBar* tools = addToolBar("Simulation");
  tools->setMovable(false);
  tools->setToolButtonStyle(Qt::ToolButtonTextBesideIcon);
  m_playAction = tools->addAction(style()->standardIcon(QStyle::SP_MediaPlay), "Play");
  m_playAction->setCheckable(true);
  m_playAction->setShortcut(Qt::Key_Space);
  connect(m_playAction, &QAction::toggled, this, [this](bool on) {
    m_playAction->setText(on ? "Pause" : "Play");
    m_playAction->setIcon(style()->standardIcon(on ? QStyle::SP_MediaPause : QStyle::SP_MediaPlay));
    if (on && m_player) setMorphPlayback(false);  // the physics instead of the playback
    if (m_worker) m_worker->setRunning(on);
  });
  QAction* step = tools->addAction(style()->standardIcon(QStyle::SP_MediaSkipForward), "Step");
  step->setToolTip("Advance one time step");
  connect(step, &QAction::triggered, this, [this] {
    m_playAction->setChecked(false);
    if (m_worker) m_worker->requestStep();
  });
  QAction* reset = tools->addAction(style()->standardIcon(QStyle::SP_MediaSkipBackward), "Reset");
  reset->setToolTip("Back to the rest pose at t = 0");
  connect(reset, &QAction::triggered, this, [this] {
    if (m_worker) m_worker->requestReset();
  });
  tools->addSeparator();
  tools->addWidget(new QLabel(" Speed ", this));
  m_speedCombo = new QComboBox(this);
  for (const auto& [label, speed] : kSpeeds) m_speedCombo->addItem(label, speed);
  m_speedCombo->setCurrentIndex(3);
  connect(m_speedCombo, qOverload<int>(&QComboBox::currentIndexChanged), this, [this](int i) {
    if (m_worker) m_worker->setSpeed(m_speedCombo->itemData(i).toDouble());
  });
  tools->addWidget(m_speedCombo);
  tools->addSeparator();
  tools->addWidget(new QLabel(" Breath style ", this));
  m_styleCombo = new QComboBox(this);
  m_styleCombo->setMinimumWidth(130);
  // wide enough for what drives instead of a style ("pattern 'startle-at-10s'")
  m_styleCombo->setSizeAdjustPolicy(QComboBox::AdjustToContents);
  connect(m_styleCombo, &QComboBox::textActivated, this,
          [this](const QString& name) { setBreathStyle(name); });
  tools->addWidget(m_styleCombo);
  tools->addSeparator();
  tools->addWidget(new QLabel(" Affect ", this));
  m_affectCombo = new QComboBox(this);
  m_affectCombo->setToolTip("Respiration pattern of an affective state (de Melo et al. 2010)");
  for (const std::string& a : sim::pattern::listAffects(sim::resourceDir()))
    m_affectCombo->addItem(QString::fromStdString(a));
  m_affectCombo->setCurrentText(
      "neutral");  // nothing is pushed yet: offer neutral, not the first in the list (anger)
  tools->addWidget(m_affectCombo);
  m_affectMode = new QComboBox(this);
  for (const auto& [label, mode] : kAffectModes) m_affectMode->addItem(label, static_cast<int>(mode));
  tools->addWidget(m_affectMode);
  QAction* push = tools->addAction("Push");
  push->setToolTip("Push the affect's respiration layers onto the pattern stack");
  connect(push, &QAction::triggered, this, [this] {
    pushAffect(m_affectCombo->currentText(),
               static_cast<sim::pattern::SwitchMode>(m_affectMode->currentData().toInt()) ==
                   sim::pattern::SwitchMode::Immediate);
  });
  // camera presets: the View menu and the buttons above the display options
  QMenu* view = menuBar()->addMenu("&View");
  for (QPushButton* button : m_cameraButtons) {
    QAction* a = view->addAction(button->text());
    connect(a, &QAction::triggered, button, &QPushButton::click);
  }
  view->addSeparator();
  m_playbackAction = view->addAction("&Morph playback");
  m_playbackAction->setCheckable(true);
  m_playbackAction->setShortcut(Qt::Key_M);
  connect(m_playbackAction, &QAction::triggered, this, [this](bool on) { setMorphPlayback(on); });
  // a new affect while the playback plays: play it from its start
  connect(m_affectCombo, &QComboBox::currentTextChanged, this, [this] {
    if (m_player) setMorphPlayback(true);
  });
  // scenarios: the teaching presets, and a second run drawn over the plots
  QMenu* scenarios = menuBar()->addMenu("S&cenarios");
  QMenu* teaching = scenarios->addMenu("&Teaching");
  for (const QString& path : teachingPresets())
    teaching->addAction(QFileInfo(path).completeBaseName().replace('-', ' '), this,
                        [this, path] { openTeachingPreset(path); });
  scenarios->addSeparator();
  scenarios->addAction("Compare with &calm breathing", this, [this] {
    overlayScenario(QString::fromStdString(sim::resourceDir()) + "/scenarios/calm.json");
  });
  scenarios->addAction("Compare with a &scenario\u2026", this, [this] {
    const QString path =
        QFileDialog::getOpenFileName(this, "Compare with a scenario", QString(), "Scenario (*.json)");
    if (!path.isEmpty()) overlayScenario(path);
  });
  scenarios->addAction("Compare with a &recording\u2026", this, [this] {
    const QString path = QFileDialog::getOpenFileName(this, "Compare with a recording (pneuma-cli simulate)",
                                                      QString(), "Recording (timeseries.csv)");
    if (!path.isEmpty()) overlayRecording(path);
  });
  scenarios->addAction("&Remove the comparison", this, &MainWindow::clearOverlay);

  QMenu* simMenu = menuBar()->addMenu("&Simulation");
  simMenu->addAction(m_playAction);
  simMenu->addAction(step);
  simMenu->addAction(reset);

  // help: a lecturer's quick guide with the shortcuts, and where the model comes from
  QMenu* help = menuBar()->addMenu("&Help");
  QAction* guide = help->addAction("&Quick guide", this, [this] {
    QMessageBox box(QMessageBox::Information, "Pneuma quick guide", quickGuide(), QMessageBox::Close, this);
    box.setTextFormat(Qt::RichText);
    box.exec();
  });
  guide->setShortcut(QKeySequence::HelpContents);
  help->addAction("&About Pneuma", this, [this] { QMessageBox::about(this, "About Pneuma", aboutText()); });
}

QString MainWindow::quickGuide() {
  return "<p><b>Show the breath.</b> The view magnifies every motion from end-expiration (<i>Parameters</i> "
         "&gt; "
         "<i>Motion magnification</i>, 5x by default; the view says so). Plots and read-outs stay real.</p>"
         "<p><b>Name the parts.</b> <i>Display</i>: structures, <i>Anatomical labels</i>, cameras (anterior, "
         "lateral, superior, posterior, oblique). Click a muscle element to plot its tension.</p>"
         "<p><b>Change the breathing.</b> The toolbar's breath style; push an affect (fear, relief, ...); "
         "<i>Scenarios</i> &gt; <i>Teaching</i> for the presets (paralysed hemidiaphragm, stiff chest wall, "
         "...) and <i>Compare with</i> to draw a second run dashed over the plots.</p>"
         "<p><b>Export.</b> <i>File</i> &gt; <i>Export</i>: the plots, a screenshot, a movie (Ogg or MP4), a "
         "ParaView series, glTF for animation tools.</p>"
         "<p><b>Keys.</b> Space: play or pause. M: morph playback. F1: this guide. Drag: rotate; wheel: "
         "zoom; "
         "the timeline scrubs back through the last 60 s.</p>"
         "<p>The user guide is docs/app.md in the source tree.</p>";
}

QString MainWindow::aboutText() {
  return QString(
             "<p><b>Pneuma %1</b>: human breathing simulated from the inside out.</p>"
             "<p>The mechanics follow Zordan, Celly, Chiu and DiLorenzo, <i>Breathe Easy: Model and Control "
             "of Simulated Respiration for Animation</i> (SCA 2004); the respiration patterns and affects "
             "de Melo, Kenny and Gratch, <i>Real-Time Expression of Affect through Respiration</i> (CAVW "
             "2010).</p>"
             "<p>Licence: GNU AGPL 3.0 or later (it links TetGen, AGPL, and CGAL, GPL). The body surface is "
             "the MakeHuman base mesh shipped in Debian's assimp-testmodels.</p>")
      .arg(QApplication::applicationVersion());
}

void MainWindow::buildDocks() {
  // right: live plots
  m_plots = new LivePlots(this);
  for (PlotView* plot : m_plots->plots())
    connect(plot, &PlotView::contextMenuRequested, this, [this, plot](const QPoint& at) {
      QMenu menu;
      menu.addAction("Export plot (PNG, SVG, PDF, CSV)\u2026", this,
                     [this, plot] { exportPlotInteractive(plot); });
      menu.exec(at);
    });
  auto* plotDock = new QDockWidget("Live plots", this);
  plotDock->setObjectName("plots");
  plotDock->setFeatures(QDockWidget::DockWidgetMovable | QDockWidget::DockWidgetFloatable);
  plotDock->setWidget(m_plots);
  plotDock->setMinimumWidth(380);
  addDockWidget(Qt::RightDockWidgetArea, plotDock);

  // left: display options and parameters
  auto* display = new QWidget(this);
  auto* displayLayout = new QVBoxLayout(display);
  // the last breaths' figures first: what a lecturer reads off
  auto* breathingBox = new QGroupBox("Breathing", display);
  breathingBox->setToolTip(
      QString("The last breaths' figures (the last %1 s of the run after settling), measured as pneuma-cli "
              "validate measures them: docs/cli.md")
          .arg(kBreathingWindow, 0, 'f', 0));
  auto* breathingLayout = new QVBoxLayout(breathingBox);
  m_breathing = new QLabel(breathingBox);
  m_breathing->setTextFormat(Qt::PlainText);
  m_breathing->setText(breathingText(nullptr));
  breathingLayout->addWidget(m_breathing);
  displayLayout->addWidget(breathingBox);

  auto* camera = new QGroupBox("Camera", display);
  auto* cameraLayout = new QGridLayout(camera);
  for (const auto& [name, preset] : viz::cameraPresets()) {
    QString label = QString::fromStdString(name);
    label[0] = label[0].toUpper();
    auto* button = new QPushButton(label, camera);
    connect(button, &QPushButton::clicked, this, [this, preset = preset] {
      m_scene->setCamera(preset);
      m_view->renderWindow()->Render();
    });
    cameraLayout->addWidget(button, static_cast<int>(m_cameraButtons.size()) / 2,
                            static_cast<int>(m_cameraButtons.size()) % 2);
    m_cameraButtons.push_back(button);
  }
  displayLayout->addWidget(camera);

  auto* colouring = new QGroupBox("Colouring", display);
  auto* colourForm = new QFormLayout(colouring);
  m_muscleColour = new QComboBox(colouring);
  for (const auto& [label, colouring] : kMuscleColourings)
    m_muscleColour->addItem(label, static_cast<int>(colouring));
  m_gutColour = new QComboBox(colouring);
  for (const auto& [label, colouring] : kGutColourings)
    m_gutColour->addItem(label, static_cast<int>(colouring));
  colourForm->addRow("Muscles", m_muscleColour);
  colourForm->addRow("Gut", m_gutColour);
  m_skinColour = new QComboBox(colouring);
  for (const auto& [label, colouring] : kSkinColourings)
    m_skinColour->addItem(label, static_cast<int>(colouring));
  colourForm->addRow("Skin", m_skinColour);
  auto* autoRange = new QCheckBox("Auto-range (95th percentile)", colouring);
  autoRange->setToolTip(
      "Off: every scale has its fixed range (tension 0-20 N, activation 0-1, gut 0-20 mm, skin 0-10 mm, gut "
      "pressure \u00b15 cmH2O), the same on every frame and run. On: each scale is topped at the 95th "
      "percentile of its values so far, rounded up, never shrinking.");
  colourForm->addRow(autoRange);
  m_structureChecks.emplace_back(autoRange, &viz::DisplayOptions::isAutoRange);
  displayLayout->addWidget(colouring);

  auto* structures = new QGroupBox("Structures", display);
  auto* structLayout = new QVBoxLayout(structures);
  auto* skinRow = new QHBoxLayout();
  skinRow->addWidget(new QLabel("Skin", structures));
  m_skinDisplay = new QComboBox(structures);
  for (const auto& [label, display] : kSkinDisplays) m_skinDisplay->addItem(label, static_cast<int>(display));
  skinRow->addWidget(m_skinDisplay, 1);
  structLayout->addLayout(skinRow);
  for (const auto& [name, flag] : kStructures) {
    auto* check = new QCheckBox(name, structures);
    structLayout->addWidget(check);
    m_structureChecks.emplace_back(check, flag);
  }
  displayLayout->addWidget(structures);

  auto* groups = new QGroupBox("Muscle groups", display);
  auto* groupLayout = new QVBoxLayout(groups);
  for (int g = 0; g < sim::kElementGroupCount; ++g) {
    const auto group = static_cast<sim::ElementGroup>(g);
    auto* check = new QCheckBox(viz::groupLabel(group), groups);
    const auto c = viz::groupColour(group);
    QPixmap swatch(12, 12);
    swatch.fill(QColor::fromRgbF(c[0], c[1], c[2]));
    check->setIcon(QIcon(swatch));
    groupLayout->addWidget(check);
    m_groupChecks.push_back(check);
  }
  displayLayout->addWidget(groups);

  auto* selectionBox = new QGroupBox("Selection", display);
  auto* selectionLayout = new QVBoxLayout(selectionBox);
  m_selection = new QLabel("Click a muscle element or a bone in the 3D view.", selectionBox);
  m_selection->setWordWrap(true);
  selectionLayout->addWidget(m_selection);
  auto* clearTraces = new QPushButton("Clear force traces", selectionBox);
  connect(clearTraces, &QPushButton::clicked, this, [this] {
    m_plots->clearTraces();
    select({});
  });
  selectionLayout->addWidget(clearTraces);
  displayLayout->addWidget(selectionBox);
  displayLayout->addStretch(1);

  syncDisplayWidgets();
  auto readOptions = [this] {
    viz::DisplayOptions o = m_scene->options();
    o.muscleColouring = static_cast<viz::MuscleColouring>(m_muscleColour->currentData().toInt());
    o.gutColouring = static_cast<viz::GutColouring>(m_gutColour->currentData().toInt());
    o.skin = static_cast<viz::SkinDisplay>(m_skinDisplay->currentData().toInt());
    o.skinColouring = static_cast<viz::SkinColouring>(m_skinColour->currentData().toInt());
    for (const auto& [check, flag] : m_structureChecks) o.*flag = check->isChecked();
    for (std::size_t g = 0; g < m_groupChecks.size(); ++g) o.showGroup[g] = m_groupChecks[g]->isChecked();
    setDisplayOptions(o);
  };
  connect(m_muscleColour, qOverload<int>(&QComboBox::currentIndexChanged), this, readOptions);
  connect(m_gutColour, qOverload<int>(&QComboBox::currentIndexChanged), this, readOptions);
  connect(m_skinDisplay, qOverload<int>(&QComboBox::currentIndexChanged), this, readOptions);
  connect(m_skinColour, qOverload<int>(&QComboBox::currentIndexChanged), this, readOptions);
  for (const auto& [check, flag] : m_structureChecks) connect(check, &QCheckBox::toggled, this, readOptions);
  for (QCheckBox* c : m_groupChecks) connect(c, &QCheckBox::toggled, this, readOptions);

  m_params = new ParameterPanel(this);
  connect(m_params, &ParameterPanel::settingsEdited, this, [this](const RunSettings& s) {
    m_settings = s;
    m_plots->setBreathPeriod(60.0 / s.style.breathsPerMinute);
    if (m_worker) m_worker->requestSettings(s);
    showPosture();
  });

  connect(m_params, &ParameterPanel::magnificationEdited, this,
          [this](double factor) { setMagnification(factor); });

  auto* tabs = new QTabWidget(this);
  auto* displayScroll = new QScrollArea(this);
  displayScroll->setWidget(display);
  displayScroll->setWidgetResizable(true);
  displayScroll->setFrameShape(QFrame::NoFrame);
  displayScroll->setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
  tabs->addTab(displayScroll, "Display");
  tabs->addTab(m_params, "Parameters");
  auto* leftDock = new QDockWidget("Controls", this);
  leftDock->setObjectName("controls");
  leftDock->setFeatures(QDockWidget::DockWidgetMovable | QDockWidget::DockWidgetFloatable);
  leftDock->setWidget(tabs);
  addDockWidget(Qt::LeftDockWidgetArea, leftDock);
  resizeDocks({leftDock, plotDock}, {262, 400}, Qt::Horizontal);

  // left, below: what the opened scenario is about (teaching presets explain what to watch)
  m_scenarioNote = new QLabel(this);
  m_scenarioNote->setWordWrap(true);
  m_scenarioNote->setTextFormat(Qt::PlainText);
  m_scenarioNote->setAlignment(Qt::AlignTop | Qt::AlignLeft);
  m_scenarioNote->setMargin(6);
  auto* noteScroll = new QScrollArea(this);
  noteScroll->setWidget(m_scenarioNote);
  noteScroll->setWidgetResizable(true);
  noteScroll->setFrameShape(QFrame::NoFrame);
  noteScroll->setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
  m_scenarioDock = new QDockWidget("Scenario", this);
  m_scenarioDock->setObjectName("scenario");
  m_scenarioDock->setFeatures(QDockWidget::DockWidgetMovable | QDockWidget::DockWidgetFloatable |
                              QDockWidget::DockWidgetClosable);
  m_scenarioDock->setWidget(noteScroll);
  addDockWidget(Qt::LeftDockWidgetArea, m_scenarioDock);
  m_scenarioDock->hide();
}

void MainWindow::syncDisplayWidgets() {
  const viz::DisplayOptions& o = m_scene->options();
  const std::vector<QSignalBlocker> blockers = [&] {
    std::vector<QSignalBlocker> b;
    b.emplace_back(m_muscleColour);
    b.emplace_back(m_gutColour);
    b.emplace_back(m_skinDisplay);
    b.emplace_back(m_skinColour);
    for (const auto& [check, flag] : m_structureChecks) b.emplace_back(check);
    for (QCheckBox* c : m_groupChecks) b.emplace_back(c);
    return b;
  }();
  m_muscleColour->setCurrentIndex(m_muscleColour->findData(static_cast<int>(o.muscleColouring)));
  m_gutColour->setCurrentIndex(m_gutColour->findData(static_cast<int>(o.gutColouring)));
  m_skinDisplay->setCurrentIndex(m_skinDisplay->findData(static_cast<int>(o.skin)));
  m_skinColour->setCurrentIndex(m_skinColour->findData(static_cast<int>(o.skinColouring)));
  for (const auto& [check, flag] : m_structureChecks) check->setChecked(o.*flag);
  for (std::size_t g = 0; g < m_groupChecks.size(); ++g) m_groupChecks[g]->setChecked(o.showGroup[g]);
}

void MainWindow::setDisplayOptions(const viz::DisplayOptions& options) {
  m_scene->setOptions(options);
  m_params->setMagnification(options.magnification);
  syncDisplayWidgets();
  // the playback's own pose (its weights, magnified anew), not the paused physics'
  if (m_player)
    m_scene->updateMorphPlayback(*m_morphs, m_player->weightsAt(*m_morphs, m_playbackTime));
  else if (m_shown)
    poseScene(*m_shown);
  m_view->renderWindow()->Render();
}

void MainWindow::poseScene(const Snapshot& s) {
  if (s.model != m_document.model()) return;
  m_scene->update(s.state, s.metrics, s.endExpiration.get());
  // the compared run's ghost at the same instant, magnified about its own breath's end-expiration
  const RunGhost& ghost = m_plots->overlay().ghost;
  const sim::State* at = ghost.at(s.state.time);
  m_scene->setGhost(at, at ? ghost.endExpirationAt(s.state.time) : nullptr);
}

QString MainWindow::modelStatus() const {
  if (!m_document.model()) return m_modelText;
  return m_modelText + QString(", posture %1").arg(sim::postureName(m_settings.options.step.posture));
}

void MainWindow::showPosture() {
  if (!m_messageTimer->isActive()) m_statusModel->setText(modelStatus());
}

void MainWindow::showMessage(const QString& text, int milliseconds) {
  m_statusModel->setText(text);
  m_messageTimer->start(milliseconds);
}

void MainWindow::report(const QString& title, const QString& message) {
  m_lastError = message;
  showMessage(title + ": " + message, 15000);
  std::fprintf(stderr, "pneuma: %s: %s\n", qPrintable(title), qPrintable(message));
  // non-blocking dialog: the run and the tests go on
  auto* box = new QMessageBox(QMessageBox::Warning, title, message, QMessageBox::Ok, this);
  box->setAttribute(Qt::WA_DeleteOnClose);
  box->open();
}

QString MainWindow::openModel(const QString& dir) {
  DocumentController::OpenedModel opened;
  try {
    // load and validate everything before touching the current run
    opened = DocumentController::readModel(dir, m_settings);
    m_scene->setModel(*opened.model, dir.toStdString());
  } catch (const std::exception& e) {
    const QString message = QString("Cannot open model '%1': %2").arg(dir, e.what());
    report("Model not loaded", message);
    return message;
  }
  // a comparison run belongs to the previous model
  if (QFileInfo(opened.dir).canonicalFilePath() != QFileInfo(m_document.modelDir()).canonicalFilePath())
    m_plots->setOverlay({});
  m_document.adopt(opened);
  // the morph targets belong to the previous model
  setMorphPlayback(false);
  m_morphs.reset();
  updatePlaybackAction();
  m_drive = nullptr;  // a new model starts with the breath style
  showDriver();
  const std::shared_ptr<const sim::Model>& model = opened.model;
  m_selected = {};
  m_plots->clearTraces();
  m_params->setSettings(m_settings, model);
  m_plots->setBreathPeriod(60.0 / m_settings.style.breathsPerMinute);
  // the nodes: the gut's, and the volume bodies' (pectorals, shoulders) counted apart
  const auto tissueNodes =
      std::count(model->nodes.region.begin(), model->nodes.region.end(), sim::NodeRegion::Tissue);
  m_modelText = QString("Model: %1 (%2 bodies, %3 elements, %4 gut nodes")
                    .arg(QString::fromStdString(model->name))
                    .arg(model->bodies.size())
                    .arg(model->elements.size())
                    .arg(model->nodes.size() - tissueNodes);
  if (tissueNodes > 0) m_modelText += QString(", %1 tissue nodes").arg(tissueNodes);
  m_modelText += ")";
  m_statusModel->setText(modelStatus());
  setWindowTitle(QString("Pneuma \u2014 %1").arg(QString::fromStdString(model->name)));

  if (!m_worker) {
    m_worker = new SimWorker(model, std::move(opened.simulation), m_settings);
    m_worker->setSpeed(m_speedCombo->currentData().toDouble());
    m_worker->moveToThread(&m_thread);
    m_thread.setObjectName(kSimulationThread);  // the OS thread's name: pneuma --measure finds its CPU time
    connect(&m_thread, &QThread::started, m_worker, &SimWorker::start);
    connect(&m_thread, &QThread::finished, m_worker, &SimWorker::stop);
    connect(&m_thread, &QThread::finished, m_worker, &QObject::deleteLater);
    connect(m_worker, &SimWorker::status, this,
            [this](const QString& message) { showMessage(message, 8000); });
    connect(m_worker, &SimWorker::failed, this, [this](const QString& message) {
      m_playAction->setChecked(false);
      report("Simulation stopped", message);
    });
    m_thread.start();
  } else {
    m_worker->requestSimulation(model, std::move(opened.simulation), m_settings);
  }
  m_view->renderWindow()->Render();
  return {};
}

QString MainWindow::openScenario(const QString& path) {
  DocumentController::OpenedScenario scenario;
  try {
    scenario = DocumentController::readScenario(path, m_settings);
  } catch (const std::exception& e) {
    const QString message = QString("Cannot open scenario '%1': %2").arg(path, e.what());
    report("Scenario not loaded", message);
    return message;
  }
  const RunSettings previous = m_settings;
  m_settings = scenario.settings;
  const QString error = openModel(scenario.modelDir);
  if (!error.isEmpty()) {
    m_settings = previous;
    return error;
  }
  m_drive = scenario.drive;
  if (m_drive) {
    m_worker->requestScenario(m_drive);
    if (m_drive->controller == sim::ControllerKind::Affect) {
      const QSignalBlocker blockAffect(m_affectCombo);
      m_affectCombo->setCurrentText(QString::fromStdString(m_drive->controllerName));
    }
  }
  showDriver();
  m_scenarioNote->setText(scenario.description.isEmpty() ? scenario.name
                                                         : scenario.name + "\n\n" + scenario.description);
  m_scenarioDock->show();
  showMessage(QString("Scenario '%1' loaded").arg(scenario.name), 5000);
  return {};
}

QStringList MainWindow::teachingPresets() {
  const QDir dir(QString::fromStdString(sim::resourceDir()) + "/scenarios/teaching");
  QStringList paths;
  for (const QString& name : dir.entryList({"*.json"}, QDir::Files, QDir::Name)) paths << dir.filePath(name);
  return paths;
}

QString MainWindow::openTeachingPreset(const QString& path) {
  const QString error = openScenario(path);
  if (!error.isEmpty()) return error;
  return overlayScenario(QString::fromStdString(sim::resourceDir()) + "/scenarios/calm.json");
}

QString MainWindow::scenarioExplanation() const { return m_scenarioNote->text(); }

QString MainWindow::overlayScenario(const QString& path) {
  if (!m_document.model()) return "No model open";
  QProgressDialog progress(QString("Running %1 to compare\u2026").arg(QFileInfo(path).fileName()), "Cancel",
                           0, 1000, this);
  progress.setWindowModality(Qt::WindowModal);
  progress.setMinimumDuration(300);
  RunOverlay overlay;
  try {
    overlay = runScenarioOverlay(path, m_document.model(), m_document.modelDir(), [&](double fraction) {
      progress.setValue(static_cast<int>(std::lround(1000.0 * fraction)));
      QApplication::processEvents();
      return !progress.wasCanceled();
    });
  } catch (const std::exception& e) {
    const QString message = QString("Cannot compare with '%1': %2").arg(path, e.what());
    report("No comparison", message);
    return message;
  }
  if (overlay.samples.empty()) return "cancelled";
  const QString name = overlay.name;
  m_plots->setOverlay(std::move(overlay));
  setDisplayOptions(m_scene->options());  // the ghost
  showMessage(QString("Comparing with '%1' (dashed, and its ghost in the 3D view)").arg(name), 5000);
  return {};
}

QString MainWindow::overlayRecording(const QString& path) {
  if (!m_document.model()) return "No model open";
  try {
    RunOverlay overlay = readRecordingOverlay(path, *m_document.model());
    const QString name = overlay.name;
    m_plots->setOverlay(std::move(overlay));
    showMessage(QString("Comparing with the recording '%1' (dashed)").arg(name), 5000);
  } catch (const std::exception& e) {
    const QString message = QString("Cannot compare with '%1': %2").arg(path, e.what());
    report("No comparison", message);
    return message;
  }
  return {};
}

void MainWindow::clearOverlay() {
  m_plots->setOverlay({});
  setDisplayOptions(m_scene->options());  // no ghost
}

QString MainWindow::openTrace(const QString& path) {
  if (!m_worker) return "no model is open";
  std::shared_ptr<const sim::Scenario> drive;
  try {
    drive = DocumentController::readTrace(path);
  } catch (const std::exception& e) {
    const QString message = QString("Cannot open trace '%1': %2").arg(path, e.what());
    report("Trace not loaded", message);
    return message;
  }
  m_drive = std::move(drive);
  m_worker->requestScenario(m_drive);
  showDriver();
  showMessage(QString("Following trace '%1'").arg(QFileInfo(path).fileName()), 5000);
  return {};
}

QString MainWindow::saveScenario(const QString& path) {
  try {
    m_document.saveScenario(path, m_settings, m_drive.get());
  } catch (const std::exception& e) {
    const QString message = QString("Cannot save scenario '%1': %2").arg(path, e.what());
    report("Scenario not saved", message);
    return message;
  }
  showMessage(QString("Scenario saved to %1").arg(path), 5000);
  return {};
}

QString MainWindow::setBreathStyle(const QString& name) {
  try {
    m_settings.style = sim::loadBreathStyle(name.toStdString());
  } catch (const sim::Error& e) {
    report("Unknown breath style", e.what());
    return e.what();
  }
  m_drive = nullptr;
  m_params->setSettings(m_settings, m_document.model());
  showDriver();
  m_plots->setBreathPeriod(60.0 / m_settings.style.breathsPerMinute);
  if (m_worker) m_worker->requestSettings(m_settings);
  return {};
}

QString MainWindow::setPosture(const QString& name) {
  if (!sim::postureFromName(name.toStdString(), m_settings.options.step.posture)) {
    const QString error = QString("unknown posture '%1' (valid: %2)")
                              .arg(name.left(60), QString::fromStdString(sim::postureNames()));
    report("Unknown posture", error);
    return error;
  }
  m_params->setSettings(m_settings, m_document.model());
  if (m_worker) m_worker->requestSettings(m_settings);
  showPosture();
  return {};
}

QString MainWindow::pushAffect(const QString& name, bool isImmediate) {
  if (m_affectCombo->findText(name) < 0) {
    QStringList valid;
    for (int i = 0; i < m_affectCombo->count(); ++i) valid << m_affectCombo->itemText(i);
    const QString error = QString("unknown affect '%1' (valid: %2)").arg(name, valid.join(", "));
    report("Unknown affect", error);
    return error;
  }
  m_affectCombo->setCurrentText(name);
  if (!m_worker) return "no model is open";
  m_worker->requestAffect(name.toStdString(), isImmediate ? sim::pattern::SwitchMode::Immediate
                                                          : sim::pattern::SwitchMode::EndOfCycle);
  // saved with the scenario: the affect pushed last
  auto drive = std::make_shared<sim::Scenario>();
  drive->name = name.toStdString();
  drive->controller = sim::ControllerKind::Affect;
  drive->controllerName = name.toStdString();
  m_drive = std::move(drive);
  showDriver();
  showMessage(
      QString("Affect '%1' pushed %2").arg(name, isImmediate ? "immediately" : "for the end of the cycle"),
      5000);
  return {};
}

QString MainWindow::setMagnification(double factor) {
  const std::string error = viz::magnificationError(factor);
  if (!error.empty()) {
    report("Motion magnification refused", QString::fromStdString(error));
    return QString::fromStdString(error);
  }
  viz::DisplayOptions o = m_scene->options();
  o.magnification = factor;
  setDisplayOptions(o);
  return {};
}

void MainWindow::showDriver() {
  QString driver;
  if (m_drive && m_drive->controller != sim::ControllerKind::Style) {
    const std::string& name = m_drive->controllerName.empty() ? m_drive->name : m_drive->controllerName;
    driver = QString("%1 '%2'").arg(sim::controllerKindName(m_drive->controller),
                                    QFileInfo(QString::fromStdString(name)).completeBaseName());
  }
  // the style box: the style in play, or a disabled entry naming what drives instead of it
  const QSignalBlocker block(m_styleCombo);
  const int previous = m_styleCombo->findData(kDriverItem);
  if (previous >= 0) m_styleCombo->removeItem(previous);
  if (driver.isEmpty()) {
    m_styleCombo->setCurrentText(QString::fromStdString(m_settings.style.name));
  } else {
    m_styleCombo->addItem(driver, kDriverItem);
    const int index = m_styleCombo->count() - 1;
    if (auto* items = qobject_cast<QStandardItemModel*>(m_styleCombo->model()))
      items->item(index)->setEnabled(false);
    m_styleCombo->setCurrentIndex(index);
  }
  m_params->setDriver(driver);
}

void MainWindow::play() { m_playAction->setChecked(true); }

void MainWindow::updatePlaybackAction() {
  const sim::Model* m = model();
  const bool hasSkin = m && m->skin.vertexCount() > 0;
  m_playbackAction->setEnabled(hasSkin);
  QString tip =
      "Play the toolbar's affect on the skin's baked morph targets alone, without physics (de Melo "
      "et al. 2010)";
  if (!m) tip = "Morph playback needs a model with a skin: no model is open";
  if (m && !hasSkin)
    tip = QString("Morph playback needs a skin: model '%1' has none (rebuild it with pneuma-cli model build)")
              .arg(QString::fromStdString(m->name));
  m_playbackAction->setToolTip(tip);
}

QString MainWindow::setMorphPlayback(bool isOn) {
  const QSignalBlocker block(m_playbackAction);
  m_playbackAction->setChecked(false);
  if (!isOn) {
    m_player.reset();
    m_scene->setMorphPlayback("");
    if (m_shown) showSnapshot(m_shown);
    return {};
  }
  const sim::Model* m = model();
  if (!m_worker || !m) return "morph playback: no model is open";
  if (m->skin.vertexCount() == 0)
    return QString("morph playback: model '%1' has no skin").arg(QString::fromStdString(m->name));
  pause();
  if (!m_morphs) {
    // the SimWorker's bake, shared with the glTF export: at most once per model
    QEventLoop loop;
    QString error;
    auto done = connect(m_worker, &SimWorker::morphTargetsReady, &loop, [&](const QString& e) {
      error = e;
      loop.quit();
    });
    m_worker->requestMorphTargets();
    loop.exec();
    disconnect(done);
    m_morphs = m_worker->morphTargets();
    if (!m_morphs) {
      report("Morph playback", "Cannot bake the morph targets: " + error);
      return "morph playback: " + error;
    }
  }
  const QString affect = m_affectCombo->currentText();
  try {
    m_player = std::make_unique<sim::MorphPlayer>(
        sim::pattern::loadAffect(affect.toStdString(), sim::resourceDir()), 0);
  } catch (const std::exception& e) {
    m_player.reset();
    report("Morph playback", e.what());
    return QString("morph playback: ") + e.what();
  }
  m_playbackAction->setChecked(true);
  m_scene->setMorphPlayback(affect.toStdString());
  m_playbackTime = 0.0;
  showMorphPlaybackAt(0.0);
  return {};
}

void MainWindow::showMorphPlaybackAt(double t) {
  if (!m_player) return;
  if (t < m_playbackTime) setMorphPlayback(true);  // back in time: the pattern from its start
  QElapsedTimer clock;
  clock.start();
  m_scene->updateMorphPlayback(*m_morphs, m_player->weightsAt(*m_morphs, t));
  m_view->renderWindow()->Render();
  countRender(clock.nsecsElapsed());
  m_playbackTime = t;
  m_playbackFrom = t;
  m_playbackClock.restart();
  m_statusTime->setText(QString("  playback t = %1 s  ").arg(t, 0, 'f', 2));
}

void MainWindow::setSpeed(double speed) {
  const int i = m_speedCombo->findData(speed);
  if (i >= 0)
    m_speedCombo->setCurrentIndex(i);
  else if (m_worker)
    m_worker->setSpeed(speed);
}

void MainWindow::pause() { m_playAction->setChecked(false); }

bool MainWindow::runUntil(double time, int timeoutMs) {
  if (!m_worker) return false;
  QEventLoop loop;
  bool isDone = false;
  auto reached = connect(m_worker, &SimWorker::targetReached, &loop, [&] {
    isDone = true;
    loop.quit();
  });
  auto failed = connect(m_worker, &SimWorker::failed, &loop, [&] { loop.quit(); });
  QTimer::singleShot(timeoutMs, &loop, &QEventLoop::quit);
  {
    const QSignalBlocker block(m_playAction);
    m_playAction->setChecked(true);
  }
  m_worker->requestRunUntil(time);
  loop.exec();
  disconnect(reached);
  disconnect(failed);
  pause();
  refresh();
  return isDone;
}

bool MainWindow::scrubTo(double time, int timeoutMs) {
  if (!m_worker) return false;
  pause();
  // the instant shown before does not count, even when it was scrubbed to (a movie's previous frame)
  const Snapshot* before = m_shown.get();
  m_worker->requestScrub(time);
  QElapsedTimer clock;
  clock.start();
  while (clock.elapsed() < timeoutMs) {
    QApplication::processEvents(QEventLoop::AllEvents, 10);
    refresh();
    if (m_shown && m_shown.get() != before && m_shown->isScrubbed) return true;
  }
  return false;
}

void MainWindow::refresh() {
  if (!m_worker) return;
  if (m_player) {
    // morph playback: a frame at every refresh, on the wall clock
    showMorphPlaybackAt(m_playbackFrom + static_cast<double>(m_playbackClock.nsecsElapsed()) * 1e-9);
  } else {
    Frame frame = m_worker->take();
    if (!frame.snapshot) return;
    const bool isNew = frame.snapshot != m_shown;
    if (frame.snapshot->generation != m_generation) {
      m_plots->clear();
      m_generation = frame.snapshot->generation;
    }
    m_plots->append(std::move(frame.samples));
    // a slow 3D render (software GL) waits its turn so that the plots keep the refresh rate
    const bool isDue = !frame.snapshot->isRunning || m_renderMs <= kRenderEveryRefreshMs ||
                       m_sinceRender.elapsed() >= 1.5 * m_renderMs;
    if (isNew && isDue) showSnapshot(frame.snapshot);
    if (m_plots->refresh()) {
      ++m_plotFrames;
      ++m_totalPlotFrames;
    }
  }

  // rates over one-second windows
  const qint64 now = QDateTime::currentMSecsSinceEpoch();
  if (now - m_fpsWindowStart >= 1000) {
    const double seconds = static_cast<double>(now - m_fpsWindowStart) / 1000.0;
    m_fps = m_framesRendered / seconds;
    m_plotHz = m_plotFrames / seconds;
    m_framesRendered = m_plotFrames = 0;
    m_fpsWindowStart = now;
    m_statusFps->setText(
        QString("  3D %1 fps \u00b7 plots %2 Hz  ").arg(m_fps, 0, 'f', 0).arg(m_plotHz, 0, 'f', 0));
  }
}

QSize MainWindow::viewSize() const { return m_view->size(); }

void MainWindow::countRender(qint64 nanoseconds) {
  const double ms = static_cast<double>(nanoseconds) * 1e-6;
  m_renderMs = 0.9 * m_renderMs + 0.1 * ms;
  ++m_framesRendered;
  ++m_totalFrames;
  m_totalRenderMs += ms;
}

void MainWindow::restartRates() {
  m_ratesClock.start();
  m_processCpuAtStart = processCpuSeconds();
  m_simulationCpuAtStart = threadCpuSeconds(kSimulationThread);
  m_totalFrames = m_totalPlotFrames = 0;
  m_totalRenderMs = 0.0;
}

MainWindow::Rates MainWindow::rates() const {
  const double seconds =
      m_ratesClock.isValid() ? static_cast<double>(m_ratesClock.nsecsElapsed()) * 1e-9 : 0.0;
  if (!(seconds > 0.0)) return {};
  const double simulationCpu = threadCpuSeconds(kSimulationThread) - m_simulationCpuAtStart;  // [s]
  const double displayCpu = processCpuSeconds() - m_processCpuAtStart - simulationCpu;        // [s]
  return {m_totalFrames / seconds, m_totalPlotFrames / seconds,
          m_totalFrames > 0 ? m_totalRenderMs / m_totalFrames : 0.0,
          m_totalFrames > 0 ? 1e3 * displayCpu / m_totalFrames : 0.0, simulationCpu / seconds};
}

QString MainWindow::breathingReadout() const { return m_breathing->text(); }

void MainWindow::showSnapshot(std::shared_ptr<const Snapshot> snapshot) {
  m_shown = std::move(snapshot);
  const Snapshot& s = *m_shown;
  QElapsedTimer clock;
  clock.start();
  poseScene(s);
  m_view->renderWindow()->Render();
  countRender(clock.nsecsElapsed());
  m_sinceRender.restart();

  m_plots->setBreaths(s.endExpirationTimes);
  m_plots->setCursor(s.isScrubbed ? s.metrics.time : std::numeric_limits<double>::quiet_NaN());
  m_statusTime->setText(
      QString("  t = %1 s%2  ").arg(s.state.time, 0, 'f', 2).arg(s.isScrubbed ? " (recorded)" : ""));
  m_statusRtf->setText(s.isRunning ? QString("  Real-time factor %1  ").arg(s.realTimeFactor, 0, 'f', 2)
                                   : QString("  Paused  "));
  if (s.isRunning != m_playAction->isChecked() && !s.isRunning && !s.isScrubbed) {
    const QSignalBlocker block(m_playAction);
    m_playAction->setChecked(false);
    m_playAction->setText("Play");
    m_playAction->setIcon(style()->standardIcon(QStyle::SP_MediaPlay));
  }
  updateTimeline();
  m_breathing->setText(breathingText(s.breathing.get()));

  // keep the selection read-out live
  if (m_selected.kind != viz::Pick::Kind::None) select(m_selected);
}

void MainWindow::updateTimeline() {
  const Snapshot& s = *m_shown;
  const double span = s.recordedTo - s.recordedFrom;
  if (!m_timeline->isSliderDown()) {
    const QSignalBlocker block(m_timeline);
    m_timeline->setValue(
        span > 0.0 ? static_cast<int>(std::lround(1000.0 * (s.metrics.time - s.recordedFrom) / span)) : 1000);
  }
  m_timeLabel->setText(
      QString("t = %1 s of %2 s").arg(s.metrics.time, 0, 'f', 2).arg(s.recordedTo, 0, 'f', 2));
}

void MainWindow::select(const viz::Pick& pick) {
  const bool isNewSelection = pick.kind != m_selected.kind || pick.index != m_selected.index;
  m_selected = pick;
  if (isNewSelection) m_scene->setHighlight(pick);
  if (pick.kind == viz::Pick::Kind::None || !m_document.model() || !m_shown) {
    m_selection->setText("Click a muscle element or a bone in the 3D view.");
    return;
  }
  // the elements whose tension the selection reports [N]
  LivePlots::Trace trace;
  trace.name = QString::fromStdString(m_scene->describe(pick));
  if (pick.kind == viz::Pick::Kind::Element) {
    trace.elements = {pick.index};
  } else {
    const sim::Elements& e = m_document.model()->elements;
    for (int i = 0; i < e.size(); ++i)
      if (e.endA.body[static_cast<std::size_t>(i)] == pick.index ||
          e.endB.body[static_cast<std::size_t>(i)] == pick.index)
        trace.elements.push_back(i);
  }
  double tension = 0.0;
  const Eigen::VectorXd& f = m_shown->metrics.elementForce;
  for (int i : trace.elements)
    if (i < f.size()) tension += std::max(0.0, -f(i));
  const QString what =
      pick.kind == viz::Pick::Kind::Element
          ? (tension > 0.0 ? QString("tension %1 N").arg(tension, 0, 'f', 2) : QString("slack (0 N)"))
          : QString("attached muscle tension %1 N (%2 elements)")
                .arg(tension, 0, 'f', 2)
                .arg(trace.elements.size());
  m_selection->setText(QString("<b>%1</b><br>%2").arg(trace.name, what));
  if (isNewSelection) {
    m_plots->addTrace(trace);
    showMessage(QString("Selected %1: %2").arg(trace.name, what), 5000);
  }
}

void MainWindow::pickAt(const QPoint& viewPos) {
  const double ratio = m_view->devicePixelRatioF();
  const int x = static_cast<int>(viewPos.x() * ratio);
  const int y = static_cast<int>((m_view->height() - viewPos.y() - 1) * ratio);
  select(m_scene->pick(x, y));
  m_view->renderWindow()->Render();
}

bool MainWindow::eventFilter(QObject* watched, QEvent* event) {
  // a click (press and release without dragging) in the 3D view picks; drags rotate the camera
  if (watched == m_view) {
    if (event->type() == QEvent::MouseButtonPress) {
      m_pressPos = static_cast<QMouseEvent*>(event)->pos();
    } else if (event->type() == QEvent::MouseButtonRelease) {
      const auto* mouse = static_cast<QMouseEvent*>(event);
      if (mouse->button() == Qt::LeftButton && (mouse->pos() - m_pressPos).manhattanLength() < 4)
        pickAt(mouse->pos());
    }
  }
  return QMainWindow::eventFilter(watched, event);
}

void MainWindow::closeEvent(QCloseEvent* event) {
  m_refresh->stop();
  m_thread.quit();
  m_thread.wait();
  event->accept();
}

void MainWindow::exportPlotInteractive(const PlotView* plot) {
  const QString path = QFileDialog::getSaveFileName(
      this, QString("Export plot \u201c%1\u201d").arg(plot->title()),
      plot->title().toLower().replace(' ', '-') + ".png",
      "PNG image (*.png);;SVG vector image (*.svg);;PDF document (*.pdf);;CSV data (*.csv)");
  if (!path.isEmpty()) exportPlot(plot, path);
}

QString MainWindow::exportPlot(const PlotView* plot, const QString& path) {
  return m_export->exportPlot(plot, path);
}

QString MainWindow::exportViewImage(const QString& path) { return m_export->exportViewImage(path); }

QString MainWindow::exportAnimation(const QString& path, const ExportController::MovieOptions& options) {
  if (!m_worker) return m_export->exportAnimation(path, {});  // refused: nothing recorded
  return m_export->exportAnimation(path, options, this);
}

QString MainWindow::exportRun(const QString& pvdPath, const viz::SeriesRange& range) {
  return m_export->exportRun(m_worker, m_document.modelDir(), pvdPath, range, this);
}

QString MainWindow::exportGltf(const QString& path) {
  return m_export->exportGltf(m_worker, m_document.modelDir(), path, false);
}

QString MainWindow::bakeMorphTargets(const QString& path) {
  return m_export->exportGltf(m_worker, m_document.modelDir(), path, true);
}

QImage MainWindow::grabView() {
  m_view->renderWindow()->Render();
  return m_view->grabFramebuffer();
}

QImage MainWindow::grabWindow() {
  m_view->renderWindow()->Render();
  return grab().toImage();
}

}  // namespace pneuma::app
