#include "FuzzLoaders.h"

#include <fstream>
#include <sstream>

#include "pneuma/meshing/AnatomyParams.h"
#include "pneuma/sim/BreathStyleController.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/ModelIO.h"
#include "pneuma/sim/Scenario.h"
#include "pneuma/sim/pattern/Pattern.h"

namespace pneuma::fuzz {

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

namespace {

// the shipped file at `relative` under `resourceDir`, read once
const std::string& shipped(const std::string& resourceDir, const std::string& relative) {
  static std::string dir, text, name;
  if (dir != resourceDir || name != relative)
    dir = resourceDir, name = relative, text = readFile(resourceDir + "/" + relative);
  return text;
}

// a scenario's controller, when checking it reads no file the input names (a path could be /dev/zero)
bool isSelfContained(const sim::Scenario& s) {
  if (s.controller == sim::ControllerKind::Pattern) return !s.patternText.empty();
  return s.controllerName.find_first_of("/.\\") == std::string::npos;
}

void load(Loader loader, const std::string& text, const std::string& resourceDir) {
  switch (loader) {
    case Loader::Model:
      sim::parseModel(text, "fuzz.json");
      return;
    case Loader::Anatomy:
      meshing::parseAnatomy(text, shipped(resourceDir, "anatomy/muscle_gains.json"), "fuzz.json",
                            "muscle_gains.json");
      return;
    case Loader::Gains:
      meshing::parseAnatomy(shipped(resourceDir, "anatomy/male.json"), text, "male.json", "fuzz.json");
      return;
    case Loader::Style:
      sim::parseBreathStyle(text, "fuzz.json");
      return;
    case Loader::Scenario: {
      const sim::Scenario s = sim::parseScenario(text, "fuzz.json", resourceDir + "/scenarios");
      if (isSelfContained(s)) sim::checkController(s, resourceDir);
      sim::serializeScenario(s);
      return;
    }
    case Loader::Pattern: {
      const sim::pattern::Pattern p = sim::pattern::parsePattern(text, "fuzz.json", resourceDir);
      sim::pattern::LayerStack stack = sim::pattern::makeLayerStack(p, 1);
      for (int k = 0; k <= 100; ++k) stack.sample(0.5 * k);  // 50 s of breaths: the scheduler must advance
      return;
    }
  }
}

}  // namespace

const std::vector<Loader>& allLoaders() {
  static const std::vector<Loader> all{Loader::Model, Loader::Anatomy,  Loader::Gains,
                                       Loader::Style, Loader::Scenario, Loader::Pattern};
  return all;
}

const char* loaderName(Loader loader) {
  switch (loader) {
    case Loader::Model:
      return "model";
    case Loader::Anatomy:
      return "anatomy";
    case Loader::Gains:
      return "gains";
    case Loader::Style:
      return "style";
    case Loader::Scenario:
      return "scenario";
    case Loader::Pattern:
      return "pattern";
  }
  return "model";
}

void runLoader(Loader loader, const std::string& text, const std::string& resourceDir) {
  try {
    load(loader, text, resourceDir);
  } catch (const sim::Error&) {
    // rejected with a message: the expected outcome for malformed input
  }
}

}  // namespace pneuma::fuzz
