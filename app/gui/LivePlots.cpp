#include "gui/LivePlots.h"

#include "gui/PlotView.h"
#include "viz/ModelScene.h"

#include <QSplitter>
#include <QVBoxLayout>

#include <algorithm>
#include <cmath>
#include <limits>

namespace pneuma::app {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kHistorySeconds = 120.0;  // [s] kept for the window and for picked traces

// short legend names of the muscle groups
QString shortLabel(sim::ElementGroup g) {
  switch (g) {
    case sim::ElementGroup::IntercostalExternal: return "ext. intercostals";
    case sim::ElementGroup::IntercostalInternal: return "int. intercostals";
    case sim::ElementGroup::Diaphragm: return "diaphragm";
    case sim::ElementGroup::Rectus: return "rectus";
    case sim::ElementGroup::TransversusObliques: return "transv./obliques";
    default: return viz::groupLabel(g);
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
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  layout->addWidget(splitter);
}

void LivePlots::clear() {
  m_history.clear();
  m_isDirty = true;
}

void LivePlots::append(std::vector<PlotSample> samples) {
  for (PlotSample& s : samples) m_history.push_back(std::move(s));
  while (!m_history.empty() && m_history.back().time - m_history.front().time > kHistorySeconds)
    m_history.pop_front();
  m_isDirty = m_isDirty || !samples.empty();
}

void LivePlots::setWindow(double seconds) {
  m_window = seconds;
  for (PlotView* plot : m_plots) plot->setWindow(seconds);
}

void LivePlots::setBreathPeriod(double seconds) { m_breathPeriod = seconds; }

void LivePlots::setCursor(double time) {
  m_cursor = time;
  for (PlotView* plot : m_plots) plot->setCursor(time);
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
  if (m_history.empty()) return 0.0;
  const double from = m_history.back().time - m_breathPeriod;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (auto it = m_history.rbegin(); it != m_history.rend() && it->time >= from; ++it)
    lo = std::min(lo, it->lungVolume), hi = std::max(hi, it->lungVolume);
  return hi - lo;
}

bool LivePlots::refresh() {
  if (!m_isDirty) return false;
  m_isDirty = false;

  // only the shown window is handed to the plots
  std::size_t first = 0;
  if (!m_history.empty()) {
    const double from = m_history.back().time - m_window;
    while (first < m_history.size() && m_history[first].time < from) ++first;
  }
  const std::size_t n = m_history.size() - first;
  std::vector<double> time(n);
  for (std::size_t k = 0; k < n; ++k) time[k] = m_history[first + k].time;
  auto column = [&](auto value) {
    std::vector<double> y(n);
    for (std::size_t k = 0; k < n; ++k) y[k] = value(m_history[first + k]);
    return y;
  };

  // lung volume [mL], with the affect pattern's target when one plays
  std::vector<PlotView::Series> volume{{"lung volume", QColor(20, 90, 190), false,
                                        column([](const PlotSample& s) { return 1e6 * s.lungVolume; }), QString()}};
  if (std::any_of(m_history.begin() + static_cast<std::ptrdiff_t>(first), m_history.end(),
                  [](const PlotSample& s) { return std::isfinite(s.targetVolume); })) {
    volume[0].legend = "simulated";
    volume.push_back({"target volume", QColor(230, 90, 20), true,
                      column([](const PlotSample& s) { return 1e6 * s.targetVolume; }), "target"});
  }
  m_plots[0]->setData(time, std::move(volume));
  // read-out: the two lungs, their split and the tidal volume
  QString note;
  if (n > 0) {
    const PlotSample& last = m_history.back();
    note = QString("lungs %1 mL").arg(1e6 * last.lungVolume, 0, 'f', 0);
    if (std::isfinite(last.rightLungVolume))
      note += QString(" (R %1 L %2)").arg(1e6 * last.rightLungVolume, 0, 'f', 0).arg(1e6 * last.leftLungVolume, 0, 'f', 0);
    note += QString("  VT %1 mL").arg(1e6 * tidalVolume(), 0, 'f', 0);
  }
  m_plots[0]->setNote(note);

  // gut volume error [%]
  m_plots[1]->setData(time, {{"gut volume error", QColor(120, 40, 160), false,
                              column([](const PlotSample& s) { return 100.0 * s.gutVolumeError; }), QString()}});
  if (n > 0) m_plots[1]->setNote(QString("now %1 %").arg(100.0 * m_history.back().gutVolumeError, 0, 'f', 3));

  // activations r and alpha of the muscle groups
  std::vector<PlotView::Series> act;
  std::vector<PlotView::Series> tension;
  for (int g = 0; g < sim::kElementGroupCount; ++g) {
    const auto group = static_cast<sim::ElementGroup>(g);
    if (!sim::isMuscleGroup(group)) continue;
    const QString name = viz::groupLabel(group);
    act.push_back({"r " + name, colourOf(group), false,
                   column([g](const PlotSample& s) { return s.activations[static_cast<std::size_t>(g)].r; }),
                   shortLabel(group)});
    act.push_back({"\u03b1 " + name, colourOf(group), true,
                   column([g](const PlotSample& s) { return s.activations[static_cast<std::size_t>(g)].alpha; }),
                   QString()});
    tension.push_back({name, colourOf(group), false,
                       column([g](const PlotSample& s) { return s.groupMeanTension[static_cast<std::size_t>(g)]; }),
                       shortLabel(group)});
  }
  m_plots[2]->setData(time, std::move(act));

  // picked traces: summed tension of their elements [N]
  for (std::size_t i = 0; i < m_traces.size(); ++i) {
    const Trace& t = m_traces[i];
    tension.push_back({t.name, kTraceColours[i], true, column([&t](const PlotSample& s) {
                         double sum = 0.0;
                         for (int e : t.elements)
                           if (static_cast<std::size_t>(e) < s.elementForce.size())
                             sum += std::max(0.0, -static_cast<double>(s.elementForce[static_cast<std::size_t>(e)]));
                         return sum;
                       }),
                       t.name});
  }
  m_plots[3]->setData(time, std::move(tension));
  return true;
}

}  // namespace pneuma::app
