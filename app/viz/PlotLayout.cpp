#include "viz/PlotLayout.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace pneuma::viz {

namespace {

constexpr double kIntervalSlack = 1.25;  // niceTicks: at most this many times the target intervals

// the spacing rules, in lines of text (PlotLayout scales with the font)
constexpr double kPad = 0.5;             // outer margin
constexpr double kGap = 0.35;            // between a label and what it labels
constexpr double kLinesPerYTick = 3.2;   // canvas height per y tick
constexpr double kLinesPerXTick = 4.5;   // canvas width per x tick
constexpr double kRangePad = 0.08;       // y range padding, fraction of the data span each side
constexpr double kMaxMarginLabel = 5.0;  // the widest x label that goes into the left margin

/// The smallest 1, 2 or 5 x 10^k giving at most 1.25 n intervals over `range` (so about n: a strict "at most
/// n" would jump from 9 intervals to 4 where 200 falls just short of range / 8 and 500 is next).
double stepFor(double range, int n) {
  const double raw = range / (kIntervalSlack * std::max(n, 1));
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0})
    if (m * p >= raw * (1.0 - 1e-9)) return m * p;
  return 10.0 * p;
}

/// Tick label with just enough decimals for `step`; never "-0".
std::string tickLabel(double v, double step) {
  const int decimals = std::max(0, -static_cast<int>(std::floor(std::log10(step) + 1e-9)));
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, std::abs(v) < step * 1e-6 ? 0.0 : v);
  return buf;
}

/// `text`, or when it is wider than `room` its unit alone ("tension [N]" -> "[N]": the plot's title names the
/// quantity), never a fragment behind an ellipsis; when not even the unit fits, the whole text.
std::string fitted(const std::string& text, double room,
                   const std::function<double(const std::string&)>& width) {
  if (width(text) <= room) return text;
  const std::size_t open = text.rfind('[');
  if (open != std::string::npos && open > 0 && width(text.substr(open)) <= room) return text.substr(open);
  return text;
}

}  // namespace

AxisTicks niceTicks(double lo, double hi, int target, int minTicks) {
  AxisTicks a;
  a.lo = lo;
  a.hi = hi;
  if (!(hi > lo) || !std::isfinite(hi - lo)) return a;
  target = std::max(target, 1);
  auto first = [&](double step) { return std::ceil(lo / step - 1e-9); };
  auto last = [&](double step) { return std::floor(hi / step + 1e-9); };
  a.step = stepFor(hi - lo, target);
  for (int n = target + 1; last(a.step) - first(a.step) + 1.0 < minTicks && n <= 8 * target; ++n)
    a.step = stepFor(hi - lo, n);
  for (double k = first(a.step); k <= last(a.step); k += 1.0) {
    const double v = k * a.step;
    a.values.push_back(std::abs(v) < a.step * 1e-9 ? 0.0 : v);
    a.labels.push_back(tickLabel(v, a.step));
  }
  return a;
}

