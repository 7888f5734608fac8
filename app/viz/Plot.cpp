#include "viz/Plot.h"

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

#include "viz/AtomicFile.h"
#include "viz/PlotLayout.h"

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
  double fontSize = 15.0;     // [px]
  bool isBold = false;        // title
  Anchor anchor = Anchor::Start;
  bool isVertical = false;  // text rotated by -90 degrees (reads bottom to top)
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
void configureText(vtkTextProperty* tp, double fontSize, const Color& c, bool isBold) {
  if (*fontFile() != '\0') {
    tp->SetFontFamily(VTK_FONT_FILE);
    tp->SetFontFile(fontFile());
  } else {
    tp->SetFontFamilyToArial();
  }
  tp->SetFontSize(static_cast<int>(std::lround(fontSize)));
  tp->SetBold(isBold ? 1 : 0);
  tp->SetColor(c.r, c.g, c.b);
  tp->SetJustificationToLeft();
  tp->SetVerticalJustificationToBottom();
}

/// Advance width of `text` at `fontSize` [px], measured with the same FreeType font the PNG uses.
double textWidth(const std::string& text, double fontSize, bool isBold) {
  if (text.empty()) return 0.0;
  vtkNew<vtkTextProperty> tp;
  configureText(tp, fontSize, Color{}, isBold);
  int bbox[4] = {0, 0, 0, 0};
  vtkFreeTypeTools::GetInstance()->GetBoundingBox(tp, vtkStdString(text), 72, bbox);
  return bbox[1] - bbox[0] + 1;
}

std::string svgColor(const Color& c) {
  auto to8 = [](double v) { return static_cast<int>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0)); };
  return "rgb(" + std::to_string(to8(c.r)) + "," + std::to_string(to8(c.g)) + "," + std::to_string(to8(c.b)) +
         ")";
}

