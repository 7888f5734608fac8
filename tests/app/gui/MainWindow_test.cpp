// What the user sees in the main window, asserted on grabs, widgets and exported files under Xvfb.
// The run uses the sim tests' toy torso (every part of the default model at a tenth of the size).

#include "gui/MainWindow.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <vtkActor.h>
#include <vtkActorCollection.h>
#include <vtkCaptionActor2D.h>
#include <vtkCellArray.h>
#include <vtkCoordinate.h>
#include <vtkDoubleArray.h>
#include <vtkMapper.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPropCollection.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkScalarsToColors.h>
#include <vtkTextActor.h>

#include <QAction>
#include <QCheckBox>
#include <QComboBox>
#include <QDialogButtonBox>
#include <QDoubleSpinBox>
#include <QElapsedTimer>
#include <QFile>
#include <QFileInfo>
#include <QLabel>
#include <QLineEdit>
#include <QProgressDialog>
#include <QPushButton>
#include <QRegularExpression>
#include <QSpinBox>
#include <QStatusBar>
#include <QSvgRenderer>
#include <QTextStream>
#include <QTimer>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <functional>
#include <set>
#include <tuple>

#include "../cli/CliRunner.h"
#include "../viz/MovieProbe.h"
#include "GuiTestSupport.h"
#include "gui/ExportController.h"
#include "gui/FlowVolumeLoop.h"
#include "gui/LivePlots.h"
#include "gui/MovieDialog.h"
#include "gui/ParameterPanel.h"
#include "gui/PlotView.h"
#include "gui/SeriesDialog.h"
#include "gui/SimWorker.h"
#include "pneuma/sim/Metrics.h"
#include "pneuma/sim/MorphTargets.h"
#include "pneuma/sim/PosedGeometry.h"
#include "pneuma/sim/Resources.h"
#include "pneuma/sim/Scenario.h"
#include "pneuma/sim/pattern/Pattern.h"
#include "viz/GltfWriter.h"
#include "viz/MovieWriter.h"

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
  // the lungs alone: the pectorals (opaque, over the front of the rib cage) would hide most of them
  o.showBones = o.showGut = o.showLandmarks = o.showTissue = false;
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

