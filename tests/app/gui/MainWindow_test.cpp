// What the user sees in the main window, asserted on grabs, widgets and exported files under Xvfb.
// The run uses the sim tests' toy torso (every part of the default model at a tenth of the size).

#include "gui/MainWindow.h"

#include <gtest/gtest.h>
#include <vtkCaptionActor2D.h>
#include <vtkCoordinate.h>
#include <vtkPropCollection.h>
#include <vtkRenderer.h>

#include <QAction>
#include <QCheckBox>
#include <QComboBox>
#include <QFile>
#include <QLabel>
#include <QLineEdit>
#include <QRegularExpression>
#include <QStatusBar>
#include <QSvgRenderer>
#include <QTextStream>
#include <cmath>
#include <set>

#include "../cli/CliRunner.h"
#include "GuiTestSupport.h"
#include "gui/LivePlots.h"
#include "gui/ParameterPanel.h"
#include "gui/PlotView.h"
#include "pneuma/sim/Metrics.h"
#include "viz/GltfWriter.h"

using namespace pneuma;
using namespace pneuma::app::test;
using pneuma::app::MainWindow;

namespace {

// a window running the toy torso
struct ToyWindow {
  QApplication& qt = application();  // before any widget
  QTemporaryDir dir;
  QString modelDir;
  MainWindow window;
  ToyWindow() {
    modelDir = writeToyModel(dir);
    window.show();
    QApplication::processEvents();
    EXPECT_EQ(window.openModel(modelDir), QString());
  }
};

// a shown window with the default model open; skips when the default model has not been built
class DefaultModelWindow : public ::testing::Test {
 protected:
  void SetUp() override {
    const QString modelDir = defaultModelDir();
    if (modelDir.isEmpty()) GTEST_SKIP() << "no default model at " << PNEUMA_DEFAULT_MODEL_DIR;
    window.show();
    ASSERT_EQ(window.openModel(modelDir), QString());
  }
  QApplication& qt = application();  // before any widget
  MainWindow window;
};

// the breathing rate [1/min] measured from the lung volume the volume plot holds, from time `from` [s]:
// the volume low-passed by a centred 0.4 s moving average (it removes the few-hertz wobble of the
// ribcage, far above any breathing rate), then the sim's own cycle analysis (sim::summarize)
double plottedRate(const app::PlotView& plot, double from) {
  const std::vector<double>& t = plot.time();
  const std::vector<double>& v = plot.series()[0].y;
  sim::Trace trace;
  std::size_t lo = 0, hi = 0;
  double sum = 0.0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    while (hi < t.size() && t[hi] <= t[k] + 0.2) sum += v[hi++];
    while (t[lo] < t[k] - 0.2) sum -= v[lo++];
    sim::Metrics m;
    m.time = t[k];
    m.lungVolume = sum / static_cast<double>(hi - lo);
    trace.append(m);
  }
  return sim::summarize(trace, {}, from).breathsPerMinute;
}

}  // namespace

TEST(MainWindow, ViewRendersBackdropAndAxes) {
  application();
  MainWindow window;
  window.show();
  QApplication::processEvents();

  // the gradient backdrop alone gives dozens of shades; a blank or failed GL view gives one or two
  const QImage view = window.grabView();
  ASSERT_FALSE(view.isNull());
  EXPECT_GT(view.width(), 200);
  EXPECT_GT(distinctColours(view), 20);

  // the whole-window grab includes the view, not a black hole where GL should be
  EXPECT_GT(distinctColours(window.grabWindow()), 20);
}

TEST(MainWindow, InhaleShowsForceColouredMusclesAndHidingThemRemovesThem) {
  ToyWindow w;
  // the rest pose, before any force acts: every element slack, grey
  const int atRest = forceColouredPixels(w.window.grabView());

  // during inhale (the controller starts after the 2 s settling phase) taut muscles take colour
  ASSERT_TRUE(w.window.runUntil(3.0));
  const int inhale = forceColouredPixels(w.window.grabView());
  EXPECT_GT(inhale, 500);
  EXPECT_GT(inhale, 10 * (atRest + 10));

  // all muscle groups hidden: no force colour left anywhere in the view
  viz::DisplayOptions o = w.window.scene().options();
  o.showGroup.fill(false);
  w.window.setDisplayOptions(o);
  EXPECT_LT(forceColouredPixels(w.window.grabView()), inhale / 200);

  // colour by group: the diaphragm's rust stays, the force scale is gone
  o.showGroup.fill(true);
  o.muscleColouring = viz::MuscleColouring::Group;
  w.window.setDisplayOptions(o);
  EXPECT_LT(forceColouredPixels(w.window.grabView()), inhale);
}

