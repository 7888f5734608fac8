#pragma once
/// @file Cycle.h
/// One respiration cycle: a curve mapping time within a breath to the volume fraction v in [0, 1]
/// (de Melo et al. 2010, "Model": 0 = minimum lung volume, 1 = total lung capacity).
///
/// A cycle is a normalised shape s(u), u in [0, 1] the fraction of the moving (non-paused) part of the
/// breath and s in [0, 1], mapped into the depth range: v = depthMin + s * (depthMax - depthMin).
/// The shape is given by keyframes (u_i, s_i); `linear` and `keyframe` interpolate them piecewise
/// linearly, `spline` with a periodic monotone cubic (Fritsch & Carlson 1980), which never leaves the
/// range of its neighbouring keyframes and therefore never overshoots [0, 1].
/// Beyond the paper: the inspiration:expiration ratio, post-inspiratory and post-expiratory pauses and
/// a per-breath random variation of the breath duration and depth (irregularity).

#include <optional>
#include <vector>

namespace pneuma::sim::pattern {

/// How the shape between keyframes is interpolated.
enum class CycleKind {
  Linear,    ///< triangle wave from the I:E ratio: rest -> peak -> rest, straight segments
  Keyframe,  ///< arbitrary (time, volume) pairs, straight segments
  Spline     ///< monotone cubic through the keyframes (or through the I:E triangle when none are given)
};

/// Stable lower-case name ("linear", "keyframe", "spline") used in pattern files.
const char* cycleKindName(CycleKind k);

/// A (time, volume) pair of a cycle's shape.
struct Keyframe {
  double time;    ///< relative cycles: [-] fraction of the moving part in [0, 1]; absolute cycles: [s] from 0
  double volume;  ///< [-] shape value in [0, 1], mapped into the depth range
};

/// Parameters of a cycle, as written in a pattern file (docs/patterns.md).
struct CycleSpec {
  CycleKind kind = CycleKind::Linear;
  bool isRelative = true;      ///< relative: time-warped to `rate`; absolute: keyframe times in [s]
  double rate = 15.0;          ///< [breaths/min] relative cycles only; in kBreathRateRange (Limits.h)
  double depthMin = 0.05;      ///< [-] volume fraction at shape 0, in [0, 1]
  double depthMax = 0.25;      ///< [-] volume fraction at shape 1, in [depthMin, 1]
  double ieRatio = 1.0 / 1.5;  ///< [-] inspiration:expiration duration ratio, > 0; generated shapes only
  double postInspiratoryPause = 0.0;  ///< [s] hold at the peak before expiration, >= 0
  double postExpiratoryPause = 0.0;   ///< [s] hold at the end of expiration, >= 0
  double rateIrregularity =
      0.0;  ///< [-] half-width of the uniform relative variation of the moving duration, [0, 0.5]
  double depthIrregularity =
      0.0;  ///< [-] half-width of the uniform relative variation of depthMax - depthMin, [0, 0.5]
  double balance =
      0.5;  ///< [-] thoraco-abdominal balance: 0 all abdomen (diaphragm), 1 all chest (intercostals)
  std::optional<double>
      inspiratoryBalance;  ///< [-] balance from the breath's start to its peak, in [0, 1]; unset: `balance`
  std::vector<Keyframe>
      keyframes;  ///< explicit shape; required for `keyframe`, optional for `spline`, none for `linear`
};

/// Checks a spec. @throws Error naming the field, e.g. "depth: min 0.4 > max 0.2" or "keyframes[2].time:
/// ...".
void validateCycle(const CycleSpec& spec);

/// The random draw for one breath: both factors are 1 for a regular breath.
struct BreathVariation {
  double durationScale = 1.0;  ///< [-] multiplies the moving part of the breath (pauses keep their length)
  double depthScale = 1.0;     ///< [-] multiplies depthMax - depthMin (the result is clamped to 1)
};

/// A validated cycle with its shape precomputed; immutable and cheap to evaluate.
class Cycle {
 public:
  /// @throws Error as validateCycle().
  explicit Cycle(const CycleSpec& spec);

  const CycleSpec& spec() const { return m_spec; }

  /// [s] duration of one breath: pauses + moving part * variation.durationScale.
  double duration(const BreathVariation& variation = {}) const;

  /// Volume fraction v in [0, 1] at time tau [s] after the start of a breath, tau clamped to [0, duration].
  double volume(double tau, const BreathVariation& variation = {}) const;

  /// [-] thoraco-abdominal balance at time tau [s] after the start of a breath: `inspiratoryBalance` before
  /// the shape's peak (when set), `balance` from the peak on.
  double balance(double tau, const BreathVariation& variation = {}) const;

  /// Normalised shape s(u) in [0, 1] of the moving part, u in [0, 1] (pauses excluded).
  double shape(double u) const;

 private:
  // [s] time of the shape's peak after the start of a breath (pauses excluded before it)
  double peakTime(const BreathVariation& variation) const;

  CycleSpec m_spec;
  std::vector<double> m_u;      // [-] keyframe times normalised to [0, 1]
  std::vector<double> m_s;      // [-] keyframe shape values
  std::vector<double> m_slope;  // [-] ds/du at each keyframe (spline only)
  int m_peak = 0;               // index of the first keyframe with the largest shape value
  double m_moving = 0.0;        // [s] nominal duration of the moving part
};

}  // namespace pneuma::sim::pattern
