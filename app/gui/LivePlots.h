#pragma once
/// @file LivePlots.h
/// The four live plots of the main window over a rolling time window, fed with the worker's samples:
///  1. lung-cavity volume [mL] with the current tidal volume, and the target volume with the tracking RMS
///  when
///     an affect, a pattern or a measured trace drives the run;
///  2. gut volume error [%] with the 0.5 % and 2 % bands;
///  3. activations r (solid) and alpha (dashed) per muscle group [-];
///  4. mean tension per element of each muscle group [N], plus the force trace of each picked element or
///  body;
/// and, on the Physiology tab,
///  5. lung flow [L/s] with the tidal volume and the breathing rate;
///  6. the abdominal (gut) and transdiaphragmatic pressures [cmH2O];
///  and the flow-volume loop of the last breaths (FlowVolumeLoop).
/// A second run (RunOverlay) may be drawn dashed over plots 1, 5 and 6.
/// When a cursor is set (a scrubbed instant) the notes read the values at the cursor, not the newest ones.
/// Memory is bounded whatever the output rate and run length: the last kHistorySeconds are kept in segments
/// whose quantities are thinned by viz::MinMaxSeries (every peak and trough kept; exact up to kSegmentBuckets
/// samples per segment, i.e. up to about 85 Hz), and the element forces behind the picked traces at most
/// kForceRate times per simulated second.

#include <QWidget>
#include <deque>
#include <vector>

#include "gui/RunOverlay.h"
#include "gui/SimWorker.h"
#include "viz/MinMaxSeries.h"

class QTabWidget;

namespace pneuma::app {

class FlowVolumeLoop;
class PlotView;

class LivePlots : public QWidget {
  Q_OBJECT

 public:
  /// A picked element (its force) or body (tension of the elements attached to it).
  struct Trace {
    QString name;
    std::vector<int> elements;  ///< elements whose tension max(0, -F) is summed [N]
  };

  explicit LivePlots(QWidget* parent = nullptr);

  /// Forgets all samples (reset, new model).
  void clear();
  /// Appends output frames (oldest first).
  void append(std::vector<PlotSample> samples);
  /// Redraws every plot from the history when new samples arrived (call at the display rate).
  /// @return true when the plots were redrawn
  bool refresh();
  /// Time span shown [s].
  void setWindow(double seconds);
  /// Breath period [s] over which the tidal volume is measured.
  void setBreathPeriod(double seconds);
  /// Plot cursor at time [s] (NaN hides it), e.g. the scrubbed instant.
  void setCursor(double time);
  /// [s] the end-expirations that bound the breaths (Snapshot::endExpirationTimes), oldest first.
  void setBreaths(std::vector<double> endExpirations);
  /// Adds a force trace to the tension plot (at most 4 are kept; the oldest goes first).
  void addTrace(const Trace& trace);
  void clearTraces();

  /// Draws a second run over the volume, flow and pressure plots (runs side by side): dashed grey, named
  /// after it in the legends, at the plots' own sample times (linear between its frames, a gap outside
  /// them). An overlay with no samples removes it.
  void setOverlay(RunOverlay overlay);
  const RunOverlay& overlay() const { return m_overlay; }

  /// Brings the Physiology tab (flow, loop, pressures) or the Mechanics tab to the front.
  void showPhysiology(bool isShown);

  /// The plots, in the order listed above.
  const std::vector<PlotView*>& plots() const { return m_plots; }
  PlotView* volumePlot() const { return m_plots[0]; }
  PlotView* flowPlot() const { return m_plots[4]; }
  PlotView* pressurePlot() const { return m_plots[5]; }
  FlowVolumeLoop* loop() const { return m_loop; }
  /// [1/min] breathing rate over the last complete breaths (60 / mean breath duration); NaN before two
  /// end-expirations.
  double breathingRate() const;
  /// [m^3] current tidal volume: max - min of the lung volume over the last breath period.
  double tidalVolume() const;

 private:
  /// A stretch of the history: column 0 is the time itself (so each bucket's first and last sample time), the
  /// others the plotted quantities in the order of appendColumns(). All columns receive the same samples, so
  /// their buckets line up.
  struct Segment {
    std::vector<viz::MinMaxSeries> columns;
  };
  /// The element forces of one sample, for the picked traces.
  struct ForceFrame {
    double time;                      // [s]
    std::vector<float> elementForce;  // [N] signed, per element
  };
  void appendSample(const PlotSample& s);
  /// The history from time `from` [s] on as a table: sample times and, per segment column, the plotted
  /// values.
  void table(double from, std::vector<double>& time, std::vector<std::vector<double>>& columns) const;
  /// Cuts the history into breaths at the end-expirations and hands the latest to the flow-volume loop.
  void refreshLoops();

  std::deque<Segment> m_segments;
  std::deque<ForceFrame> m_forces;
  PlotSample m_latest;  // the newest sample (for the notes)
  bool m_hasLatest = false;
  std::vector<PlotView*> m_plots;
  FlowVolumeLoop* m_loop = nullptr;
  QTabWidget* m_tabs = nullptr;
  std::vector<double> m_breaths;  // [s] end-expirations
  std::vector<Trace> m_traces;
  RunOverlay m_overlay;
  double m_window = 20.0;       // [s]
  double m_breathPeriod = 4.0;  // [s]
  double m_cursor;              // [s]
  bool m_isDirty = true;
};

}  // namespace pneuma::app
