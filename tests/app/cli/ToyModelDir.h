#pragma once
// A model directory holding the sim tests' toy torso (tests/sim/ToyTorso.h), written once per test
// binary, so the CLI tests run the whole pipeline in seconds without the meshing layer.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "../../sim/ToyTorso.h"
#include "pneuma/sim/ModelIO.h"

namespace pneuma::test {

inline const std::string& toyModelDir() {
  static const std::string dir = [] {
    const std::string d = testing::TempDir() + "pneuma_cli_toy_model_" + std::to_string(getpid());
    std::filesystem::create_directories(d);
    sim::saveModel(sim::test::makeToyTorso(), d);
    return d;
  }();
  return dir;
}

/// A fresh empty output directory for one test.
inline std::string freshOutDir(const std::string& name) {
  const std::string d = testing::TempDir() + "pneuma_cli_out_" + std::to_string(getpid()) + "_" + name;
  std::filesystem::remove_all(d);
  return d;
}

}  // namespace pneuma::test
