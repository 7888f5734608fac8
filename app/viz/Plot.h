#pragma once
/// @file Plot.h
/// Line charts written as SVG (vector) or PNG (software rasteriser), with no OpenGL and no display.
///
/// The chart's geometry (ranges, ticks, margins, title, legend, axis labels) is PlotLayout's, the same
/// function the app's on-screen PlotView draws from; here it becomes a list of drawing primitives in pixel
/// coordinates that the SVG writer prints and the PNG writer rasterises (anti-aliased lines by exact pixel
/// coverage, FreeType text). So the PNG and the SVG of a plot show the same picture, and an exported screen
/// plot has the screen's ticks. Used by pneuma-cli (simulate, validate) and by the desktop app's plot export.

#include <string>
#include <utility>
#include <vector>

namespace pneuma::viz {

struct PlotLayout;

/// sRGB colour, each component in [0, 1].
struct Color {
  double r = 0.0, g = 0.0, b = 0.0;
};

/// A 2D line chart: one or more (x, y) series plus optional horizontal reference lines.
class Plot {
 public:
  /// One polyline. Non-finite y values break the line.
  struct Series {
    std::string label;      ///< legend text; empty hides it from the legend
    std::vector<double> x;  ///< abscissae in the x axis unit (#S)
    std::vector<double> y;  ///< ordinates in the y axis unit (#S)
    Color color;            ///< line colour
    bool isDashed = false;  ///< dashed line (reference curves)
  };

  /// @param title   headline above the chart
  /// @param xLabel  x axis label with its unit, e.g. "time [s]"
  /// @param yLabel  y axis label with its unit, e.g. "lung-cavity volume [mL]"
  Plot(std::string title, std::string xLabel, std::string yLabel);

  /// Adds a solid series in the next palette colour. x and y must have the same length.
  void addSeries(const std::string& label, std::vector<double> x, std::vector<double> y);
  /// Adds a series with explicit colour and dash.
  void addSeries(Series series);
  /// Adds a dashed horizontal reference line at `y` spanning the x range (e.g. the 500 mL calm tidal volume).
  void addReferenceLine(const std::string& label, double y, Color color = Color{0.25, 0.25, 0.25});
  /// Output size in pixels (SVG user units); default 960 x 540. @throws std::invalid_argument below 200 x
  /// 150.
  void setSize(int widthPx, int heightPx);
  /// Body text size [px] (ticks, labels, legend; the title is bold at the same size); default 15.
  /// @throws std::invalid_argument outside [6, 200].
  void setTextSize(double px);
  /// One line of text right of the title, e.g. "tidal volume 498 mL".
  void setNote(std::string note);
  /// Shows x in [lo, hi] (e.g. a rolling time window) instead of the data's range; lo < hi.
  void setXRange(double lo, double hi);
  /// Always include 0 in the y range (e.g. tensions).
  void setIncludeZero(bool includeZero);
  /// Draw to scale: one unit as long on both axes (outlines in mm); the shorter range widens about its
  /// middle.
  void setEqualAspect(bool isEqualAspect);

  const std::string& title() const { return m_title; }
  const std::string& xLabel() const { return m_xLabel; }
  const std::string& yLabel() const { return m_yLabel; }
  const std::string& note() const { return m_note; }
  const std::vector<Series>& series() const { return m_series; }
  /// The horizontal reference lines, each a Series whose y[0] is its ordinate (x is empty).
  const std::vector<Series>& references() const { return m_references; }
  bool hasXRange() const { return m_hasXRange; }
  std::pair<double, double> xRange() const { return m_xRange; }
  bool includesZero() const { return m_includeZero; }
  bool hasEqualAspect() const { return m_equalAspect; }
  int width() const { return m_width; }
  int height() const { return m_height; }
  double textSize() const { return m_textSize; }
  /// [px] the line height of the body text: 1.25 x textSize().
  double lineHeight() const { return 1.25 * m_textSize; }

  /// The chart's geometry at its size, with the exporters' font (include viz/PlotLayout.h to use it).
  PlotLayout layout() const;

  /// The chart as an SVG document.
  std::string toSvg() const;
  /// The chart as the bytes of a PNG file (8-bit RGB).
  std::vector<unsigned char> toPng() const;

  /// Writes toSvg() to `path` through a temporary file and a rename. @throws std::runtime_error on I/O
  /// failure.
  void writeSvg(const std::string& path) const;
  /// Writes toPng() to `path` through a temporary file and a rename. @throws std::runtime_error on I/O
  /// failure.
  void writePng(const std::string& path) const;

 private:
  struct Primitive;
  std::vector<Primitive> primitives() const;

  std::string m_title;
  std::string m_xLabel;
  std::string m_yLabel;
  std::string m_note;
  std::vector<Series> m_series;
  std::vector<Series> m_references;  // horizontal lines at y[0]
  bool m_hasXRange = false;
  std::pair<double, double> m_xRange{0.0, 1.0};  // x unit
  bool m_includeZero = false;
  bool m_equalAspect = false;
  int m_width = 960;         // [px]
  int m_height = 540;        // [px]
  double m_textSize = 15.0;  // [px]
};

}  // namespace pneuma::viz
