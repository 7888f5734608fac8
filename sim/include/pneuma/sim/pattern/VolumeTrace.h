#pragma once
/// @file VolumeTrace.h
/// A measured lung-volume curve (a spirometer or a calibrated respiratory belt) made ready for the pattern
/// controller to follow (PatternController's trace constructor; docs/patterns.md, "Following a measured
/// trace").
///
/// File: CSV text; the first non-comment line is the header, which names a time column `time [s]` and a
/// volume column `volume [L]` or `volume [mL]` (`lung_volume` is accepted for `volume`, so a run's own
/// timeseries.csv plays back as it is); other columns are ignored, `#` starts a comment line.
///
/// Preparation, in this order:
///  1. resampling to the drive's step h = kDriveTimeStep (100 Hz): sample k (time k h after the first row) is
///     the mean of the rows' piecewise-linear curve over [k h - h/2, k h + h/2] (a box anti-alias filter for
///     a denser recording; for a sparser one, nearly linear interpolation: a 10 ms box keeps 99.98 % of 1
///     Hz);
///  2. a zero-phase low-pass: a second-order Butterworth (bilinear transform, cut-off kTraceCutoff) run
///     forwards then backwards, so the filtered curve has no lag; |H(f)|^2 = 1 / (1 + (f / f_c)^4). The ends:
///     the trace is padded by 2 / f_c at each end with its odd reflection about the edge value (2 e - V(-t)),
///     e being the edge value of a least-squares parabola over the first (last) 1 / f_c, so the padding
///     continues the edge's value and slope and the filter's start-up transient dies in it (scipy's 'odd'
///     padding with a noise-averaged pivot). On a clean sine the filtered ends stay within 0.1 % of the
///     peak-to-peak at 0.25 Hz and 1.5 % at 1 Hz (VolumeTrace_test);
///  3. offset: volumes are stored relative to the filtered curve's minimum, which the controller places at
///     the model's resting (end-expiratory) volume.

#include <string>
#include <vector>

namespace pneuma::sim::pattern {

/// [Hz] cut-off of the trace's zero-phase low-pass. Tidal breathing lies below 1 Hz (60 b/m) and its shape
/// in its first few harmonics; the drive's slowest lever lags 0.2 s (a 0.8 Hz corner), so the model cannot
/// follow much above a few Hz either. At 4 Hz the forward-backward filter keeps 99.6 % of a 1 Hz component
/// and 94 % of 2 Hz, and leaves 2.5 % of 10 Hz sensor noise and under 0.1 % of 25 Hz.
inline constexpr double kTraceCutoff = 4.0;

/// [m^3] largest peak-to-peak swing a trace may have: the vital capacity of a large adult is about 5 L.
inline constexpr double kMaxTraceSwing = 5e-3;

/// A trace ready to follow: uniform samples relative to the trace's minimum.
struct VolumeTrace {
  std::string name;            ///< for display, e.g. the file name
  double timeStep = 0.01;      ///< [s] h, the sample spacing
  std::vector<double> volume;  ///< [m^3] V(k h) - min V, k = 0 .. n-1; time 0 is the first row's time
  /// [m^3] volume above the minimum at time t [s], linear between samples, held beyond both ends.
  double sample(double t) const;
  /// [s] time of the last sample.
  double duration() const;
};

/// Parses and prepares a trace from CSV text (see the file comment).
/// @param sourceName  prefix of error messages (the file path)
/// @param timeStep    [s] resampling step h, > 0
/// @param cutoff      [Hz] low-pass cut-off, in (0, 1 / (2 h))
/// @throws Error "<sourceName>:<line>: column <c> '<header>': <reason>" for a missing or unknown unit, a
///         value that is not a finite number, a time that does not increase, a negative volume or a swing
///         beyond kMaxTraceSwing; "<sourceName>: ..." for a missing column or fewer than two rows.
VolumeTrace parseVolumeTrace(const std::string& text, const std::string& sourceName, double timeStep,
                             double cutoff = kTraceCutoff);

/// Reads a trace file (readInputFile()) and prepares it at the drive's step kDriveTimeStep.
/// @throws Error as readInputFile() and parseVolumeTrace().
VolumeTrace loadVolumeTrace(const std::string& path);

}  // namespace pneuma::sim::pattern