std::string xmlEscape(const std::string& s) {
  std::string out;
  for (char ch : s) {
    switch (ch) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += ch;
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
  Canvas(int w, int h)
      : m_w(w),
        m_h(h),
        m_rgb(static_cast<std::size_t>(3 * w * h), 1.0),
        m_cover(static_cast<std::size_t>(w * h), 0.0f) {}

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
            coverSegment(ax + t0 * (bx - ax), ay + t0 * (by - ay), ax + t1 * (bx - ax), ay + t1 * (by - ay),
                         width, x0, y0, x1, y1);
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
    for (int py = std::max(0, static_cast<int>(std::floor(y)));
         py < std::min(m_h, static_cast<int>(std::ceil(y + h))); ++py)
      for (int px = std::max(0, static_cast<int>(std::floor(x)));
           px < std::min(m_w, static_cast<int>(std::ceil(x + w))); ++px) {
        // fractional coverage at the rectangle's edges
        const double cx = std::max(0.0, std::min(px + 1.0, x + w) - std::max(px + 0.0, x));
        const double cy = std::max(0.0, std::min(py + 1.0, y + h) - std::max(py + 0.0, y));
        blend(px, py, c, cx * cy);
      }
  }

  /// Draws FreeType text with its baseline anchored at (x, y); `align` is 0 (start), 0.5 (middle) or 1 (end).
  void drawText(double x, double y, const std::string& text, double fontSize, bool isBold, double align,
                bool isVertical, const Color& c) {
    vtkNew<vtkTextProperty> tp;
    configureText(tp, fontSize, c, isBold);
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
          px[k] = static_cast<unsigned char>(std::lround(
              std::clamp(m_rgb[static_cast<std::size_t>(3 * (y * m_w + x) + k)], 0.0, 1.0) * 255.0));
      }
    vtkNew<vtkPNGWriter> writer;
    writer->SetInputData(img);
    writer->WriteToMemoryOn();
    writer->Write();
    vtkUnsignedCharArray* result = writer->GetResult();
    if (result == nullptr || result->GetNumberOfValues() == 0)
      throw std::runtime_error("PNG encoding failed");
    return std::vector<unsigned char>(result->GetPointer(0),
                                      result->GetPointer(0) + result->GetNumberOfValues());
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
  void coverSegment(double ax, double ay, double bx, double by, double w, int& x0, int& y0, int& x1,
                    int& y1) {
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
    throw std::invalid_argument("Plot series '" + series.label + "': x has " +
                                std::to_string(series.x.size()) + " values but y has " +
                                std::to_string(series.y.size()));
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
    throw std::invalid_argument("Plot size must be at least 200 x 150 px, got " + std::to_string(widthPx) +
                                " x " + std::to_string(heightPx));
  m_width = widthPx;
  m_height = heightPx;
}

void Plot::setTextSize(double px) {
  if (!(px >= 6.0 && px <= 200.0))
    throw std::invalid_argument("Plot text size must be in [6, 200] px, got " + std::to_string(px));
  m_textSize = px;
}

void Plot::setNote(std::string note) { m_note = std::move(note); }

void Plot::setXRange(double lo, double hi) {
  if (!(lo < hi) || !std::isfinite(hi - lo))
    throw std::invalid_argument("Plot x range must have lo < hi, got [" + std::to_string(lo) + ", " +
                                std::to_string(hi) + "]");
  m_hasXRange = true;
  m_xRange = {lo, hi};
}

void Plot::setIncludeZero(bool includeZero) { m_includeZero = includeZero; }

void Plot::setEqualAspect(bool isEqualAspect) { m_equalAspect = isEqualAspect; }

PlotLayout Plot::layout() const {
  TextMetrics m;
  m.lineHeight = lineHeight();
  m.width = [size = m_textSize](const std::string& s) { return textWidth(s, size, false); };
  m.titleWidth = [size = m_textSize](const std::string& s) { return textWidth(s, size, true); };
  return layoutPlot(*this, m_width, m_height, m);
}

std::vector<Plot::Primitive> Plot::primitives() const {
  using P = Primitive;
  using S = PlotStyle;
  using Align = PlotLayout::Align;
  const PlotLayout L = layout();
  const double k = L.scale();
  std::vector<P> out;

  auto line = [&](double ax, double ay, double bx, double by, const Color& c, double w, bool isDashed) {
    P p;
    p.xy = {ax, ay, bx, by};
    p.color = c;
    p.width = w;
    p.isDashed = isDashed;
    out.push_back(std::move(p));
  };
  // a text of the layout: baseline 0.35 em below the middle of its box (DejaVu's cap height is 0.73 em)
  auto text = [&](const PlotLayout::Text& t, const Color& c, bool isBold) {
    if (t.text.empty()) return;
    P p;
    p.kind = P::Kind::Text;
    p.text = t.text;
    p.fontSize = m_textSize;
    p.isBold = isBold;
    p.color = c;
    p.isVertical = t.isVertical;
    const double cx = (t.box.left + t.box.right) / 2.0, cy = (t.box.top + t.box.bottom) / 2.0;
    if (t.isVertical) {
      p.xy = {cx + 0.35 * m_textSize, cy};
      p.anchor = P::Anchor::Middle;
    } else {
      p.xy = {t.align == Align::Start    ? t.box.left
              : t.align == Align::Middle ? cx
                                         : t.box.right,
              cy + 0.35 * m_textSize};
      p.anchor = t.align == Align::Start    ? P::Anchor::Start
                 : t.align == Align::Middle ? P::Anchor::Middle
                                            : P::Anchor::End;
    }
    out.push_back(std::move(p));
  };

  // grid, then the data's frame
  for (double t : L.x.values) {
    const double x = std::round(L.mapX(t)) + 0.5;
    line(x, L.area.top, x, L.area.bottom, S::kGrid, S::kGridWidth * k, false);
  }
  for (double t : L.y.values) {
    const double y = std::round(L.mapY(t)) + 0.5;
    line(L.area.left, y, L.area.right, y, S::kGrid, S::kGridWidth * k, false);
  }
  P frame;
  frame.kind = P::Kind::Rect;
  frame.xy = {std::round(L.area.left) + 0.5, std::round(L.area.top) + 0.5, std::round(L.area.width()),
              std::round(L.area.height())};
  frame.color = S::kFrame;
  frame.width = S::kGridWidth * k;
  out.push_back(frame);

  // reference lines across the box, then the data; values outside the shown x range or non-finite break the
  // line
  for (const Series& r : m_references)
    line(L.area.left, L.mapY(r.y[0]), L.area.right, L.mapY(r.y[0]), r.color, S::kReferenceWidth * k, true);
  for (const Series& s : m_series) {
    P p;
    p.color = s.color;
    p.width = S::kDataWidth * k;
    p.isDashed = s.isDashed;
    for (std::size_t i = 0; i <= s.x.size(); ++i) {
      const bool isShown = i < s.x.size() && std::isfinite(s.x[i]) && std::isfinite(s.y[i]) &&
                           s.x[i] >= L.x.lo && s.x[i] <= L.x.hi;
      if (isShown) {
        p.xy.push_back(L.mapX(s.x[i]));
        p.xy.push_back(L.mapY(s.y[i]));
      } else if (!p.xy.empty()) {
        out.push_back(p);
        p.xy.clear();
      }
    }
  }

  // texts and the legend
  for (const PlotLayout::Text& t : L.xTickLabels) text(t, S::kText, false);
  for (const PlotLayout::Text& t : L.yTickLabels) text(t, S::kText, false);
  text(L.xLabel, S::kText, false);
  text(L.yLabel, S::kText, false);
  text(L.title, S::kTitle, true);
  text(L.note, S::kNote, false);
  for (const PlotLayout::LegendEntry& e : L.legend) {
    const Series& s = e.isReference ? m_references[e.index] : m_series[e.index];
    const double mid = (e.box.top + e.box.bottom) / 2.0;
    line(e.box.left, mid, e.box.left + L.legendSample, mid, s.color, S::kLegendWidth * k, s.isDashed);
    text(e.label, S::kLegend, false);
  }
  return out;
}

std::string Plot::toSvg() const {
  using P = Primitive;
  std::ostringstream svg;
  svg << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << m_width << "\" height=\"" << m_height
      << "\" viewBox=\"0 0 " << m_width << " " << m_height
      << "\" font-family=\"DejaVu Sans, Verdana, Arial, sans-serif\">\n"
      << "<rect x=\"0\" y=\"0\" width=\"" << m_width << "\" height=\"" << m_height << "\" fill=\"white\"/>\n";
  for (const P& p : primitives()) {
    switch (p.kind) {
      case P::Kind::Polyline: {
        svg << "<polyline fill=\"none\" stroke=\"" << svgColor(p.color) << "\" stroke-width=\""
            << num(p.width) << "\" stroke-linejoin=\"round\" stroke-linecap=\"round\"";
        if (p.isDashed) svg << " stroke-dasharray=\"" << kDashOn << " " << kDashOff << "\"";
        svg << " points=\"";
        for (std::size_t i = 0; i + 1 < p.xy.size(); i += 2)
          svg << (i ? " " : "") << num(p.xy[i]) << "," << num(p.xy[i + 1]);
        svg << "\"/>\n";
        break;
      }
      case P::Kind::Rect:
        svg << "<rect x=\"" << num(p.xy[0]) << "\" y=\"" << num(p.xy[1]) << "\" width=\"" << num(p.xy[2])
            << "\" height=\"" << num(p.xy[3]) << "\" fill=\"" << (p.hasFill ? svgColor(p.fill) : "none")
            << "\" stroke=\"" << svgColor(p.color) << "\" stroke-width=\"" << num(p.width) << "\"/>\n";
        break;
      case P::Kind::Text: {
        const char* anchor = p.anchor == P::Anchor::Start    ? "start"
                             : p.anchor == P::Anchor::Middle ? "middle"
                                                             : "end";
        svg << "<text x=\"" << num(p.xy[0]) << "\" y=\"" << num(p.xy[1]) << "\" font-size=\""
            << num(p.fontSize) << "\" text-anchor=\"" << anchor << "\" fill=\"" << svgColor(p.color) << "\"";
        if (p.isBold) svg << " font-weight=\"bold\"";
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
  for (const P& p : primitives()) {
    switch (p.kind) {
      case P::Kind::Polyline:
        canvas.strokePolyline(p.xy, p.width, p.color, p.isDashed);
        break;
      case P::Kind::Rect: {
        const double x = p.xy[0], y = p.xy[1], w = p.xy[2], h = p.xy[3];
        if (p.hasFill) canvas.fillRect(x, y, w, h, p.fill);
        canvas.strokePolyline({x, y, x + w, y, x + w, y + h, x, y + h, x, y}, p.width, p.color, false);
        break;
      }
      case P::Kind::Text: {
        const double align = p.anchor == P::Anchor::Start ? 0.0 : p.anchor == P::Anchor::Middle ? 0.5 : 1.0;
        canvas.drawText(p.xy[0], p.xy[1], p.text, p.fontSize, p.isBold, align, p.isVertical, p.color);
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
