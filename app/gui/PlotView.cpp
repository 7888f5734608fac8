#include "gui/PlotView.h"

#include <QContextMenuEvent>
#include <QMouseEvent>
#include <QPainter>
#include <QPainterPath>
#include <QWheelEvent>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "viz/PlotLayout.h"

namespace pneuma::app {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

viz::Color toColor(const QColor& c) { return {c.redF(), c.greenF(), c.blueF()}; }
QColor toQColor(const viz::Color& c) { return QColor::fromRgbF(c.r, c.g, c.b); }

// the export is the screen plot at this many times its size (at least), fonts and lines scaled alike
constexpr double kMinExportScale = 2.0;
constexpr double kExportWidth = 960.0;  // [px] the export's width when the widget is narrower than half of it
constexpr double kZoomStep = 1.25;      // [-] span factor per wheel notch
constexpr double kMinWindow = 1.0;      // [s] narrowest span

}  // namespace

PlotView::PlotView(QString title, QString yLabel, QWidget* parent)
    : QWidget(parent), m_title(std::move(title)), m_yLabel(std::move(yLabel)), m_cursor(kNaN), m_end(kNaN) {
  setMinimumSize(260, 150);
  setSizePolicy(QSizePolicy::Expanding, QSizePolicy::Expanding);
}

void PlotView::setData(std::vector<double> time, std::vector<Series> series) {
  m_time = std::move(time);
  m_series = std::move(series);
  update();
}

void PlotView::setReferences(std::vector<Reference> references) {
  m_references = std::move(references);
  update();
}

void PlotView::setWindow(double seconds) {
  m_window = seconds;
  update();
}

void PlotView::setViewEnd(double time) {
  m_end = time;
  update();
}

void PlotView::setCursor(double time) {
  m_cursor = time;
  // follow the timeline: a cursor outside the span brings the span to it; back live, follow the newest
  if (std::isnan(time)) {
    m_end = kNaN;
  } else if (m_window > 0.0 && !m_time.empty() && (time < shownEnd() - m_window || time > shownEnd())) {
    m_end = std::min(m_time.back(), time + 0.5 * m_window);
  }
  update();
}

void PlotView::wheelEvent(QWheelEvent* event) {
  if (m_time.empty() || event->angleDelta().y() == 0) return;
  const viz::PlotLayout L = layout();
  const double span = m_window > 0.0 ? m_window : m_time.back() - m_time.front();
  const double end = shownEnd();
  // the time under the mouse stays where it is
  const double at = std::clamp(
      L.x.lo + (event->position().x() - L.area.left) / std::max(1.0, L.area.width()) * (L.x.hi - L.x.lo),
      end - span, end);
  const double full = std::max(kMinWindow, m_time.back() - m_time.front());
  const double next =
      std::clamp(event->angleDelta().y() > 0 ? span / kZoomStep : span * kZoomStep, kMinWindow, full);
  const double newEnd = at + (end - at) * next / span;
  m_window = next;
  m_end = newEnd >= m_time.back() ? kNaN : newEnd;
  emit viewChanged(m_window, m_end);
  update();
}

void PlotView::mousePressEvent(QMouseEvent* event) {
  if (event->button() == Qt::LeftButton) m_dragFrom = event->localPos().x();
}

void PlotView::mouseMoveEvent(QMouseEvent* event) {
  if (!(event->buttons() & Qt::LeftButton) || m_time.empty()) return;
  const viz::PlotLayout L = layout();
  const double secondsPerPixel = (L.x.hi - L.x.lo) / std::max(1.0, L.area.width());
  const double x = event->localPos().x();
  const double end =
      std::clamp(shownEnd() - (x - m_dragFrom) * secondsPerPixel,
                 m_time.front() + std::min(m_window, m_time.back() - m_time.front()), m_time.back());
  m_dragFrom = x;
  m_end = end >= m_time.back() ? kNaN : end;
  emit viewChanged(m_window, m_end);
  update();
}

void PlotView::mouseDoubleClickEvent(QMouseEvent*) {
  m_end = kNaN;
  emit viewChanged(m_window, m_end);
  update();
}