// the two lungs are drawn (translucent, inside the rib cage) and the "Lungs" check box hides them
TEST_F(DefaultModelWindow, LungsAreDrawnAndTheirCheckBoxHidesThem) {
  viz::DisplayOptions o = window.scene().options();
  EXPECT_TRUE(o.showLungs);
  o.showBones = o.showGut = o.showLandmarks = false;
  o.skin = viz::SkinDisplay::Hidden;
  o.showGroup.fill(false);
  window.setDisplayOptions(o);
  const QImage with = window.grabView();
  QCheckBox* box = nullptr;
  for (QCheckBox* c : window.findChildren<QCheckBox*>())
    if (c->text() == "Lungs") box = c;
  ASSERT_NE(box, nullptr);
  EXPECT_TRUE(box->isChecked());
  box->click();
  QApplication::processEvents();
  EXPECT_FALSE(window.scene().options().showLungs);
  const QImage without = window.grabView();
  ASSERT_EQ(with.size(), without.size());
  // the lungs cover a good part of the view; where they are, the backdrop shows through them (translucent)
  int covered = 0;
  for (int y = 0; y < with.height(); ++y)
    for (int x = 0; x < with.width(); ++x) {
      const QColor a = with.pixelColor(x, y), b = without.pixelColor(x, y);
      covered +=
          std::abs(a.red() - b.red()) + std::abs(a.green() - b.green()) + std::abs(a.blue() - b.blue()) > 30;
    }
  EXPECT_GT(covered, with.width() * with.height() / 50);
}

// pixels that differ by more than 30 (sum over RGB) between two grabs of the view
int differing(const QImage& a, const QImage& b) {
  int n = 0;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x) {
      const QColor p = a.pixelColor(x, y), q = b.pixelColor(x, y);
      n += std::abs(p.red() - q.red()) + std::abs(p.green() - q.green()) + std::abs(p.blue() - q.blue()) > 30;
    }
  return n;
}

// the skin: translucent by default, its combo box makes it opaque (a body covering a good part of the view)
// or hides it; translucent, the rib cage and muscles inside show through (the grab differs from the opaque
// one)
TEST_F(DefaultModelWindow, SkinShowsTheBodyAndTheRibCageThroughIt) {
  EXPECT_EQ(window.scene().options().skin, viz::SkinDisplay::Translucent);
  QComboBox* combo = nullptr;
  for (QComboBox* c : window.findChildren<QComboBox*>())
    if (c->findText("Opaque") >= 0) combo = c;
  ASSERT_NE(combo, nullptr);
  const QImage translucent = window.grabView();
  combo->setCurrentIndex(combo->findText("Opaque"));
  QApplication::processEvents();
  EXPECT_EQ(window.scene().options().skin, viz::SkinDisplay::Opaque);
  const QImage opaque = window.grabView();
  combo->setCurrentIndex(combo->findText("Hidden"));
  QApplication::processEvents();
  EXPECT_EQ(window.scene().options().skin, viz::SkinDisplay::Hidden);
  const QImage hidden = window.grabView();
  ASSERT_EQ(opaque.size(), hidden.size());
  const int area = opaque.width() * opaque.height();
  EXPECT_GT(differing(opaque, hidden), area / 10) << "the opaque body covers the view's middle";
  EXPECT_GT(differing(translucent, opaque), area / 50) << "the inside shows through the translucent skin";
}

