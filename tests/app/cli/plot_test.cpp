// pneuma::viz::Plot: PNG and SVG from one layout (viz::layoutPlot, shared with the app's PlotView), without
// OpenGL.
#include "viz/Plot.h"

#include <gtest/gtest.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkSmartPointer.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLUtilities.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "viz/PlotLayout.h"

using pneuma::viz::AxisTicks;
using pneuma::viz::Color;
using pneuma::viz::niceTicks;
using pneuma::viz::Plot;
using pneuma::viz::PlotLayout;

namespace {

Plot sinePlot() {
  Plot plot("Lung-cavity volume", "time [s]", "volume [mL]");
  std::vector<double> t, v, w;
  for (int i = 0; i <= 400; ++i) {
    t.push_back(i * 0.05);
    v.push_back(2500.0 + 250.0 * std::sin(2.0 * M_PI * 0.25 * t.back()));
    w.push_back(2500.0 + 400.0 * std::sin(2.0 * M_PI * 0.2 * t.back()));
  }
  plot.addSeries("calm", t, v);
  plot.addSeries("deep", t, w);
  plot.addReferenceLine("500 mL reference", 2750.0);
  return plot;
}

vtkSmartPointer<vtkImageData> decodePng(const std::vector<unsigned char>& bytes) {
  vtkNew<vtkPNGReader> reader;
  reader->SetMemoryBuffer(bytes.data());
  reader->SetMemoryBufferLength(static_cast<vtkIdType>(bytes.size()));
  reader->Update();
  return reader->GetOutput();
}

}  // namespace

TEST(Plot, PngDecodesWithRequestedSizeAndShowsBothSeriesColours) {
  Plot plot = sinePlot();
  plot.setSize(800, 450);
  const std::vector<unsigned char> png = plot.toPng();
  ASSERT_GT(png.size(), 8u);
  EXPECT_EQ(std::string(png.begin(), png.begin() + 8), std::string("\x89PNG\r\n\x1a\n", 8));
  auto img = decodePng(png);
  int dims[3];
  img->GetDimensions(dims);
  EXPECT_EQ(dims[0], 800);
  EXPECT_EQ(dims[1], 450);
  // count pixels close to the series colours (palette: black, then blue 0.12 0.47 0.71)
  int dark = 0, blue = 0, white = 0;
  for (int y = 0; y < dims[1]; ++y)
    for (int x = 0; x < dims[0]; ++x) {
      auto* p = static_cast<unsigned char*>(img->GetScalarPointer(x, y, 0));
      dark += p[0] < 40 && p[1] < 40 && p[2] < 40;
      blue += std::abs(p[0] - 31) < 20 && std::abs(p[1] - 120) < 20 && std::abs(p[2] - 181) < 20;
      white += p[0] == 255 && p[1] == 255 && p[2] == 255;
    }
  EXPECT_GT(blue, 1000);  // a 2 px line across ~700 px
  EXPECT_GT(dark, 1000);  // calm series, frame and text
  EXPECT_GT(white, 800 * 450 / 2);
}

TEST(Plot, SvgIsWellFormedXmlWithEscapedLabels) {
  Plot plot("a < b & c", "time [s]", "tension [N]");
  plot.addSeries("x", {0.0, 1.0, 2.0}, {0.0, 1.0, 0.0});
  const std::string svg = plot.toSvg();
  // well-formed XML (expat); the document element is <svg>
  vtkSmartPointer<vtkXMLDataElement> root;
  root.TakeReference(vtkXMLUtilities::ReadElementFromString(svg.c_str()));
  ASSERT_NE(root, nullptr);
  EXPECT_EQ(vtkXMLUtilities::ReadElementFromString("<svg><g></svg>"),
            nullptr);  // the parser does reject bad XML
  EXPECT_STREQ(root->GetName(), "svg");
  EXPECT_STREQ(root->GetAttribute("width"), "960");
  EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
  EXPECT_NE(svg.find("a &lt; b &amp; c"), std::string::npos);
  EXPECT_NE(svg.find(">tension [N]</text>"), std::string::npos);
  EXPECT_NE(svg.find("rotate(-90"), std::string::npos);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
}

