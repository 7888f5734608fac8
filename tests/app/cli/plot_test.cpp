// pneuma::viz::Plot: PNG and SVG from one layout, without OpenGL.
#include "viz/Plot.h"

#include <gtest/gtest.h>

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkSmartPointer.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLUtilities.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

using pneuma::viz::Color;
using pneuma::viz::Plot;

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
  EXPECT_GT(blue, 1000);   // a 2 px line across ~700 px
  EXPECT_GT(dark, 1000);   // calm series, frame and text
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
  EXPECT_EQ(vtkXMLUtilities::ReadElementFromString("<svg><g></svg>"), nullptr);  // the parser does reject bad XML
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
  // grid and frame lines plus two data pieces: the data colour (black, first palette entry) appears with width 2
  std::size_t n = 0;
  for (std::size_t pos = 0; (pos = svg.find("stroke=\"rgb(0,0,0)\" stroke-width=\"2.00\"", pos)) != std::string::npos; ++pos) ++n;
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
