#pragma once
/// @file Plot.h
/// Line charts written as SVG (vector) or PNG (software rasteriser), with no OpenGL and no display.
///
/// One layout (title, axes, nice ticks, grid, axis labels with units, legend) is computed once as a list
/// of drawing primitives in pixel coordinates; the SVG writer prints them and the PNG writer rasterises
/// them (anti-aliased lines by exact pixel coverage, FreeType text from VTK's embedded fonts). So the
/// PNG and the SVG of a plot show the same picture. Used by pneuma-cli (simulate, validate) and by the
/// desktop app's plot export.

#include <string>
#include <vector>

namespace pneuma::viz {

/// sRGB colour, each component in [0, 1].
struct Color {
  double r = 0.0, g = 0.0, b = 0.0;
};

/// A 2D line chart: one or more (x, y) series plus optional horizontal reference lines.
class Plot {
 public:
  /// One polyline. Non-finite y values break the line.
  struct Series {
    std::string label;        ///< legend text; empty hides it from the legend
    std::vector<double> x;    ///< abscissae in the x axis unit (#S)
    std::vector<double> y;    ///< ordinates in the y axis unit (#S)
    Color color;              ///< line colour
    bool isDashed = false;    ///< dashed line (reference curves)
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
  /// Output size in pixels (SVG user units); default 960 x 540.
  void setSize(int widthPx, int heightPx);

  /// The chart as an SVG document.
  std::string toSvg() const;
  /// The chart as the bytes of a PNG file (8-bit RGB).
  std::vector<unsigned char> toPng() const;

  /// Writes toSvg() to `path` through a temporary file and a rename. @throws std::runtime_error on I/O failure.
  void writeSvg(const std::string& path) const;
  /// Writes toPng() to `path` through a temporary file and a rename. @throws std::runtime_error on I/O failure.
  void writePng(const std::string& path) const;

 private:
  struct Primitive;
  std::vector<Primitive> layout() const;

  std::string m_title;
  std::string m_xLabel;
  std::string m_yLabel;
  std::vector<Series> m_series;
  std::vector<Series> m_references;  // horizontal lines; x is filled in by layout()
  int m_width = 960;                 // [px]
  int m_height = 540;                // [px]
};

}  // namespace pneuma::viz