TEST(Plot, NonFiniteValuesBreakTheLine) {
  Plot plot("gap", "time [s]", "y [-]");
  plot.addSeries("y", {0, 1, 2, 3, 4}, {0, 1, NAN, 1, 0});
  const std::string svg = plot.toSvg();
  // grid and frame lines plus two data pieces: the data colour (black, first palette entry) at the data width
  char width[64];
  std::snprintf(width, sizeof width, "stroke=\"rgb(0,0,0)\" stroke-width=\"%.2f\"",
                pneuma::viz::PlotStyle::kDataWidth * plot.layout().scale());
  std::size_t n = 0;
  for (std::size_t pos = 0; (pos = svg.find(width, pos)) != std::string::npos; ++pos) ++n;
  EXPECT_EQ(n, 2u);
}

TEST(Plot, MismatchedSeriesLengthsAreRejected) {
  Plot plot("t", "x", "y");
  EXPECT_THROW(plot.addSeries("bad", {0.0, 1.0}, {0.0}), std::invalid_argument);
}

TEST(Plot, WritesFilesThroughTemporaryNames) {
  const std::string dir = testing::TempDir();
  Plot plot = sinePlot();
  plot.writePng(dir + "plot_test.png");
  plot.writeSvg(dir + "plot_test.svg");
  std::ifstream png(dir + "plot_test.png", std::ios::binary), svg(dir + "plot_test.svg");
  EXPECT_TRUE(png.good());
  EXPECT_TRUE(svg.good());
  EXPECT_THROW(plot.writePng("/nonexistent-dir/plot.png"), std::runtime_error);
}

TEST(PlotLayout, NiceTicksForKnownRanges) {
  auto expectTicks = [](double lo, double hi, int target, const std::vector<double>& values,
                        const std::vector<std::string>& labels) {
    SCOPED_TRACE("[" + std::to_string(lo) + ", " + std::to_string(hi) + "], target " +
                 std::to_string(target));
    const AxisTicks a = niceTicks(lo, hi, target);
    ASSERT_EQ(a.values.size(), values.size());
    for (std::size_t i = 0; i < values.size(); ++i) EXPECT_NEAR(a.values[i], values[i], 1e-12);
    EXPECT_EQ(a.labels, labels);
  };
  expectTicks(0.0, 1.0, 5, {0.0, 0.2, 0.4, 0.6, 0.8, 1.0}, {"0.0", "0.2", "0.4", "0.6", "0.8", "1.0"});
  expectTicks(0.0, 10.0, 5, {0, 2, 4, 6, 8, 10}, {"0", "2", "4", "6", "8", "10"});
  expectTicks(10.0, 30.0, 4, {10, 15, 20, 25, 30}, {"10", "15", "20", "25", "30"});
  expectTicks(-0.35, 0.35, 4, {-0.2, 0.0, 0.2}, {"-0.2", "0.0", "0.2"});  // zero is "0.0", never "-0.0"
  expectTicks(0.0, 0.003, 3, {0.0, 0.001, 0.002, 0.003}, {"0.000", "0.001", "0.002", "0.003"});
  // a 1.5 L range that one 1000 mL step would label only once gets finer steps: at least two labels
  expectTicks(4400.0, 5900.0, 2, {4500, 5000, 5500}, {"4500", "5000", "5500"});
  // at most 1.25 target intervals (or, when a step with fewer than two ticks had to be refined, fewer than 6
  // ticks: the next finer step is at least 1/2.5 of it), each tick a whole multiple of its 1, 2 or 5 x 10^k
  // step
  for (double span : {0.7, 3.3, 17.0, 420.0, 9.1e4})
    for (int target = 2; target <= 10; ++target) {
      const AxisTicks a = niceTicks(-0.3 * span, 0.7 * span, target);
      EXPECT_LE(a.values.size(), std::max<std::size_t>(static_cast<std::size_t>(1.25 * target) + 1, 5));
      EXPECT_GE(a.values.size(), 2u);
      const double mantissa = a.step / std::pow(10.0, std::floor(std::log10(a.step) + 1e-12));
      EXPECT_TRUE(std::abs(mantissa - 1) < 1e-9 || std::abs(mantissa - 2) < 1e-9 ||
                  std::abs(mantissa - 5) < 1e-9)
          << a.step;
      for (double v : a.values) EXPECT_NEAR(v / a.step, std::round(v / a.step), 1e-9);
    }
}

