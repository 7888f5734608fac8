#include "gui/LivePlots.h"

#include <QSplitter>
#include <QTabWidget>
#include <QVBoxLayout>
#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>

#include "gui/FlowVolumeLoop.h"
#include "gui/PlotView.h"
#include "viz/ModelScene.h"

namespace pneuma::app {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kHistorySeconds = 120.0;  // [s] kept for the window and for picked traces
constexpr double kSegmentSeconds = 6.0;    // [s] of history per segment
constexpr std::size_t kSegmentBuckets =
    512;                             // MinMaxSeries buckets per segment: exact up to 512 / 6 s = 85 Hz
constexpr double kForceRate = 60.0;  // [Hz] most element-force frames kept per simulated second

// the columns of a segment: time, lung volume [m^3], target volume [m^3], gut volume error [-], flow [m^3/s],
// gut and transdiaphragmatic pressures [Pa], then r, alpha and mean tension [N] of each muscle group
enum Column : std::size_t { kTime, kLung, kTarget, kGut, kFlow, kGutPressure, kPdi, kFirstGroupColumn };
constexpr double kPascalPerCmH2O = 98.0665;  // [Pa / cmH2O]
constexpr int kLoops = 3;                    // complete breaths drawn in the flow-volume loop
constexpr std::size_t kColumnsPerGroup = 3;
const QColor kOverlayColour(90, 90, 90);  // an overlaid run, dashed

const std::vector<sim::ElementGroup>& muscleGroups() {
  static const std::vector<sim::ElementGroup> groups = [] {
    std::vector<sim::ElementGroup> g;
    for (int i = 0; i < sim::kElementGroupCount; ++i)
      if (sim::isMuscleGroup(static_cast<sim::ElementGroup>(i)))
        g.push_back(static_cast<sim::ElementGroup>(i));
    return g;
  }();
  return groups;
}

// short legend names of the muscle groups
QString shortLabel(sim::ElementGroup g) {
  switch (g) {
    case sim::ElementGroup::IntercostalExternal:
      return "ext. intercostals";
    case sim::ElementGroup::IntercostalInternal:
      return "int. intercostals";
    case sim::ElementGroup::Diaphragm:
      return "diaphragm";
    case sim::ElementGroup::Rectus:
      return "rectus";
    case sim::ElementGroup::TransversusObliques:
      return "transv./obliques";
    default:
      return viz::groupLabel(g);
  }
}

QColor colourOf(sim::ElementGroup g) {
  const auto c = viz::groupColour(g);
  return QColor::fromRgbF(c[0], c[1], c[2]).darker(115);
}

const std::array<QColor, 4> kTraceColours{QColor(20, 20, 20), QColor(200, 0, 160), QColor(0, 150, 150),
                                          QColor(120, 90, 0)};

}  // namespace

LivePlots::LivePlots(QWidget* parent) : QWidget(parent), m_cursor(kNaN) {
  auto* splitter = new QSplitter(Qt::Vertical, this);
  m_plots = {new PlotView("Lung volume", "volume [mL]"), new PlotView("Gut volume error", "error [%]"),
             new PlotView("Activations (r solid, \u03b1 dashed)", "r, \u03b1 [-]"),
             new PlotView("Muscle tension (mean per element)", "tension [N]")};
  m_plots[1]->setReferences({{"+0.5 %", 0.5, QColor(40, 160, 60)},
                             {"-0.5 %", -0.5, QColor(40, 160, 60)},
                             {"+2 %", 2.0, QColor(220, 120, 0)},
                             {"-2 %", -2.0, QColor(220, 120, 0)}});
  m_plots[3]->setIncludeZero(true);
  for (PlotView* plot : m_plots) splitter->addWidget(plot);

  // the physiology tab: flow, the flow-volume loop, pressures
  auto* physiology = new QSplitter(Qt::Vertical, this);
  m_plots.push_back(new PlotView("Flow", "flow [L/s]"));
  m_plots.push_back(new PlotView("Pressures", "pressure [cmH2O]"));
  m_plots[4]->setIncludeZero(true);
  m_plots[5]->setIncludeZero(true);
  m_loop = new FlowVolumeLoop(physiology);
  physiology->addWidget(m_plots[4]);
  physiology->addWidget(m_loop);
  physiology->addWidget(m_plots[5]);

  // one time axis: zooming or scrolling one plot moves them all
  for (PlotView* plot : m_plots)
    connect(plot, &PlotView::viewChanged, this, [this](double window, double end) {
      for (PlotView* p : m_plots) {
        p->setWindow(window);
        p->setViewEnd(end);
      }
    });

  m_tabs = new QTabWidget(this);
  m_tabs->addTab(splitter, "Mechanics");
  m_tabs->addTab(physiology, "Physiology");
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  layout->addWidget(m_tabs);
}

