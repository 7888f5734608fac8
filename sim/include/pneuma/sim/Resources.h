#pragma once
/// @file Resources.h
/// Where Pneuma finds its data: the resource folder (anatomy tables and gains, breath-style and affect
/// presets, patterns, scenarios) and the default model. Every program and library asks here; nothing
/// else compiles in or re-derives a path to them.
///
/// The folder sits beside the executable's directory, at <bindir>/../share/pneuma, in both layouts:
///  - installed: PREFIX/bin/pneuma-cli finds PREFIX/share/pneuma (the default model in models/default);
///  - build tree: build/bin/pneuma-cli finds build/share/pneuma, whose entries link to the source tree's
///    resources/ (so edits there are seen without a rebuild) and whose models/default the build writes.
/// The location follows the running executable (/proc/self/exe), so an installed tree can be moved. Code
/// loaded as a shared object (the Python module, build/python/pneuma*.so) counts from the object's own folder
/// instead.

#include <string>

namespace pneuma::sim {

/// The resource folder: $PNEUMA_RESOURCE_DIR when set and not empty, else installDataDir().
std::string resourceDir();

/// The default model directory: $PNEUMA_MODEL_DIR when set and not empty, else
/// installDataDir()/models/default.
std::string defaultModelDir();

/// <directory of the running executable, or of the shared object holding pneuma::sim>/../share/pneuma,
/// normalised (the current directory stands in for the executable's when /proc/self/exe cannot be read). The
/// one place that knows the data folder's position.
std::string installDataDir();

}  // namespace pneuma::sim
