#pragma once
/// @file Commands.h
/// The pneuma-cli subcommands (docs/cli.md). Each add*Command() registers one subcommand with its
/// options and a callback; the callback ends with CLI::RuntimeError(exit code) on failure (CliSupport.h).

namespace CLI {
class App;
}

namespace pneuma::app {

/// `simulate`: run one controller on a model; write timeseries.csv, summary.json, plots, optional VTK series.
void addSimulateCommand(CLI::App& app);
/// `validate`: rerun the papers' experiments and write report.html, report.md and report.json.
void addValidateCommand(CLI::App& app);
/// `silhouette`: the body's silhouettes at end-expiration and end-inspiration per breath style (CSV, SVG,
/// PNG).
void addSilhouetteCommand(CLI::App& app);
/// `bench`: real-time factor per breath style and step time per element count.
void addBenchCommand(CLI::App& app);
/// `sweep FILE`: run a sweep file's variants in parallel (or write a Slurm job array); write their table.
void addSweepCommand(CLI::App& app);
/// `scenario check FILE`: validate a scenario file; `scenario show FILE`: print it with all defaults.
void addScenarioCommand(CLI::App& app);

/// `bake`: morph targets from physics runs of the skinned model, written as a .glb.
void addBakeCommand(CLI::App& app);
/// `play`: an affect or pattern mapped straight to morph weights, no physics, written as a .glb animation.
void addPlayCommand(CLI::App& app);

}  // namespace pneuma::app
