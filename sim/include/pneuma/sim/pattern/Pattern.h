#pragma once
/// @file Pattern.h
/// Pattern files: a versioned JSON description of a layer stack plus an optional timeline of scheduled
/// pushes (format: docs/patterns.md). Affect presets (resources/presets/affect/NAME.json) are pattern files.

#include <cstdint>
#include <string>
#include <vector>

#include "pneuma/sim/pattern/LayerStack.h"

namespace pneuma::sim::pattern {

/// Current pattern-file format version.
constexpr int kPatternFormatVersion = 1;

/// A scheduled push: at `time`, `layers` go on the stack in `mode`.
struct TimelineEvent {
  double time = 0.0;  ///< [s] simulation time, >= 0
  SwitchMode mode = SwitchMode::Immediate;
  std::string label;          ///< e.g. the affect name, for display
  std::vector<Layer> layers;  ///< play order (first plays first)
};

/// A parsed pattern file.
struct Pattern {
  std::string name;
  std::string description;
  std::vector<Layer> layers;            ///< initial stack in play order (first plays first)
  std::vector<TimelineEvent> timeline;  ///< sorted by time
};

/// Parses the text of a pattern file. `"affect": NAME` references (instead of `"layers"`) are resolved
/// against `resourceDir`/presets/affect/NAME.json.
/// @throws Error "<sourceName>: <json path>: <reason>", e.g.
///         "startle.json: layers[0].cycle.kind: unknown cycle kind 'cubic' (valid: linear, keyframe,
///         spline)".
Pattern parsePattern(const std::string& jsonText, const std::string& sourceName,
                     const std::string& resourceDir);

/// Reads and parses a pattern file. @throws Error as parsePattern(), or when the file cannot be read.
Pattern loadPatternFile(const std::string& path, const std::string& resourceDir);

/// Names of the affect presets in `resourceDir`/presets/affect (file stems, sorted).
std::vector<std::string> listAffects(const std::string& resourceDir);

/// Loads the affect preset NAME. @throws Error "unknown affect 'NAME' (valid: ...)" listing listAffects().
Pattern loadAffect(const std::string& name, const std::string& resourceDir);

/// A layer stack playing `pattern`: its layers pushed at t = 0 and its timeline scheduled.
LayerStack makeLayerStack(const Pattern& pattern, std::uint64_t seed);

}  // namespace pneuma::sim::pattern
