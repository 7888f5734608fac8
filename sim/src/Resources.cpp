#include "pneuma/sim/Resources.h"

#include <dlfcn.h>

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
  // the binary that holds this code: a shared object (the Python module, build/python or PREFIX/...), else
  // the running executable
  std::error_code ec;
  fs::path binary;
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&installDataDir), &info) != 0 && info.dli_fname != nullptr &&
      fs::path(info.dli_fname).extension() == ".so")
    binary = fs::absolute(info.dli_fname, ec);
  if (binary.empty()) binary = fs::read_symlink("/proc/self/exe", ec);
  const fs::path bin = binary.empty() ? fs::current_path(ec) : binary.parent_path();
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
