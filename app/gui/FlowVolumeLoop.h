#pragma once
/// @file FlowVolumeLoop.h
/// The flow-volume loop of the last breaths, as a respiratory physiologist draws it: lung flow [L/s]
/// (inspiration up) against the lung volume above the breath's end-expiration [mL]. Each breath runs from one
/// end-expiration to the next (Snapshot::endExpirationTimes), so a steady breath closes its loop; the breath
/// in progress is drawn open. The newest complete breath is dark, older ones lighter, the one in progress
/// orange, and a dot marks the cursor's instant.

#include <QWidget>
#include <vector>

namespace pneuma::app {

class FlowVolumeLoop : public QWidget {
  Q_OBJECT

 public:
  /// One breath's loop: one point per plotted sample.
  struct Loop {
    std::vector<double> time;    ///< [s]
    std::vector<double> volume;  ///< [mL] lung volume above the breath's first sample (its end-expiration)
    std::vector<double> flow;    ///< [L/s] inspiration > 0
    bool isComplete = false;     ///< ends at the next end-expiration
  };

  explicit FlowVolumeLoop(QWidget* parent = nullptr);

  /// Replaces the loops, oldest first.
  void setLoops(std::vector<Loop> loops);
  /// Marks the instant `time` [s] on its loop (NaN: none).
  void setCursor(double time);
  const std::vector<Loop>& loops() const { return m_loops; }

 protected:
  void paintEvent(class QPaintEvent* event) override;

 private:
  std::vector<Loop> m_loops;
  double m_cursor;  // [s]
};

}  // namespace pneuma::app
