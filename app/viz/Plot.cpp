#include "viz/Plot.h"

#include "viz/AtomicFile.h"

#include <vtkFreeTypeTools.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkStdString.h>
#include <vtkTextProperty.h>
#include <vtkTextRenderer.h>
#include <vtkUnsignedCharArray.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace pneuma::viz {

/// One drawing instruction in pixel coordinates (origin top-left, y down).
struct Plot::Primitive {
  enum class Kind { Polyline, Rect, Text };
  enum class Anchor { Start, Middle, End };
  Kind kind = Kind::Polyline;
  std::vector<double> xy;     // polyline: x0 y0 x1 y1 ...; rect: x y w h; text: x y (baseline anchor)
  Color color;                // stroke or text colour
  double width = 1.0;         // [px] stroke width (rect: 0 = no frame)
  bool isDashed = false;      // polyline dash pattern
  bool hasFill = false;       // rect fill
  Color fill{1.0, 1.0, 1.0};  // rect fill colour
  std::string text;           // text content
  int fontSize = 14;          // [px]
  Anchor anchor = Anchor::Start;
  bool isVertical = false;    // text rotated by -90 degrees (reads bottom to top)
};

namespace {

constexpr double kDashOn = 7.0;   // [px]
constexpr double kDashOff = 5.0;  // [px]

const Color kPalette[] = {{0.00, 0.00, 0.00}, {0.12, 0.47, 0.71}, {0.84, 0.15, 0.16}, {0.17, 0.63, 0.17},
                          {1.00, 0.50, 0.05}, {0.58, 0.40, 0.74}, {0.55, 0.34, 0.29}, {0.89, 0.47, 0.76},
                          {0.09, 0.75, 0.81}, {0.74, 0.74, 0.13}};

/// DejaVu Sans (Debian's fonts-dejavu-core) when installed, else VTK's embedded Arial, whose square
/// brackets look like parentheses (bad for "[mL]" unit labels).
const char* fontFile() {
  static const char* file = [] {
    const char* dejavu = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
    return std::ifstream(dejavu).good() ? dejavu : "";
  }();
  return file;
}

/// FreeType text property for a font size in pixels (72 dpi: 1 pt = 1 px).
void configureText(vtkTextProperty* tp, int fontSize, const Color& c) {
  if (*fontFile() != '\0') {
    tp->SetFontFamily(VTK_FONT_FILE);
    tp->SetFontFile(fontFile());
  } else {
    tp->SetFontFamilyToArial();
  }
  tp->SetFontSize(fontSize);
  tp->SetColor(c.r, c.g, c.b);
  tp->SetJustificationToLeft();
  tp->SetVerticalJustificationToBottom();
}

/// Advance width of `text` at `fontSize` [px], measured with the same FreeType font the PNG uses.
double textWidth(const std::string& text, int fontSize) {
  if (text.empty()) return 0.0;
  vtkNew<vtkTextProperty> tp;
  configureText(tp, fontSize, Color{});
  int bbox[4] = {0, 0, 0, 0};
  vtkFreeTypeTools::GetInstance()->GetBoundingBox(tp, vtkStdString(text), 72, bbox);
  return bbox[1] - bbox[0] + 1;
}

/// Tick positions at 1, 2 or 5 times a power of ten covering [lo, hi] with about `target` ticks.
std::vector<double> niceTicks(double lo, double hi, int target, double& step) {
  const double raw = (hi - lo) / std::max(1, target);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double m = raw / mag;
  step = (m < 1.5 ? 1.0 : m < 3.5 ? 2.0 : m < 7.5 ? 5.0 : 10.0) * mag;
  std::vector<double> ticks;
  for (double t = std::ceil(lo / step - 1e-9) * step; t <= hi + step * 1e-9; t += step)
    ticks.push_back(std::abs(t) < step * 1e-9 ? 0.0 : t);
  return ticks;
}

/// Tick label with just enough decimals for `step`.
std::string tickLabel(double v, double step) {
  const int decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

std::string svgColor(const Color& c) {
  auto to8 = [](double v) { return static_cast<int>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0)); };
  return "rgb(" + std::to_string(to8(c.r)) + "," + std::to_string(to8(c.g)) + "," + std::to_string(to8(c.b)) + ")";
}