// the cheaper render (docs/app.md, "Measured under Xvfb"): the closed surfaces draw their front faces only
// and the translucent ones blend in drawing order. The opaque skin still hides everything inside it (no back
// face culled away opens a hole: hiding the bones changes no pixel), and through the translucent skin the
// bones still show (hiding them changes a good part of the body)
TEST_F(DefaultModelWindow, OpaqueSkinHidesTheInsideAndTheTranslucentOneShowsIt) {
  viz::DisplayOptions o = window.scene().options();
  // the bones and the skin alone: the pectorals (opaque, on the front of the rib cage) hidden too
  o.showGut = o.showLungs = o.showLandmarks = o.showTissue = false;
  o.showGroup.fill(false);
  o.skin = viz::SkinDisplay::Opaque;
  const auto grab = [&](bool bones) {
    o.showBones = bones;
    window.setDisplayOptions(o);
    return window.grabView();
  };
  const QImage opaqueBones = grab(true), opaqueNoBones = grab(false);
  o.skin = viz::SkinDisplay::Translucent;
  const QImage translucentBones = grab(true), translucentNoBones = grab(false);
  o.skin = viz::SkinDisplay::Hidden;
  const QImage bonesAlone = grab(true), nothing = grab(false);
  const int bonePixels = differing(bonesAlone, nothing);
  EXPECT_GT(bonePixels, opaqueBones.width() * opaqueBones.height() / 40)
      << "the skeleton fills the view's middle";
  EXPECT_LT(differing(opaqueBones, opaqueNoBones), bonePixels / 200)
      << "nothing shows through the opaque skin";
  EXPECT_GT(differing(translucentBones, translucentNoBones), bonePixels / 2)
      << "the bones show through the translucent skin";
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
  // in the reader's words: the field's label, no style name or file key in front
  EXPECT_TRUE(panel->refusal().startsWith("Frequency [breaths/min]: -4 refused: breaths per minute"))
      << panel->refusal().toStdString();
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
  // two bad fields: both reasons are shown, one line each; fixing one leaves the other's
  const QStringList both = panel->refusal().split('\n');
  ASSERT_EQ(both.size(), 2) << panel->refusal().toStdString();
  EXPECT_TRUE(both[0].contains("not a number")) << both[0].toStdString();
  EXPECT_TRUE(both[1].contains("kappa: must be finite and > 0")) << both[1].toStdString();
  EXPECT_FALSE(panel->settings().options.step.kappa.has_value());
  panel->frequencyField()->setText("12");
  emit panel->frequencyField()->editingFinished();
  EXPECT_FALSE(panel->refusal().contains("not a number")) << panel->refusal().toStdString();
  EXPECT_TRUE(panel->refusal().contains("kappa")) << panel->refusal().toStdString();
  kappa->setText("150");
  emit kappa->editingFinished();
  EXPECT_EQ(panel->settings().options.step.kappa, 150e3);
  EXPECT_TRUE(panel->refusal().isEmpty()) << panel->refusal().toStdString();
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

namespace {

// the caption text actors the view shows (the "motion x5" of the magnification among them)
std::vector<std::string> shownTexts(vtkRenderer* renderer) {
  std::vector<std::string> texts;
  vtkPropCollection* props = renderer->GetViewProps();
  props->InitTraversal();
  while (vtkProp* prop = props->GetNextProp())
    if (auto* text = vtkTextActor::SafeDownCast(prop); text && text->GetVisibility() && text->GetInput())
      texts.emplace_back(text->GetInput());
  return texts;
}

}  // namespace

// motion magnification moves what is drawn by the stated factor: at the end of a calm inhale the landmarks'
// projected screen displacement from the end-expiratory pose is five times larger at 5x than at 1x, the view
// says "motion x5", and the plotted volume is the real one; a factor outside [1, 20] is refused
TEST_F(DefaultModelWindow, MagnificationMovesTheDrawnLandmarksByTheFactor) {
  ASSERT_TRUE(window.runUntil(12.0)) << window.lastError().toStdString();
  // the end of the last inhale: the largest plotted volume after t = 8.5 s (calm: 15 b/m after 2 s settling)
  const app::PlotView* plot = window.plots()->volumePlot();
  const std::vector<double> t = plot->time();  // copies: a refresh replaces the plot's data
  const std::vector<double> v = plot->series()[0].y;
  std::size_t peak = 0;
  for (std::size_t k = 0; k < t.size(); ++k)
    if (t[k] > 8.5 && (peak == 0 || v[k] > v[peak])) peak = k;
  ASSERT_TRUE(window.scrubTo(t[peak]));
  const app::Snapshot* shown = window.shown();
  ASSERT_NE(shown->endExpiration, nullptr) << "an end-expiration found before " << t[peak] << " s";
  EXPECT_LT(shown->endExpiration->time, t[peak]);
  EXPECT_GT(shown->endExpiration->time, t[peak] - 4.0) << "the breath's own end-expiration";

  // the landmarks of the end-expiratory pose and as drawn, projected to the screen [px]
  vtkRenderer* renderer = window.scene().renderer();
  window.scene().setCamera(viz::CameraPreset::Anterior);
  window.grabView();
  sim::PosedGeometry endExpiration;
  sim::poseGeometry(*window.model(), *shown->endExpiration, endExpiration);
  auto screen = [&](const Eigen::Vector3d& x) {
    vtkNew<vtkCoordinate> c;
    c->SetCoordinateSystemToWorld();
    c->SetValue(x.x(), x.y(), x.z());
    const double* d = c->GetComputedDoubleDisplayValue(renderer);
    return Eigen::Vector2d(d[0], d[1]);
  };
  auto drawnDisplacement = [&](double factor) {
    EXPECT_EQ(window.setMagnification(factor), QString());
    window.grabView();
    std::vector<Eigen::Vector2d> d;
    const Eigen::Matrix3Xd& drawn = window.scene().posed().landmarks;
    for (Eigen::Index l = 0; l < drawn.cols(); ++l)
      d.push_back(screen(drawn.col(l)) - screen(endExpiration.landmarks.col(l)));
    return d;
  };
  const std::vector<Eigen::Vector2d> real = drawnDisplacement(1.0);
  EXPECT_TRUE(shownTexts(renderer).empty() ||
              std::none_of(shownTexts(renderer).begin(), shownTexts(renderer).end(),
                           [](const std::string& s) { return s.rfind("motion", 0) == 0; }))
      << "no caption at 1x";
  const std::vector<Eigen::Vector2d> magnified = drawnDisplacement(5.0);
  const std::vector<std::string> texts = shownTexts(renderer);
  EXPECT_NE(std::find(texts.begin(), texts.end(), "motion \u00d75"), texts.end());
  // the landmark that moves most on screen (the umbilicus or the xiphoid in an anterior view)
  std::size_t most = 0;
  for (std::size_t l = 0; l < real.size(); ++l)
    if (real[l].norm() > real[most].norm()) most = l;
  ASSERT_GT(real[most].norm(), 1.0) << "a calm inhale moves a landmark at least a pixel";
  EXPECT_NEAR(magnified[most].norm() / real[most].norm(), 5.0, 0.25);
  EXPECT_GT(magnified[most].normalized().dot(real[most].normalized()), 0.99) << "the same direction";
  // the numbers stay real: the snapshot's volume is the plotted one
  EXPECT_NEAR(1e6 * shown->metrics.lungVolume, v[peak], 1e-6);

  // out of range: refused with the reason, the factor kept
  const QString error = window.setMagnification(25.0);
  EXPECT_TRUE(error.contains("motion magnification: 25 is outside [1, 20]")) << error.toStdString();
  EXPECT_EQ(window.scene().options().magnification, 5.0);
  QLineEdit* field = window.parameters()->magnificationField();
  field->setText("0.5");
  emit field->editingFinished();
  EXPECT_TRUE(window.parameters()->refusal().contains("0.5 is outside [1, 20]"))
      << window.parameters()->refusal().toStdString();
  EXPECT_EQ(window.scene().options().magnification, 5.0);
  field->setText("10");
  emit field->editingFinished();
  EXPECT_EQ(window.scene().options().magnification, 10.0);
}

namespace {

// what each shown colour legend says: its title, range and labels as drawn
std::vector<std::string> shownLegends(vtkRenderer* renderer) {
  std::vector<std::string> legends;
  vtkPropCollection* props = renderer->GetViewProps();
  props->InitTraversal();
  while (vtkProp* prop = props->GetNextProp()) {
    auto* bar = vtkScalarBarActor::SafeDownCast(prop);
    if (!bar || !bar->GetVisibility()) continue;
    std::string text = std::string(bar->GetTitle()) + " |";
    EXPECT_TRUE(bar->GetUseCustomLabels()) << bar->GetTitle();
    vtkDoubleArray* labels = bar->GetCustomLabels();
    for (vtkIdType i = 0; labels && i < labels->GetNumberOfTuples(); ++i) {
      char label[64];
      std::snprintf(label, sizeof label, bar->GetLabelFormat(), labels->GetValue(i));
      // round numbers: no exponent, no trailing zero after a decimal point
      EXPECT_TRUE(QRegularExpression("^-?[0-9]+(\\.[0-9]*[1-9])?$").match(label).hasMatch())
          << bar->GetTitle() << ": label '" << label << "'";
      text += std::string(" ") + label;
    }
    const double* range = bar->GetLookupTable()->GetRange();
    text += " [" + std::to_string(range[0]) + ", " + std::to_string(range[1]) + "]";
    legends.push_back(text);
  }
  return legends;
}

}  // namespace

// the colour legends of a recorded run stay fixed across its frames (tension 0-20 N, gut and skin
// displacement 0-20 and 0-10 mm from end-expiration), with round labels; the auto range (95th percentile)
// fits the run and never shrinks while it is replayed
TEST_F(DefaultModelWindow, ColourLegendsOfARecordedRunStayFixedAcrossFrames) {
  viz::DisplayOptions o = window.scene().options();
  o.skinColouring = viz::SkinColouring::Displacement;
  window.setDisplayOptions(o);
  ASSERT_TRUE(window.runUntil(10.0)) << window.lastError().toStdString();
  vtkRenderer* renderer = window.scene().renderer();
  std::vector<std::string> first;
  for (double t : {2.5, 4.0, 5.2, 6.9, 8.3, 9.9}) {
    ASSERT_TRUE(window.scrubTo(t));
    window.grabView();
    const std::vector<std::string> legends = shownLegends(renderer);
    ASSERT_EQ(legends.size(), 3u) << "tension, gut and skin";
    if (first.empty()) first = legends;
    EXPECT_EQ(legends, first) << "at t = " << t << " s";
  }
  EXPECT_EQ(first[0], "Tension per\nelement [N] | 0 5 10 15 20 [0.000000, 20.000000]");
  EXPECT_EQ(first[1], "Gut\ndisplacement\n[mm] | 0 5 10 15 20 [0.000000, 20.000000]");
  EXPECT_EQ(first[2], "Skin\ndisplacement\n[mm] | 0 2 4 6 8 10 [0.000000, 10.000000]");

  // auto range: fitted to the values shown, never shrinking as the replay goes on
  o.isAutoRange = true;
  window.setDisplayOptions(o);
  double top = 0.0;
  for (double t : {3.0, 5.0, 7.0, 9.0}) {
    ASSERT_TRUE(window.scrubTo(t));
    const std::vector<std::string> legends = shownLegends(renderer);
    vtkPropCollection* props = renderer->GetViewProps();
    props->InitTraversal();
    while (vtkProp* prop = props->GetNextProp())
      if (auto* bar = vtkScalarBarActor::SafeDownCast(prop);
          bar && bar->GetVisibility() && std::string(bar->GetTitle()).rfind("Gut", 0) == 0) {
        EXPECT_GE(bar->GetLookupTable()->GetRange()[1], top) << "at t = " << t << " s";
        top = bar->GetLookupTable()->GetRange()[1];
      }
  }
  EXPECT_GE(top, 1.0);
  EXPECT_LT(top, 100.0) << "the gut moves a few millimetres from end-expiration, not the settling sag";
}

// the physiology panel: the flow-volume loop closes each calm breath (from one end-expiration to the next the
// lung volume returns within 5 % of the tidal volume and the flow to near zero), the plotted flow integrates
// to the plotted volume change, the pressures are in cmH2O, and at a scrubbed instant the notes read that
// instant
TEST_F(DefaultModelWindow, FlowVolumeLoopClosesEachBreath) {
  ASSERT_TRUE(window.runUntil(19.0)) << window.lastError().toStdString();
  const app::FlowVolumeLoop* loop = window.plots()->loop();
  int complete = 0;
  for (const app::FlowVolumeLoop::Loop& l : loop->loops()) {
    ASSERT_GT(l.time.size(), 10u);
    const auto [vMin, vMax] = std::minmax_element(l.volume.begin(), l.volume.end());
    double peakFlow = 0.0, integral = 0.0;  // [L/s], [mL]
    for (std::size_t k = 0; k < l.flow.size(); ++k) {
      if (std::isfinite(l.flow[k])) peakFlow = std::max(peakFlow, std::abs(l.flow[k]));
      if (k > 0) integral += 1e3 * l.flow[k] * (l.time[k] - l.time[k - 1]);
    }
    if (!l.isComplete) continue;
    ++complete;
    const double tidal = *vMax - *vMin;  // [mL]
    EXPECT_NEAR(tidal, 530.0, 80.0) << "a calm breath";
    EXPECT_NEAR(l.volume.front(), 0.0, 1e-9);
    EXPECT_LT(std::abs(l.volume.back()), 0.05 * tidal)
        << "the loop closes: breath from " << l.time.front() << " s";
    EXPECT_LT(std::abs(l.flow.back()), 0.2 * peakFlow) << "ends near zero flow";
    EXPECT_GT(peakFlow, 0.2) << "calm breathing peaks at a few tenths of a litre per second";
    EXPECT_NEAR(integral, l.volume.back(), 0.02 * tidal) << "flow [L/s] integrates to the volume [mL]";
    EXPECT_NEAR(l.time.back() - l.time.front(), 4.0, 0.4) << "15 breaths per minute";
  }
  EXPECT_GE(complete, 2);
  EXPECT_NEAR(window.plots()->breathingRate(), 15.0, 1.0);

  // pressures in cmH2O: the gut's and, the model having a pleural pressure, the transdiaphragmatic one
  const app::PlotView* pressures = window.plots()->pressurePlot();
  ASSERT_EQ(pressures->series().size(), 2u);
  const std::vector<double>& pdi = pressures->series()[1].y;
  const double pdiLast = pdi.back();
  EXPECT_GT(pdiLast, 0.0) << "the diaphragm holds the abdomen below the chest";
  EXPECT_LT(pdiLast, 40.0) << "cmH2O, not Pa";

  // scrubbed: the notes read that instant
  ASSERT_TRUE(window.scrubTo(15.0));
  window.plots()->refresh();
  const double t = window.shown()->metrics.time;
  const std::string at = QString("at %1 s").arg(t, 0, 'f', 2).toStdString();
  for (const app::PlotView* plot :
       {window.plots()->volumePlot(), window.plots()->flowPlot(), window.plots()->pressurePlot()})
    EXPECT_NE(plot->toPlot().note().find(at), std::string::npos) << plot->toPlot().note();
  EXPECT_NE(
      window.plots()->volumePlot()->toPlot().note().find(
          QString("lungs %1 mL").arg(1e6 * window.shown()->metrics.lungVolume, 0, 'f', 0).toStdString()),
      std::string::npos)
      << "the scrubbed volume, not the live one";
}

// scenarios round-trip whatever drives them: the shipped startle scenario (a pattern with a timeline) opens
// and plays its target volume; saved, it reopens to the same pattern; after a pushed affect the saved
// scenario records the affect, not the calm style
TEST_F(DefaultModelWindow, AffectAndPatternScenariosOpenPlayAndSaveWhatDrivesTheRun) {
  const QString startle = QString::fromStdString(sim::resourceDir()) + "/scenarios/startle-at-10s.json";
  ASSERT_EQ(window.openScenario(startle), QString());
  // the style box and the parameter panel say that the pattern drives, not the calm style
  EXPECT_EQ(window.styleBox()->currentText().toStdString(), "pattern 'startle-at-10s'");
  EXPECT_FALSE(window.parameters()->frequencyField()->isEnabled());
  EXPECT_TRUE(window.parameters()->driverText().contains("pattern"))
      << window.parameters()->driverText().toStdString();
  ASSERT_TRUE(window.runUntil(5.0, 120000)) << window.lastError().toStdString();
  const app::PlotView* plot = window.plots()->volumePlot();
  ASSERT_EQ(plot->series().size(), 2u) << "simulated and target volume";
  const std::vector<double> target = plot->series()[1].y;
  EXPECT_TRUE(std::any_of(target.begin(), target.end(), [](double v) { return v > 1000.0; }))
      << "the pattern's target lung volume [mL] is plotted";

  QTemporaryDir dir;
  const QString saved = dir.filePath("startle.json");
  ASSERT_EQ(window.saveScenario(saved), QString());
  const sim::Scenario original = sim::loadScenario(startle.toStdString());
  const sim::Scenario reread = sim::loadScenario(saved.toStdString());
  EXPECT_EQ(reread.controller, sim::ControllerKind::Pattern);
  EXPECT_EQ(reread.patternText, original.patternText);
  EXPECT_EQ(reread.seed, original.seed);
  ASSERT_EQ(window.openScenario(saved), QString()) << "the saved scenario reopens";

  ASSERT_EQ(window.setBreathStyle("calm"), QString());
  EXPECT_EQ(window.styleBox()->currentText().toStdString(), "calm");
  EXPECT_TRUE(window.parameters()->frequencyField()->isEnabled());
  ASSERT_EQ(window.pushAffect("panic", true), QString());
  EXPECT_EQ(window.styleBox()->currentText().toStdString(), "affect 'panic'");
  EXPECT_FALSE(window.parameters()->frequencyField()->isEnabled());
  ASSERT_EQ(window.saveScenario(saved), QString());
  const sim::Scenario affect = sim::loadScenario(saved.toStdString());
  EXPECT_EQ(affect.controller, sim::ControllerKind::Affect);
  EXPECT_EQ(affect.controllerName, "panic");
  ASSERT_EQ(window.setBreathStyle("deep"), QString());
  EXPECT_EQ(window.styleBox()->currentText().toStdString(), "deep");
  EXPECT_EQ(window.styleBox()->findData("driver"), -1) << "the affect's entry is gone";
  EXPECT_TRUE(window.parameters()->frequencyField()->isEnabled());
  ASSERT_EQ(window.saveScenario(saved), QString());
  EXPECT_EQ(sim::loadScenario(saved.toStdString()).controllerName, "deep");
}

// File > Open trace: the shipped example trace drives the run; the volume plot draws its target beside the
// simulated volume, the two agree within 5 % of the target's swing, and the note shows the tracking RMS; a
// bad trace is refused naming its line and column, and the run keeps following the good one
TEST_F(DefaultModelWindow, OpenedTraceIsDrawnOnTheVolumePlotWithItsTrackingRms) {
  const QString trace = QString::fromStdString(sim::resourceDir()) + "/traces/calm-sigh.csv";
  ASSERT_EQ(window.openTrace(trace), QString());
  ASSERT_TRUE(window.runUntil(14.0, 120000)) << window.lastError().toStdString();
  window.plots()->refresh();
  const app::PlotView* plot = window.plots()->volumePlot();
  ASSERT_EQ(plot->series().size(), 2u) << "simulated and target volume";
  EXPECT_EQ(plot->series()[0].legend.toStdString(), "simulated");
  EXPECT_EQ(plot->series()[1].legend.toStdString(), "target");
  // the plotted curves [mL], once the drive has blended into the trace (after 6 s)
  const std::vector<double>& t = plot->time();
  const std::vector<double>& simulated = plot->series()[0].y;
  const std::vector<double>& target = plot->series()[1].y;
  double lo = 1e9, hi = -1e9, squares = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    if (t[k] < 6.0 || !std::isfinite(target[k])) continue;
    lo = std::min(lo, target[k]), hi = std::max(hi, target[k]);
    squares += (simulated[k] - target[k]) * (simulated[k] - target[k]), ++n;
  }
  ASSERT_GT(n, 100);
  EXPECT_GT(hi - lo, 300.0) << "the trace's breaths (about 0.5 L) are in the target";
  EXPECT_LT(std::sqrt(squares / n), 0.05 * (hi - lo)) << "the simulated volume follows the drawn target";
  // the note: "tracking RMS x.x %", under 5 %
  const QString note = QString::fromStdString(plot->toPlot().note());
  const QRegularExpressionMatch rms = QRegularExpression("tracking RMS ([0-9.]+) %").match(note);
  ASSERT_TRUE(rms.hasMatch()) << note.toStdString();
  EXPECT_LT(rms.captured(1).toDouble(), 5.0) << note.toStdString();

  // a bad trace: the error names the file, line and column; the good trace still drives the run
  QTemporaryDir dir;
  const QString bad = dir.filePath("bad.csv");
  QFile file(bad);
  ASSERT_TRUE(file.open(QIODevice::WriteOnly));
  file.write("time [s],volume [L]\n0,2.4\n0.5,2.6\n0.4,2.5\n");
  file.close();
  const QString error = window.openTrace(bad);
  EXPECT_TRUE(error.contains(bad + ":4: column 1 'time [s]': time must increase")) << error.toStdString();
  ASSERT_TRUE(window.runUntil(15.0, 60000));
  window.plots()->refresh();
  EXPECT_TRUE(QString::fromStdString(plot->toPlot().note()).contains("tracking RMS"));
}