void PlotView::setNote(QString note) {
  m_note = std::move(note);
  update();
}

void PlotView::setIncludeZero(bool includeZero) { m_includeZero = includeZero; }

QString PlotView::unit() const {
  const int open = m_yLabel.lastIndexOf('[');
  return open >= 0 ? m_yLabel.mid(open) : QString();
}

double PlotView::shownEnd() const {
  if (m_time.empty()) return 0.0;
  return std::isnan(m_end) ? m_time.back() : std::min(m_end, m_time.back());
}

std::size_t PlotView::firstShown() const {
  if (m_time.empty() || m_window <= 0.0) return 0;
  const double from = shownEnd() - m_window;
  return static_cast<std::size_t>(std::lower_bound(m_time.begin(), m_time.end(), from) - m_time.begin());
}

std::size_t PlotView::endShown() const {
  if (m_time.empty() || m_window <= 0.0 || std::isnan(m_end)) return m_time.size();
  return static_cast<std::size_t>(std::upper_bound(m_time.begin(), m_time.end(), shownEnd()) -
                                  m_time.begin());
}

double PlotView::cursorValue(std::size_t i) const {
  if (std::isnan(m_cursor) || m_time.empty() || i >= m_series.size()) return kNaN;
  auto it = std::lower_bound(m_time.begin(), m_time.end(), m_cursor);
  std::size_t k = static_cast<std::size_t>(it - m_time.begin());
  if (k == m_time.size() || (k > 0 && m_cursor - m_time[k - 1] < m_time[k] - m_cursor)) k = k > 0 ? k - 1 : 0;
  if (std::abs(m_time[k] - m_cursor) > 0.1) return kNaN;  // no sample near the cursor
  return m_series[i].y[k];
}

viz::Plot PlotView::toPlot() const {
  return toPlot(std::max(kMinExportScale, kExportWidth / std::max(1, width())));
}

viz::Plot PlotView::toPlot(double scale) const {
  viz::Plot plot(m_title.toStdString(), "time [s]", m_yLabel.toStdString());
  plot.setNote(m_note.toStdString());
  plot.setIncludeZero(m_includeZero);
  // x range: the rolling window ending at the newest sample or the scrolled-to end (starting at the first one
  // early on)
  const double t0 = m_time.empty() ? 0.0 : m_time.front();
  const double tLast = shownEnd();
  const double tStart = m_window > 0.0 ? std::max(t0, tLast - m_window) : t0;
  const double tEnd = m_window > 0.0 ? std::max(tLast, tStart + m_window) : std::max(tLast, t0 + 1.0);
  plot.setXRange(tStart, std::max(tEnd, tStart + 1e-6));
  const std::size_t first = firstShown(), last = endShown();
  const std::vector<double> x(m_time.begin() + static_cast<std::ptrdiff_t>(first),
                              m_time.begin() + static_cast<std::ptrdiff_t>(std::max(first, last)));
  for (const Series& s : m_series) {
    viz::Plot::Series out;
    out.label = s.legend.toStdString();
    const std::size_t n = std::min({s.y.size(), m_time.size(), last});
    out.y.assign(s.y.begin() + static_cast<std::ptrdiff_t>(std::min(first, n)),
                 s.y.begin() + static_cast<std::ptrdiff_t>(n));
    out.x.assign(x.begin(), x.begin() + static_cast<std::ptrdiff_t>(out.y.size()));
    out.color = toColor(s.colour);
    out.isDashed = s.isDashed;
    plot.addSeries(std::move(out));
  }
  for (const Reference& r : m_references) plot.addReferenceLine(r.name.toStdString(), r.y, toColor(r.colour));
  const QFontMetricsF fm(font());
  plot.setSize(std::max(200, static_cast<int>(std::lround(scale * width()))),
               std::max(150, static_cast<int>(std::lround(scale * height()))));
  plot.setTextSize(
      std::clamp(scale * fm.height() / 1.25, 6.0, 200.0));  // the export's line height: scale x ours
  return plot;
}