TEST(MainWindow, ExportedPlotFilesHoldThePlottedData) {
  ToyWindow w;
  ASSERT_TRUE(w.window.runUntil(2.5));
  const app::PlotView* plot = w.window.plots()->volumePlot();
  ASSERT_GT(plot->time().size(), 100u);
  QTemporaryDir out;

  // csv: a units header and exactly the plotted samples
  ASSERT_EQ(w.window.exportPlot(plot, out.filePath("volume.csv")), QString());
  QFile csv(out.filePath("volume.csv"));
  ASSERT_TRUE(csv.open(QIODevice::ReadOnly));
  const QStringList lines = QString::fromUtf8(csv.readAll()).split('\n', Qt::SkipEmptyParts);
  ASSERT_EQ(static_cast<std::size_t>(lines.size()), plot->time().size() + 1);
  EXPECT_EQ(lines[0], "time [s],lung volume [mL]");
  for (std::size_t k = 0; k < plot->time().size(); k += 37) {
    const QStringList cells = lines[static_cast<int>(k) + 1].split(',');
    ASSERT_EQ(cells.size(), 2);
    EXPECT_NEAR(cells[0].toDouble(), plot->time()[k], 1e-9);
    EXPECT_NEAR(cells[1].toDouble(), plot->series()[0].y[k], 1e-6);
  }

  // svg: valid, titled, and drawing the curve
  ASSERT_EQ(w.window.exportPlot(plot, out.filePath("volume.svg")), QString());
  QSvgRenderer svg(out.filePath("volume.svg"));
  EXPECT_TRUE(svg.isValid());
  QFile svgFile(out.filePath("volume.svg"));
  ASSERT_TRUE(svgFile.open(QIODevice::ReadOnly));
  const QByteArray svgText = svgFile.readAll();
  EXPECT_TRUE(svgText.contains("Lung volume"));
  EXPECT_TRUE(svgText.contains("volume [mL]"));

  // png: decodes, and is not blank
  ASSERT_EQ(w.window.exportPlot(plot, out.filePath("volume.png")), QString());
  const QImage png(out.filePath("volume.png"));
  ASSERT_FALSE(png.isNull());
  EXPECT_GT(distinctColours(png), 5);

  // pdf: a complete PDF document
  ASSERT_EQ(w.window.exportPlot(plot, out.filePath("volume.pdf")), QString());
  QFile pdf(out.filePath("volume.pdf"));
  ASSERT_TRUE(pdf.open(QIODevice::ReadOnly));
  const QByteArray pdfBytes = pdf.readAll();
  EXPECT_TRUE(pdfBytes.startsWith("%PDF-"));
  EXPECT_TRUE(pdfBytes.trimmed().endsWith("%%EOF"));
  EXPECT_GT(pdfBytes.size(), 1000);

  // 3d view png
  ASSERT_EQ(w.window.exportViewImage(out.filePath("view.png")), QString());
  EXPECT_FALSE(QImage(out.filePath("view.png")).isNull());

  // a failed export reports the error and leaves no file behind
  const QString bad = out.filePath("missing-folder/volume.png");
  EXPECT_NE(w.window.exportPlot(plot, bad), QString());
  EXPECT_FALSE(QFile::exists(bad));
  EXPECT_EQ(QDir(out.path()).entryList(QDir::Files).size(), 5);  // no temporaries left
}

TEST(MainWindow, InvalidParameterIsRefusedWithTheReason) {
  ToyWindow w;
  app::ParameterPanel* panel = w.window.parameters();
  const double before = panel->settings().style.breathsPerMinute;
  panel->frequencyField()->setText("-4");
  emit panel->frequencyField()->editingFinished();
  EXPECT_TRUE(panel->refusal().contains("-4")) << panel->refusal().toStdString();
  EXPECT_EQ(panel->settings().style.breathsPerMinute, before);
  panel->frequencyField()->setText("fast");
  emit panel->frequencyField()->editingFinished();
  EXPECT_TRUE(panel->refusal().contains("not a number"));
  EXPECT_EQ(panel->settings().style.breathsPerMinute, before);

  // the gut kappa field shows the model's own kappa while the options leave it unset (sim::resolveOptions());
  // a non-positive one is refused, by the sim's own check
  QLineEdit* kappa = nullptr;
  for (QLineEdit* f : panel->findChildren<QLineEdit*>())
    if (f->property("label").toString().contains("kPa")) kappa = f;
  ASSERT_NE(kappa, nullptr);
  ASSERT_FALSE(panel->settings().options.step.kappa.has_value());
  EXPECT_EQ(kappa->text().toDouble(), 1e-3 * w.window.model()->gut.kappa);
  kappa->setText("-1");
  emit kappa->editingFinished();
  EXPECT_TRUE(panel->refusal().contains("kappa: must be finite and > 0")) << panel->refusal().toStdString();
  EXPECT_FALSE(panel->settings().options.step.kappa.has_value());
  kappa->setText("150");
  emit kappa->editingFinished();
  EXPECT_EQ(panel->settings().options.step.kappa, 150e3);
}

