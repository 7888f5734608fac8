#pragma once
// The default model of the build (PNEUMA_DEFAULT_MODEL_DIR, or the same environment variable), loaded once
// per test process; null when it has not been built (tests then skip).
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include "pneuma/sim/ModelIO.h"

namespace pneuma::sim::test {

inline std::shared_ptr<const Model> defaultModel() {
  static const std::shared_ptr<const Model> model = []() -> std::shared_ptr<const Model> {
    const char* env = std::getenv("PNEUMA_DEFAULT_MODEL_DIR");
    const std::string dir = env != nullptr ? env : PNEUMA_DEFAULT_MODEL_DIR;
    if (!std::filesystem::exists(dir + "/model.json")) return nullptr;
    return std::make_shared<const Model>(loadModel(dir));
  }();
  return model;
}

}  // namespace pneuma::sim::test

#define REQUIRE_DEFAULT_MODEL()             \
  if (!::pneuma::sim::test::defaultModel()) \
  GTEST_SKIP() << "default model not built (PNEUMA_DEFAULT_MODEL_DIR)"
