#include "gui/RunOverlay.h"

#include <QDir>
#include <QFileInfo>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "gui/DocumentController.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/JsonReader.h"
#include "pneuma/sim/Resources.h"
#include "pneuma/sim/Scenario.h"

namespace pneuma::app {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// the comma-separated fields of one CSV line
std::vector<std::string> fields(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream in(line);
  for (std::string f; std::getline(in, f, ',');) out.push_back(f);
  return out;
}

}  // namespace

RunOverlay runScenarioOverlay(const QString& path, std::shared_ptr<const sim::Model> model,
                              const QString& modelDir, const std::function<bool(double)>& progress) {
  const sim::Scenario scenario = sim::loadScenario(path.toStdString());
  // the same model, or nothing to compare
  const QString wanted = scenario.model == "default" ? DocumentController::defaultModelDir()
                                                     : QString::fromStdString(scenario.model);
  if (QFileInfo(wanted).canonicalFilePath() != QFileInfo(modelDir).canonicalFilePath())
    throw sim::Error("overlay: " + path.toStdString() + " runs the model in '" + wanted.toStdString() +
                     "', the window shows '" + modelDir.toStdString() + "': open that model to compare");
  sim::SimulationOptions options = scenario.options;
  options.recordSeconds = sim::kTraceOnlyRecordSeconds;
  sim::Simulation simulation(model, sim::makeController(scenario, model, sim::resourceDir()), options);

  RunOverlay overlay;
  overlay.name = QString::fromStdString(scenario.name);
  const double end = options.settleTime + scenario.duration;  // [s]
  double previousTime = kNaN, previousVolume = kNaN;
  bool isStopped = false;
  EndExpirationFinder endExpirations;
  double nextGhost = 0.0;  // [s] the next state kept for the ghost
  simulation.advance(end, [&](const sim::Simulation& s) {
    overlay.samples.push_back(plotSample(s, previousTime, previousVolume));
    if (auto found = endExpirations.add(s)) overlay.ghost.endExpirations.push_back(std::move(found));
    if (s.state().time >= nextGhost - 1e-9) {
      overlay.ghost.states.push_back(s.state());
      nextGhost = s.state().time + 1.0 / kGhostRate;
    }
    previousTime = s.latestMetrics().time;
    previousVolume = s.latestMetrics().lungVolume;
    isStopped = progress && !progress(std::min(1.0, s.state().time / end));
    return !isStopped;
  });
  if (isStopped) overlay = RunOverlay{};
  return overlay;
}

const sim::State* RunGhost::at(double t) const {
  const auto after = std::upper_bound(states.begin(), states.end(), t,
                                      [](double time, const sim::State& s) { return time < s.time; });
  return after == states.begin() ? nullptr : &*(after - 1);
}

const sim::State* RunGhost::endExpirationAt(double t) const {
  const sim::State* found = nullptr;
  for (const auto& e : endExpirations)
    if (e->time <= t) found = e.get();
  return found;
}

RunOverlay readRecordingOverlay(const QString& path, const sim::Model& model) {
  const QFileInfo info(path);
  const QString csvPath = info.isDir() ? QDir(path).filePath("timeseries.csv") : path;
  const std::string csv = csvPath.toStdString();
  const QString summaryPath = QFileInfo(csvPath).absoluteDir().filePath("summary.json");
  const std::string summaryText =
      sim::readInputFile(summaryPath.toStdString(), " (a recording is a pneuma-cli simulate folder)");
  const sim::JsonDocument summary = sim::JsonDocument::parse(summaryText, summaryPath.toStdString());
  const std::string recorded = summary.root().at("model_name").string();
  if (recorded != model.name)
    throw sim::Error("overlay: " + csv + " was recorded on model '" + recorded + "', the window shows '" +
                     model.name + "'");

  std::stringstream text(sim::readInputFile(csv));
  std::string line;
  std::getline(text, line);
  const std::vector<std::string> header = fields(line);
  const auto column = [&](const char* name) {
    const auto it = std::find(header.begin(), header.end(), name);
    if (it == header.end()) throw sim::Error(csv + ": no column '" + name + "'");
    return static_cast<std::size_t>(it - header.begin());
  };
  const std::size_t timeColumn = column("time [s]"), volumeColumn = column("lung_volume [mL]");
  RunOverlay overlay;
  overlay.name = QFileInfo(csvPath).absoluteDir().dirName();
  double previousTime = kNaN, previousVolume = kNaN;
  for (int row = 2; std::getline(text, line); ++row) {
    const std::vector<std::string> f = fields(line);
    PlotSample s;
    try {
      s.time = std::stod(f.at(timeColumn));
      s.lungVolume = 1e-6 * std::stod(f.at(volumeColumn));  // [mL] -> [m^3]
    } catch (const std::exception&) {
      throw sim::Error(csv + ": line " + std::to_string(row) + ": not a number in the time or volume column");
    }
    if (s.time > previousTime) s.flow = (s.lungVolume - previousVolume) / (s.time - previousTime);
    s.gutPressure = kNaN;
    previousTime = s.time;
    previousVolume = s.lungVolume;
    overlay.samples.push_back(std::move(s));
  }
  if (overlay.samples.empty()) throw sim::Error(csv + ": no samples");
  return overlay;
}

}  // namespace pneuma::app
