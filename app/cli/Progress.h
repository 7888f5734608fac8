#pragma once
/// @file Progress.h
/// Terminal progress bar (simulated time, real-time factor, ETA) and clean Ctrl-C handling for long runs.

#include <atomic>
#include <chrono>
#include <string>

namespace pneuma::app {

/// Installs a SIGINT handler that only raises a flag for the lifetime of the object. The simulation looks at
/// the flag before every step (sim::Simulation::setStopFlag(), also during the drive calibration), so the
/// first Ctrl-C stops a run within a step and the run still writes its outputs. A second Ctrl-C ends the
/// process at once, by SIGINT, without writing anything more (docs/cli.md).
class InterruptGuard {
 public:
  InterruptGuard();
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;
  /// True once SIGINT arrived.
  static bool isInterrupted();
  /// The flag the handler raises (lock-free, for sim::Simulation::setStopFlag()).
  static const std::atomic<bool>* flag();
};

/// One-line progress bar on stderr, redrawn at most 10 times per second; silent when stderr is not a TTY.
class ProgressBar {
 public:
  /// @param label     shown before the bar, e.g. "calm"
  /// @param totalTime [s] simulated time of the whole run
  ProgressBar(std::string label, double totalTime);
  /// Reports simulated time `t` [s] reached; redraws when due.
  void update(double t);
  /// Clears the line (call before printing anything else).
  void finish();

 private:
  void draw(double t);
  std::string m_label;
  double m_total;  // [s]
  bool m_isTty;
  std::chrono::steady_clock::time_point m_start;
  std::chrono::steady_clock::time_point m_lastDraw;
  bool m_hasDrawn = false;
};

}  // namespace pneuma::app