// Reset empties the plots and every read-out above them: no note keeps the run before the reset (the gut
// volume error's "now -0.244 %" stayed); the next samples write them again, as the plotted values
TEST(MainWindow, ResetClearsEveryPlotsReadOut) {
  ToyWindow w;
  ASSERT_TRUE(w.window.runUntil(1.0));
  const app::PlotView* gut = w.window.plots()->plots()[1];
  const std::string before = gut->toPlot().note();
  EXPECT_EQ(before.rfind("now ", 0), 0u) << before;
  for (QAction* a : w.window.findChildren<QAction*>())
    if (a->text() == "Reset") a->trigger();
  QElapsedTimer clock;
  clock.start();
  while (!w.window.plots()->volumePlot()->time().empty() && clock.elapsed() < 10000)
    QApplication::processEvents(QEventLoop::AllEvents, 20);
  ASSERT_TRUE(w.window.plots()->volumePlot()->time().empty()) << "the reset emptied the plots";
  for (const app::PlotView* plot : w.window.plots()->plots())
    EXPECT_EQ(plot->toPlot().note(), "") << plot->title().toStdString() << " keeps a read-out of the old run";
  // the new run's read-out: the gut volume error of its latest sample, within the last plotted values
  ASSERT_TRUE(w.window.runUntil(0.5));
  const std::string after = gut->toPlot().note();
  double shown = std::nan("");
  ASSERT_EQ(std::sscanf(after.c_str(), "now %lf %%", &shown), 1) << after;
  const std::vector<double>& t = gut->time();
  const std::vector<double>& y = gut->series()[0].y;
  ASSERT_FALSE(t.empty());
  double lo = 1e300, hi = -1e300;
  for (std::size_t k = 0; k < t.size(); ++k)
    if (t[k] >= t.back() - 0.1) lo = std::min(lo, y[k]), hi = std::max(hi, y[k]);
  EXPECT_GE(shown, lo - 5e-4) << after;
  EXPECT_LE(shown, hi + 5e-4) << after;
}

TEST(MainWindow, ScrubbingRestoresThatInstantsVolumeInThePlotCursor) {
  ToyWindow w;
  ASSERT_TRUE(w.window.runUntil(5.0));
  const app::PlotView* plot = w.window.plots()->volumePlot();
  // the live sample nearest to t = 3 s
  const std::vector<double> t = plot->time();  // a copy: the scrub refreshes the plot
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
  // one dataset entry per part and recorded frame (0.5 s at 60 Hz: 30 or 31 frames, 7 parts each)
  EXPECT_GE(text.count("<DataSet"), 7 * 30);
  EXPECT_FALSE(QDir(out.filePath("run")).entryList({"*.vtp"}, QDir::Files).isEmpty());

  // an unwritable destination is an error, not a crash
  EXPECT_NE(w.window.exportRun("/proc/pneuma-no-such-dir/run.pvd"), QString());
}

