#pragma once
// The 3 x 3 sweep of the sweep tests (local and on Slurm): two muscle gains of the calm breath on the toy
// torso.
#include <filesystem>
#include <fstream>
#include <string>

#include "CliRunner.h"
#include "ToyModelDir.h"

namespace pneuma::test {

/// A calm breath on the toy torso, short and without plots (the tests are about the table).
inline const char* kSweepBaseScenario = R"({
  "format": "pneuma-scenario", "version": 1, "name": "calm-toy",
  "duration_s": 10, "controller": {"style": "calm"},
  "overrides": {"dt_s": 0.004, "settle_time_s": 0.5},
  "outputs": {"output_rate_hz": 30, "csv": false, "plots": false}
})";

/// Writes a sweep file `name` into a fresh folder; `body` is the part after the scenario.
inline std::string writeSweepFile(const std::string& name, const std::string& body) {
  const std::string dir = freshOutDir("sweepfile_" + name);
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/" + name + ".json";
  std::ofstream(path) << R"({"format": "pneuma-sweep", "version": 1, "name": ")" << name
                      << R"(", "scenario": )" << kSweepBaseScenario << ", " << body << "}";
  return path;
}

/// The 3 x 3 grid over the diaphragm's and the external intercostals' active gains.
inline std::string gainGridSweep() {
  return writeSweepFile("gains", R"("design": "grid", "parameters": {
      "active_gain_scale.diaphragm": [0.5, 1, 1.5],
      "active_gain_scale.intercostal_external": {"from": 0.5, "to": 1.5, "steps": 3}},
    "outputs": ["tidal_volume_ml", "rib_cage_fraction"])");
}

}  // namespace pneuma::test