std::string xmlEscape(const std::string& s) {
  std::string out;
  for (char ch : s) {
    switch (ch) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += ch;
    }
  }
  return out;
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  return buf;
}

/// A float RGB canvas with coverage-based anti-aliased drawing.
class Canvas {
 public:
  Canvas(int w, int h) : m_w(w), m_h(h), m_rgb(static_cast<std::size_t>(3 * w * h), 1.0), m_cover(static_cast<std::size_t>(w * h), 0.0f) {}

  /// Strokes a polyline of width `width` [px]: coverage of each pixel centre is the max over segments,
  /// so joints are not blended twice.
  void strokePolyline(const std::vector<double>& xy, double width, const Color& c, bool isDashed) {
    const std::size_t n = xy.size() / 2;
    if (n < 2) return;
    int x0 = m_w, y0 = m_h, x1 = -1, y1 = -1;
    double along = 0.0;  // [px] arc length for the dash pattern
    for (std::size_t i = 0; i + 1 < n; ++i) {
      const double ax = xy[2 * i], ay = xy[2 * i + 1], bx = xy[2 * i + 2], by = xy[2 * i + 3];
      const double len = std::hypot(bx - ax, by - ay);
      if (!isDashed) {
        coverSegment(ax, ay, bx, by, width, x0, y0, x1, y1);
      } else {
        // split the segment into the "on" parts of the dash pattern
        double s = 0.0;
        while (s < len) {
          const double phase = std::fmod(along + s, kDashOn + kDashOff);
          const double rest = phase < kDashOn ? kDashOn - phase : kDashOn + kDashOff - phase;
          const double e = std::min(len, s + rest);
          if (phase < kDashOn) {
            const double t0 = s / len, t1 = e / len;
            coverSegment(ax + t0 * (bx - ax), ay + t0 * (by - ay), ax + t1 * (bx - ax), ay + t1 * (by - ay), width,
                         x0, y0, x1, y1);
          }
          s = e;
        }
      }
      along += len;
    }
    // blend the accumulated coverage once
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        float& a = m_cover[static_cast<std::size_t>(y * m_w + x)];
        if (a > 0.0f) blend(x, y, c, a);
        a = 0.0f;
      }
  }

  void fillRect(double x, double y, double w, double h, const Color& c) {
    for (int py = std::max(0, static_cast<int>(std::floor(y))); py < std::min(m_h, static_cast<int>(std::ceil(y + h))); ++py)
      for (int px = std::max(0, static_cast<int>(std::floor(x))); px < std::min(m_w, static_cast<int>(std::ceil(x + w))); ++px) {
        // fractional coverage at the rectangle's edges
        const double cx = std::max(0.0, std::min(px + 1.0, x + w) - std::max(px + 0.0, x));
        const double cy = std::max(0.0, std::min(py + 1.0, y + h) - std::max(py + 0.0, y));
        blend(px, py, c, cx * cy);
      }
  }

  /// Draws FreeType text with its baseline anchored at (x, y); `align` is 0 (start), 0.5 (middle) or 1 (end).
  void drawText(double x, double y, const std::string& text, int fontSize, double align, bool isVertical, const Color& c) {
    vtkNew<vtkTextProperty> tp;
    configureText(tp, fontSize, c);
    vtkNew<vtkImageData> img;
    int dims[2] = {0, 0};
    auto* ft = vtkFreeTypeTools::GetInstance();
    ft->ScaleToPowerTwoOff();
    if (text.empty() || !ft->RenderString(tp, vtkStdString(text), 72, img, dims)) return;
    vtkTextRenderer::Metrics metrics;
    ft->GetMetrics(tp, vtkStdString(text), 72, metrics);
    // the image's bottom rows hold the descent; the baseline is `ascent` rows below its top
    const int baseline = dims[1] - metrics.Ascent[1];
    const int ax = static_cast<int>(std::lround(x)), ay = static_cast<int>(std::lround(y));
    const int offset = static_cast<int>(std::lround(align * dims[0]));
    for (int j = 0; j < dims[1]; ++j)
      for (int i = 0; i < dims[0]; ++i) {
        const auto* px = static_cast<const unsigned char*>(img->GetScalarPointer(i, j, 0));
        if (px[3] == 0) continue;
        const int u = i - offset, v = j - baseline;  // along the baseline, up from it
        const int cx = isVertical ? ax - v - 1 : ax + u;
        const int cy = isVertical ? ay - u - 1 : ay - v - 1;
        blend(cx, cy, c, px[3] / 255.0);
      }
  }

  /// Encodes the canvas as PNG bytes with vtkPNGWriter (rows flipped: VTK images start at the bottom).
  std::vector<unsigned char> png() const {
    vtkNew<vtkImageData> img;
    img->SetDimensions(m_w, m_h, 1);
    img->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
    for (int y = 0; y < m_h; ++y)
      for (int x = 0; x < m_w; ++x) {
        auto* px = static_cast<unsigned char*>(img->GetScalarPointer(x, m_h - 1 - y, 0));
        for (int k = 0; k < 3; ++k)
          px[k] = static_cast<unsigned char>(std::lround(std::clamp(m_rgb[static_cast<std::size_t>(3 * (y * m_w + x) + k)], 0.0, 1.0) * 255.0));
      }
    vtkNew<vtkPNGWriter> writer;
    writer->SetInputData(img);
    writer->WriteToMemoryOn();
    writer->Write();
    vtkUnsignedCharArray* result = writer->GetResult();
    if (result == nullptr || result->GetNumberOfValues() == 0) throw std::runtime_error("PNG encoding failed");
    return std::vector<unsigned char>(result->GetPointer(0), result->GetPointer(0) + result->GetNumberOfValues());
  }

 private:
  void blend(int x, int y, const Color& c, double a) {
    if (x < 0 || y < 0 || x >= m_w || y >= m_h) return;
    double* p = &m_rgb[static_cast<std::size_t>(3 * (y * m_w + x))];
    p[0] += (c.r - p[0]) * a;
    p[1] += (c.g - p[1]) * a;
    p[2] += (c.b - p[2]) * a;
  }

  /// Coverage of pixel centres by a segment of width `w` with round caps: clamp(w/2 + 1/2 - distance, 0, 1).
  void coverSegment(double ax, double ay, double bx, double by, double w, int& x0, int& y0, int& x1, int& y1) {
    const double r = w / 2.0 + 0.5;
    const int lx = std::max(0, static_cast<int>(std::floor(std::min(ax, bx) - r)));
    const int hx = std::min(m_w - 1, static_cast<int>(std::ceil(std::max(ax, bx) + r)));
    const int ly = std::max(0, static_cast<int>(std::floor(std::min(ay, by) - r)));
    const int hy = std::min(m_h - 1, static_cast<int>(std::ceil(std::max(ay, by) + r)));
    if (lx > hx || ly > hy) return;
    x0 = std::min(x0, lx), y0 = std::min(y0, ly), x1 = std::max(x1, hx), y1 = std::max(y1, hy);
    const double dx = bx - ax, dy = by - ay, len2 = dx * dx + dy * dy;
    for (int y = ly; y <= hy; ++y)
      for (int x = lx; x <= hx; ++x) {
        const double px = x + 0.5 - ax, py = y + 0.5 - ay;
        const double t = len2 > 0.0 ? std::clamp((px * dx + py * dy) / len2, 0.0, 1.0) : 0.0;
        const double d = std::hypot(px - t * dx, py - t * dy);
        const float cov = static_cast<float>(std::clamp(r - d, 0.0, 1.0));
        float& a = m_cover[static_cast<std::size_t>(y * m_w + x)];
        a = std::max(a, cov);
      }
  }

  int m_w, m_h;                // [px]
  std::vector<double> m_rgb;   // linear 0..1 RGB, row-major from the top (3 x w x h)
  std::vector<float> m_cover;  // per-pixel coverage of the polyline being drawn (w x h)
};

}  // namespace

