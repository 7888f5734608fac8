#include "pneuma/sim/Resources.h"

#include <cstdlib>
#include <filesystem>

namespace pneuma::sim {

namespace fs = std::filesystem;

namespace {

/// The value of environment variable `name`, or "" when it is unset.
std::string environment(const char* name) {
  const char* value = std::getenv(name);
  return value != nullptr ? value : "";
}

}  // namespace

std::string installDataDir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  const fs::path bin = ec ? fs::current_path(ec) : exe.parent_path();
  // PNEUMA_DATA_FROM_BIN: the data folder relative to the binaries' folder, from the install layout
  // (CMakeLists.txt: "../share/pneuma")
  return (bin / PNEUMA_DATA_FROM_BIN).lexically_normal().string();
}

std::string resourceDir() {
  const std::string env = environment("PNEUMA_RESOURCE_DIR");
  return env.empty() ? installDataDir() : env;
}

std::string defaultModelDir() {
  const std::string env = environment("PNEUMA_MODEL_DIR");
  return env.empty() ? (fs::path(installDataDir()) / "models" / "default").string() : env;
}

}  // namespace pneuma::sim
