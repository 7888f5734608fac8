#pragma once
/// @file LayerStack.h
/// The stack of respiration layers (de Melo et al. 2010, "Model"): each layer is a cycle and a repetition
/// count (possibly infinite); the top layer plays, and pops when its repetitions are done, after which the
/// layer below starts a fresh cycle. Layers can be pushed to take effect at the end of the current cycle
/// or immediately, now or at a scheduled time (timelines).
///
/// Continuity: whenever the volume at a switch differs from the start of the new cycle (an immediate
/// push, or a cycle whose rest level differs), the output cross-fades from the volume held at the switch
/// into the new cycle, v = w(t) v_switch + (1 - w(t)) v_new(t), with w a smoothstep falling from 1 to 0
/// over blendDuration() — a convex combination, so v stays continuous and inside [0, 1].
///
/// Irregularity draws one BreathVariation per breath from a SplitMix64 stream seeded explicitly; the same
/// seed and the same pushes give bit-identical volumes.

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "pneuma/sim/pattern/Cycle.h"
#include "pneuma/sim/pattern/SplitMix64.h"

namespace pneuma::sim {
class CheckpointWriter;
class CheckpointReader;
}  // namespace pneuma::sim

namespace pneuma::sim::pattern {

/// Repetition count of a layer that never pops.
constexpr int kInfinite = -1;

/// One respiration layer.
struct Layer {
  std::string name;  ///< for display and CSV/plots, e.g. "sigh"
  CycleSpec cycle;
  int repetitions = kInfinite;  ///< number of breaths before the layer pops, >= 1, or kInfinite
};

/// When a push takes effect.
enum class SwitchMode {
  EndOfCycle,  ///< when the currently playing breath ends (at once if nothing plays)
  Immediate    ///< at once, cross-fading from the current volume
};

/// Stable names "end_of_cycle" and "immediate" used in pattern files and by the CLI/app.
const char* switchModeName(SwitchMode m);
/// Inverse of switchModeName(); returns false when the name is unknown.
bool switchModeFromName(const std::string& name, SwitchMode& out);

/// Plays a stack of layers as a function of time.
class LayerStack {
 public:
  /// @param seed  seed of the irregularity stream
  explicit LayerStack(std::uint64_t seed = 0);

  /// Pushes `playOrder` (first entry plays first, i.e. ends on top) to take effect at time `atTime` [s]
  /// (default: the time of the last sample) in the given mode. Pushes due at the same time apply in call
  /// order.
  /// @throws Error when a layer is invalid (the message names "layers[i].<field>") or a repetition count is
  /// < 1.
  void push(const std::vector<Layer>& playOrder, SwitchMode mode,
            double atTime = -std::numeric_limits<double>::infinity());

  /// Advances to time t [s] (t >= 0 and not decreasing; the stack starts at t = 0) and returns the volume
  /// fraction v(t) in [0, 1]. The very first breath starts at its own rest volume; before it the volume
  /// is 0, and after the last layer popped the volume holds. @throws Error when t decreases or is not finite.
  double sample(double t);

  /// Sets the volume fraction v in [0, 1] the stack holds before its first breath, which then cross-fades
  /// from it (a pattern taking over a breathing torso). Call before the first sample().
  void setStartVolume(double v);

  /// Volume fraction of the last sample.
  double volume() const { return m_volume; }
  /// [-] thoraco-abdominal balance of the playing layer (0.5 when nothing plays).
  double balance() const;
  /// Name of the playing layer, or "" when nothing plays.
  std::string currentLayerName() const;
  /// Number of layers on the stack, the playing one included.
  int depth() const { return static_cast<int>(m_layers.size()); }
  /// [s] time of the last sample.
  double time() const { return m_time; }

  /// [s] cross-fade duration used when switching into `cycle`: min(0.4 s, a quarter of its nominal breath).
  static double blendDuration(const Cycle& cycle);

  /// Writes the whole stack (layers, pending pushes, random stream, clock, blend) under keys starting with
  /// `prefix`, for an exact restart; loadState() reads it back into any LayerStack.
  void saveState(CheckpointWriter& out, const std::string& prefix) const;
  /// @throws Error when the data is not a stack's (Checkpoint.h) or a stored cycle is invalid.
  void loadState(CheckpointReader& in, const std::string& prefix);

 private:
  struct Active {
    std::string name;
    Cycle cycle;
    int repetitions;  // kInfinite or >= 1
    int done = 0;     // breaths completed
  };
  struct Pending {
    double time;  // [s] when the push becomes due (-inf: at the next sample)
    SwitchMode mode;
    std::vector<Active> layers;  // play order, validated
  };

  double evaluate(double t) const;                  // volume at t with the current state, no transitions
  void startBreath(double t, double fromVolume);    // start a new breath of the top layer at t
  void pushNow(const std::vector<Active>& layers);  // place layers on top (first entry on top)
  void endBreath(double t);                         // completes the top breath at t: next breath, push or pop

  SplitMix64 m_random;
  std::vector<Active> m_layers;       // bottom first, top last
  std::vector<Pending> m_scheduled;   // due in the future, sorted by time (stable)
  std::vector<Pending> m_atCycleEnd;  // due, waiting for the end of the current breath
  double m_time = 0.0;                // [s] last sample
  double m_volume = 0.0;              // [-] volume at m_time
  double m_hold = 0.0;                // [-] volume held while nothing plays
  bool m_hasVolume = false;           // false until a breath started or setStartVolume(): the first breath
                                      // then starts without cross-fade
  // the playing breath
  double m_breathStart = 0.0;  // [s]
  BreathVariation m_variation;
  // cross-fade from a held volume
  double m_blendFrom = 0.0;      // [-] volume held at the switch
  double m_blendStart = 0.0;     // [s]
  double m_blendDuration = 0.0;  // [s] 0 when not blending
};

}  // namespace pneuma::sim::pattern