Plot::Plot(std::string title, std::string xLabel, std::string yLabel)
    : m_title(std::move(title)), m_xLabel(std::move(xLabel)), m_yLabel(std::move(yLabel)) {}

void Plot::addSeries(const std::string& label, std::vector<double> x, std::vector<double> y) {
  Series s;
  s.label = label;
  s.x = std::move(x);
  s.y = std::move(y);
  s.color = kPalette[m_series.size() % (sizeof kPalette / sizeof kPalette[0])];
  addSeries(std::move(s));
}

void Plot::addSeries(Series series) {
  if (series.x.size() != series.y.size())
    throw std::invalid_argument("Plot series '" + series.label + "': x has " + std::to_string(series.x.size()) +
                                " values but y has " + std::to_string(series.y.size()));
  m_series.push_back(std::move(series));
}

void Plot::addReferenceLine(const std::string& label, double y, Color color) {
  Series s;
  s.label = label;
  s.y = {y, y};
  s.color = color;
  s.isDashed = true;
  m_references.push_back(std::move(s));
}

void Plot::setSize(int widthPx, int heightPx) {
  if (widthPx < 200 || heightPx < 150)
    throw std::invalid_argument("Plot size must be at least 200 x 150 px, got " + std::to_string(widthPx) + " x " +
                                std::to_string(heightPx));
  m_width = widthPx;
  m_height = heightPx;
}