// triggers the window's menu action whose text starts with `action` and hands the modal dialog it opens, of
// type Dialog, to `fill` (which accepts or rejects it); false when there is no such action or dialog
template <class Dialog>
bool runDialog(MainWindow& window, const QString& action, const std::function<void(Dialog*)>& fill) {
  QAction* found = nullptr;
  for (QAction* a : window.findChildren<QAction*>())
    if (a->text().startsWith(action)) found = a;
  if (!found) return false;
  bool isShown = false;
  QTimer::singleShot(0, [&] {
    auto* d = qobject_cast<Dialog*>(QApplication::activeModalWidget());
    if (!d) {
      if (QApplication::activeModalWidget()) QApplication::activeModalWidget()->close();
      return;
    }
    isShown = true;
    fill(d);
  });
  found->trigger();
  return isShown;
}

// the times [s] of the frames a .pvd lists (its bones part, one per frame)
std::vector<double> seriesTimes(const QString& pvdPath) {
  QFile pvd(pvdPath);
  std::vector<double> times;
  if (!pvd.open(QIODevice::ReadOnly)) return times;
  const QRegularExpression entry("timestep=\"([^\"]+)\" group=\"\" part=\"0\"");
  for (auto m = entry.globalMatch(QString::fromUtf8(pvd.readAll())); m.hasNext();)
    times.push_back(m.next().captured(1).toDouble());
  return times;
}

// File > Export > Run as ParaView series: the dialog announces the frames of the chosen range and stride and
// their size before anything is written, and the export writes those frames, at those times, of that size
TEST(MainWindow, SeriesDialogAnnouncesFramesAndSizeAndTheExportWritesThem) {
  ToyWindow w;
  ASSERT_TRUE(w.window.runUntil(2.0));
  QTemporaryDir out;
  QString summary, emptyRange;
  bool wasRefused = false;
  int announced = 0;
  ASSERT_TRUE(runDialog<app::SeriesDialog>(w.window, "Run as ParaView series", [&](app::SeriesDialog* d) {
    d->setPath(out.filePath("run.pvd"));
    d->fromBox()->setValue(1.5);
    d->toBox()->setValue(0.5);
    emptyRange = d->summary();
    wasRefused = !d->canExport();
    d->fromBox()->setValue(0.5);
    d->toBox()->setValue(1.5);
    d->strideBox()->setValue(3);
    summary = d->summary();
    announced = d->frameCount();
    d->accept();
  }));
  EXPECT_TRUE(wasRefused) << emptyRange.toStdString();
  // 0.5 s to 1.5 s of a 60 Hz recording is 61 frames; one in three is 21
  EXPECT_EQ(announced, 21);
  EXPECT_TRUE(summary.startsWith("21 frames (every 3rd recorded frame: 20 per second, 0.50 s to 1.50 s)"))
      << summary.toStdString();
  const std::vector<double> times = seriesTimes(out.filePath("run.pvd"));
  ASSERT_EQ(times.size(), 21u);
  EXPECT_NEAR(times.front(), 0.5, 1e-6);
  EXPECT_NEAR(times.back(), 1.5, 1e-6);
  for (std::size_t k = 1; k < times.size(); ++k) EXPECT_NEAR(times[k] - times[k - 1], 0.05, 1e-6);
  // the size written is the size announced, within 10 % (the frames differ a little)
  const QRegularExpressionMatch about = QRegularExpression("about ([0-9.]+) (kB|MB)").match(summary);
  ASSERT_TRUE(about.hasMatch()) << summary.toStdString();
  const double estimate = about.captured(1).toDouble() * (about.captured(2) == "MB" ? 1e6 : 1e3);  // [bytes]
  double written = 0.0;
  const QFileInfoList files = QDir(out.filePath("run")).entryInfoList(QDir::Files);
  EXPECT_EQ(files.size(), 7 * 21);  // seven parts per frame (VtkSeriesWriter.h)
  for (const QFileInfo& f : files) written += static_cast<double>(f.size());
  EXPECT_NEAR(written, estimate, 0.1 * estimate);
}

// Cancel during a series export removes the frames it wrote and nothing else: an earlier series of the same
// name and another file stay as they were, and no error is reported
TEST(MainWindow, CancelledSeriesExportRemovesOnlyItsOwnFiles) {
  ToyWindow w;
  ASSERT_TRUE(w.window.runUntil(2.0));
  QTemporaryDir out;
  ASSERT_EQ(w.window.exportRun(out.filePath("run.pvd"), {0.0, 0.5, 1}), QString());  // the earlier series
  {
    QFile other(out.filePath("notes.txt"));
    ASSERT_TRUE(other.open(QIODevice::WriteOnly));
    other.write("the lecturer's notes");
  }
  const QStringList before =
      QDir(out.path()).entryList(QDir::AllEntries | QDir::NoDotAndDotDot | QDir::Hidden);
  const QStringList frames = QDir(out.filePath("run")).entryList(QDir::Files);
  const std::size_t earlier = seriesTimes(out.filePath("run.pvd")).size();
  EXPECT_GE(earlier, 30u) << "0 s to 0.5 s at 60 Hz";
  // cancel from the progress dialog once three frames are written; the worker waits for the click
  int cancelledAt = -1;
  app::SimWorker* worker = w.window.worker();
  ASSERT_NE(worker, nullptr);
  auto connection = QObject::connect(
      worker, &app::SimWorker::exportProgress, &w.window,
      [&](int written, int) {
        if (written < 3 || cancelledAt >= 0) return;
        for (QProgressDialog* dialog : w.window.findChildren<QProgressDialog*>())
          if (dialog->isVisible()) {
            cancelledAt = written;
            dialog->findChild<QPushButton*>()->click();  // as the user does
          }
      },
      Qt::BlockingQueuedConnection);
  const QString error = w.window.exportRun(out.filePath("run.pvd"), {0.0, 2.0, 1});
  QObject::disconnect(connection);
  EXPECT_EQ(error, app::ExportController::cancelled());
  EXPECT_EQ(cancelledAt, 3) << "the progress dialog counted the frames";
  EXPECT_EQ(QDir(out.path()).entryList(QDir::AllEntries | QDir::NoDotAndDotDot | QDir::Hidden), before);
  EXPECT_EQ(QDir(out.filePath("run")).entryList(QDir::Files), frames) << "the earlier series is whole";
  EXPECT_EQ(seriesTimes(out.filePath("run.pvd")).size(), earlier);
  EXPECT_EQ(w.window.lastError(), QString()) << "a cancel is not an error";
}