void LivePlots::setOverlay(RunOverlay overlay) {
  m_overlay = std::move(overlay);
  m_isDirty = true;
}

void LivePlots::showPhysiology(bool isShown) { m_tabs->setCurrentIndex(isShown ? 1 : 0); }

void LivePlots::clear() {
  m_segments.clear();
  m_forces.clear();
  m_hasLatest = false;
  m_isDirty = true;
}

void LivePlots::append(std::vector<PlotSample> samples) {
  for (const PlotSample& s : samples) appendSample(s);
  if (samples.empty()) return;
  m_latest = std::move(samples.back());
  m_latest.elementForce.clear();
  m_hasLatest = true;
  m_isDirty = true;
  // forget what lies beyond the history (the newest segment and force frame always stay)
  const double from = m_latest.time - kHistorySeconds;
  while (m_segments.size() > 1 && m_segments.front().columns[kTime].buckets().back().vMax < from)
    m_segments.pop_front();
  while (m_forces.size() > 1 && m_forces[1].time <= from) m_forces.pop_front();
}

void LivePlots::appendSample(const PlotSample& s) {
  if (m_segments.empty() ||
      s.time - m_segments.back().columns[kTime].buckets().front().tMin >= kSegmentSeconds) {
    const std::size_t columnCount = kFirstGroupColumn + kColumnsPerGroup * muscleGroups().size();
    m_segments.push_back({std::vector<viz::MinMaxSeries>(columnCount, viz::MinMaxSeries(kSegmentBuckets))});
  }
  std::vector<viz::MinMaxSeries>& c = m_segments.back().columns;
  c[kTime].append(s.time, s.time);  // a bucket's minimum is its first sample time, its maximum its last
  c[kLung].append(s.time, s.lungVolume);
  c[kTarget].append(s.time, s.targetVolume);
  c[kGut].append(s.time, s.gutVolumeError);
  c[kFlow].append(s.time, s.flow);
  c[kGutPressure].append(s.time, s.gutPressure);
  c[kPdi].append(s.time, s.transdiaphragmaticPressure);
  std::size_t k = kFirstGroupColumn;
  for (const sim::ElementGroup g : muscleGroups()) {
    const auto i = static_cast<std::size_t>(g);
    c[k++].append(s.time, s.activations[i].r);
    c[k++].append(s.time, s.activations[i].alpha);
    c[k++].append(s.time, s.groupMeanTension[i]);
  }
  // element forces for the picked traces, at most kForceRate frames per simulated second
  if (!s.elementForce.empty() &&
      (m_forces.empty() || s.time >= m_forces.back().time + (1.0 - 1e-6) / kForceRate))
    m_forces.push_back({s.time, s.elementForce});
}

void LivePlots::setWindow(double seconds) {
  m_window = seconds;
  for (PlotView* plot : m_plots) plot->setWindow(seconds);
}

void LivePlots::setBreathPeriod(double seconds) { m_breathPeriod = seconds; }

void LivePlots::setCursor(double time) {
  if (time == m_cursor || (std::isnan(time) && std::isnan(m_cursor))) return;
  m_cursor = time;
  for (PlotView* plot : m_plots) plot->setCursor(time);
  m_loop->setCursor(time);
  m_isDirty = true;
}

void LivePlots::setBreaths(std::vector<double> endExpirations) {
  if (endExpirations == m_breaths) return;
  m_breaths = std::move(endExpirations);
  m_isDirty = true;
}