std::vector<Plot::Primitive> Plot::layout() const {
  using P = Primitive;
  const int titleSize = 18, labelSize = 15, tickSize = 13, legendSize = 13;
  std::vector<P> out;

  // data ranges over all finite values
  const double inf = std::numeric_limits<double>::infinity();
  double xlo = inf, xhi = -inf, ylo = inf, yhi = -inf;
  for (const Series& s : m_series)
    for (std::size_t i = 0; i < s.x.size(); ++i)
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) {
        xlo = std::min(xlo, s.x[i]), xhi = std::max(xhi, s.x[i]);
        ylo = std::min(ylo, s.y[i]), yhi = std::max(yhi, s.y[i]);
      }
  for (const Series& s : m_references) ylo = std::min(ylo, s.y[0]), yhi = std::max(yhi, s.y[0]);
  if (!(xlo <= xhi)) xlo = 0.0, xhi = 1.0;
  if (!(ylo <= yhi)) ylo = 0.0, yhi = 1.0;
  if (xhi - xlo <= 1e-12 * std::max(1.0, std::abs(xlo))) xlo -= 0.5, xhi += 0.5;
  if (yhi - ylo <= 1e-12 * std::max(1.0, std::abs(ylo))) ylo -= 1.0, yhi += 1.0;
  const double pad = 0.06 * (yhi - ylo);
  ylo -= pad, yhi += pad;

  double xstep = 1.0, ystep = 1.0;
  const std::vector<double> xticks = niceTicks(xlo, xhi, 8, xstep);
  const std::vector<double> yticks = niceTicks(ylo, yhi, 6, ystep);
  double yTickWidth = 0.0;
  for (double t : yticks) yTickWidth = std::max(yTickWidth, textWidth(tickLabel(t, ystep), tickSize));

  // legend entries; more than three go outside, to the right of the plot box
  std::vector<const Series*> entries;
  for (const Series& s : m_series)
    if (!s.label.empty()) entries.push_back(&s);
  for (const Series& s : m_references)
    if (!s.label.empty()) entries.push_back(&s);
  const bool hasLegend = entries.size() > 1 || !m_references.empty();
  double legendTextWidth = 0.0;
  for (const Series* s : entries) legendTextWidth = std::max(legendTextWidth, textWidth(s->label, legendSize));
  const double legendW = legendTextWidth + 52.0;
  const bool isLegendOutside = hasLegend && entries.size() > 3;

  // plot box from the margins the labels need
  const double left = 14.0 + labelSize + 10.0 + yTickWidth + 8.0;
  const double right = m_width - 24.0 - (isLegendOutside ? legendW + 4.0 : 0.0);
  const double top = 16.0 + titleSize + 12.0;
  const double bottom = m_height - (14.0 + labelSize + 10.0 + tickSize + 8.0);
  auto mapX = [&](double x) { return left + (x - xlo) / (xhi - xlo) * (right - left); };
  auto mapY = [&](double y) { return bottom - (y - ylo) / (yhi - ylo) * (bottom - top); };

  auto line = [&](double ax, double ay, double bx, double by, const Color& c, double w) {
    P p;
    p.xy = {ax, ay, bx, by};
    p.color = c;
    p.width = w;
    out.push_back(std::move(p));
  };
  auto text = [&](double x, double y, const std::string& s, int size, P::Anchor anchor, bool isVertical) {
    P p;
    p.kind = P::Kind::Text;
    p.xy = {x, y};
    p.text = s;
    p.fontSize = size;
    p.anchor = anchor;
    p.isVertical = isVertical;
    out.push_back(std::move(p));
  };

  // grid, ticks and tick labels
  const Color grid{0.88, 0.88, 0.88}, axis{0.0, 0.0, 0.0};
  for (double t : xticks) {
    const double x = std::round(mapX(t)) + 0.5;
    line(x, top, x, bottom, grid, 1.0);
    line(x, bottom, x, bottom + 5.0, axis, 1.0);
    text(x, bottom + 8.0 + tickSize, tickLabel(t, xstep), tickSize, P::Anchor::Middle, false);
  }
  for (double t : yticks) {
    const double y = std::round(mapY(t)) + 0.5;
    line(left, y, right, y, grid, 1.0);
    line(left - 5.0, y, left, y, axis, 1.0);
    text(left - 8.0, y + 0.35 * tickSize, tickLabel(t, ystep), tickSize, P::Anchor::End, false);
  }

  // data, clipped to the plot box by construction of the ranges; non-finite values break the line
  auto addData = [&](const Series& s, const std::vector<double>& xs) {
    P p;
    p.color = s.color;
    p.width = 2.0;
    p.isDashed = s.isDashed;
    for (std::size_t i = 0; i <= xs.size(); ++i) {
      const bool isFinite = i < xs.size() && std::isfinite(xs[i]) && std::isfinite(s.y[i]);
      if (isFinite) {
        p.xy.push_back(mapX(xs[i]));
        p.xy.push_back(mapY(s.y[i]));
      } else if (!p.xy.empty()) {
        out.push_back(p);
        p.xy.clear();
      }
    }
  };
  for (const Series& s : m_references) addData(s, {xlo, xhi});
  for (const Series& s : m_series) addData(s, s.x);

  // axes frame
  P frame;
  frame.kind = P::Kind::Rect;
  frame.xy = {std::round(left) + 0.5, std::round(top) + 0.5, std::round(right - left), std::round(bottom - top)};
  frame.color = axis;
  frame.width = 1.0;
  out.push_back(frame);

  // title and axis labels
  text(m_width / 2.0, 16.0 + titleSize, m_title, titleSize, P::Anchor::Middle, false);
  text((left + right) / 2.0, m_height - 14.0, m_xLabel, labelSize, P::Anchor::Middle, false);
  text(14.0 + labelSize, (top + bottom) / 2.0, m_yLabel, labelSize, P::Anchor::Middle, true);

  // legend in the top-right corner of the plot box, or right of it
  if (hasLegend) {
    const double rowH = legendSize + 6.0, boxW = legendW, boxH = rowH * entries.size() + 10.0;
    const double bx = std::round(isLegendOutside ? right + 12.0 : right - boxW - 10.0) + 0.5;
    const double by = std::round(isLegendOutside ? top : top + 10.0) + 0.5;
    P box;
    box.kind = P::Kind::Rect;
    box.xy = {bx, by, boxW, boxH};
    box.color = Color{0.6, 0.6, 0.6};
    box.hasFill = true;
    out.push_back(box);
    for (std::size_t i = 0; i < entries.size(); ++i) {
      const double cy = by + 5.0 + rowH * (i + 0.5);
      P sample;
      sample.xy = {bx + 8.0, cy, bx + 38.0, cy};
      sample.color = entries[i]->color;
      sample.width = 2.0;
      sample.isDashed = entries[i]->isDashed;
      out.push_back(sample);
      text(bx + 44.0, cy + 0.35 * legendSize, entries[i]->label, legendSize, P::Anchor::Start, false);
    }
  }
  return out;
}

