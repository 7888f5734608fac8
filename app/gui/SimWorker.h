#pragma once
/// @file SimWorker.h
/// Runs a pneuma::sim::Simulation off the GUI thread. The GUI never touches the live simulation:
/// it queues edits (MuJoCo simulate's `pending_`), which the worker applies at one sync point
/// before each batch of steps, and it reads immutable snapshots the worker publishes after each batch.

#include <QObject>
#include <QString>
#include <array>
#include <atomic>
#include <chrono>
#include <deque>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "pneuma/sim/BreathStyleController.h"
#include "pneuma/sim/Metrics.h"
#include "pneuma/sim/MorphTargets.h"
#include "pneuma/sim/Scenario.h"
#include "pneuma/sim/Simulation.h"
#include "pneuma/sim/State.h"
#include "pneuma/sim/pattern/PatternController.h"
#include "viz/VtkSeriesWriter.h"

class QTimer;

namespace pneuma::app {

/// The user-editable run settings: the breath style (frequency, r values) and the simulation options
/// (gains, kappa, joint friction, gravity, posture). A new posture restarts the run from the rest pose.
struct RunSettings {
  sim::BreathStyle style;
  sim::SimulationOptions options;
};

/// One output frame for the live plots (a slim copy of sim::Metrics).
struct PlotSample {
  double time = 0.0;             ///< [s]
  double lungVolume = 0.0;       ///< [m^3] the two lungs (sim::Metrics::lungVolume)
  double rightLungVolume = 0.0;  ///< [m^3] NaN for a model without lung surfaces
  double leftLungVolume = 0.0;   ///< [m^3] NaN for a model without lung surfaces
  double gutVolumeError = 0.0;   ///< [-] signed (V - V0) / V0
  /// [m^3/s] lung flow dV/dt, the backward difference over the output frame (inspiration > 0); NaN at a
  /// run's first frame
  double flow = std::numeric_limits<double>::quiet_NaN();
  double gutPressure = 0.0;  ///< [Pa] abdominal (gut) pressure P of Eq. 4
  /// [Pa] transdiaphragmatic pressure Pdi = Pab - Ppl (gut pressure minus the cavity's pleural pressure,
  /// Model.h Cavity); NaN for a model without a pleural pressure (cavity.compliance 0)
  double transdiaphragmaticPressure = std::numeric_limits<double>::quiet_NaN();
  double targetVolume = std::numeric_limits<double>::quiet_NaN();  ///< [m^3] the affect pattern's target lung
                                                                   ///< volume; NaN without one
  /// [%] the controller's tracking RMS so far, as a share of its target's peak-to-peak
  /// (sim::Controller::trackingRmsPercent()); NaN for a controller without a volume target
  double trackingRmsPercent = std::numeric_limits<double>::quiet_NaN();
  sim::Activations activations{};                                  ///< r and alpha per group
  std::array<double, sim::kElementGroupCount> groupMeanTension{};  ///< [N] sim::Metrics::groupMeanTension
  std::vector<float> elementForce;                                 ///< [N] signed, per element (#E)
};

/// The plotted quantities of `simulation`'s latest frame, the one rule for the live plots and an overlaid run
/// (RunOverlay.h): flow is the backward difference from the previous frame at `previousTime` [s] with lung
/// volume `previousVolume` [m^3] (NaN when `previousTime` is NaN or not earlier); targetVolume stays NaN and
/// elementForce empty.
PlotSample plotSample(const sim::Simulation& simulation, double previousTime, double previousVolume);

/// Follows the lung volume of a run's output frames and finds each breath's end-expiratory state: a volume
/// minimum after settling, confirmed once the volume has risen kEndExpirationRise (0.5 %) of itself above it.
/// The motion magnification draws the motion from it (viz::DisplayOptions::magnification).
class EndExpirationFinder {
 public:
  /// Feeds the simulation's latest output frame; returns the end-expiratory state of the breath whose
  /// minimum this frame confirms, else null.
  std::shared_ptr<const sim::State> add(const sim::Simulation& simulation);
  /// Starts again (reset, new model, new posture).
  void clear();