// the toy torso is not calibrated to breathe cleanly, so the rate is measured on the default model
TEST_F(DefaultModelWindow, FrequencyEditChangesTheMeasuredBreathingRate) {
  app::ParameterPanel* panel = window.parameters();
  window.plots()->setWindow(100.0);

  // 30 breaths/min: the volume the plot records follows the new rate
  panel->frequencyField()->setText("30");
  emit panel->frequencyField()->editingFinished();
  ASSERT_TRUE(panel->refusal().isEmpty()) << panel->refusal().toStdString();
  ASSERT_TRUE(window.runUntil(9.0));
  EXPECT_NEAR(plottedRate(*window.plots()->volumePlot(), 3.0), 30.0, 3.0);

  // at 12 breaths/min the measured rate drops with it
  panel->frequencyField()->setText("12");
  emit panel->frequencyField()->editingFinished();
  ASSERT_TRUE(window.runUntil(21.0));
  EXPECT_NEAR(plottedRate(*window.plots()->volumePlot(), 11.0), 12.0, 1.5);
}

// the figure after `label` in the Breathing read-out, e.g. "Dome descent 14.6 mm" -> 14.6 (NaN if absent)
double readoutFigure(const QString& text, const QString& label) {
  const QRegularExpressionMatch m =
      QRegularExpression(QRegularExpression::escape(label) + " (-?[0-9.]+) ").match(text + " ");
  return m.hasMatch() ? m.captured(1).toDouble() : std::nan("");
}

TEST_F(DefaultModelWindow, BreathingReadOutShowsTheCalmBreathsMotion) {
  EXPECT_EQ(window.breathingReadout(), "Measured after the first full breath.");
  // three calm breaths after the 2 s settling
  ASSERT_TRUE(window.runUntil(14.5)) << window.lastError().toStdString();
  const QString text = window.breathingReadout();
  // the calm figures validate checks (docs/cli.md): 500 mL +/- 10 % at 15 b/m; the dome descending 12-25 mm
  // (Boussuges et al. 2009); the lower ribs widening >= 2 mm; the belly moving forward; the rib cage and
  // abdomen in phase (< 30 deg)
  EXPECT_NEAR(readoutFigure(text, "Tidal volume"), 500.0, 50.0) << text.toStdString();
  EXPECT_NEAR(readoutFigure(text, "at"), 15.0, 0.5) << text.toStdString();
  EXPECT_GE(readoutFigure(text, "Dome descent"), 12.0) << text.toStdString();
  EXPECT_LE(readoutFigure(text, "Dome descent"), 25.0) << text.toStdString();
  EXPECT_GE(readoutFigure(text, "Rib 8 widening"), 2.0) << text.toStdString();
  EXPECT_GT(readoutFigure(text, "Belly forward"), 0.0) << text.toStdString();
  EXPECT_LT(readoutFigure(text, "Rib cage-abdomen phase"), 30.0) << text.toStdString();
  // a reset clears it until the next full breath
  for (QAction* a : window.findChildren<QAction*>())
    if (a->text() == "Reset") a->trigger();
  ASSERT_TRUE(window.runUntil(1.0)) << window.lastError().toStdString();
  EXPECT_EQ(window.breathingReadout(), "Measured after the first full breath.");
}