std::string Plot::toSvg() const {
  using P = Primitive;
  std::ostringstream svg;
  svg << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << m_width << "\" height=\"" << m_height
      << "\" viewBox=\"0 0 " << m_width << " " << m_height << "\" font-family=\"DejaVu Sans, Verdana, Arial, sans-serif\">\n"
      << "<rect x=\"0\" y=\"0\" width=\"" << m_width << "\" height=\"" << m_height << "\" fill=\"white\"/>\n";
  for (const P& p : layout()) {
    switch (p.kind) {
      case P::Kind::Polyline: {
        svg << "<polyline fill=\"none\" stroke=\"" << svgColor(p.color) << "\" stroke-width=\"" << num(p.width)
            << "\" stroke-linejoin=\"round\" stroke-linecap=\"round\"";
        if (p.isDashed) svg << " stroke-dasharray=\"" << kDashOn << " " << kDashOff << "\"";
        svg << " points=\"";
        for (std::size_t i = 0; i + 1 < p.xy.size(); i += 2) svg << (i ? " " : "") << num(p.xy[i]) << "," << num(p.xy[i + 1]);
        svg << "\"/>\n";
        break;
      }
      case P::Kind::Rect:
        svg << "<rect x=\"" << num(p.xy[0]) << "\" y=\"" << num(p.xy[1]) << "\" width=\"" << num(p.xy[2])
            << "\" height=\"" << num(p.xy[3]) << "\" fill=\"" << (p.hasFill ? svgColor(p.fill) : "none") << "\" stroke=\""
            << svgColor(p.color) << "\" stroke-width=\"" << num(p.width) << "\"/>\n";
        break;
      case P::Kind::Text: {
        const char* anchor = p.anchor == P::Anchor::Start ? "start" : p.anchor == P::Anchor::Middle ? "middle" : "end";
        svg << "<text x=\"" << num(p.xy[0]) << "\" y=\"" << num(p.xy[1]) << "\" font-size=\"" << p.fontSize
            << "\" text-anchor=\"" << anchor << "\" fill=\"" << svgColor(p.color) << "\"";
        if (p.isVertical) svg << " transform=\"rotate(-90 " << num(p.xy[0]) << " " << num(p.xy[1]) << ")\"";
        svg << ">" << xmlEscape(p.text) << "</text>\n";
        break;
      }
    }
  }
  svg << "</svg>\n";
  return svg.str();
}

