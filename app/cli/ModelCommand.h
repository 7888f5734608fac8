#pragma once
/// @file ModelCommand.h
/// `pneuma-cli model build` and `pneuma-cli model info` (docs/cli.md).

namespace CLI {
class App;
}

namespace pneuma::app {

/// Registers the `model` subcommand with `build` and `info` on `app`.
///  - `model build [--anatomy FILE] --out DIR [--no-preview]`: builds a model from an anatomy preset
///    (default sim::resourceDir()/anatomy/male.json), writes DIR (temporary directory, then rename) and
///    prints its summary; renders preview_front.png and preview_side.png unless --no-preview or no X display.
///  - `model info DIR [--json]`: reads DIR/model.json and prints its summary.
/// Failures print one line on stderr and end the command with exit code 2 (bad input).
void addModelCommand(CLI::App& app);

}  // namespace pneuma::app