double LivePlots::breathingRate() const {
  const std::size_t n = std::min<std::size_t>(m_breaths.size(), kLoops + 1);
  if (n < 2) return std::numeric_limits<double>::quiet_NaN();
  return 60.0 * static_cast<double>(n - 1) / (m_breaths.back() - m_breaths[m_breaths.size() - n]);
}

void LivePlots::addTrace(const Trace& trace) {
  if (m_traces.size() == kTraceColours.size()) m_traces.erase(m_traces.begin());
  m_traces.push_back(trace);
  m_isDirty = true;
}

void LivePlots::clearTraces() {
  m_traces.clear();
  m_isDirty = true;
}

double LivePlots::tidalVolume() const {
  if (!m_hasLatest) return 0.0;
  const double from = m_latest.time - m_breathPeriod;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (auto seg = m_segments.rbegin(); seg != m_segments.rend(); ++seg) {
    const auto& time = seg->columns[kTime].buckets();
    const auto& volume = seg->columns[kLung].buckets();
    for (std::size_t k = time.size(); k-- > 0 && time[k].vMax >= from;)
      lo = std::min(lo, volume[k].vMin), hi = std::max(hi, volume[k].vMax);
    if (time.front().vMin < from) break;
  }
  return hi >= lo ? hi - lo : 0.0;
}

void LivePlots::table(double from, std::vector<double>& time,
                      std::vector<std::vector<double>>& columns) const {
  // per bucket its first and last sample time, and each column's minimum and maximum in the order they
  // occurred (a bucket of one sample gives one row)
  time.clear();
  columns.assign(m_segments.empty() ? 0 : m_segments.front().columns.size(), {});
  for (const Segment& seg : m_segments) {
    const auto& tb = seg.columns[kTime].buckets();
    for (std::size_t k = 0; k < tb.size(); ++k) {
      if (tb[k].vMax < from) continue;
      const bool isPair = tb[k].vMax > tb[k].vMin;
      time.push_back(tb[k].vMin);
      if (isPair) time.push_back(tb[k].vMax);
      for (std::size_t c = kTime + 1; c < columns.size(); ++c) {
        const viz::MinMaxSeries::Bucket& b = seg.columns[c].buckets()[k];
        const bool minFirst = b.tMin <= b.tMax;
        columns[c].push_back(minFirst ? b.vMin : b.vMax);
        if (isPair) columns[c].push_back(minFirst ? b.vMax : b.vMin);
      }
    }
  }
}

void LivePlots::refreshLoops() {
  // the last kLoops complete breaths and the one in progress, each from its end-expiration on
  std::vector<FlowVolumeLoop::Loop> loops;
  const std::size_t first = m_breaths.size() > kLoops ? m_breaths.size() - kLoops - 1 : 0;
  if (m_breaths.empty() || !m_hasLatest) return m_loop->setLoops({});
  std::vector<double> time;
  std::vector<std::vector<double>> columns;
  table(m_breaths[first], time, columns);
  std::size_t k = 0;
  for (std::size_t b = first; b < m_breaths.size(); ++b) {
    const double end = b + 1 < m_breaths.size() ? m_breaths[b + 1] : std::numeric_limits<double>::infinity();
    while (k < time.size() && time[k] < m_breaths[b]) ++k;
    FlowVolumeLoop::Loop loop;
    loop.isComplete = b + 1 < m_breaths.size();
    const double v0 = k < time.size() ? columns[kLung][k] : 0.0;
    for (std::size_t j = k; j < time.size() && time[j] <= end; ++j) {
      loop.time.push_back(time[j]);
      loop.volume.push_back(1e6 * (columns[kLung][j] - v0));
      loop.flow.push_back(1e3 * columns[kFlow][j]);
    }
    if (!loop.time.empty()) loops.push_back(std::move(loop));
  }
  m_loop->setLoops(std::move(loops));
}

