// PlotView and its export share one layout (viz::layoutPlot): the same ranges, ticks and legend on screen
// and in the exported file.
#include "gui/PlotView.h"

#include <gtest/gtest.h>

#include <QApplication>
#include <QMouseEvent>
#include <QWheelEvent>
#include <cmath>
#include <string>
#include <vector>

#include "GuiTestSupport.h"
#include "viz/PlotLayout.h"

using namespace pneuma;
using pneuma::app::PlotView;

namespace {

// 30 s of a 4 s breath around 2500 mL, a dashed target, and a reference line; shown over a 20 s window
void fill(PlotView& view) {
  std::vector<double> t, v, target;
  for (int i = 0; i <= 600; ++i) {
    t.push_back(0.05 * i);
    v.push_back(2500.0 + 250.0 * std::sin(2.0 * M_PI * t.back() / 4.0));
    target.push_back(2500.0 + 230.0 * std::sin(2.0 * M_PI * t.back() / 4.0));
  }
  view.setData(t, {{"lung volume", QColor(20, 90, 190), false, v, "simulated"},
                   {"target volume", QColor(230, 90, 20), true, target, "target"}});
  view.setReferences({{"500 mL tidal", 2750.0, QColor(40, 160, 60)}});
  view.setNote("tidal volume 500 mL");
  view.setWindow(20.0);
}

}  // namespace

