#pragma once
/// @file Limits.h
/// The bounds of every time step, duration and rate a run accepts, each stated once. The CLI, the scenario
/// and pattern loaders, the app's parameter panel and its worker all check through these, so that one input
/// gets one answer and one message ("--dt: must be in [1e-06, 0.05] s, got 1e-300"). The bounds keep every
/// accepted run finite: nothing loops for ever or takes longer than kMaxStepsPerRun steps. docs/cli.md
/// ("Limits") lists them.

#include <string>

namespace pneuma::sim {

/// A closed range [lo, hi] of a quantity in SI (or the named) units.
struct Range {
  double lo;         ///< smallest accepted value
  double hi;         ///< largest accepted value
  const char* unit;  ///< unit in messages ("s", "Hz", "breaths/min")

  /// Whether `v` is finite and in [lo, hi].
  bool contains(double v) const;
  /// "" when contains(v), else "must be in [lo, hi] unit, got v".
  std::string problem(double v) const;
  /// @throws Error "<field>: must be in [lo, hi] unit, got v" unless contains(v).
  void check(const std::string& field, double v) const;
};

/// [s] time step of the integrators: below 1 us a run of seconds takes millions of steps; above 50 ms the
/// implicit integrator's linearisation no longer holds the gut.
inline constexpr Range kTimeStepRange{1e-6, 0.05, "s"};
/// [s] settling phase before the controller starts (the default model settles in about 2 s).
inline constexpr Range kSettleTimeRange{0.0, 600.0, "s"};
/// [s] simulated duration of one run after the settling phase: up to a day.
inline constexpr Range kDurationRange{1e-3, 86400.0, "s"};
/// [Hz] output (metrics, CSV, plot and frame) rate.
inline constexpr Range kOutputRateRange{0.01, 10000.0, "Hz"};
/// [breaths/min] breathing rate of a breath style or a relative pattern cycle; 200 /min is a 0.3 s breath.
inline constexpr Range kBreathRateRange{0.5, 200.0, "breaths/min"};
/// [s] length of one breath of any cycle, pauses included (60 / kBreathRateRange, and absolute keyframes).
inline constexpr Range kBreathPeriodRange{0.3, 120.0, "s"};
/// [s] shortest time between two keyframes of a cycle.
inline constexpr double kMinKeyframeGap = 1e-3;
/// [-] most steps one run (settling + duration) may take: about 3 h of computing at 10 us a step.
inline constexpr double kMaxStepsPerRun = 1e9;

/// @throws Error "<field>: <seconds> s at dt <dt> s needs more than the 1e+09 steps a run may take" when
///         seconds / dt exceeds kMaxStepsPerRun (seconds [s] simulated, dt [s] > 0).
void checkStepCount(const std::string& field, double seconds, double dt);

}  // namespace pneuma::sim
