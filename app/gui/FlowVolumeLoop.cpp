#include "gui/FlowVolumeLoop.h"

#include <QPainter>
#include <QPainterPath>
#include <algorithm>
#include <cmath>
#include <limits>

#include "viz/PlotLayout.h"

namespace pneuma::app {

FlowVolumeLoop::FlowVolumeLoop(QWidget* parent)
    : QWidget(parent), m_cursor(std::numeric_limits<double>::quiet_NaN()) {
  setMinimumHeight(140);
  setBackgroundRole(QPalette::Base);
  setAutoFillBackground(true);
}

void FlowVolumeLoop::setLoops(std::vector<Loop> loops) {
  m_loops = std::move(loops);
  update();
}

void FlowVolumeLoop::setCursor(double time) {
  m_cursor = time;
  update();
}

void FlowVolumeLoop::paintEvent(QPaintEvent*) {
  QPainter p(this);
  p.setRenderHint(QPainter::Antialiasing);
  const QFontMetrics fm = p.fontMetrics();
  const int line = fm.height();
  QFont bold = p.font();
  bold.setBold(true);
  p.setFont(bold);
  p.drawText(QPoint(8, line), "Flow-volume loop");
  p.setFont(font());

  // ranges over every loop: volume from 0, flow symmetric so that zero flow is the middle line
  double vMax = 1.0, fMax = 0.1;  // [mL], [L/s]
  for (const Loop& l : m_loops)
    for (std::size_t k = 0; k < l.volume.size(); ++k) {
      if (std::isfinite(l.volume[k])) vMax = std::max(vMax, std::abs(l.volume[k]));
      if (std::isfinite(l.flow[k])) fMax = std::max(fMax, std::abs(l.flow[k]));
    }
  const viz::AxisTicks vTicks = viz::niceTicks(-0.05 * vMax, vMax, 5);
  const viz::AxisTicks fTicks = viz::niceTicks(-fMax, fMax, 5);
  const QRectF box(8 + 4.5 * fm.averageCharWidth(), 1.6 * line, width() - 16 - 4.5 * fm.averageCharWidth(),
                   height() - 3.4 * line);
  if (box.width() < 20 || box.height() < 20) return;
  auto at = [&](double v, double f) {
    return QPointF(box.left() + (v - vTicks.lo) / (vTicks.hi - vTicks.lo) * box.width(),
                   box.bottom() - (f - fTicks.lo) / (fTicks.hi - fTicks.lo) * box.height());
  };

  // grid, zero lines and tick labels
  p.setPen(QPen(QColor(225, 225, 225), 1));
  for (double v : vTicks.values) p.drawLine(at(v, fTicks.lo), at(v, fTicks.hi));
  for (double f : fTicks.values) p.drawLine(at(vTicks.lo, f), at(vTicks.hi, f));
  p.setPen(QPen(QColor(150, 150, 150), 1));
  p.drawLine(at(vTicks.lo, 0.0), at(vTicks.hi, 0.0));
  p.drawRect(box);
  p.setPen(palette().color(QPalette::Text));
  for (std::size_t i = 0; i < vTicks.values.size(); ++i)
    p.drawText(QRectF(at(vTicks.values[i], fTicks.lo).x() - 30, box.bottom() + 2, 60, line), Qt::AlignHCenter,
               QString::fromStdString(vTicks.labels[i]));
  for (std::size_t i = 0; i < fTicks.values.size(); ++i)
    p.drawText(QRectF(0, at(vTicks.lo, fTicks.values[i]).y() - line / 2.0, box.left() - 4, line),
               Qt::AlignRight, QString::fromStdString(fTicks.labels[i]));
  p.drawText(QRectF(box.left(), box.bottom() + line, box.width(), line), Qt::AlignHCenter,
             "volume above end-expiration [mL]");
  p.drawText(QRectF(box.left() + 4, box.top() + 2, box.width(), line), Qt::AlignLeft,
             "flow [L/s], inspiration up");

  // the loops: older ones light, the newest complete one dark, the one in progress orange
  p.setClipRect(box);
  int complete = 0;
  for (const Loop& l : m_loops) complete += l.isComplete ? 1 : 0;
  int seen = 0;
  for (const Loop& l : m_loops) {
    QColor colour(230, 110, 20);
    if (l.isComplete) colour = ++seen == complete ? QColor(20, 90, 190) : QColor(150, 175, 215);
    QPainterPath path;
    bool isOpen = false;
    for (std::size_t k = 0; k < l.volume.size(); ++k) {
      if (!std::isfinite(l.volume[k]) || !std::isfinite(l.flow[k])) continue;
      if (!isOpen)
        path.moveTo(at(l.volume[k], l.flow[k]));
      else
        path.lineTo(at(l.volume[k], l.flow[k]));
      isOpen = true;
    }
    p.setPen(QPen(colour, 1.6));
    p.drawPath(path);
    // the cursor's instant
    if (std::isfinite(m_cursor) && !l.time.empty() && m_cursor >= l.time.front() &&
        m_cursor <= l.time.back()) {
      const auto k =
          static_cast<std::size_t>(std::lower_bound(l.time.begin(), l.time.end(), m_cursor) - l.time.begin());
      if (k < l.time.size() && std::isfinite(l.flow[k])) {
        p.setBrush(QColor(200, 0, 60));
        p.setPen(Qt::NoPen);
        p.drawEllipse(at(l.volume[k], l.flow[k]), 4.0, 4.0);
        p.setBrush(Qt::NoBrush);
      }
    }
  }
}

}  // namespace pneuma::app
