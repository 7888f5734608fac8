#include <unistd.h>

#include <filesystem>

#include "VtpWriter.h"
#include "pneuma/meshing/ModelBuilder.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/ModelIO.h"

namespace pneuma::meshing {

namespace fs = std::filesystem;

namespace {

// a sibling "<target>.<tag>-<pid>-<n>" that does not exist yet, so that nothing of anyone else's is touched
fs::path freshSibling(const fs::path& target, const char* tag) {
  for (int n = 0;; ++n) {
    const fs::path p = target.string() + "." + tag + "-" + std::to_string(static_cast<long>(::getpid())) +
                       "-" + std::to_string(n);
    if (!fs::exists(fs::symlink_status(p))) return p;
  }
}

}  // namespace

void writeModelDirectory(const BuiltModel& built, const std::string& dir) {
  fs::path target = fs::absolute(fs::path(dir)).lexically_normal();
  if (!target.has_filename()) target = target.parent_path();  // "dir/" names dir

  // replace only an empty directory or an earlier model (one that holds model.json)
  std::error_code ec;
  if (fs::exists(fs::symlink_status(target))) {
    if (!fs::is_directory(target)) throw sim::Error(dir + ": exists and is not a directory");
    if (!fs::is_empty(target, ec) && !fs::exists(target / "model.json"))
      throw sim::Error(dir + ": not a model directory (no model.json) and not empty; refusing to replace it");
  }

  fs::path tmp;
  fs::path old;
  try {
    // write everything into a temporary sibling directory of our own
    tmp = freshSibling(target, "tmp");
    fs::create_directories(tmp / "meshes");
    const sim::Bodies& b = built.model.bodies;
    for (int i = 0; i < b.size(); ++i) {
      writeVtp(built.bodyMeshes[static_cast<std::size_t>(i)],
               (tmp / b.mesh[static_cast<std::size_t>(i)]).string());
    }
    sim::saveModel(built.model, tmp.string());

    // swap it into place, keeping the earlier model until the new one is there
    if (fs::exists(target)) {
      old = freshSibling(target, "old");
      fs::rename(target, old);
    }
    fs::rename(tmp, target);
    tmp.clear();
    if (!old.empty()) fs::remove_all(old);
  } catch (const fs::filesystem_error& e) {
    if (!tmp.empty()) fs::remove_all(tmp, ec);
    if (!old.empty() && !fs::exists(target)) fs::rename(old, target, ec);
    throw sim::Error(dir + ": cannot write the model directory: " + e.what());
  } catch (const sim::Error&) {
    if (!tmp.empty()) fs::remove_all(tmp, ec);
    throw;
  }
}

}  // namespace pneuma::meshing