viz::PlotLayout PlotView::layout() const { return layoutOf(toPlot(1.0)); }

viz::PlotLayout PlotView::layoutOf(const viz::Plot& plot) const {
  const QFontMetricsF fm(font());
  QFont bold = font();
  bold.setBold(true);
  const QFontMetricsF fmBold(bold);
  viz::TextMetrics m;
  m.lineHeight = fm.height();
  m.width = [fm](const std::string& s) { return fm.horizontalAdvance(QString::fromStdString(s)); };
  m.titleWidth = [fmBold](const std::string& s) {
    return fmBold.horizontalAdvance(QString::fromStdString(s));
  };
  return viz::layoutPlot(plot, width(), height(), m);
}

std::string PlotView::toCsv() const {
  std::ostringstream csv;
  csv.precision(10);
  const std::string u = unit().toStdString();
  csv << "time [s]";
  for (const Series& s : m_series) csv << ',' << s.name.toStdString() << ' ' << u;
  csv << '\n';
  for (std::size_t k = firstShown(); k < endShown(); ++k) {
    csv << m_time[k];
    for (const Series& s : m_series) csv << ',' << s.y[k];
    csv << '\n';
  }
  return csv.str();
}

void PlotView::contextMenuEvent(QContextMenuEvent* event) { emit contextMenuRequested(event->globalPos()); }

