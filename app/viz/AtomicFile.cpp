#include "viz/AtomicFile.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>

namespace pneuma::viz {

std::string temporaryPathFor(const std::string& path) {
  return path + ".tmp-" + std::to_string(static_cast<long>(getpid()));
}

void commitTemporary(const std::string& temporaryPath, const std::string& path) {
  if (std::rename(temporaryPath.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    std::remove(temporaryPath.c_str());
    throw std::runtime_error("cannot rename " + temporaryPath + " to " + path + ": " + reason);
  }
}

void writeFileAtomically(const std::string& path, const std::string& bytes) {
  const std::string tmp = temporaryPathFor(path);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.flush();
    if (!out) {
      std::remove(tmp.c_str());
      throw std::runtime_error("cannot write " + path + ": write failed");
    }
  }
  commitTemporary(tmp, path);
}

}  // namespace pneuma::viz
