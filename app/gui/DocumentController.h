#pragma once
/// @file DocumentController.h
/// What the window shows, as files: the open model (its directory) and the run settings' scenario files.
/// Reading checks everything before anything changes: a model is loaded and a simulation of it made with the
/// settings, a scenario's style and options are read, and only then does the caller adopt them. Saving writes
/// a scenario that names an unedited style preset, or an edited style as its own preset file beside the
/// scenario.

#include <QString>
#include <memory>

#include "gui/SimWorker.h"
#include "pneuma/sim/Scenario.h"

namespace pneuma::app {

class DocumentController {
 public:
  /// A model read from disk with a simulation of it, not adopted yet.
  struct OpenedModel {
    std::shared_ptr<const sim::Model> model;
    std::unique_ptr<sim::Simulation> simulation;  ///< a breath-style run of the settings it was opened with
    QString dir;                                  ///< absolute
  };
  /// A scenario read from disk: the settings it asks for and its model's directory.
  struct OpenedScenario {
    QString name;
    QString description;  ///< the scenario's explanation (a teaching preset: what to watch and why)
    RunSettings settings;
    QString modelDir;
    /// the scenario itself when an affect or a pattern drives it (null for a breath style): the worker makes
    /// its controller (SimWorker::requestScenario())
    std::shared_ptr<const sim::Scenario> drive;
  };

  /// The directory of the default model: sim::defaultModelDir() ($PNEUMA_MODEL_DIR, else
  /// <bindir>/../share/pneuma/models/default).
  static QString defaultModelDir();

  /// Loads the model in `dir` and makes a simulation of it under `settings`.
  /// @throws std::exception naming the problem ("Cannot open model '<dir>': ...").
  static OpenedModel readModel(const QString& dir, const RunSettings& settings);
  /// Reads the scenario at `path`: its breath style and options (recordSeconds kept from `current`), its
  /// model.
  /// An affect or pattern scenario is checked (sim::checkController()) and kept in OpenedScenario::drive.
  /// @throws std::exception naming the problem.
  static OpenedScenario readScenario(const QString& path, const RunSettings& current);
  /// Reads the measured volume trace at `path` (CSV, sim/pattern/VolumeTrace.h) as the drive of the open
  /// model's run: a trace scenario (sim::ControllerKind::Trace) named after the file, read and checked before
  /// anything changes. @throws std::exception naming the file, line and column
  /// (sim::pattern::parseVolumeTrace()).
  static std::shared_ptr<const sim::Scenario> readTrace(const QString& path);

  /// The adopted model and its directory (null and empty before the first one).
  const std::shared_ptr<const sim::Model>& model() const { return m_model; }
  const QString& modelDir() const { return m_modelDir; }
  /// Makes `opened` the document's model (its simulation is left to the caller).
  void adopt(const OpenedModel& opened);

  /// Writes `settings` and the model as the scenario `path` (60 s): driven by `drive`'s affect or pattern
  /// when given (a pushed affect, an opened pattern scenario), else by the breath style; an edited style goes
  /// beside it as "<stem>.style.json". @throws std::exception naming the file.
  void saveScenario(const QString& path, const RunSettings& settings,
                    const sim::Scenario* drive = nullptr) const;

 private:
  std::shared_ptr<const sim::Model> m_model;
  QString m_modelDir;
};

}  // namespace pneuma::app