TEST(PlotLayout, ScaledCanvasAndFontKeepTheTicks) {
  // the app exports a screen plot at k times its size and line height: the same ticks at every k
  Plot small = sinePlot();
  small.setSize(480, 300);
  small.setTextSize(12.0);
  const PlotLayout a = small.layout();
  for (int k : {2, 3}) {
    Plot large = sinePlot();
    large.setSize(480 * k, 300 * k);
    large.setTextSize(12.0 * k);
    const PlotLayout b = large.layout();
    EXPECT_EQ(b.x.values, a.x.values);
    EXPECT_EQ(b.y.values, a.y.values);
    EXPECT_EQ(b.y.labels, a.y.labels);
    EXPECT_NEAR(b.area.top / b.height, a.area.top / a.height, 0.02);
  }
}

TEST(PlotLayout, RangesFollowTheDataTheWindowAndZero) {
  Plot plot("p", "time [s]", "tension [N]");
  plot.addSeries("a", {0.0, 5.0, 10.0}, {20.0, 30.0, 25.0});
  PlotLayout L = plot.layout();
  EXPECT_DOUBLE_EQ(L.x.lo, 0.0);
  EXPECT_DOUBLE_EQ(L.x.hi, 10.0);
  EXPECT_NEAR(L.y.lo, 20.0 - 0.8, 1e-9);  // padded by 8 % of the 10 N span
  EXPECT_NEAR(L.y.hi, 30.0 + 0.8, 1e-9);
  plot.setIncludeZero(true);
  plot.setXRange(4.0, 8.0);
  L = plot.layout();
  EXPECT_DOUBLE_EQ(L.x.lo, 4.0);
  EXPECT_DOUBLE_EQ(L.x.hi, 8.0);
  EXPECT_NEAR(L.y.lo, -2.4, 1e-9);
  EXPECT_THROW(plot.setXRange(1.0, 1.0), std::invalid_argument);
  // the data map onto the plot box
  EXPECT_NEAR(L.mapX(4.0), L.area.left, 1e-9);
  EXPECT_NEAR(L.mapY(L.y.hi), L.area.top, 1e-9);
}

// to scale: a 300 x 100 mm outline on a 900 x 600 px canvas keeps one millimetre as long across as up, the
// data inside the box, and the shorter range widened about its middle
TEST(PlotLayout, EqualAspectDrawsToScale) {
  Plot plot("outline", "anterior [mm]", "height [mm]");
  plot.addSeries("a", {-150.0, 150.0, 150.0, -150.0, -150.0}, {1000.0, 1000.0, 1100.0, 1100.0, 1000.0});
  const PlotLayout free = plot.layout();
  plot.setEqualAspect(true);
  for (const auto& [w, h] : {std::pair{900, 600}, std::pair{400, 900}}) {
    plot.setSize(w, h);
    const PlotLayout L = plot.layout();
    const double perPxX = (L.x.hi - L.x.lo) / L.area.width(), perPxY = (L.y.hi - L.y.lo) / L.area.height();
    EXPECT_NEAR(perPxX, perPxY, 1e-9 * perPxY) << w << " x " << h;
    EXPECT_LE(L.x.lo, -150.0);
    EXPECT_GE(L.x.hi, 150.0);
    EXPECT_LE(L.y.lo, 1000.0);
    EXPECT_GE(L.y.hi, 1100.0);
    EXPECT_NEAR(0.5 * (L.x.lo + L.x.hi), 0.0, 1e-9);
    EXPECT_NEAR(0.5 * (L.y.lo + L.y.hi), 1050.0, 1e-9);
  }
  // without it, the 8 %-padded data fill the box in y
  EXPECT_GT((free.x.hi - free.x.lo) / free.area.width() / ((free.y.hi - free.y.lo) / free.area.height()),
            1.2);
}
