#include "pneuma/meshing/ModelBuilder.h"

#include "VtpWriter.h"

#include "pneuma/sim/Error.h"
#include "pneuma/sim/ModelIO.h"

#include <filesystem>

namespace pneuma::meshing {

namespace fs = std::filesystem;

void writeModelDirectory(const BuiltModel& built, const std::string& dir) {
  const fs::path target = fs::absolute(fs::path(dir)).lexically_normal();
  const fs::path tmp = target.string() + ".tmp";
  const fs::path old = target.string() + ".old";
  try {
    // write everything into a sibling temporary directory
    fs::remove_all(tmp);
    fs::create_directories(tmp / "meshes");
    const sim::Bodies& b = built.model.bodies;
    for (int i = 0; i < b.size(); ++i) {
      writeVtp(built.bodyMeshes[static_cast<std::size_t>(i)], (tmp / b.mesh[static_cast<std::size_t>(i)]).string());
    }
    sim::saveModel(built.model, tmp.string());

    // swap it into place
    fs::remove_all(old);
    if (fs::exists(target)) fs::rename(target, old);
    fs::rename(tmp, target);
    fs::remove_all(old);
  } catch (const fs::filesystem_error& e) {
    fs::remove_all(tmp);
    throw sim::Error(dir + ": cannot write the model directory: " + e.what());
  }
}

}  // namespace pneuma::meshing