// File > Export > Run as glTF and Baked morph targets: the recording's skin fitted onto targets baked from
// the physics (docs/patterns.md), read back with the skin's vertex count; a bad folder is an error, not a
// file
TEST_F(DefaultModelWindow, RunExportsAsGltfWithBakedMorphTargets) {
  ASSERT_TRUE(window.runUntil(2.5));
  QTemporaryDir out;
  ASSERT_EQ(window.exportGltf(out.filePath("run.glb")), QString());
  const sim::MorphTargets run = viz::readGltfMorphTargets(out.filePath("run.glb").toStdString());
  // breathing, chest, belly, and the shoulders of the default model's shoulder girdle
  ASSERT_EQ(run.targets.size(), window.model()->bodies.anySupported() ? 4u : 3u);
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

// the teaching view: no caption covers another caption or a colour legend, from any camera preset and with
// all three legends shown ("diaphragm apex" lay over "xiphoid", a landmark's caption over the colour bar);
// every caption is inside the view and of one height (one font size)
TEST_F(DefaultModelWindow, CaptionsOverlapNeitherEachOtherNorTheLegends) {
  const std::set<std::string> groupNames = {
      "External intercostals", "Internal intercostals",  "Diaphragm",
      "Rectus abdominis",      "Transversus / obliques", "Costal cartilage"};
  ASSERT_TRUE(window.runUntil(3.5)) << window.lastError().toStdString();  // mid-inspiration, magnified
  viz::DisplayOptions o = window.scene().options();
  o.showLabels = true;
  o.showLandmarks = true;
  o.skinColouring = viz::SkinColouring::Displacement;
  window.setDisplayOptions(o);
  vtkRenderer* renderer = window.scene().renderer();
  struct Box {
    std::string text;
    QRectF rect;  // [px] display coordinates
  };
  auto boxOf = [renderer](vtkActor2D* actor) {
    const int* a = actor->GetPositionCoordinate()->GetComputedDisplayValue(renderer);
    const int* b = actor->GetPosition2Coordinate()->GetComputedDisplayValue(renderer);
    return QRectF(QPointF(a[0], a[1]), QPointF(b[0], b[1])).normalized();
  };
  for (const auto& [name, preset] : viz::cameraPresets()) {
    window.scene().setCamera(preset);
    window.grabView();  // renders, which lays the captions out
    const QRectF view(0, 0, renderer->GetSize()[0], renderer->GetSize()[1]);
    std::vector<Box> captions, legends;
    vtkPropCollection* props = renderer->GetViewProps();
    props->InitTraversal();
    while (vtkProp* prop = props->GetNextProp()) {
      if (!prop->GetVisibility()) continue;
      if (auto* caption = vtkCaptionActor2D::SafeDownCast(prop))
        captions.push_back({caption->GetCaption(), boxOf(caption)});
      if (auto* bar = vtkScalarBarActor::SafeDownCast(prop)) legends.push_back({bar->GetTitle(), boxOf(bar)});
    }
    EXPECT_EQ(legends.size(), 3u) << "tension, gut and skin legends";
    int groups = 0;
    for (std::size_t i = 0; i < captions.size(); ++i) {
      groups += static_cast<int>(groupNames.count(captions[i].text));
      EXPECT_TRUE(view.contains(captions[i].rect)) << "camera " << name << ": '" << captions[i].text << "'";
      EXPECT_NEAR(captions[i].rect.height(), captions[0].rect.height(), 1.0)
          << "camera " << name << ": '" << captions[i].text << "'";
      for (std::size_t j = i + 1; j < captions.size(); ++j)
        EXPECT_FALSE(captions[i].rect.intersects(captions[j].rect))
            << "camera " << name << ": '" << captions[i].text << "' covers '" << captions[j].text << "'";
      for (const Box& legend : legends)
        EXPECT_FALSE(captions[i].rect.intersects(legend.rect))
            << "camera " << name << ": '" << captions[i].text << "' covers the legend '" << legend.text
            << "'";
    }
    EXPECT_EQ(groups, 6);
    EXPECT_GE(captions.size(), 6u + 6u) << "the groups, five landmarks and the sternum";
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

// movie options over [from, to] [s] at `fps`, at `size` (empty: as shown)
app::ExportController::MovieOptions movieOptions(double from, double to, QSize size = {}, double fps = 25.0) {
  app::ExportController::MovieOptions o;
  o.from = from;
  o.to = to;
  o.size = size;
  o.fps = fps;
  return o;
}

// true when this process has no child left, running or unreaped (ffmpeg was stopped and waited for)
bool hasNoChildProcess() {
  int status = 0;
  return waitpid(-1, &status, WNOHANG) == -1 && errno == ECHILD;
}

// pixels that differ between two images of one size inside `area`
int differingPixels(const QImage& a, const QImage& b, const QRect& area) {
  int n = 0;
  for (int y = area.top(); y <= area.bottom(); ++y)
    for (int x = area.left(); x <= area.right(); ++x) n += a.pixel(x, y) != b.pixel(x, y) ? 1 : 0;
  return n;
}

TEST(MainWindow, AnimationExportsAsMp4OggAndPngSequenceOverTheRangeAndSize) {
  ToyWindow w;
  ASSERT_TRUE(w.window.runUntil(1.5));
  QTemporaryDir out;
  // 0.2 s at 25 fps: 6 frames
  ASSERT_EQ(w.window.exportAnimation(out.filePath("breath.png"), movieOptions(0.4, 0.6)), QString());
  const QStringList frames = QDir(out.path()).entryList({"breath_*.png"}, QDir::Files, QDir::Name);
  ASSERT_EQ(frames.size(), 6);
  EXPECT_EQ(QImage(out.filePath(frames.front())).size(), w.window.viewSize());

  ASSERT_EQ(w.window.exportAnimation(out.filePath("breath.ogv"), movieOptions(0.4, 0.6)), QString());
  QFile movie(out.filePath("breath.ogv"));
  ASSERT_TRUE(movie.open(QIODevice::ReadOnly));
  EXPECT_TRUE(movie.read(4) == "OggS");  // an Ogg container
  EXPECT_GT(movie.size(), 1000);

  // MP4 as shown: the view's size, cropped to even numbers
  ASSERT_EQ(w.window.exportAnimation(out.filePath("shown.mp4"), movieOptions(0.4, 0.6)), QString());
  test::expectMp4(out.filePath("shown.mp4").toStdString(), 6, w.window.viewSize().width() & ~1,
                  w.window.viewSize().height() & ~1);

  // a chosen range and size: 0.4 s to 1.2 s is 21 frames, 0.84 s of movie, rendered at 1280 x 720
  ASSERT_EQ(w.window.exportAnimation(out.filePath("range.mp4"), movieOptions(0.4, 1.2, QSize(1280, 720))),
            QString());
  test::expectMp4(out.filePath("range.mp4").toStdString(), 21, 1280, 720);
  EXPECT_TRUE(QDir(out.path()).entryList({"*.tmp-*"}, QDir::Files).isEmpty());
  EXPECT_TRUE(hasNoChildProcess());

  // the view is back on screen afterwards: it draws the model again (the rendering left the off-screen
  // window)
  const QImage after = w.window.grabView();
  EXPECT_GT(distinctColours(after), 20);
}

// the overlays are drawn where they are said to be, over the same picture: the time stamp at the top left,
// the volume panel at the bottom left, nothing else changed; the panel's cursor moves with the frame
TEST(MainWindow, MovieOverlaysDrawTheTimeStampAndTheVolumePanel) {
  ToyWindow w;
  ASSERT_TRUE(w.window.runUntil(2.0));
  QTemporaryDir out;
  // 0.8 s to 1.6 s at 2.5 frames per second: the instants 0.8, 1.2 and 1.6 s
  app::ExportController::MovieOptions plain = movieOptions(0.8, 1.6, QSize(640, 360), 2.5);
  app::ExportController::MovieOptions overlaid = plain;
  overlaid.hasTimeStamp = true;
  overlaid.hasVolumePanel = true;
  ASSERT_EQ(w.window.exportAnimation(out.filePath("plain.png"), plain), QString());
  ASSERT_EQ(w.window.exportAnimation(out.filePath("over.png"), overlaid), QString());
  const QImage a = QImage(out.filePath("plain_0000.png")).convertToFormat(QImage::Format_RGB32);
  const QImage b = QImage(out.filePath("over_0000.png")).convertToFormat(QImage::Format_RGB32);
  const QImage b2 = QImage(out.filePath("over_0002.png")).convertToFormat(QImage::Format_RGB32);
  ASSERT_EQ(a.size(), QSize(640, 360));
  ASSERT_EQ(b.size(), a.size());
  const QRect stamp(220, 0, 200, 40);   // "t = 0.80 s" at the top centre, 9 px down
  const QRect panel(9, 231, 268, 120);  // 42 % of the width, 120 px high (the least), 9 px from the corner
  const QRect rest(300, 45, 340, 315);  // neither overlay
  const QRect corner(0, 0, 150, 40);    // the view's caption "motion x5" stays visible
  EXPECT_GT(differingPixels(a, b, stamp), 500) << "the time stamp";
  EXPECT_GT(differingPixels(a, b, panel), 0.5 * panel.width() * panel.height()) << "the volume panel";
  EXPECT_EQ(differingPixels(a, b, rest), 0) << "the overlays cover nothing else";
  EXPECT_EQ(differingPixels(a, b, corner), 0) << "nor the magnification caption";
  // 1.2 s later the stamp reads another time and the panel's cursor stands elsewhere
  EXPECT_GT(differingPixels(b, b2, stamp), 50);
  EXPECT_GT(differingPixels(b, b2, panel), 100);
}

// File > Export > Animation: the dialog offers the whole recording, shows the frame count and the estimated
// size of what it will write before rendering, refuses an empty range, and writes what it announced
TEST(MainWindow, MovieDialogAnnouncesFramesAndSizeAndWritesThem) {
  ToyWindow w;
  ASSERT_TRUE(w.window.runUntil(1.5));
  QTemporaryDir out;
  QString summary, emptyRange;
  bool wasRefused = false;
  ASSERT_TRUE(runDialog<app::MovieDialog>(w.window, "Animation of the recording", [&](app::MovieDialog* d) {
    EXPECT_NEAR(d->fromBox()->value(), w.window.shown()->recordedFrom, 0.01);
    EXPECT_NEAR(d->toBox()->value(), w.window.shown()->recordedTo, 0.01);
    d->setPath(out.filePath("dialog.mp4"));
    d->fromBox()->setValue(1.2);
    d->toBox()->setValue(0.4);
    emptyRange = d->summary();
    wasRefused = !d->canExport();
    d->fromBox()->setValue(0.4);
    d->toBox()->setValue(1.2);
    d->sizeBox()->setCurrentIndex(1);  // 640 x 360
    d->timeStampBox()->setChecked(true);
    d->volumePanelBox()->setChecked(true);
    summary = d->summary();
    d->accept();
  }));
  EXPECT_TRUE(wasRefused) << emptyRange.toStdString();
  EXPECT_TRUE(emptyRange.contains("From must come before To")) << emptyRange.toStdString();
  EXPECT_TRUE(summary.contains("21 frames (0.80 s at 25 fps), 640 x 360 px, MP4")) << summary.toStdString();
  EXPECT_TRUE(summary.contains(QRegularExpression("about [0-9.]+ (kB|MB)"))) << summary.toStdString();
  test::expectMp4(out.filePath("dialog.mp4").toStdString(), 21, 640, 360);
}

// the dialog's size estimate holds for the default model's view: an MP4 at 640 x 360 and at 1280 x 720 comes
// within a factor of two of viz::MovieWriter::estimatedBytes()
TEST_F(DefaultModelWindow, MovieSizeEstimateHoldsForTheDefaultModel) {
  ASSERT_TRUE(window.runUntil(5.0)) << window.lastError().toStdString();
  QTemporaryDir out;
  for (const QSize size : {QSize(640, 360), QSize(1280, 720)}) {
    const QString path = out.filePath(QString("calm_%1.mp4").arg(size.width()));
    const app::ExportController::MovieOptions o = movieOptions(3.0, 5.0, size);
    ASSERT_EQ(window.exportAnimation(path, o), QString());
    const double estimate = viz::MovieWriter::estimatedBytes(
        viz::MovieWriter::Format::Mp4, size.width(), size.height(), app::ExportController::frameCount(o));
    const double written = static_cast<double>(QFileInfo(path).size());  // [bytes]
    EXPECT_GT(written, 0.5 * estimate) << size.width() << ": " << written << " bytes, estimated " << estimate;
    EXPECT_LT(written, 2.0 * estimate) << size.width() << ": " << written << " bytes, estimated " << estimate;
  }
}

// a movie export shows its progress, and Cancel part-way stops ffmpeg and leaves no file of its own behind
// (neither the movie nor a temporary) while another file in the folder stays, with no error reported
TEST(MainWindow, CancelledAnimationExportLeavesNoFile) {
  ToyWindow w;
  ASSERT_TRUE(w.window.runUntil(1.5));
  QTemporaryDir out;
  {
    QFile other(out.filePath("notes.txt"));
    ASSERT_TRUE(other.open(QIODevice::WriteOnly));
    other.write("the lecturer's notes");
  }
  for (const QString name : {"breath.mp4", "breath.ogv"}) {
    int shownAt = -1;
    QTimer clicker;
    QObject::connect(&clicker, &QTimer::timeout, [&] {
      for (QProgressDialog* dialog : w.window.findChildren<QProgressDialog*>())
        if (dialog->isVisible() && dialog->value() >= 3 && shownAt < 0) {
          shownAt = dialog->value();
          EXPECT_EQ(dialog->maximum(), 26) << "1 s at 25 fps";
          dialog->cancel();
        }
    });
    clicker.start(2);
    const QString error = w.window.exportAnimation(out.filePath(name), movieOptions(0.4, 1.4));
    clicker.stop();
    EXPECT_EQ(error, app::ExportController::cancelled()) << name.toStdString();
    EXPECT_GE(shownAt, 3) << "the progress dialog was shown and counted frames";
    EXPECT_EQ(QDir(out.path()).entryList(QDir::Files | QDir::Hidden), QStringList{"notes.txt"})
        << QDir(out.path()).entryList(QDir::Files | QDir::Hidden).join(", ").toStdString();
    EXPECT_EQ(w.window.lastError(), QString()) << "a cancel is not an error";
  }
  EXPECT_TRUE(hasNoChildProcess()) << "ffmpeg was stopped and reaped";
}

// without ffmpeg, an MP4 is refused with a message that says what to install, in the dialog and the export,
// and an Ogg movie still exports
TEST(MainWindow, MissingFfmpegIsExplainedAndOggStillWorks) {
  ToyWindow w;
  ASSERT_TRUE(w.window.runUntil(1.0));
  QTemporaryDir out;
  setenv("PNEUMA_FFMPEG", "/nonexistent/ffmpeg", 1);
  app::MovieDialog dialog(0.0, 1.0, QSize(320, 240));
  dialog.setPath(out.filePath("breath.mp4"));
  const QString summary = dialog.summary();
  const bool isEnabled = dialog.canExport();
  const QString error = w.window.exportAnimation(out.filePath("breath.mp4"), movieOptions(0.4, 0.6));
  const QString ogg = w.window.exportAnimation(out.filePath("breath.ogv"), movieOptions(0.4, 0.6));
  unsetenv("PNEUMA_FFMPEG");
  EXPECT_FALSE(isEnabled);
  EXPECT_TRUE(summary.contains("apt install ffmpeg")) << summary.toStdString();
  EXPECT_TRUE(error.contains("apt install ffmpeg")) << error.toStdString();
  EXPECT_EQ(w.window.lastError(), error);
  EXPECT_EQ(ogg, QString());
  EXPECT_EQ(QDir(out.path()).entryList(QDir::Files | QDir::Hidden), QStringList{"breath.ogv"});
}

// pneuma --movie: simulates, writes the asked range at the asked size with overlays, and exits; bad options
// are refused by name before anything runs
TEST(App, MovieFromTheCommandLine) {
  application();
  QTemporaryDir dir;
  const QString model = writeToyModel(dir);
  const std::string movie = dir.filePath("cli.mp4").toStdString();
  const test::CliResult r =
      test::runProgram("pneuma", {"--model", model.toStdString(), "--movie", movie, "--from", "0.5", "--to",
                                  "1.5", "--size", "640x360", "--overlay", "time,volume"});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("26 frames"), std::string::npos) << r.out;
  test::expectMp4(movie, 26, 640, 360);

  const std::vector<std::pair<std::vector<std::string>, std::string>> bad = {
      {{"--movie", movie, "--size", "640by360"}, "--size"},
      {{"--movie", movie, "--overlay", "time,pressure"}, "unknown overlay 'pressure'"},
      {{"--movie", movie, "--from", "2", "--to", "1"}, "--from"},
      {{"--size", "640x360"}, "--size needs --movie FILE"}};
  for (const auto& [args, message] : bad) {
    const test::CliResult refused = test::runProgram("pneuma", args);
    EXPECT_EQ(refused.exitCode, 2) << refused.err;
    EXPECT_NE(refused.err.find(message), std::string::npos) << refused.err;
  }
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

namespace {

// pixels of a 3D-view grab that belong to a drawn body: redder than blue (the backdrop is blue-grey)
std::vector<bool> bodyMask(const QImage& image) {
  std::vector<bool> mask;
  mask.reserve(static_cast<std::size_t>(image.width() * image.height()));
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) {
      const QColor c = image.pixelColor(x, y);
      mask.push_back(c.red() > c.blue() + 20);
    }
  return mask;
}

void waitMs(int ms) {
  QElapsedTimer clock;
  clock.start();
  while (clock.elapsed() < ms) QApplication::processEvents(QEventLoop::AllEvents, 10);
}

}  // namespace

// de Melo's morph playback: the physics pauses, the caption says so, and the skin driven by the pattern
// alone breathes: its drawn silhouette at the pattern's end-inspiration differs from its end-expiration,
// half a breath earlier (both found by playing the same pattern on the same targets, sim::MorphPlayer);
// off again, the physics' instant comes back, not advanced
TEST_F(DefaultModelWindow, MorphPlaybackBreathesTheSkinWithThePhysicsPaused) {
  ASSERT_TRUE(window.morphPlaybackAction()->isEnabled());
  window.play();
  ASSERT_EQ(window.setMorphPlayback(true), QString());
  EXPECT_TRUE(window.isMorphPlayback());
  EXPECT_TRUE(window.morphPlaybackAction()->isChecked());
  const std::vector<std::string> texts = shownTexts(window.scene().renderer());
  EXPECT_NE(
      std::find(texts.begin(), texts.end(), "morph playback: neutral, no physics \u00b7 motion \u00d75"),
      texts.end());

  // the end-expiration and end-inspiration of the second breath, from the weights' sum
  const std::shared_ptr<const sim::MorphTargets> morphs = window.morphTargets();
  ASSERT_NE(morphs, nullptr);
  sim::MorphPlayer player(sim::pattern::loadAffect("neutral", sim::resourceDir()), 0);
  double low = 1e9, high = -1e9, tLow = 0.0, tHigh = 0.0;
  for (double t = 0.0; t < 12.0; t += 0.05) {
    const double a = player.weightsAt(*morphs, t).sum();
    if (t > 4.0 && a < low) std::tie(low, tLow) = std::make_pair(a, t);
    if (t > 4.0 && a > high) std::tie(high, tHigh) = std::make_pair(a, t);
  }
  ASSERT_GT(high, low + 0.1) << "the neutral breath moves the weights";
  const int sternum = static_cast<int>(std::find(morphs->bones.begin(), morphs->bones.end(), "sternum") -
                                       morphs->bones.begin());
  ASSERT_LT(sternum, static_cast<int>(morphs->bones.size())) << "the targets carry the bones";
  window.showMorphPlaybackAt(tLow);
  const Eigen::Vector3d sternumLow =
      window.scene().posed().body[static_cast<std::size_t>(sternum)].translation();
  window.showMorphPlaybackAt(tHigh);
  const Eigen::Vector3d sternumHigh =
      window.scene().posed().body[static_cast<std::size_t>(sternum)].translation();
  // the bones ride with the skin: the sternum moves forward (+y) on the inhale, magnified 5x
  EXPECT_GT(sternumHigh.y() - sternumLow.y(), 0.005) << "the sternum moves forward at end-inspiration";
  // and they are drawn inside the translucent skin: hiding them changes the picture
  const QImage withBones = window.grabView();
  viz::DisplayOptions noBones = window.scene().options();
  noBones.showBones = false;
  window.setDisplayOptions(noBones);
  const QImage withoutBones = window.grabView();
  noBones.showBones = true;
  window.setDisplayOptions(noBones);
  EXPECT_GT(differing(withBones, withoutBones), withBones.width() * withBones.height() / 50)
      << "the playback draws the bones";

  // the silhouette, with the skin opaque as a user would show it
  viz::DisplayOptions opaque = window.scene().options();
  opaque.skin = viz::SkinDisplay::Opaque;
  window.setDisplayOptions(opaque);
  window.showMorphPlaybackAt(std::min(tLow, tHigh));
  const std::vector<bool> first = bodyMask(window.grabView());
  window.showMorphPlaybackAt(std::max(tLow, tHigh));
  const std::vector<bool> second = bodyMask(window.grabView());
  int moved = 0, body = 0;
  for (std::size_t i = 0; i < first.size(); ++i) {
    moved += first[i] != second[i];
    body += first[i];
  }
  EXPECT_GT(body, static_cast<int>(first.size()) / 10) << "the skin covers the view's middle";
  EXPECT_GT(moved, 1000) << "the silhouette moves between end-expiration and end-inspiration";

  // the physics stayed paused
  waitMs(300);
  ASSERT_EQ(window.setMorphPlayback(false), QString());
  EXPECT_FALSE(window.morphPlaybackAction()->isChecked());
  waitMs(300);
  ASSERT_NE(window.shown(), nullptr);
  const double paused = window.shown()->state.time;
  waitMs(500);
  EXPECT_EQ(window.shown()->state.time, paused);
  for (const std::string& text : shownTexts(window.scene().renderer()))
    EXPECT_EQ(text.find("morph playback"), std::string::npos) << text;
}

// the skin is drawn decimated (docs/app.md, "Measured under Xvfb": half its triangles, embedded in the full
// skin and posed from it) and still covers the body's pixels: opaque and alone in the view, its silhouette at
// a breathing instant is the full-resolution skin's, posed the same, to within a few pixels along the
// outline; coloured by displacement, its heat map still shows the breathing chest and belly in orange to red
TEST_F(DefaultModelWindow, SkinIsDrawnDecimatedAndCoversTheFullSkinsPixels) {
  const sim::Model& model = *window.model();
  ASSERT_GT(model.skin.vertexCount(), 0);
  ASSERT_TRUE(window.runUntil(5.0));
  viz::DisplayOptions o = window.scene().options();
  o.showBones = o.showGut = o.showLungs = o.showLandmarks = o.showTissue = false;
  o.showGroup.fill(false);
  o.skin = viz::SkinDisplay::Opaque;
  window.setDisplayOptions(o);
  const QImage drawn = window.grabView();

  // the one actor shown is the skin, with at most 60 % of the model's triangles
  vtkActor* skin = nullptr;
  int shown = 0;
  vtkActorCollection* actors = window.scene().renderer()->GetActors();
  actors->InitTraversal();
  while (vtkActor* a = actors->GetNextActor())
    if (a->GetVisibility()) {
      skin = a;
      ++shown;
    }
  ASSERT_EQ(shown, 1);
  const vtkIdType triangles = vtkPolyData::SafeDownCast(skin->GetMapper()->GetInput())->GetNumberOfPolys();
  EXPECT_LT(triangles, 0.6 * static_cast<double>(model.skin.triangles.cols()));
  EXPECT_GT(triangles, 0.3 * static_cast<double>(model.skin.triangles.cols()));

  // the full skin as posed for the same frame, drawn alone in its place
  const Eigen::Matrix3Xd& full = window.scene().posed().skin;
  vtkNew<vtkPolyData> mesh;
  vtkNew<vtkPoints> points;
  for (Eigen::Index v = 0; v < full.cols(); ++v) points->InsertNextPoint(full(0, v), full(1, v), full(2, v));
  mesh->SetPoints(points);
  vtkNew<vtkCellArray> cells;
  for (Eigen::Index t = 0; t < model.skin.triangles.cols(); ++t) {
    const vtkIdType ids[3] = {model.skin.triangles(0, t), model.skin.triangles(1, t),
                              model.skin.triangles(2, t)};
    cells->InsertNextCell(3, ids);
  }
  mesh->SetPolys(cells);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(mesh);
  vtkNew<vtkActor> reference;
  reference->SetMapper(mapper);
  reference->GetProperty()->SetColor(skin->GetProperty()->GetColor());
  o.skin = viz::SkinDisplay::Hidden;
  window.setDisplayOptions(o);
  window.scene().renderer()->AddActor(reference);
  const QImage fullSkin = window.grabView();
  window.scene().renderer()->RemoveActor(reference);

  const std::vector<bool> a = bodyMask(drawn), b = bodyMask(fullSkin);
  ASSERT_EQ(a.size(), b.size());
  // the full skin's outline: its pixels with a horizontal or vertical neighbour outside it
  const auto w = static_cast<std::size_t>(drawn.width());
  int body = 0, mismatched = 0, outline = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    body += b[i];
    mismatched += a[i] != b[i];
    outline += b[i] && ((i % w > 0 && !b[i - 1]) || (i % w + 1 < w && !b[i + 1]) || (i >= w && !b[i - w]) ||
                        (i + w < b.size() && !b[i + w]));
  }
  EXPECT_GT(body, static_cast<int>(b.size()) / 10) << "the skin covers the view's middle";
  EXPECT_LT(mismatched, outline) << "the drawn skin covers the full skin's pixels to within a pixel or so";

  // the breathing heat map: orange to red skin (blue under 55 % of red) over a tenth of the body at the
  // breath's largest displacement, none with the plain colour
  const auto heated = [](const QImage& image) {
    int n = 0;
    for (int y = 0; y < image.height(); ++y)
      for (int x = 0; x < image.width(); ++x) {
        const QColor c = image.pixelColor(x, y);
        n += c.red() > 80 && c.blue() < 0.55 * c.red();
      }
    return n;
  };
  o.skin = viz::SkinDisplay::Opaque;
  o.skinColouring = viz::SkinColouring::Plain;
  window.setDisplayOptions(o);
  EXPECT_LT(heated(window.grabView()), body / 100) << "plain skin is skin-coloured";
  o.skinColouring = viz::SkinColouring::Displacement;
  window.setDisplayOptions(o);
  int most = 0;
  for (double t = 5.25; t <= 9.0; t += 0.25) {
    ASSERT_TRUE(window.runUntil(t));
    most = std::max(most, heated(window.grabView()));
  }
  EXPECT_GT(most, body / 10) << "the breathing skin shows its displacement";
}

TEST(MainWindow, MorphPlaybackOfAModelWithoutSkinIsDisabledWithTheReason) {
  ToyWindow w;
  EXPECT_FALSE(w.window.morphPlaybackAction()->isEnabled());
  EXPECT_TRUE(w.window.morphPlaybackAction()->toolTip().contains("needs a skin"))
      << w.window.morphPlaybackAction()->toolTip().toStdString();
  EXPECT_TRUE(w.window.setMorphPlayback(true).contains("has no skin"));
  EXPECT_FALSE(w.window.isMorphPlayback());
}

namespace {

// a copy of the shipped calm scenario, shortened to `seconds` after settling, in `dir`
QString shortCalm(const QTemporaryDir& dir, double seconds) {
  sim::Scenario calm = sim::loadScenario(sim::resourceDir() + "/scenarios/calm.json");
  calm.name = "calm-short";
  calm.duration = seconds;
  const QString path = dir.filePath("calm-short.json");
  sim::saveScenario(calm, path.toStdString());
  return path;
}

// the volume plot's series named `name`, null when absent
const app::PlotView::Series* seriesNamed(const app::PlotView* plot, const QString& name) {
  for (const app::PlotView::Series& s : plot->series())
    if (s.name == name) return &s;
  return nullptr;
}

}  // namespace

// a teaching preset opens with its explanation on show; the normal run drawn dashed over it carries that
// run's own volumes, and the paralysed run breathes less than the normal one beside it
TEST_F(DefaultModelWindow, TeachingPresetShowsItsExplanationAndTheNormalRunDashed) {
  const QStringList presets = MainWindow::teachingPresets();
  EXPECT_EQ(presets.size(), 6) << presets.join(", ").toStdString();
  const QString left =
      QString::fromStdString(sim::resourceDir()) + "/scenarios/teaching/paralysed-left-hemidiaphragm.json";
  ASSERT_TRUE(presets.contains(left));
  ASSERT_EQ(window.openScenario(left), QString());
  EXPECT_TRUE(window.scenarioExplanation().startsWith("paralysed-left-hemidiaphragm"));
  EXPECT_TRUE(window.scenarioExplanation().contains("Laroche et al. 1988"));

  QTemporaryDir dir;
  ASSERT_EQ(window.overlayScenario(shortCalm(dir, 6.0)), QString());
  ASSERT_TRUE(window.runUntil(7.5, 180000)) << window.lastError().toStdString();
  const app::PlotView* plot = window.plots()->volumePlot();
  const app::PlotView::Series* normal = seriesNamed(plot, "calm-short lung volume");
  ASSERT_NE(normal, nullptr) << "the compared run is plotted";
  EXPECT_TRUE(normal->isDashed);
  EXPECT_EQ(normal->legend, "calm-short");
  // at every plotted time the overlaid run sampled too, the dashed value is that run's volume there [mL]
  const std::vector<app::PlotSample>& run = window.plots()->overlay().samples;
  ASSERT_GT(run.size(), 100u);
  int matched = 0;
  for (std::size_t k = 0; k < plot->time().size(); ++k) {
    const auto at = std::lower_bound(run.begin(), run.end(), plot->time()[k],
                                     [](const app::PlotSample& s, double t) { return s.time < t; });
    if (at == run.end() || std::abs(at->time - plot->time()[k]) > 1e-9) continue;
    EXPECT_NEAR(normal->y[k], 1e6 * at->lungVolume, 1e-6) << "at " << plot->time()[k] << " s";
    ++matched;
  }
  EXPECT_GT(matched, 100);
  // over the last breath, the paralysed run's swing is well below the normal one's
  const auto swing = [&](const std::vector<double>& y) {
    double lo = 1e300, hi = -1e300;
    for (std::size_t k = 0; k < y.size(); ++k)
      if (plot->time()[k] >= 3.5 && std::isfinite(y[k])) lo = std::min(lo, y[k]), hi = std::max(hi, y[k]);
    return hi - lo;
  };
  EXPECT_LT(swing(plot->series()[0].y), 0.9 * swing(normal->y));
  // the flow plot has its dashed twin too, and removing the comparison removes both
  EXPECT_NE(seriesNamed(window.plots()->flowPlot(), "calm-short flow"), nullptr);
  window.clearOverlay();
  window.plots()->refresh();
  EXPECT_EQ(seriesNamed(window.plots()->volumePlot(), "calm-short lung volume"), nullptr);
}

// a run of another model is not drawn: a scenario of the default model or a recording of it, over the toy
// torso, each gives a message naming both models
// the ghost of the compared run: its gut and lungs drawn light grey where that run has them at the shown
// instant (magnified as the run is). Calm compared with calm, the ghost lies on the run's own gut and lungs;
// a paralysed left hemidiaphragm compared with calm, it does not. Its check box hides it, and removing the
// comparison removes it.
TEST_F(DefaultModelWindow, GhostOfTheComparedRunIsDrawnWhereThatRunIs) {
  QTemporaryDir dir;
  const QString calm = shortCalm(dir, 10.0);
  const QString left =
      QString::fromStdString(sim::resourceDir()) + "/scenarios/teaching/paralysed-left-hemidiaphragm.json";
  const viz::DisplayOptions defaults = window.scene().options();  // opening a model frames what is shown
  viz::DisplayOptions o = defaults;
  o.showBones = o.showLandmarks = o.showCavity = false;
  o.skin = viz::SkinDisplay::Hidden;
  o.showGroup.fill(false);
  o.gutColouring = viz::GutColouring::Plain;  // no legend
  o.magnification = viz::kMaxMagnification;
  // seen from the side at the second end-inspiration (8 s): the chest and belly forward, the dome down
  const auto runToEndInspiration = [&] {
    if (!window.runUntil(8.0, 180000)) return false;
    for (QPushButton* b : window.findChildren<QPushButton*>())
      if (b->text() == "Lateral") b->click();
    QApplication::processEvents();
    return true;
  };
  // the pixels where a grab differs from the empty view
  const auto mask = [](const QImage& a, const QImage& empty) {
    std::vector<char> m(static_cast<std::size_t>(a.width() * a.height()));
    for (int y = 0; y < a.height(); ++y)
      for (int x = 0; x < a.width(); ++x) {
        const QColor p = a.pixelColor(x, y), q = empty.pixelColor(x, y);
        m[static_cast<std::size_t>(y * a.width() + x)] =
            std::abs(p.red() - q.red()) + std::abs(p.green() - q.green()) + std::abs(p.blue() - q.blue()) >
            30;
      }
    return m;
  };
  // the share of the run's gut-and-lung pixels that the ghost alone does not cover, or covers where the run
  // has none
  const auto ghostMismatch = [&] {
    o.showGut = o.showLungs = true;
    o.showGhost = false;
    window.setDisplayOptions(o);
    const QImage run = window.grabView();
    o.showGut = o.showLungs = false;
    o.showGhost = true;
    window.setDisplayOptions(o);
    EXPECT_TRUE(window.scene().isGhostShown());
    const QImage ghost = window.grabView();
    o.showGhost = false;
    window.setDisplayOptions(o);
    const QImage empty = window.grabView();
    const std::vector<char> a = mask(run, empty), b = mask(ghost, empty);
    int covered = 0, differ = 0;
    for (std::size_t k = 0; k < a.size(); ++k) {
      covered += a[k];
      differ += a[k] != b[k];
    }
    EXPECT_GT(covered, static_cast<int>(a.size()) / 40) << "the gut and lungs fill the view's middle";
    return static_cast<double>(differ) / std::max(covered, 1);
  };

  ASSERT_EQ(window.openScenario(calm), QString());
  ASSERT_EQ(window.overlayScenario(calm), QString());
  ASSERT_TRUE(runToEndInspiration()) << window.lastError().toStdString();
  const double same = ghostMismatch();
  // (the translucent edges of the differently coloured surfaces cross the mask's threshold at different
  // pixels: a few per cent, 8 % with the view framed on the whole body, arms and head; a paralysed
  // hemidiaphragm gives 42 %)
  EXPECT_LT(same, 0.1) << "calm against calm: the ghost lies on the run";

  window.setDisplayOptions(defaults);
  ASSERT_EQ(window.openScenario(left), QString());
  ASSERT_EQ(window.overlayScenario(calm), QString());
  ASSERT_TRUE(runToEndInspiration()) << window.lastError().toStdString();
  const double paralysed = ghostMismatch();
  EXPECT_GT(paralysed, 3.0 * same) << "paralysed against calm: the ghost is elsewhere";

  // the check box hides it; removing the comparison removes it
  QCheckBox* box = nullptr;
  for (QCheckBox* c : window.findChildren<QCheckBox*>())
    if (c->text() == "Ghost of the compared run") box = c;
  ASSERT_NE(box, nullptr);
  o.showGhost = true;
  window.setDisplayOptions(o);
  EXPECT_TRUE(window.scene().isGhostShown());
  box->click();
  QApplication::processEvents();
  EXPECT_FALSE(window.scene().isGhostShown());
  box->click();
  QApplication::processEvents();
  EXPECT_TRUE(window.scene().isGhostShown());
  window.clearOverlay();
  EXPECT_FALSE(window.scene().isGhostShown());
}

TEST(MainWindow, ComparisonWithAnotherModelIsRefusedWithAMessage) {
  ToyWindow w;
  const QString calm = QString::fromStdString(sim::resourceDir()) + "/scenarios/calm.json";
  const QString error = w.window.overlayScenario(calm);
  EXPECT_TRUE(error.contains("runs the model in")) << error.toStdString();
  EXPECT_TRUE(error.contains("the window shows '" + w.modelDir + "'")) << error.toStdString();

  QTemporaryDir dir;
  QFile summary(dir.filePath("summary.json"));
  ASSERT_TRUE(summary.open(QIODevice::WriteOnly));
  summary.write(R"({"model_name": "adult_male"})");
  summary.close();
  QFile csv(dir.filePath("timeseries.csv"));
  ASSERT_TRUE(csv.open(QIODevice::WriteOnly));
  csv.write("time [s],lung_volume [mL]\n0,4500\n0.1,4510\n");
  csv.close();
  const QString recording = w.window.overlayRecording(dir.filePath("timeseries.csv"));
  EXPECT_TRUE(recording.contains("was recorded on model 'adult_male', the window shows '" +
                                 QString::fromStdString(w.window.model()->name) + "'"))
      << recording.toStdString();
  EXPECT_TRUE(w.window.plots()->overlay().samples.empty()) << "nothing is drawn";
}