bool LivePlots::refresh() {
  if (!m_isDirty) return false;
  m_isDirty = false;

  // the whole history: the plots show their span of it and scroll over the rest
  const double from = -std::numeric_limits<double>::infinity();
  std::vector<double> time;
  std::vector<std::vector<double>> columns;
  table(from, time, columns);
  const std::size_t n = time.size();
  auto column = [&](std::size_t c, double scale) {
    std::vector<double> y = c < columns.size() ? columns[c] : std::vector<double>(n, kNaN);
    for (double& v : y) v *= scale;
    return y;
  };

  // the overlaid run's quantity `of` times `scale` at the plotted times, dashed (none without an overlay)
  const bool hasOverlay = !m_overlay.samples.empty();
  auto overlaid = [&](const QString& what, double PlotSample::*of, double scale) {
    std::vector<double> y(n, kNaN);
    const std::vector<PlotSample>& o = m_overlay.samples;
    for (std::size_t k = 0, j = 0; k < n && !o.empty(); ++k) {
      while (j + 1 < o.size() && o[j + 1].time <= time[k]) ++j;
      if (time[k] < o.front().time || time[k] > o.back().time) continue;
      const PlotSample& a = o[j];
      const PlotSample& b = o[std::min(j + 1, o.size() - 1)];
      const double w = b.time > a.time ? (time[k] - a.time) / (b.time - a.time) : 0.0;
      y[k] = scale * ((1.0 - w) * a.*of + w * b.*of);
    }
    return PlotView::Series{m_overlay.name + " " + what, kOverlayColour, true, std::move(y), m_overlay.name};
  };

  // lung volume [mL], with the target of the affect, pattern or trace that plays
  std::vector<PlotView::Series> volume{
      {"lung volume", QColor(20, 90, 190), false, column(kLung, 1e6), QString()}};
  std::vector<double> target = column(kTarget, 1e6);
  if (std::any_of(target.begin(), target.end(), [](double v) { return std::isfinite(v); })) {
    volume[0].legend = "simulated";
    volume.push_back({"target volume", QColor(230, 90, 20), true, std::move(target), "target"});
  }
  if (hasOverlay) {
    if (volume[0].legend.isEmpty()) volume[0].legend = "this run";
    volume.push_back(overlaid("lung volume", &PlotSample::lungVolume, 1e6));
  }
  m_plots[0]->setData(time, std::move(volume));
  // read-out: the two lungs, their split and the tidal volume; at a cursor, the lungs there; with a volume
  // target, its tracking RMS instead of the split (the line keeps its width)
  const bool atCursor = std::isfinite(m_cursor);
  const bool tracks = std::isfinite(m_latest.trackingRmsPercent);
  QString note;
  if (n > 0 && atCursor) {
    note =
        QString("at %1 s: lungs %2 mL").arg(m_cursor, 0, 'f', 2).arg(m_plots[0]->cursorValue(0), 0, 'f', 0);
  } else if (n > 0) {
    note = QString("lungs %1 mL").arg(1e6 * m_latest.lungVolume, 0, 'f', 0);
    if (std::isfinite(m_latest.rightLungVolume) && !tracks)
      note += QString(" (R %1 L %2)")
                  .arg(1e6 * m_latest.rightLungVolume, 0, 'f', 0)
                  .arg(1e6 * m_latest.leftLungVolume, 0, 'f', 0);
    note += QString("  VT %1 mL").arg(1e6 * tidalVolume(), 0, 'f', 0);
    if (tracks) note += QString("  tracking RMS %1 %").arg(m_latest.trackingRmsPercent, 0, 'f', 2);
  }
  m_plots[0]->setNote(note);

  // flow [L/s] with the tidal volume and rate; the abdominal and transdiaphragmatic pressures [cmH2O]
  std::vector<PlotView::Series> flow{{"flow", QColor(20, 90, 190), false, column(kFlow, 1e3), QString()}};
  if (hasOverlay) {
    flow[0].legend = "this run";
    flow.push_back(overlaid("flow", &PlotSample::flow, 1e3));
  }
  m_plots[4]->setData(time, std::move(flow));
  const double rate = breathingRate();
  QString flowNote = QString("VT %1 mL").arg(1e6 * tidalVolume(), 0, 'f', 0);
  if (std::isfinite(rate)) flowNote += QString("  %1 b/min").arg(rate, 0, 'f', 1);
  if (atCursor)
    flowNote +=
        QString("  at %1 s: %2 L/s").arg(m_cursor, 0, 'f', 2).arg(m_plots[4]->cursorValue(0), 0, 'f', 2);
  m_plots[4]->setNote(n > 0 ? flowNote : QString());
  std::vector<PlotView::Series> pressures{{"abdominal (gut) pressure", QColor(120, 40, 160), false,
                                           column(kGutPressure, 1.0 / kPascalPerCmH2O), "Pab (gut)"}};
  std::vector<double> pdi = column(kPdi, 1.0 / kPascalPerCmH2O);
  const bool hasPdi = std::any_of(pdi.begin(), pdi.end(), [](double v) { return std::isfinite(v); });
  if (hasPdi)
    pressures.push_back({"transdiaphragmatic pressure", QColor(200, 60, 20), false, std::move(pdi), "Pdi"});
  if (hasOverlay) {
    PlotView::Series pab =
        overlaid("abdominal (gut) pressure", &PlotSample::gutPressure, 1.0 / kPascalPerCmH2O);
    pab.legend = "Pab " + m_overlay.name;
    if (std::any_of(pab.y.begin(), pab.y.end(), [](double v) { return std::isfinite(v); }))
      pressures.push_back(std::move(pab));
  }
  m_plots[5]->setData(time, std::move(pressures));
  QString pressureNote;  // none while the plots are empty (after a reset), like the others
  if (n > 0) {
    const double pab = atCursor ? m_plots[5]->cursorValue(0) : m_latest.gutPressure / kPascalPerCmH2O;
    const double pdiNow = hasPdi ? (atCursor ? m_plots[5]->cursorValue(1)
                                             : m_latest.transdiaphragmaticPressure / kPascalPerCmH2O)
                                 : std::numeric_limits<double>::quiet_NaN();
    pressureNote = (atCursor ? QString("at %1 s: ").arg(m_cursor, 0, 'f', 2) : QString()) +
                   QString("Pab %1").arg(pab, 0, 'f', 1);
    if (hasPdi) pressureNote += QString("  Pdi %1").arg(pdiNow, 0, 'f', 1);
    pressureNote += " cmH2O";
  }
  m_plots[5]->setNote(pressureNote);
  refreshLoops();

  // gut volume error [%]
  m_plots[1]->setData(time,
                      {{"gut volume error", QColor(120, 40, 160), false, column(kGut, 100.0), QString()}});
  m_plots[1]->setNote(n > 0 ? QString("now %1 %").arg(100.0 * m_latest.gutVolumeError, 0, 'f', 3)
                            : QString());

  // activations r and alpha, and mean tension, of the muscle groups
  std::vector<PlotView::Series> act;
  std::vector<PlotView::Series> tension;
  std::size_t c = kFirstGroupColumn;
  for (const sim::ElementGroup group : muscleGroups()) {
    const QString name = viz::groupLabel(group);
    act.push_back({"r " + name, colourOf(group), false, column(c++, 1.0), shortLabel(group)});
    act.push_back({"\u03b1 " + name, colourOf(group), true, column(c++, 1.0), QString()});
    tension.push_back({name, colourOf(group), false, column(c++, 1.0), shortLabel(group)});
  }
  m_plots[2]->setData(time, std::move(act));

  // picked traces: summed tension of their elements [N], from the latest force frame at or before each time
  for (std::size_t i = 0; i < m_traces.size(); ++i) {
    const Trace& t = m_traces[i];
    std::vector<double> y(n, kNaN);
    auto frame = m_forces.begin();
    for (std::size_t k = 0; k < n; ++k) {
      while (frame != m_forces.end() && std::next(frame) != m_forces.end() &&
             std::next(frame)->time <= time[k])
        ++frame;
      if (frame == m_forces.end() || frame->time > time[k]) continue;
      double sum = 0.0;
      for (int e : t.elements)
        if (static_cast<std::size_t>(e) < frame->elementForce.size())
          sum += std::max(0.0, -static_cast<double>(frame->elementForce[static_cast<std::size_t>(e)]));
      y[k] = sum;
    }
    tension.push_back({t.name, kTraceColours[i], true, std::move(y), t.name});
  }
  m_plots[3]->setData(std::move(time), std::move(tension));
  return true;
}

}  // namespace pneuma::app
