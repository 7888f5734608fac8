#pragma once
/// @file FuzzLoaders.h
/// The loaders that read user files, as the fuzzers (fuzz/Fuzzer.cpp, built with PNEUMA_BUILD_FUZZERS) and
/// the corpus replay test (tests/fuzz) call them: each takes the file's text and must either accept it or
/// reject it with a pneuma::sim::Error; any other exception, a crash, a hang or a sanitizer report is a bug.

#include <string>
#include <vector>

namespace pneuma::fuzz {

enum class Loader {
  Model,     ///< model.json: sim::parseModel() (with validateModel())
  Anatomy,   ///< an anatomy preset: meshing::parseAnatomy() with the shipped muscle_gains.json
  Gains,     ///< muscle_gains.json: meshing::parseAnatomy() with the shipped male.json
  Style,     ///< a breath-style preset: sim::parseBreathStyle()
  Scenario,  ///< a scenario file: sim::parseScenario(), then its controller when that needs no other file
  Pattern,   ///< a pattern file or affect preset: sim::pattern::parsePattern() and its layer stack
};

/// Every loader, in the order above.
const std::vector<Loader>& allLoaders();
/// "model", "anatomy", "gains", "style", "scenario", "pattern": the corpus folder names under fuzz/corpus/.
const char* loaderName(Loader loader);

/// The bytes of the file at `path` ("" when it cannot be read).
std::string readFile(const std::string& path);

/// Runs `loader` on `text`. Returns normally when the text is accepted or rejected with a sim::Error;
/// everything else escapes. `resourceDir` holds the shipped anatomy, presets and patterns.
void runLoader(Loader loader, const std::string& text, const std::string& resourceDir);

}  // namespace pneuma::fuzz