TEST(MainWindow, ScrubbingRestoresThatInstantsVolumeInThePlotCursor) {
  ToyWindow w;
  ASSERT_TRUE(w.window.runUntil(5.0));
  const app::PlotView* plot = w.window.plots()->volumePlot();
  // the live sample nearest to t = 3 s
  const auto& t = plot->time();
  const std::size_t k = static_cast<std::size_t>(std::lower_bound(t.begin(), t.end(), 3.0) - t.begin());
  ASSERT_LT(k, t.size());
  const double liveVolume = plot->series()[0].y[k];  // [mL]
  const double latestVolume = plot->series()[0].y.back();

  ASSERT_TRUE(w.window.scrubTo(t[k]));
  const app::Snapshot* shown = w.window.shown();
  ASSERT_TRUE(shown->isScrubbed);
  EXPECT_NEAR(shown->state.time, t[k], 1e-6);
  EXPECT_NEAR(1e6 * shown->metrics.lungVolume, liveVolume, 1e-6);  // the recorded state's volume
  EXPECT_NEAR(plot->cursorValue(0), liveVolume, 1e-9);             // in the cursor read-out
  EXPECT_NE(liveVolume, latestVolume);
}

TEST(MainWindow, CorruptModelOrScenarioKeepsThePreviousModel) {
  ToyWindow w;
  const sim::Model* before = w.window.model();
  ASSERT_NE(before, nullptr);

  // a model.json that is not JSON
  QTemporaryDir bad;
  QFile file(bad.filePath("model.json"));
  ASSERT_TRUE(file.open(QIODevice::WriteOnly));
  file.write("{\"format\": \"pneuma-model\", \"bodies\": [1, 2");
  file.close();
  const QString error = w.window.openModel(bad.path());
  EXPECT_TRUE(error.contains("model.json")) << error.toStdString();
  EXPECT_EQ(w.window.model(), before);

  // a scenario with a bad field
  QFile scenario(bad.filePath("run.json"));
  ASSERT_TRUE(scenario.open(QIODevice::WriteOnly));
  scenario.write("{\"format\": \"pneuma-scenario\", \"version\": 1, \"duration_s\": -3}");
  scenario.close();
  EXPECT_NE(w.window.openScenario(bad.filePath("run.json")), QString());
  EXPECT_EQ(w.window.model(), before);

  // and the kept model still runs
  EXPECT_TRUE(w.window.runUntil(0.5));
}

TEST(MainWindow, ScenarioRoundTripKeepsModelAndParameters) {
  ToyWindow w;
  app::ParameterPanel* panel = w.window.parameters();
  panel->frequencyField()->setText("21");
  emit panel->frequencyField()->editingFinished();
  QTemporaryDir out;
  ASSERT_EQ(w.window.saveScenario(out.filePath("lecture.json")), QString());
  panel->frequencyField()->setText("9");
  emit panel->frequencyField()->editingFinished();

  ASSERT_EQ(w.window.openScenario(out.filePath("lecture.json")), QString());
  EXPECT_EQ(w.window.parameters()->settings().style.breathsPerMinute, 21.0);
  EXPECT_EQ(w.window.model()->name, "toy_torso");
}

namespace {

// mean displacement [m] of the free gut nodes from the rest pose in the instant on screen
Eigen::Vector3d shownGutSag(const MainWindow& window) {
  const sim::Model& m = *window.model();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  for (int n = 0; n < m.nodes.size(); ++n)
    if (!m.nodes.isFixed(n)) {
      sum += window.shown()->state.nodePosition.col(n) - m.nodes.rest.col(n);
      ++count;
    }
  return sum / std::max(count, 1);
}

}  // namespace