std::vector<unsigned char> Plot::toPng() const {
  using P = Primitive;
  Canvas canvas(m_width, m_height);
  for (const P& p : layout()) {
    switch (p.kind) {
      case P::Kind::Polyline: canvas.strokePolyline(p.xy, p.width, p.color, p.isDashed); break;
      case P::Kind::Rect: {
        const double x = p.xy[0], y = p.xy[1], w = p.xy[2], h = p.xy[3];
        if (p.hasFill) canvas.fillRect(x, y, w, h, p.fill);
        canvas.strokePolyline({x, y, x + w, y, x + w, y + h, x, y + h, x, y}, p.width, p.color, false);
        break;
      }
      case P::Kind::Text: {
        const double align = p.anchor == P::Anchor::Start ? 0.0 : p.anchor == P::Anchor::Middle ? 0.5 : 1.0;
        canvas.drawText(p.xy[0], p.xy[1], p.text, p.fontSize, align, p.isVertical, p.color);
        break;
      }
    }
  }
  return canvas.png();
}

void Plot::writeSvg(const std::string& path) const { writeFileAtomically(path, toSvg()); }

void Plot::writePng(const std::string& path) const {
  const std::vector<unsigned char> bytes = toPng();
  writeFileAtomically(path, std::string(bytes.begin(), bytes.end()));
}

}  // namespace pneuma::viz