 private:
  bool m_isSeekingMinimum = true;
  double m_extremeVolume = std::numeric_limits<double>::quiet_NaN();  // [m^3] running minimum or maximum
  sim::State m_atMinimum;                                             // the state at the running minimum
};

/// What the GUI draws at one instant, copied out of the simulation.
struct Snapshot {
  std::shared_ptr<const sim::Model> model;  ///< the model the state belongs to
  sim::State state;
  sim::Metrics metrics;
  double realTimeFactor = 0.0;  ///< [-] simulated seconds per wall-clock second, last batch
  bool isRunning = false;
  bool isScrubbed = false;         ///< the state was restored from the recording (timeline)
  double recordedFrom = 0.0;       ///< [s] oldest recorded frame
  double recordedTo = 0.0;         ///< [s] newest recorded frame
  std::size_t recordedFrames = 0;  ///< frames recorded, evenly spaced from recordedFrom to recordedTo
  long long generation = 0;        ///< increments on reset and model change: plots restart
  /// The breath's figures over the last kBreathingWindow simulated seconds after settling (sim::summarize:
  /// tidal volume, rate and the motion in anatomical axes), refreshed once per simulated second; null before
  /// the first full breath.
  std::shared_ptr<const sim::Summary> breathing;
  /// The end-expiratory state the shown instant's breath started from (the last volume minimum at or before
  /// it, after settling): the view magnifies the motion from it (viz::DisplayOptions::magnification). Null
  /// before the first end-expiration.
  std::shared_ptr<const sim::State> endExpiration;
  /// [s] the times of the end-expirations found within the recording, oldest first: the breaths' bounds
  std::vector<double> endExpirationTimes;
};

/// [s] span of the run that Snapshot::breathing measures: two breaths at 10 b/m.
constexpr double kBreathingWindow = 12.0;

/// What the GUI takes from the worker at each display refresh.
struct Frame {
  std::shared_ptr<const Snapshot> snapshot;  ///< the latest instant
  std::vector<PlotSample> samples;           ///< output frames since the previous take, oldest first
};

class SimWorker : public QObject {
  Q_OBJECT

 public:
  /// @param model       the model `simulation` runs (kept alive by the snapshots)
  /// @param simulation  the run to drive, constructed and validated by the caller
  SimWorker(std::shared_ptr<const sim::Model> model, std::unique_ptr<sim::Simulation> simulation,
            RunSettings settings);
  ~SimWorker() override;

  // thread-safe requests, applied at the next sync point
  void setRunning(bool isRunning);
  void requestStep();
  void requestReset();
  /// Simulated seconds per wall second; 0 = as fast as possible.
  void setSpeed(double speed);
  void requestSettings(const RunSettings& settings);
  /// Replaces the simulation (new model); the settings travel with it.
  void requestSimulation(std::shared_ptr<const sim::Model> model, std::unique_ptr<sim::Simulation> simulation,
                         const RunSettings& settings);
  /// Shows the recorded frame nearest to `time` [s] (pauses the run).
  void requestScrub(double time);
  /// Runs as fast as possible until simulated time `time` [s], then pauses and emits targetReached().
  void requestRunUntil(double time);
  /// Plays affect preset `name` (de Melo et al. 2010) by pushing its layers in `mode`. The first push
  /// calibrates the muscle drive on the model (a few simulated seconds, in the worker thread) and
  /// switches to a pattern controller; a later breath-style edit switches back.
  void requestAffect(const std::string& name, sim::pattern::SwitchMode mode);
  /// Drives the run with the affect or pattern of `scenario` (sim::makeController(): the muscle drive is
  /// calibrated first, a few simulated seconds in the worker thread).
  void requestScenario(std::shared_ptr<const sim::Scenario> scenario);
  /// Writes the recorded frames that `range` keeps as a ParaView series `outDir`/`baseName`.pvd
  /// (viz::VtkSeriesWriter), emitting exportProgress() after each frame, then exportDone(). cancelExport()
  /// stops it between two frames; the writer then removes what it wrote and exportDone() says kCancelled.
  void requestExportRun(const std::string& modelDir, const std::string& outDir, const std::string& baseName,
                        const viz::SeriesRange& range = {});
  /// Stops a running series export (thread-safe; any thread).
  void cancelExport() { m_isExportCancelled = true; }
  /// What exportDone() says when cancelExport() stopped the export.
  static constexpr const char* kCancelled = "cancelled";
  /// Writes the recorded frames as a glTF 2.0 .glb at `path` (viz::writeGltf: skin morph weights fitted per
  /// frame, bone poses; bone meshes from `modelDir`), or with `isBakeOnly` the morph targets alone with a
  /// demo breath; then emits exportDone(). The morph targets are baked on the model once
  /// (sim::bakeMorphTargets, a few seconds in the worker thread) and kept until another model is loaded.
  void requestExportGltf(const std::string& modelDir, const std::string& path, bool isBakeOnly);
  /// Bakes the model's morph targets unless they are baked already (the same bake as the glTF export's),
  /// then emits morphTargetsReady().
  void requestMorphTargets();
  /// The model's baked morph targets; null before the first bake on the current model. Thread-safe.
  std::shared_ptr<const sim::MorphTargets> morphTargets() const;

  /// The latest snapshot and the plot samples produced since the previous call (each handed out once).
  Frame take();