// the Parameters panel's posture box lists sim's postures; lying on the back restarts the run, and what it
// shows then has the viscera sinking posteriorly (-y) where upright they sink caudally (-z); an unknown name
// is refused with the valid ones and a scenario keeps the posture
TEST(MainWindow, PostureBoxRestartsTheRunWithGravityTurned) {
  ToyWindow w;
  QComboBox* box = w.window.parameters()->postureBox();
  ASSERT_NE(box, nullptr);
  QStringList names;
  for (int i = 0; i < box->count(); ++i) names << box->itemText(i);
  EXPECT_EQ(names.join(", ").toStdString(), sim::postureNames());
  EXPECT_EQ(box->currentText(), "upright");
  ASSERT_TRUE(w.window.runUntil(1.5));
  const Eigen::Vector3d upright = shownGutSag(w.window);
  EXPECT_LT(upright.z(), 0.0);
  EXPECT_GT(-upright.z(), 3.0 * std::abs(upright.y()));

  box->setCurrentText("supine");
  emit box->textActivated("supine");
  EXPECT_EQ(w.window.parameters()->settings().options.step.posture, sim::Posture::Supine);
  ASSERT_TRUE(w.window.runUntil(1.5));
  EXPECT_NEAR(w.window.shown()->state.time, 1.5, 0.05);  // started over, not 3 s into the old run
  const Eigen::Vector3d supine = shownGutSag(w.window);
  EXPECT_LT(supine.y(), 0.0);
  EXPECT_GT(-supine.y(), 3.0 * std::abs(supine.z()));
  bool isStated = false;  // the status bar says which posture runs
  for (const QLabel* label : w.window.statusBar()->findChildren<QLabel*>())
    isStated = isStated || label->text().endsWith(", posture supine");
  EXPECT_TRUE(isStated);

  const QString error = w.window.setPosture("sitting");
  EXPECT_EQ(error.toStdString(),
            "unknown posture 'sitting' (valid: upright, supine, prone, left-lateral, right-lateral)");
  EXPECT_EQ(w.window.parameters()->settings().options.step.posture, sim::Posture::Supine);

  QTemporaryDir out;
  ASSERT_EQ(w.window.saveScenario(out.filePath("lying.json")), QString());
  ASSERT_EQ(w.window.setPosture("upright"), QString());
  EXPECT_EQ(box->currentText(), "upright");
  ASSERT_EQ(w.window.openScenario(out.filePath("lying.json")), QString());
  EXPECT_EQ(box->currentText(), "supine");
}

TEST(MainWindow, ClickingAMuscleSelectsItAndAddsItsForceTrace) {
  ToyWindow w;
  ASSERT_TRUE(w.window.runUntil(3.0));
  // a force-coloured pixel is a taut muscle element
  const QImage view = w.window.grabView();
  QPoint hit(-1, -1);
  for (int y = view.height() / 4; y < view.height() && hit.x() < 0; ++y)
    for (int x = view.width() / 4; x < static_cast<int>(0.8 * view.width()); ++x)
      if (isForceColoured(view.pixel(x, y)) && isForceColoured(view.pixel(x + 1, y)) &&
          isForceColoured(view.pixel(x, y + 1))) {
        hit = QPoint(x, y);
        break;
      }
  ASSERT_GE(hit.x(), 0);
  const app::PlotView* tension = w.window.plots()->plots()[3];
  const std::size_t before = tension->series().size();
  w.window.pickAt(hit);
  w.window.plots()->refresh();
  ASSERT_EQ(tension->series().size(), before + 1);
  EXPECT_TRUE(tension->series().back().name.contains("element"))
      << tension->series().back().name.toStdString();
  // its trace holds the element's tension: positive while it is coloured
  EXPECT_GT(tension->series().back().y.back(), 0.0);
}

TEST(MainWindow, RunExportsAsParaViewSeries) {
  ToyWindow w;
  ASSERT_TRUE(w.window.runUntil(0.5));
  QTemporaryDir out;
  ASSERT_EQ(w.window.exportRun(out.filePath("run.pvd")), QString());
  QFile pvd(out.filePath("run.pvd"));
  ASSERT_TRUE(pvd.open(QIODevice::ReadOnly));
  const QByteArray text = pvd.readAll();
  EXPECT_TRUE(text.contains("<VTKFile type=\"Collection\""));
  // one dataset entry per part and recorded frame (0.5 s at 60 Hz: 30 or 31 frames, 6 parts each)
  EXPECT_GE(text.count("<DataSet"), 6 * 30);
  EXPECT_FALSE(QDir(out.filePath("run")).entryList({"*.vtp"}, QDir::Files).isEmpty());

  // an unwritable destination is an error, not a crash
  EXPECT_NE(w.window.exportRun("/proc/pneuma-no-such-dir/run.pvd"), QString());
}

