#include "ModelCommand.h"

#include <CLI/CLI.hpp>
#include <chrono>
#include <iostream>
#include <memory>

#include "ModelPreview.h"
#include "pneuma/meshing/AnatomyParams.h"
#include "pneuma/meshing/ModelBuilder.h"
#include "pneuma/meshing/ModelSummary.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/ModelIO.h"
#include "pneuma/sim/Resources.h"

namespace pneuma::app {

namespace {

constexpr int kBadInput = 2;

struct BuildOptions {
  std::string anatomy = sim::resourceDir() + "/anatomy/male.json";
  std::string out;
  std::string skin = meshing::kDefaultSkinFile;
  bool isPreviewSkipped = false;
  bool hasShoulderGirdle = false;   // --shoulder-girdle (true) or --no-shoulder-girdle (false)
  bool isGirdleOverridden = false;  // either was given: it replaces the preset's shoulder_girdle
};

struct InfoOptions {
  std::string dir;
  bool isJson = false;
};

void runBuild(const BuildOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  meshing::AnatomyParams anatomy = meshing::loadAnatomy(o.anatomy);
  if (o.isGirdleOverridden) anatomy.hasShoulderGirdle = o.hasShoulderGirdle;
  const meshing::BuiltModel built = meshing::buildModel(anatomy, o.skin);
  meshing::writeModelDirectory(built, o.out);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const meshing::BuildReport& r = built.report;
  std::cout << "model " << built.model.name << " (" << built.model.anatomy << ") written to " << o.out << "\n"
            << meshing::summaryText(r.summary) << "gut tetrahedra:  " << r.tetrahedra << " (TetGen volume "
            << r.tetVolume * 1e6 << " mL)\n"
            << "gut triangle quality: min " << r.gutQualityMin << ", mean " << r.gutQualityMean << "\n"
            << "bone triangles:  " << r.boneTriangles << "\n";
  if (r.skinTetrahedra > 0)
    std::cout << "skin registration: largest landmark residual " << r.skinLandmarkResidual * 1e3
              << " mm, least skin-to-bone distance " << r.skinBoneClearance * 1e3 << " mm\n";
  std::cout << "build time:      " << seconds << " s\n";

  if (o.isPreviewSkipped) return;
  std::string why;
  if (renderModelPreviews(o.out, why)) {
    std::cout << "previews:        " << o.out << "/preview_front.png, " << o.out << "/preview_side.png\n";
  } else {
    std::cerr << "pneuma-cli: warning: previews skipped: " << why << "\n";
  }
}

void runInfo(const InfoOptions& o) {
  const sim::Model model = sim::loadModel(o.dir);
  const meshing::ModelSummary s = meshing::summarizeModel(model);
  if (o.isJson) {
    std::cout << meshing::summaryJson(s) << "\n";
  } else {
    std::cout << "model " << model.name << " (" << model.anatomy << ") in " << o.dir << "\n"
              << meshing::summaryText(s);
  }
}

/// Runs `f`; an exception becomes one line on stderr and exit code 2.
template <typename F>
void guarded(F f) {
  try {
    f();
  } catch (const sim::Error& e) {
    std::cerr << "pneuma-cli: error: " << e.what() << "\n";
    throw CLI::RuntimeError(kBadInput);
  } catch (const std::exception& e) {  // e.g. a CGAL precondition on degenerate geometry
    std::cerr << "pneuma-cli: error: " << e.what() << "\n";
    throw CLI::RuntimeError(kBadInput);
  }
}

}  // namespace

void addModelCommand(CLI::App& app) {
  CLI::App* model = app.add_subcommand("model", "Build a model from an anatomy preset, or describe one");
  model->require_subcommand(1);

  auto build = std::make_shared<BuildOptions>();
  CLI::App* b = model->add_subcommand("build", "Build the torso model of an anatomy preset into a directory");
  b->add_option("--anatomy", build->anatomy, "Anatomy preset (JSON)")->check(CLI::ExistingFile);
  b->add_option("--out", build->out,
                "Output model directory: new, empty or an earlier model (replaced as a whole)")
      ->required();
  b->add_option(
       "--skin", build->skin,
       "Body surface mesh (any format assimp reads: OBJ, STL, PLY, glTF, Collada), registered to the "
       "anatomy")
      ->capture_default_str();
  CLI::Option* girdle = b->add_flag("--shoulder-girdle,!--no-shoulder-girdle", build->hasShoulderGirdle,
                                    "Build with (or without) the shoulder girdle, arms and neck, whatever "
                                    "the preset's shoulder_girdle says");
  b->add_flag("--no-preview", build->isPreviewSkipped, "Do not render preview_front.png / preview_side.png");
  b->callback([build, girdle] {
    build->isGirdleOverridden = girdle->count() > 0;
    guarded([&] { runBuild(*build); });
  });

  auto info = std::make_shared<InfoOptions>();
  CLI::App* i = model->add_subcommand("info", "Print the summary of a model directory");
  i->add_option("dir", info->dir, "Model directory (holding model.json)")->required();
  i->add_flag("--json", info->isJson, "Print JSON");
  i->callback([info] { guarded([&] { runInfo(*info); }); });
}

}  // namespace pneuma::app
