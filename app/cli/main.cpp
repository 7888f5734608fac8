/// @file main.cpp
/// pneuma-cli: the headless twin of the Pneuma desktop app (docs/cli.md).
///
/// Exit codes: 0 success, 1 a check or run failed (e.g. `validate` with a failing check),
/// 2 bad usage or bad input (unknown option, missing model, unwritable output, invalid scenario).

#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>
#include <string>

#include "Commands.h"
#include "ModelCommand.h"

namespace {

/// The usage line of the deepest subcommand the user reached, e.g. "Usage: pneuma-cli simulate [OPTIONS]".
std::string usageLine(const CLI::App& root) {
  const CLI::App* app = &root;
  while (!app->get_subcommands().empty()) app = app->get_subcommands().front();
  auto fmt = std::dynamic_pointer_cast<CLI::Formatter>(root.get_formatter());
  std::string name = app == &root ? root.get_name() : root.get_name() + " " + app->get_name();
  std::string usage = fmt ? fmt->make_usage(app, name) : "Usage: " + name + "\n";
  while (!usage.empty() && usage.front() == '\n') usage.erase(usage.begin());
  return usage;
}

/// Bad usage: a one-line error, the usage line and a pointer to --help on stderr; exit code 2.
int usageError(const CLI::App& app, const std::string& message) {
  std::cerr << "pneuma-cli: error: " << message << "\n"
            << usageLine(app) << "Run 'pneuma-cli --help' for more information.\n";
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Pneuma headless: simulate breathing, export data and plots, validate against the papers.",
               "pneuma-cli"};
  app.set_version_flag("--version", std::string("pneuma-cli ") + PNEUMA_VERSION,
                       "Print the version and exit");
  pneuma::app::addSimulateCommand(app);
  pneuma::app::addSweepCommand(app);
  pneuma::app::addScenarioCommand(app);
  pneuma::app::addValidateCommand(app);
  pneuma::app::addSilhouetteCommand(app);
  pneuma::app::addBenchCommand(app);
  pneuma::app::addModelCommand(app);
  pneuma::app::addBakeCommand(app);
  pneuma::app::addPlayCommand(app);
  app.footer("Run 'pneuma-cli SUBCOMMAND --help' for the options of a subcommand. Docs: docs/cli.md");

  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);  // --help, --version
  } catch (const CLI::RuntimeError& e) {
    return e.get_exit_code();  // a subcommand finished and chose its exit code (it printed its own messages)
  } catch (const CLI::ParseError& e) {
    // one-line error plus usage, exit 2 (issue 2: bad input)
    return usageError(app, e.what());
  }
  if (app.get_subcommands().empty()) return usageError(app, "a subcommand is required");
  return 0;
}