// File > Export > Run as glTF and Baked morph targets: the recording's skin fitted onto targets baked from
// the physics (docs/patterns.md), read back with the skin's vertex count; a bad folder is an error, not a
// file
TEST_F(DefaultModelWindow, RunExportsAsGltfWithBakedMorphTargets) {
  ASSERT_TRUE(window.runUntil(2.5));
  QTemporaryDir out;
  ASSERT_EQ(window.exportGltf(out.filePath("run.glb")), QString());
  const sim::MorphTargets run = viz::readGltfMorphTargets(out.filePath("run.glb").toStdString());
  ASSERT_EQ(run.targets.size(), 3u);
  EXPECT_EQ(run.vertexCount(), window.model()->skin.vertexCount());
  // the breathing target lifts the body: its largest displacement is centimetres, not zero and not metres
  const double largest = run.targets[0].displacement.colwise().norm().maxCoeff();  // [m]
  EXPECT_GT(largest, 0.01);
  EXPECT_LT(largest, 0.1);
  ASSERT_EQ(window.bakeMorphTargets(out.filePath("morphs.glb")), QString());
  EXPECT_TRUE(QFile::exists(out.filePath("morphs.glb")));
  EXPECT_NE(window.exportGltf("/proc/pneuma-no-such-dir/run.glb"), QString());
  EXPECT_FALSE(QFile::exists("/proc/pneuma-no-such-dir/run.glb"));
}

TEST(MainWindow, GltfExportOfAModelWithoutSkinIsRefused) {
  ToyWindow w;
  ASSERT_TRUE(w.window.runUntil(0.5));
  QTemporaryDir out;
  const QString error = w.window.exportGltf(out.filePath("toy.glb"));
  EXPECT_TRUE(error.contains("has no skin")) << error.toStdString();
  EXPECT_TRUE(QDir(out.path()).isEmpty());
}

// the teaching view: no muscle group's caption covers another caption, from any camera preset
TEST_F(DefaultModelWindow, GroupCaptionsDoNotOverlapOtherCaptions) {
  const std::set<std::string> groupNames = {
      "External intercostals", "Internal intercostals",  "Diaphragm",
      "Rectus abdominis",      "Transversus / obliques", "Costal cartilage"};
  viz::DisplayOptions o = window.scene().options();
  o.showLabels = true;
  o.showLandmarks = true;
  window.setDisplayOptions(o);
  vtkRenderer* renderer = window.scene().renderer();
  for (const viz::CameraPreset preset : {viz::CameraPreset::Anterior, viz::CameraPreset::Lateral,
                                         viz::CameraPreset::Superior, viz::CameraPreset::Oblique}) {
    window.scene().setCamera(preset);
    window.grabView();  // renders
    struct Box {
      std::string text;
      QRectF rect;  // [px] display coordinates
    };
    std::vector<Box> boxes;
    vtkPropCollection* props = renderer->GetViewProps();
    props->InitTraversal();
    while (vtkProp* prop = props->GetNextProp()) {
      auto* caption = vtkCaptionActor2D::SafeDownCast(prop);
      if (caption == nullptr || !caption->GetVisibility()) continue;
      const int* a = caption->GetPositionCoordinate()->GetComputedDisplayValue(renderer);
      const int* b = caption->GetPosition2Coordinate()->GetComputedDisplayValue(renderer);
      boxes.push_back({caption->GetCaption(), QRectF(QPointF(a[0], a[1]), QPointF(b[0], b[1])).normalized()});
    }
    int groups = 0;
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      if (groupNames.count(boxes[i].text) == 0) continue;
      ++groups;
      for (std::size_t j = 0; j < boxes.size(); ++j) {
        if (j == i) continue;
        EXPECT_FALSE(boxes[i].rect.intersects(boxes[j].rect))
            << "camera " << static_cast<int>(preset) << ": '" << boxes[i].text << "' covers '"
            << boxes[j].text << "'";
      }
    }
    EXPECT_EQ(groups, 6);
  }
}

