#include "gui/DocumentController.h"

#include <QDir>
#include <QFileInfo>

#include "pneuma/sim/Error.h"
#include "pneuma/sim/ModelIO.h"
#include "pneuma/sim/Resources.h"
#include "pneuma/sim/Scenario.h"
#include "pneuma/sim/pattern/VolumeTrace.h"
#include "viz/AtomicFile.h"

namespace pneuma::app {

QString DocumentController::defaultModelDir() { return QString::fromStdString(sim::defaultModelDir()); }

DocumentController::OpenedModel DocumentController::readModel(const QString& dir,
                                                              const RunSettings& settings) {
  OpenedModel opened;
  opened.model = std::make_shared<const sim::Model>(sim::loadModel(dir.toStdString()));
  opened.simulation = std::make_unique<sim::Simulation>(
      opened.model, std::make_unique<sim::BreathStyleController>(settings.style), settings.options);
  opened.dir = QFileInfo(dir).absoluteFilePath();
  return opened;
}

DocumentController::OpenedScenario DocumentController::readScenario(const QString& path,
                                                                    const RunSettings& current) {
  const sim::Scenario scenario = sim::loadScenario(path.toStdString());
  OpenedScenario opened;
  opened.name = QString::fromStdString(scenario.name);
  opened.description = QString::fromStdString(scenario.description);
  if (scenario.controller == sim::ControllerKind::Style) {
    opened.settings.style = sim::loadBreathStyle(scenario.controllerName);
  } else {
    sim::checkController(scenario, sim::resourceDir());
    opened.settings.style = current.style;  // shown in the panel; the affect or pattern drives the run
    opened.drive = std::make_shared<const sim::Scenario>(scenario);
  }
  opened.settings.options = scenario.options;
  opened.settings.options.recordSeconds = current.options.recordSeconds;
  opened.modelDir = scenario.model == "default" ? defaultModelDir() : QString::fromStdString(scenario.model);
  return opened;
}

std::shared_ptr<const sim::Scenario> DocumentController::readTrace(const QString& path) {
  auto scenario = std::make_shared<sim::Scenario>();
  scenario->name = QFileInfo(path).completeBaseName().toStdString();
  scenario->controller = sim::ControllerKind::Trace;
  scenario->controllerName = QFileInfo(path).absoluteFilePath().toStdString();
  sim::pattern::loadVolumeTrace(scenario->controllerName);  // its own message: file, line and column
  return scenario;
}

void DocumentController::adopt(const OpenedModel& opened) {
  m_model = opened.model;
  m_modelDir = opened.dir;
}

void DocumentController::saveScenario(const QString& path, const RunSettings& settings,
                                      const sim::Scenario* drive) const {
  sim::Scenario scenario;
  scenario.name = QFileInfo(path).completeBaseName().toStdString();
  scenario.description = "Saved from the Pneuma desktop app";
  scenario.model = m_modelDir.isEmpty() ? "default" : m_modelDir.toStdString();
  scenario.duration = 60.0;
  scenario.controller = sim::ControllerKind::Style;
  scenario.options = settings.options;
  // an edited style travels as its own preset file next to the scenario
  const sim::BreathStyle& s = settings.style;
  scenario.controllerName = s.name;
  // compare everything but the note: an unedited preset is referenced by name
  bool isPreset = false;
  try {
    sim::BreathStyle preset = sim::loadBreathStyle(s.name);
    preset.note = s.note;
    isPreset = sim::serializeBreathStyle(preset) == sim::serializeBreathStyle(s);
  } catch (const sim::Error&) {
  }
  if (!isPreset) {
    sim::BreathStyle edited = s;
    edited.note = "Edited in the Pneuma desktop app";
    const QFileInfo info(path);
    const QString stylePath = info.absoluteDir().absoluteFilePath(info.completeBaseName() + ".style.json");
    viz::writeFileAtomically(stylePath.toStdString(), sim::serializeBreathStyle(edited));
    scenario.controllerName = stylePath.toStdString();
  }
  if (drive) {
    scenario.controller = drive->controller;
    scenario.controllerName = drive->controllerName;
    scenario.patternText = drive->patternText;
    scenario.seed = drive->seed;
  }
  sim::saveScenario(scenario, path.toStdString());
}

}  // namespace pneuma::app
