#pragma once
/// @file PlotLayout.h
/// The geometry of a line chart, computed once for both of its painters: the app's PlotView (QPainter, on
/// screen) and viz::Plot's SVG and PNG writers (exports and pneuma-cli's figures). It holds the shown ranges,
/// the ticks and their labels, the margins those labels need, the plot box, and where the title, note, legend
/// and axis labels go: pixels, origin at the top left, y down. Pure (std only): the painters' fonts enter
/// through TextMetrics.
///
/// The tick density follows the canvas size measured in text lines, so a chart drawn at twice the size with
/// twice the font (an export of a screen plot) has the same ticks.

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "viz/Plot.h"

namespace pneuma::viz {

/// One axis: the shown range and its ticks at 1, 2 or 5 times a power of ten.
struct AxisTicks {
  double lo = 0.0;                  ///< start of the shown range, in the axis unit
  double hi = 1.0;                  ///< end of the shown range, in the axis unit
  double step = 0.2;                ///< tick spacing, in the axis unit
  std::vector<double> values;       ///< tick positions in [lo, hi], ascending, exact multiples of `step`
  std::vector<std::string> labels;  ///< one per value, with just enough decimals for `step` ("0.2", "1000")
};

/// Ticks over [lo, hi] (lo < hi): the smallest step of 1, 2 or 5 times a power of ten that gives at most
/// 1.25 `target` intervals, made finer until at least `minTicks` ticks fall inside (a 1.7 L range over three
/// ticks would otherwise label a single 1000 mL step). [0, 1] with target 5 gives 0, 0.2, ..., 1.
AxisTicks niceTicks(double lo, double hi, int target, int minTicks = 2);

/// The painter's text sizes [px]: body text (ticks, axis labels, legend, note) and the title (bold).
struct TextMetrics {
  double lineHeight = 18.0;                              ///< [px] height of a line of text
  std::function<double(const std::string&)> width;       ///< [px] advance width of body text
  std::function<double(const std::string&)> titleWidth;  ///< [px] advance width of title text
};

/// The look both painters share: colours, and stroke widths [px] at a 15 px line height (painters multiply
/// them by PlotLayout::scale()).
struct PlotStyle {
  static constexpr Color kBackground{1.0, 1.0, 1.0};
  static constexpr Color kFrame{0.78, 0.78, 0.82};
  static constexpr Color kGrid{0.90, 0.90, 0.92};
  static constexpr Color kTitle{0.12, 0.12, 0.14};
  static constexpr Color kText{0.30, 0.30, 0.35};  ///< ticks and axis labels
  static constexpr Color kLegend{0.20, 0.20, 0.24};
  static constexpr Color kNote{0.08, 0.27, 0.55};
  static constexpr double kDataWidth = 1.8;
  static constexpr double kReferenceWidth = 1.2;
  static constexpr double kLegendWidth = 2.5;
  static constexpr double kGridWidth = 1.0;
};

/// A chart's geometry on a canvas of a given size.
struct PlotLayout {
  /// An axis-aligned rectangle [px].
  struct Box {
    double left = 0.0, top = 0.0, right = 0.0, bottom = 0.0;
    double width() const { return right - left; }
    double height() const { return bottom - top; }
  };
  enum class Align { Start, Middle, End };
  /// A line of text placed in a box: horizontally by `align`, vertically centred. A vertical text reads
  /// bottom to top, centred in its box.
  struct Text {
    std::string text;
    Box box;
    Align align = Align::Start;
    bool isVertical = false;
  };
  /// One legend entry: a line sample (box.left to box.left + legendSample, at the box's mid-height) and its
  /// label.
  struct LegendEntry {
    bool isReference = false;  ///< true: plot.references()[index]; false: plot.series()[index]
    std::size_t index = 0;
    Box box;
    Text label;
  };
  double width = 0.0, height = 0.0;  ///< [px] canvas
  Box area;                          ///< the plot box the data are drawn in
  AxisTicks x, y;                    ///< shown ranges and ticks
  std::vector<Text> xTickLabels;     ///< one per x tick, centred under it
  std::vector<Text> yTickLabels;     ///< one per y tick, right-aligned left of the box
  Text title, note, xLabel, yLabel;  ///< note: right-aligned, on the title's row when both fit; yLabel: when
                                     ///< longer than the box, its leading words give way to an ellipsis
  std::vector<LegendEntry> legend;  ///< flowing in rows under the title; empty for a single unlabelled series
  double legendSample = 16.0;       ///< [px] length of a legend entry's line sample
  double lineHeight = 15.0;         ///< [px] the metrics' line height the layout was made for

  /// Stroke-width factor for PlotStyle's widths: lineHeight / 15.
  double scale() const { return lineHeight / 15.0; }

  /// [px] canvas x of an abscissa, canvas y of an ordinate.
  double mapX(double v) const { return area.left + (v - x.lo) / (x.hi - x.lo) * area.width(); }
  double mapY(double v) const { return area.bottom - (v - y.lo) / (y.hi - y.lo) * area.height(); }
};

/// Lays out `plot` on a `width` x `height` px canvas with the painter's text metrics.
/// Ranges: x is plot.xRange() when set, else the finite data's; y covers the finite data shown, the reference
/// lines and 0 when plot.includesZero(), padded by 8 % each side; an empty or flat range widens to a unit
/// span.
PlotLayout layoutPlot(const Plot& plot, double width, double height, const TextMetrics& metrics);

}  // namespace pneuma::viz
