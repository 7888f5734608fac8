#include "gui/PlotView.h"

#include <QContextMenuEvent>
#include <QPainter>
#include <QPainterPath>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace pneuma::app {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// tick step of about range / n, rounded to 1, 2 or 5 times a power of ten
double niceStep(double range, int n) {
  const double raw = range / std::max(n, 1);
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0})
    if (m * p >= raw) return m * p;
  return 10.0 * p;
}

// tick step for the range [lo, hi]: about n ticks, but at least two labelled ones (a range of 1.7 L over
// three ticks rounds up to 1 L steps, which label one value only)
double tickStep(double lo, double hi, int n) {
  double step = niceStep(hi - lo, n);
  for (int k = n + 1; std::floor(hi / step) - std::ceil(lo / step) < 1.0 && k <= 8 * n; ++k) step = niceStep(hi - lo, k);
  return step;
}

QString tickText(double v, double step) {
  const int decimals = std::max(0, -static_cast<int>(std::floor(std::log10(step) + 1e-9)));
  return QString::number(std::abs(v) < step * 1e-6 ? 0.0 : v, 'f', decimals);
}

viz::Color toColor(const QColor& c) { return {c.redF(), c.greenF(), c.blueF()}; }

}  // namespace

PlotView::PlotView(QString title, QString yLabel, QWidget* parent)
    : QWidget(parent), m_title(std::move(title)), m_yLabel(std::move(yLabel)), m_cursor(kNaN) {
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

void PlotView::setCursor(double time) {
  m_cursor = time;
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

std::size_t PlotView::firstShown() const {
  if (m_time.empty() || m_window <= 0.0) return 0;
  const double from = m_time.back() - m_window;
  return static_cast<std::size_t>(std::lower_bound(m_time.begin(), m_time.end(), from) - m_time.begin());
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
  viz::Plot plot(m_title.toStdString(), "time [s]", m_yLabel.toStdString());
  const std::size_t first = firstShown();
  const std::vector<double> x(m_time.begin() + static_cast<std::ptrdiff_t>(first), m_time.end());
  for (const Series& s : m_series) {
    viz::Plot::Series out;
    out.label = s.legend.isEmpty() ? std::string() : s.name.toStdString();
    out.x = x;
    out.y.assign(s.y.begin() + static_cast<std::ptrdiff_t>(first), s.y.end());
    out.color = toColor(s.colour);
    out.isDashed = s.isDashed;
    plot.addSeries(std::move(out));
  }
  for (const Reference& r : m_references) plot.addReferenceLine(r.name.toStdString(), r.y, toColor(r.colour));
  return plot;
}

std::string PlotView::toCsv() const {
  std::ostringstream csv;
  csv.precision(10);
  const std::string u = unit().toStdString();
  csv << "time [s]";
  for (const Series& s : m_series) csv << ',' << s.name.toStdString() << ' ' << u;
  csv << '\n';
  for (std::size_t k = firstShown(); k < m_time.size(); ++k) {
    csv << m_time[k];
    for (const Series& s : m_series) csv << ',' << s.y[k];
    csv << '\n';
  }
  return csv.str();
}

void PlotView::contextMenuEvent(QContextMenuEvent* event) { emit contextMenuRequested(event->globalPos()); }

void PlotView::paintEvent(QPaintEvent*) {
  QPainter p(this);
  p.setRenderHint(QPainter::Antialiasing, true);
  p.fillRect(rect(), QColor(250, 250, 252));

  const QFontMetrics fm(font());
  const int lineH = fm.height();

  // header: title and note on the first row, then the legend flowing over as many rows as it needs
  struct Entry {
    const Series* series;
    QRect box;
  };
  std::vector<Entry> legend;
  QFont bold = font();
  bold.setBold(true);
  const bool isNoteOwnRow =
      QFontMetrics(bold).horizontalAdvance(m_title) + fm.horizontalAdvance(m_note) + 24 > width();
  const int noteY = isNoteOwnRow ? 4 + lineH : 4;
  int lx = 8, ly = 6 + lineH + (isNoteOwnRow ? lineH : 0);
  for (const Series& s : m_series) {
    if (s.legend.isEmpty()) continue;
    const int w = 22 + fm.horizontalAdvance(s.legend) + 12;
    if (lx + w > width() - 8 && lx > 8) lx = 8, ly += lineH;
    legend.push_back({&s, QRect(lx, ly, w, lineH)});
    lx += w;
  }
  const int top = (legend.empty() ? ly : ly + lineH) + 8;
  const QRect area(62, top, width() - 62 - 14, height() - top - lineH - 8);
  if (area.width() < 20 || area.height() < 20) return;

  // x range: the rolling window ending at the newest sample (starting at the first one early on)
  const std::size_t first = firstShown();
  const double t0 = m_time.empty() ? 0.0 : m_time.front();
  const double tLast = m_time.empty() ? 0.0 : m_time.back();
  const double tStart = m_window > 0.0 ? std::max(t0, tLast - m_window) : t0;
  const double tEnd = m_window > 0.0 ? std::max(tLast, tStart + m_window) : std::max(tLast, t0 + 1.0);
  const double tSpan = std::max(tEnd - tStart, 1e-6);

  // y range: shown data and reference lines, padded
  double yMin = std::numeric_limits<double>::infinity(), yMax = -yMin;
  for (const Series& s : m_series)
    for (std::size_t k = first; k < s.y.size(); ++k)
      if (std::isfinite(s.y[k])) yMin = std::min(yMin, s.y[k]), yMax = std::max(yMax, s.y[k]);
  for (const Reference& r : m_references) yMin = std::min(yMin, r.y), yMax = std::max(yMax, r.y);
  if (m_includeZero) yMin = std::min(yMin, 0.0), yMax = std::max(yMax, 0.0);
  if (!std::isfinite(yMin)) yMin = 0.0, yMax = 1.0;
  if (yMax - yMin < 1e-9) yMin -= 0.5, yMax += 0.5;
  const double pad = 0.08 * (yMax - yMin);
  yMin -= pad;
  yMax += pad;

  auto px = [&](double t) { return area.left() + (t - tStart) / tSpan * area.width(); };
  auto py = [&](double y) { return area.bottom() - (y - yMin) / (yMax - yMin) * area.height(); };

  // title, note and legend
  p.setPen(QColor(30, 30, 36));
  p.setFont(bold);
  p.drawText(QRect(8, 4, width() - 16, lineH), Qt::AlignLeft | Qt::AlignVCenter, m_title);
  p.setFont(font());
  p.setPen(QColor(20, 70, 140));
  p.drawText(QRect(8, noteY, width() - 16, lineH), Qt::AlignRight | Qt::AlignVCenter, m_note);
  for (const Entry& e : legend) {
    p.setPen(QPen(e.series->colour, 2.5, e.series->isDashed ? Qt::DashLine : Qt::SolidLine));
    const double mid = e.box.center().y() + 0.5;
    p.drawLine(QPointF(e.box.left(), mid), QPointF(e.box.left() + 16, mid));
    p.setPen(QColor(50, 50, 60));
    p.drawText(e.box.adjusted(22, 0, 0, 0), Qt::AlignLeft | Qt::AlignVCenter, e.series->legend);
  }

  // grid and tick labels
  p.setPen(QColor(200, 200, 208));
  p.drawRect(area);
  const double yStep = tickStep(yMin, yMax, std::max(2, area.height() / (2 * lineH)));
  for (double y = std::ceil(yMin / yStep) * yStep; y <= yMax; y += yStep) {
    p.setPen(QColor(228, 228, 234));
    p.drawLine(QPointF(area.left(), py(y)), QPointF(area.right(), py(y)));
    p.setPen(QColor(80, 80, 90));
    p.drawText(QRectF(0, py(y) - lineH / 2.0, area.left() - 6, lineH), Qt::AlignRight | Qt::AlignVCenter,
               tickText(y, yStep));
  }
  const double tStep = niceStep(tSpan, std::max(2, area.width() / 70));
  for (double t = std::ceil(tStart / tStep) * tStep; t <= tEnd + 1e-9; t += tStep) {
    p.setPen(QColor(228, 228, 234));
    p.drawLine(QPointF(px(t), area.top()), QPointF(px(t), area.bottom()));
    p.setPen(QColor(80, 80, 90));
    p.drawText(QRectF(px(t) - 30, area.bottom() + 2, 60, lineH), Qt::AlignCenter, tickText(t, tStep));
  }
  p.drawText(QRect(0, area.bottom() + 2, area.left() - 8, lineH), Qt::AlignRight | Qt::AlignVCenter, "time [s]");
  p.save();
  p.translate(12, area.center().y());
  p.rotate(-90);
  p.drawText(QRect(-area.height() / 2, -lineH / 2 - 2, area.height(), lineH), Qt::AlignCenter, m_yLabel);
  p.restore();

  // reference lines and series, clipped to the plot area
  p.setClipRect(area.adjusted(1, 1, -1, -1));
  for (const Reference& r : m_references) {
    p.setPen(QPen(r.colour, 1.2, Qt::DashLine));
    p.drawLine(QPointF(area.left(), py(r.y)), QPointF(area.right(), py(r.y)));
  }
  for (const Series& s : m_series) {
    // at most the first, lowest, highest and last sample per pixel column: the same picture, far fewer segments
    QPainterPath path;
    bool isDrawing = false;
    auto add = [&](std::size_t k) {
      const QPointF at(px(m_time[k]), py(s.y[k]));
      if (isDrawing) path.lineTo(at);
      else path.moveTo(at);
      isDrawing = true;
    };
    const std::size_t end = std::min(s.y.size(), m_time.size());
    for (std::size_t k = first; k < end;) {
      if (!std::isfinite(s.y[k])) {
        isDrawing = false;
        ++k;
        continue;
      }
      const int column = static_cast<int>(px(m_time[k]));
      std::size_t lo = k, hi = k, last = k;
      while (last + 1 < end && std::isfinite(s.y[last + 1]) && static_cast<int>(px(m_time[last + 1])) == column) {
        ++last;
        if (s.y[last] < s.y[lo]) lo = last;
        if (s.y[last] > s.y[hi]) hi = last;
      }
      add(k);
      if (std::min(lo, hi) != k) add(std::min(lo, hi));
      if (std::max(lo, hi) != k && std::max(lo, hi) != last) add(std::max(lo, hi));
      if (last != k) add(last);
      k = last + 1;
    }
    p.setPen(QPen(s.colour, 1.8, s.isDashed ? Qt::DashLine : Qt::SolidLine));
    p.drawPath(path);
  }

  // cursor and its read-out
  if (std::isfinite(m_cursor) && m_cursor >= tStart && m_cursor <= tEnd) {
    p.setPen(QPen(QColor(20, 110, 200), 1.5));
    p.drawLine(QPointF(px(m_cursor), area.top()), QPointF(px(m_cursor), area.bottom()));
    QStringList lines{QString("t = %1 s").arg(m_cursor, 0, 'f', 2)};
    for (std::size_t i = 0; i < m_series.size() && lines.size() < 4; ++i) {
      const double v = cursorValue(i);
      if (std::isfinite(v)) lines << QString("%1 %2").arg(m_series[i].name).arg(v, 0, 'g', 4);
    }
    const QString text = lines.join('\n');
    QRectF box = fm.boundingRect(QRect(0, 0, 400, 200), 0, text);
    box.moveTopLeft(QPointF(std::min(px(m_cursor) + 6, area.right() - box.width() - 6), area.top() + 4));
    p.fillRect(box.adjusted(-4, -2, 4, 2), QColor(255, 255, 255, 225));
    p.setPen(QColor(20, 70, 140));
    p.drawText(box, 0, text);
  }
}

}  // namespace pneuma::app