void PlotView::paintEvent(QPaintEvent*) {
  using S = viz::PlotStyle;
  QPainter p(this);
  p.setRenderHint(QPainter::Antialiasing, true);
  p.fillRect(rect(), toQColor(S::kBackground));

  const viz::Plot plot = toPlot(1.0);
  const viz::PlotLayout L = layoutOf(plot);
  if (L.area.width() < 20 || L.area.height() < 20) return;
  const double k = L.scale();
  const QRectF area(QPointF(L.area.left, L.area.top), QPointF(L.area.right, L.area.bottom));
  auto box = [](const viz::PlotLayout::Box& b) {
    return QRectF(QPointF(b.left, b.top), QPointF(b.right, b.bottom));
  };
  auto align = [](viz::PlotLayout::Align a) {
    return (a == viz::PlotLayout::Align::Start    ? Qt::AlignLeft
            : a == viz::PlotLayout::Align::Middle ? Qt::AlignHCenter
                                                  : Qt::AlignRight) |
           Qt::AlignVCenter;
  };
  auto text = [&](const viz::PlotLayout::Text& t, const viz::Color& c) {
    if (t.text.empty()) return;
    p.setPen(toQColor(c));
    if (!t.isVertical) {
      p.drawText(box(t.box), align(t.align), QString::fromStdString(t.text));
      return;
    }
    const QRectF b = box(t.box);
    p.save();
    p.translate(b.center());
    p.rotate(-90);
    p.drawText(QRectF(-b.height() / 2.0, -b.width() / 2.0, b.height(), b.width()), Qt::AlignCenter,
               QString::fromStdString(t.text));
    p.restore();
  };

  // grid and frame
  p.setPen(QPen(toQColor(S::kGrid), S::kGridWidth * k));
  for (double t : L.x.values) p.drawLine(QPointF(L.mapX(t), area.top()), QPointF(L.mapX(t), area.bottom()));
  for (double y : L.y.values) p.drawLine(QPointF(area.left(), L.mapY(y)), QPointF(area.right(), L.mapY(y)));
  p.setPen(QPen(toQColor(S::kFrame), S::kGridWidth * k));
  p.drawRect(area);

  // texts and the legend
  for (const viz::PlotLayout::Text& t : L.xTickLabels) text(t, S::kText);
  for (const viz::PlotLayout::Text& t : L.yTickLabels) text(t, S::kText);
  text(L.xLabel, S::kText);
  text(L.yLabel, S::kText);
  QFont bold = font();
  bold.setBold(true);
  p.setFont(bold);
  text(L.title, S::kTitle);
  p.setFont(font());
  text(L.note, S::kNote);
  for (const viz::PlotLayout::LegendEntry& e : L.legend) {
    const viz::Plot::Series& s = e.isReference ? plot.references()[e.index] : plot.series()[e.index];
    const double mid = (e.box.top + e.box.bottom) / 2.0 + 0.5;
    p.setPen(QPen(toQColor(s.color), S::kLegendWidth * k, s.isDashed ? Qt::DashLine : Qt::SolidLine));
    p.drawLine(QPointF(e.box.left, mid), QPointF(e.box.left + L.legendSample, mid));
    text(e.label, S::kLegend);
  }

  // reference lines and series, clipped to the plot area
  p.setClipRect(area.adjusted(1, 1, -1, -1));
  for (const viz::Plot::Series& r : plot.references()) {
    p.setPen(QPen(toQColor(r.color), S::kReferenceWidth * k, Qt::DashLine));
    p.drawLine(QPointF(area.left(), L.mapY(r.y[0])), QPointF(area.right(), L.mapY(r.y[0])));
  }
  for (const viz::Plot::Series& s : plot.series()) {
    // at most the first, lowest, highest and last sample per pixel column: the same picture, far fewer
    // segments
    QPainterPath path;
    bool isDrawing = false;
    auto add = [&](std::size_t i) {
      const QPointF at(L.mapX(s.x[i]), L.mapY(s.y[i]));
      if (isDrawing)
        path.lineTo(at);
      else
        path.moveTo(at);
      isDrawing = true;
    };
    const std::size_t end = std::min(s.y.size(), s.x.size());
    for (std::size_t i = 0; i < end;) {
      if (!std::isfinite(s.y[i])) {
        isDrawing = false;
        ++i;
        continue;
      }
      const int column = static_cast<int>(L.mapX(s.x[i]));
      std::size_t lo = i, hi = i, last = i;
      while (last + 1 < end && std::isfinite(s.y[last + 1]) &&
             static_cast<int>(L.mapX(s.x[last + 1])) == column) {
        ++last;
        if (s.y[last] < s.y[lo]) lo = last;
        if (s.y[last] > s.y[hi]) hi = last;
      }
      add(i);
      if (std::min(lo, hi) != i) add(std::min(lo, hi));
      if (std::max(lo, hi) != i && std::max(lo, hi) != last) add(std::max(lo, hi));
      if (last != i) add(last);
      i = last + 1;
    }
    p.setPen(QPen(toQColor(s.color), S::kDataWidth * k, s.isDashed ? Qt::DashLine : Qt::SolidLine));
    p.drawPath(path);
  }
  p.setClipping(false);

  // cursor and its read-out (screen only)
  const QFontMetrics fm(font());
  if (std::isfinite(m_cursor) && m_cursor >= L.x.lo && m_cursor <= L.x.hi) {
    const double cx = L.mapX(m_cursor);
    p.setPen(QPen(QColor(20, 110, 200), 1.5));
    p.drawLine(QPointF(cx, area.top()), QPointF(cx, area.bottom()));
    QStringList lines{QString("t = %1 s").arg(m_cursor, 0, 'f', 2)};
    const QString u = unit();  // "[mL]" -> "mL"
    const QString unitName = u.size() >= 2 ? u.mid(1, u.size() - 2) : QString();
    for (std::size_t i = 0; i < m_series.size() && lines.size() < 4; ++i) {
      const double v = cursorValue(i);
      if (std::isfinite(v))
        lines << QString("%1 %2 %3").arg(m_series[i].name).arg(v, 0, 'g', 4).arg(unitName);
    }
    const QString readOut = lines.join('\n');
    QRectF readOutBox = fm.boundingRect(QRect(0, 0, 400, 200), 0, readOut);
    readOutBox.moveTopLeft(QPointF(std::min(cx + 6, area.right() - readOutBox.width() - 6), area.top() + 4));
    p.fillRect(readOutBox.adjusted(-4, -2, 4, 2), QColor(255, 255, 255, 225));
    p.setPen(toQColor(S::kNote));
    p.drawText(readOutBox, 0, readOut);
  }
}

}  // namespace pneuma::app