TEST(PlotView, ExportHasTheScreensRangesTicksAndLegend) {
  app::test::application();
  for (const QSize size : {QSize(480, 300), QSize(300, 170), QSize(760, 420)}) {
    SCOPED_TRACE(std::to_string(size.width()) + " x " + std::to_string(size.height()));
    PlotView view("Lung-cavity volume", "lung-cavity volume [mL]");
    view.resize(size);
    fill(view);
    const viz::PlotLayout screen = view.layout();
    const viz::Plot exported = view.toPlot();
    const viz::PlotLayout file = exported.layout();
    EXPECT_GE(exported.width(), 960);
    EXPECT_GE(exported.width(), 2 * size.width());

    // the rolling window on both
    EXPECT_DOUBLE_EQ(screen.x.lo, 10.0);
    EXPECT_DOUBLE_EQ(screen.x.hi, 30.0);
    EXPECT_DOUBLE_EQ(file.x.lo, screen.x.lo);
    EXPECT_DOUBLE_EQ(file.x.hi, screen.x.hi);
    EXPECT_DOUBLE_EQ(file.y.lo, screen.y.lo);
    EXPECT_DOUBLE_EQ(file.y.hi, screen.y.hi);
    // the same ticks and labels, at least two labelled on each axis
    EXPECT_EQ(file.x.values, screen.x.values);
    EXPECT_EQ(file.x.labels, screen.x.labels);
    EXPECT_EQ(file.y.values, screen.y.values);
    EXPECT_EQ(file.y.labels, screen.y.labels);
    EXPECT_GE(screen.x.values.size(), 2u);
    EXPECT_GE(screen.y.values.size(), 2u);
    // the same legend entries (two series and the reference line)
    ASSERT_EQ(screen.legend.size(), 3u);
    ASSERT_EQ(file.legend.size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(file.legend[i].label.text, screen.legend[i].label.text);
    // and the file shows those labels
    const std::string svg = exported.toSvg();
    for (const std::string& label : screen.y.labels)
      EXPECT_NE(svg.find(">" + label + "</text>"), std::string::npos) << label;
    for (const std::string& label : screen.x.labels)
      EXPECT_NE(svg.find(">" + label + "</text>"), std::string::npos) << label;
  }
}

TEST(PlotView, TicksLieInsideTheBoxAndLabelsDoNotOverlap) {
  app::test::application();
  PlotView view("Lung-cavity volume", "lung-cavity volume [mL]");
  view.resize(420, 260);
  fill(view);
  const viz::PlotLayout L = view.layout();
  for (double t : L.x.values) {
    EXPECT_GE(L.mapX(t), L.area.left - 1e-9);
    EXPECT_LE(L.mapX(t), L.area.right + 1e-9);
  }
  for (std::size_t i = 0; i + 1 < L.xTickLabels.size(); ++i)
    EXPECT_LT(L.xTickLabels[i].box.right, L.xTickLabels[i + 1].box.left);
  // "time [s]" beside the first x tick's label, not under it
  ASSERT_FALSE(L.xTickLabels.empty());
  if (L.xLabel.box.top < L.xTickLabels.front().box.bottom) {
    EXPECT_LE(L.xLabel.box.right, L.xTickLabels.front().box.left + 1e-9);
  }
  for (std::size_t i = 0; i + 1 < L.yTickLabels.size(); ++i)  // ascending values go up the screen
    EXPECT_GT(L.yTickLabels[i].box.top, L.yTickLabels[i + 1].box.bottom - 1e-9);
  for (const viz::PlotLayout::Text& t : L.yTickLabels) EXPECT_LE(t.box.right, L.area.left);
  EXPECT_GT(L.area.top, L.title.box.bottom);
  for (const viz::PlotLayout::LegendEntry& e : L.legend) EXPECT_LE(e.box.bottom, L.area.top);
}

// the plot keeps the whole history: the wheel zooms the span about the mouse, a drag scrolls back, a cursor
// outside the span brings the span to it (the plots follow the timeline), a double click follows the newest
// sample again
TEST(PlotView, WheelZoomsDragScrollsAndTheSpanFollowsTheCursor) {
  app::test::application();
  PlotView view("Lung-cavity volume", "lung-cavity volume [mL]");
  view.resize(480, 300);
  fill(view);  // 0-30 s, a 20 s span
  viz::PlotLayout L = view.layout();
  EXPECT_DOUBLE_EQ(L.x.lo, 10.0);
  const QPointF right(L.area.right - 1.0, 0.5 * (L.area.top + L.area.bottom));
  QWheelEvent in(right, view.mapToGlobal(right.toPoint()), QPoint(), QPoint(0, 120), Qt::NoButton,
                 Qt::NoModifier, Qt::NoScrollPhase, false);
  QApplication::sendEvent(&view, &in);
  EXPECT_DOUBLE_EQ(view.window(), 16.0);
  L = view.layout();
  EXPECT_NEAR(L.x.hi, 30.0, 0.1);
  EXPECT_NEAR(L.x.hi - L.x.lo, 16.0, 1e-9);

  // drag right by half the plot: 8 s earlier, and the series stop at the span's end
  const double pixels = 0.5 * L.area.width();
  const QPointF from(L.area.left + 10.0, right.y()), to(from.x() + pixels, right.y());
  QMouseEvent press(QEvent::MouseButtonPress, from, Qt::LeftButton, Qt::LeftButton, Qt::NoModifier);
  QMouseEvent move(QEvent::MouseMove, to, Qt::NoButton, Qt::LeftButton, Qt::NoModifier);
  QApplication::sendEvent(&view, &press);
  QApplication::sendEvent(&view, &move);
  L = view.layout();
  EXPECT_NEAR(L.x.hi, 22.0, 0.2);
  const viz::Plot shown = view.toPlot(1.0);
  ASSERT_FALSE(shown.series()[0].x.empty());
  EXPECT_LE(shown.series()[0].x.back(), L.x.hi + 1e-9);
  EXPECT_GE(shown.series()[0].x.front(), L.x.lo - 0.05);

  // a scrubbed instant outside the span: the span moves to centre it
  view.setCursor(3.0);
  L = view.layout();
  EXPECT_LE(L.x.lo, 3.0);
  EXPECT_GE(L.x.hi, 3.0);
  EXPECT_TRUE(std::isfinite(view.cursorValue(0)));

  // a double click follows the newest sample
  QMouseEvent twice(QEvent::MouseButtonDblClick, from, Qt::LeftButton, Qt::LeftButton, Qt::NoModifier);
  QApplication::sendEvent(&view, &twice);
  EXPECT_TRUE(std::isnan(view.viewEnd()));
  EXPECT_NEAR(view.layout().x.hi, 30.0, 1e-9);
}