// the pattern drive calibrates on a model whose muscles raise the lung volume: the default model (the toy
// torso's volume only sinks during the calibration staircase, which the drive refuses)
TEST_F(DefaultModelWindow, PushedAffectPlotsItsTargetBesideTheSimulatedVolume) {
  // before anything is pushed the affect selector offers neutral, not the first name in the list
  int selectors = 0;
  for (const QComboBox* c : window.findChildren<QComboBox*>())
    if (c->toolTip().contains("affective state")) {
      ++selectors;
      EXPECT_EQ(c->currentText(), "neutral");
    }
  EXPECT_EQ(selectors, 1);
  // an unknown name is refused with the valid ones; the known one is pushed
  const QString error = window.pushAffect("pnic", true);
  EXPECT_TRUE(error.contains("unknown affect 'pnic'")) << error.toStdString();
  EXPECT_TRUE(error.contains("panic")) << error.toStdString();
  EXPECT_EQ(window.pushAffect("neutral", true), QString());
  ASSERT_TRUE(window.runUntil(4.0)) << window.lastError().toStdString();
  const app::PlotView* volume = window.plots()->volumePlot();
  ASSERT_EQ(volume->series().size(), 2u);
  EXPECT_EQ(volume->series()[1].name, "target volume");
  // the target is defined once control starts after settling
  EXPECT_TRUE(std::isfinite(volume->series()[1].y.back()));
  EXPECT_GT(volume->series()[1].y.back(), 0.0);
  // a new posture restarts the run with the breath style: the affect's drive was calibrated upright
  ASSERT_EQ(window.setPosture("supine"), QString());
  ASSERT_TRUE(window.runUntil(3.0)) << window.lastError().toStdString();
  EXPECT_NEAR(window.shown()->state.time, 3.0, 0.05);
  const auto& series = window.plots()->volumePlot()->series();
  EXPECT_TRUE(series.size() < 2 || series[1].y.empty() || !std::isfinite(series[1].y.back()));
}

TEST(MainWindow, AnimationExportsAsMovieAndPngSequence) {
  ToyWindow w;
  ASSERT_TRUE(w.window.runUntil(1.0));
  QTemporaryDir out;
  // 0.2 s at 25 fps: 6 frames
  ASSERT_EQ(w.window.exportAnimation(out.filePath("breath.png"), 0.4, 0.6, 25.0), QString());
  const QStringList frames = QDir(out.path()).entryList({"breath_*.png"}, QDir::Files, QDir::Name);
  ASSERT_EQ(frames.size(), 6);
  EXPECT_FALSE(QImage(out.filePath(frames.front())).isNull());

  ASSERT_EQ(w.window.exportAnimation(out.filePath("breath.ogv"), 0.4, 0.6, 25.0), QString());
  QFile movie(out.filePath("breath.ogv"));
  ASSERT_TRUE(movie.open(QIODevice::ReadOnly));
  EXPECT_TRUE(movie.read(4) == "OggS");  // an Ogg container
  EXPECT_GT(movie.size(), 1000);
  EXPECT_TRUE(QDir(out.path()).entryList({"*.tmp-*"}, QDir::Files).isEmpty());
}

TEST(MainWindow, SimulationBlowUpPausesAndShowsTheSimsError) {
  ToyWindow w;
  // muscle gains far beyond what the time step can integrate
  auto fields = w.window.parameters()->findChildren<QLineEdit*>();
  QLineEdit* gain = nullptr;
  for (QLineEdit* f : fields)
    if (f->property("label").toString().contains("Active gain")) gain = f;
  ASSERT_NE(gain, nullptr);
  gain->setText("1e6");
  emit gain->editingFinished();
  EXPECT_FALSE(w.window.runUntil(5.0));
  EXPECT_TRUE(w.window.lastError().contains("blew up")) << w.window.lastError().toStdString();
  ASSERT_NE(w.window.shown(), nullptr);
  EXPECT_FALSE(w.window.shown()->isRunning);
}

// without a display the app says what to do and exits 2, instead of Qt's plugin abort
TEST(App, WithoutADisplayExplainsAndExitsTwo) {
  const test::CliResult r =
      test::runProgram("pneuma", {"--style", "calm"}, 0.0, {"DISPLAY=", "WAYLAND_DISPLAY="});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.err.find("no display"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("pneuma-cli"), std::string::npos) << r.err;
}