 public slots:
  /// Starts the stepping timer; call in the worker thread (connect to QThread::started).
  void start();
  /// Stops the stepping timer; call in the worker thread before it quits.
  void stop();

 signals:
  void snapshotReady();
  /// The simulation threw (blow-up or bad parameter); the run is paused.
  void failed(const QString& message);
  void targetReached();
  /// A run export finished; `error` is empty on success, kCancelled when cancelled.
  void exportDone(const QString& error);
  /// A series export wrote `written` of its `total` frames.
  void exportProgress(int written, int total);
  /// A requestMorphTargets() finished; `error` is empty on success (then morphTargets() has them).
  void morphTargetsReady(const QString& error);
  /// Progress worth showing in the status bar (e.g. calibration).
  void status(const QString& message);

 private:
  struct GltfRequest {
    std::string modelDir, path;
    bool isBakeOnly = false;
  };
  struct SeriesRequest {
    std::string modelDir, outDir, baseName;
    viz::SeriesRange range;
  };
  struct Pending {
    std::optional<bool> isRunning;
    bool doStep = false;
    bool doReset = false;
    std::optional<double> speed;
    std::optional<RunSettings> settings;
    std::shared_ptr<const sim::Model> model;
    std::unique_ptr<sim::Simulation> simulation;
    std::optional<double> scrubTime;
    std::optional<double> runUntil;
    std::optional<std::pair<std::string, sim::pattern::SwitchMode>> affect;
    std::shared_ptr<const sim::Scenario> scenario;
    std::optional<SeriesRequest> exportRun;
    std::optional<GltfRequest> exportGltf;
    bool doBake = false;
  };

  void tick();
  void sync();
  void applySettings(const RunSettings& settings);
  void collect(const sim::Simulation& simulation);
  void pushAffect(const std::string& name, sim::pattern::SwitchMode mode);
  void playScenario(const sim::Scenario& scenario);
  void exportRun(const SeriesRequest& request);
  void exportGltf(const GltfRequest& request);
  /// Bakes m_morphs on m_model unless it is baked. @throws on a model without a skin or a failed run.
  void bake();
  /// Recorded frame `i` as a state and the metrics the recording keeps (time, volumes, element forces and the
  /// gut pressure, as measured then: sim::Recorder::restore()).
  void restoreRecorded(std::size_t i, sim::State& state, sim::Metrics& metrics) const;
  void publish(bool isScrubbed);
  /// Forgets the end-expirations found (reset, new model, new posture).
  void clearEndExpirations();
  /// Keeps the state at each end-expiration (EndExpirationFinder) within the recording.
  void findEndExpiration(const sim::Simulation& simulation);

  std::shared_ptr<const sim::Model> m_model;
  std::unique_ptr<sim::Simulation> m_sim;
  sim::pattern::PatternController* m_pattern = nullptr;  // the sim's controller when an affect plays
  // baked on m_model at the first glTF export or playback; written in the worker thread, read by the GUI
  std::shared_ptr<const sim::MorphTargets> m_morphs;
  mutable std::mutex m_morphsMutex;
  RunSettings m_settings;
  QTimer* m_timer = nullptr;

  std::mutex m_pendingMutex;
  Pending m_pending;
  std::atomic<bool> m_isExportCancelled{false};  // cancelExport(), read between the frames of an export

  // worker-thread state
  bool m_isRunning = false;
  double m_speed = 1.0;      // [-] simulated / wall seconds, 0 = max
  double m_runUntil = -1.0;  // [s] < 0: none
  double m_scrubTime = 0.0;  // [s] time of the shown recorded frame
  double m_debt = 0.0;       // [s] simulated time owed to real-time pacing
  double m_rtf = 0.0;        // [-]
  // (wall clock, simulated time [s]) at the ticks of the last kRealTimeFactorWindow seconds while running:
  // the real-time factor is the simulated time over the wall time across them
  std::deque<std::pair<std::chrono::steady_clock::time_point, double>> m_rtfWindow;
  long long m_generation = 0;
  std::shared_ptr<const sim::Summary> m_breathing;  // Snapshot::breathing
  double m_breathingAt = -1.0;                      // [s] simulated time it was measured at
  std::chrono::steady_clock::time_point m_lastTick;
  std::vector<PlotSample> m_samples;  // collected since the last publish
  // end-expirations: the confirmed ones within the recording (oldest first), and the search for the next
  std::vector<std::shared_ptr<const sim::State>> m_endExpirations;
  EndExpirationFinder m_endExpirationFinder;
  double m_previousTime =
      std::numeric_limits<double>::quiet_NaN();  // [s] the last output frame, for the flow
  double m_previousVolume = 0.0;                 // [m^3] its lung volume

  std::mutex m_outboxMutex;
  Frame m_outbox;
};

}  // namespace pneuma::app