PlotLayout layoutPlot(const Plot& plot, double width, double height, const TextMetrics& m) {
  using Box = PlotLayout::Box;
  using Align = PlotLayout::Align;
  PlotLayout L;
  L.width = width;
  L.height = height;
  L.lineHeight = m.lineHeight;
  const double lh = m.lineHeight, pad = kPad * lh, gap = kGap * lh;

  // ranges
  const double inf = std::numeric_limits<double>::infinity();
  double xlo = inf, xhi = -inf, ylo = inf, yhi = -inf;
  const bool hasXRange = plot.hasXRange();
  const auto [xFrom, xTo] = plot.xRange();
  for (const Plot::Series& s : plot.series())
    for (std::size_t i = 0; i < s.x.size(); ++i)
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i]) &&
          (!hasXRange || (s.x[i] >= xFrom && s.x[i] <= xTo))) {
        xlo = std::min(xlo, s.x[i]), xhi = std::max(xhi, s.x[i]);
        ylo = std::min(ylo, s.y[i]), yhi = std::max(yhi, s.y[i]);
      }
  for (const Plot::Series& r : plot.references()) ylo = std::min(ylo, r.y[0]), yhi = std::max(yhi, r.y[0]);
  if (plot.includesZero()) ylo = std::min(ylo, 0.0), yhi = std::max(yhi, 0.0);
  if (hasXRange) xlo = xFrom, xhi = xTo;
  if (!(xlo <= xhi)) xlo = 0.0, xhi = 1.0;
  if (!(ylo <= yhi)) ylo = 0.0, yhi = 1.0;
  if (xhi - xlo <= 1e-12 * std::max(1.0, std::abs(xlo))) xlo -= 0.5, xhi += 0.5;
  if (yhi - ylo <= 1e-12 * std::max(1.0, std::abs(ylo))) ylo -= 0.5, yhi += 0.5;
  const double yPad = kRangePad * (yhi - ylo);
  ylo -= yPad, yhi += yPad;

  // header: the title, the note on its row when both fit, then the legend flowing over as many rows as it
  // needs
  const double tw = m.titleWidth(plot.title()), nw = m.width(plot.note());
  L.title = {plot.title(), Box{pad, 0.25 * lh, width - pad, 1.25 * lh}, Align::Start, false};
  const bool isNoteOwnRow = !plot.note().empty() && tw + nw + 3.0 * pad > width;
  L.note = {plot.note(), L.title.box, Align::End, false};
  if (isNoteOwnRow) L.note.box = Box{pad, L.title.box.bottom, width - pad, L.title.box.bottom + lh};
  double rowTop = (isNoteOwnRow ? L.note.box.bottom : L.title.box.bottom) + 0.15 * lh;

  std::vector<PlotLayout::LegendEntry> entries;
  for (std::size_t i = 0; i < plot.series().size(); ++i)
    if (!plot.series()[i].label.empty()) entries.push_back({false, i, Box{}, {}});
  std::size_t referenceEntries = 0;
  for (std::size_t i = 0; i < plot.references().size(); ++i)
    if (!plot.references()[i].label.empty()) entries.push_back({true, i, Box{}, {}}), ++referenceEntries;
  L.legendSample = 1.1 * lh;
  if (entries.size() > 1 || referenceEntries > 0) {
    double x = pad;
    for (PlotLayout::LegendEntry& e : entries) {
      const std::string& label =
          e.isReference ? plot.references()[e.index].label : plot.series()[e.index].label;
      const double w = L.legendSample + gap + m.width(label) + 2.0 * gap;
      if (x + w > width - pad && x > pad) x = pad, rowTop += lh;
      e.box = Box{x, rowTop, x + w, rowTop + lh};
      e.label = {label, Box{x + L.legendSample + gap, rowTop, x + w, rowTop + lh}, Align::Start, false};
      x += w + gap;
    }
    rowTop += lh;
    L.legend = std::move(entries);
  }
  L.area.top = rowTop + pad;
  L.area.right = width - 2.0 * pad;

  // tick density from the canvas size in lines; the left margin fits the y axis label and tick labels, and
  // the x label on the tick row unless that is too long
  const int yTarget = std::clamp(static_cast<int>(height / lh / kLinesPerYTick + 1e-9), 2, 8);
  const int xTarget = std::clamp(static_cast<int>(width / lh / kLinesPerXTick + 1e-9), 2, 10);
  L.y = niceTicks(ylo, yhi, yTarget);
  double tickWidth = 0.0;
  for (const std::string& s : L.y.labels) tickWidth = std::max(tickWidth, m.width(s));
  L.area.left = pad + lh + gap + tickWidth + gap;
  // a short x label ("time [s]") widens the margin rather than take a row of its own: height is the scarcer
  // (and half the first x tick's label, which is centred on the box's left edge, beyond it)
  const std::vector<std::string> xFirst = niceTicks(xlo, xhi, xTarget).labels;
  const double xLabelWidth =
      m.width(plot.xLabel()) + (xFirst.empty() ? 0.0 : m.width(xFirst.front()) / 2.0 + gap);
  const bool isXLabelOwnRow = m.width(plot.xLabel()) > kMaxMarginLabel * lh;
  if (!isXLabelOwnRow) L.area.left = std::max(L.area.left, pad + xLabelWidth + gap);
  L.area.bottom = height - pad - lh - 0.15 * lh - (isXLabelOwnRow ? lh : 0.0);
  if (plot.hasEqualAspect() && L.area.width() > 0.0 && L.area.height() > 0.0) {
    // to scale: the range with fewer units per pixel widens about its middle. The y ticks set the left margin
    // and so the box's width: redo them until the margin settles (x gets 2 % to spare), then x takes exactly
    // the y scale
    const double xm = 0.5 * (xlo + xhi), ym = 0.5 * (ylo + yhi), xSpan = xhi - xlo, ySpan = yhi - ylo;
    double perPx = 0.0;  // [unit/px]
    for (int pass = 0; pass < 3; ++pass) {
      perPx = std::max(1.02 * xSpan / L.area.width(), ySpan / L.area.height());
      ylo = ym - 0.5 * perPx * L.area.height(), yhi = ym + 0.5 * perPx * L.area.height();
      L.y = niceTicks(ylo, yhi, yTarget);
      tickWidth = 0.0;
      for (const std::string& s : L.y.labels) tickWidth = std::max(tickWidth, m.width(s));
      L.area.left = pad + lh + gap + tickWidth + gap;
      if (!isXLabelOwnRow) L.area.left = std::max(L.area.left, pad + xLabelWidth + gap);
    }
    xlo = xm - 0.5 * perPx * L.area.width(), xhi = xm + 0.5 * perPx * L.area.width();
  }
  L.x = niceTicks(xlo, xhi, xTarget);

  for (std::size_t i = 0; i < L.y.values.size(); ++i) {
    const double cy = L.mapY(L.y.values[i]);
    L.yTickLabels.push_back(
        {L.y.labels[i], Box{pad, cy - lh / 2.0, L.area.left - gap, cy + lh / 2.0}, Align::End, false});
  }
  const double tickRow = L.area.bottom + 0.15 * lh;
  for (std::size_t i = 0; i < L.x.values.size(); ++i) {
    const double cx = L.mapX(L.x.values[i]);
    const double half = m.width(L.x.labels[i]) / 2.0 + gap;
    L.xTickLabels.push_back(
        {L.x.labels[i], Box{cx - half, tickRow, cx + half, tickRow + lh}, Align::Middle, false});
  }
  L.xLabel =
      isXLabelOwnRow
          ? PlotLayout::Text{plot.xLabel(), Box{L.area.left, tickRow + lh, L.area.right, tickRow + 2.0 * lh},
                             Align::Middle, false}
          : PlotLayout::Text{plot.xLabel(),
                             Box{pad, tickRow, pad + m.width(plot.xLabel()) + gap, tickRow + lh}, Align::End,
                             false};
  L.yLabel = {fitted(plot.yLabel(), L.area.height(), m.width), Box{pad, L.area.top, pad + lh, L.area.bottom},
              Align::Middle, true};
  return L;
}

}  // namespace pneuma::viz
