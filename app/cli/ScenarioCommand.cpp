/// @file ScenarioCommand.cpp
/// `pneuma-cli scenario check FILE...` and `pneuma-cli scenario show FILE`: validate scenario files
/// (every field, and the style, affect or pattern they name) without running them.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "CliSupport.h"
#include "Commands.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/Resources.h"
#include "pneuma/sim/Scenario.h"

namespace pneuma::app {

namespace {

sim::Scenario loadChecked(const std::string& path) {
  try {
    sim::Scenario s = sim::loadScenario(path);
    try {
      sim::checkController(s, sim::resourceDir());
    } catch (const sim::Error& e) {
      throw sim::Error(path + ": " + e.what());
    }
    return s;
  } catch (const sim::Error& e) {
    fail(kExitBadInput, e.what());
  }
}

}  // namespace

void addScenarioCommand(CLI::App& app) {
  CLI::App* cmd =
      app.add_subcommand("scenario", "Check or show scenario files (docs/cli.md, 'Scenario files')");
  cmd->require_subcommand(1);

  auto files = std::make_shared<std::vector<std::string>>();
  CLI::App* check =
      cmd->add_subcommand("check", "Validate scenario files; exit 0 when all are valid, 2 otherwise");
  check->add_option("FILE", *files, "Scenario files")->required();
  check->callback([files] {
    for (const std::string& f : *files) {
      const sim::Scenario s = loadChecked(f);
      std::printf("%s: ok (%s '%s', %g s)\n", f.c_str(), sim::controllerKindName(s.controller),
                  s.controllerName.empty() ? "inline" : s.controllerName.c_str(), s.duration);
    }
  });

  auto file = std::make_shared<std::string>();
  CLI::App* show = cmd->add_subcommand("show", "Print a scenario with every default filled in");
  show->add_option("FILE", *file, "Scenario file")->required();
  show->callback([file] { std::fputs(sim::serializeScenario(loadChecked(*file)).c_str(), stdout); });
}

}  // namespace pneuma::app
