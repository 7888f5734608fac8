#include "gui/SimWorker.h"

#include <QTimer>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include "pneuma/sim/Error.h"
#include "pneuma/sim/Resources.h"
#include "viz/AtomicFile.h"
#include "viz/GltfWriter.h"
#include "viz/VtkSeriesWriter.h"

namespace pneuma::app {

namespace {

using Clock = std::chrono::steady_clock;
constexpr double kWallBudget = 0.030;          // [s] longest stepping batch between two sync points
constexpr int kTickMs = 8;                     // [ms] worker tick
constexpr double kRealTimeFactorWindow = 2.0;  // [s] wall time the real-time factor is measured over
// [-] rise of the lung volume above its running minimum, as a fraction of it, that confirms an
// end-expiration (0.5 %: 29 mL of a 5.8 L chest, well under a calm breath's 500 mL, well over the rib
// cage's few-hertz wobble)
constexpr double kEndExpirationRise = 0.005;

double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

}  // namespace

SimWorker::SimWorker(std::shared_ptr<const sim::Model> model, std::unique_ptr<sim::Simulation> simulation,
                     RunSettings settings)
    : m_model(std::move(model)), m_sim(std::move(simulation)), m_settings(std::move(settings)) {
  publish(false);
}

SimWorker::~SimWorker() = default;

void SimWorker::setRunning(bool isRunning) {
  std::lock_guard lock(m_pendingMutex);
  m_pending.isRunning = isRunning;
}

void SimWorker::requestStep() {
  std::lock_guard lock(m_pendingMutex);
  m_pending.doStep = true;
}

void SimWorker::requestReset() {
  std::lock_guard lock(m_pendingMutex);
  m_pending.doReset = true;
}

void SimWorker::setSpeed(double speed) {
  std::lock_guard lock(m_pendingMutex);
  m_pending.speed = speed;
}

void SimWorker::requestSettings(const RunSettings& settings) {
  std::lock_guard lock(m_pendingMutex);
  m_pending.settings = settings;
}

void SimWorker::requestSimulation(std::shared_ptr<const sim::Model> model,
                                  std::unique_ptr<sim::Simulation> simulation, const RunSettings& settings) {
  std::lock_guard lock(m_pendingMutex);
  m_pending.model = std::move(model);
  m_pending.simulation = std::move(simulation);
  m_pending.settings = settings;
}

void SimWorker::requestScrub(double time) {
  std::lock_guard lock(m_pendingMutex);
  m_pending.scrubTime = time;
  m_pending.isRunning = false;
}

void SimWorker::requestRunUntil(double time) {
  std::lock_guard lock(m_pendingMutex);
  m_pending.runUntil = time;
  m_pending.isRunning = true;
}

void SimWorker::requestAffect(const std::string& name, sim::pattern::SwitchMode mode) {
  std::lock_guard lock(m_pendingMutex);
  m_pending.affect = std::make_pair(name, mode);
}

void SimWorker::requestScenario(std::shared_ptr<const sim::Scenario> scenario) {
  std::lock_guard lock(m_pendingMutex);
  m_pending.scenario = std::move(scenario);
}

void SimWorker::requestExportGltf(const std::string& modelDir, const std::string& path, bool isBakeOnly) {
  std::lock_guard lock(m_pendingMutex);
  m_pending.exportGltf = GltfRequest{modelDir, path, isBakeOnly};
}

void SimWorker::requestMorphTargets() {
  std::lock_guard lock(m_pendingMutex);
  m_pending.doBake = true;
}

std::shared_ptr<const sim::MorphTargets> SimWorker::morphTargets() const {
  std::lock_guard lock(m_morphsMutex);
  return m_morphs;
}

void SimWorker::requestExportRun(const std::string& modelDir, const std::string& outDir,
                                 const std::string& baseName, const viz::SeriesRange& range) {
  std::lock_guard lock(m_pendingMutex);
  m_isExportCancelled = false;
  m_pending.exportRun = SeriesRequest{modelDir, outDir, baseName, range};
}

Frame SimWorker::take() {
  std::lock_guard lock(m_outboxMutex);
  Frame frame;
  frame.snapshot = m_outbox.snapshot;
  frame.samples.swap(m_outbox.samples);
  return frame;
}

void SimWorker::start() {
  m_timer = new QTimer(this);
  m_timer->setInterval(kTickMs);
  connect(m_timer, &QTimer::timeout, this, &SimWorker::tick);
  m_lastTick = Clock::now();
  m_timer->start();
}

void SimWorker::stop() {
  if (m_timer) m_timer->stop();
}

void SimWorker::sync() {
  Pending p;
  {
    std::lock_guard lock(m_pendingMutex);
    std::swap(p, m_pending);
  }
  // apply the queued edits, in a fixed order
  if (p.simulation) {
    m_model = std::move(p.model);
    m_sim = std::move(p.simulation);
    {
      std::lock_guard lock(m_morphsMutex);
      m_morphs.reset();
    }
    m_pattern = nullptr;
    m_rtf = 0.0;
    m_rtfWindow.clear();
    m_samples.clear();
    ++m_generation;
    m_breathing = nullptr;
    m_breathingAt = -1.0;
    clearEndExpirations();
  }
  // a new posture turns gravity: the run starts over from the rest pose and settles in it
  const bool isNewPosture = p.settings && p.settings->options.step.posture != m_settings.options.step.posture;
  if (p.settings) applySettings(*p.settings);
  if (isNewPosture && m_pattern) {
    // an affect's drive was calibrated in the old posture: back to the breath style until one is pushed again
    m_sim->setController(std::make_unique<sim::BreathStyleController>(m_settings.style));
    m_pattern = nullptr;
  }
  if (p.doReset || isNewPosture) {
    m_sim->reset();
    m_runUntil = -1.0;
    m_samples.clear();
    ++m_generation;
    m_breathing = nullptr;
    m_breathingAt = -1.0;
    clearEndExpirations();
  }
  if (p.speed) {
    m_speed = *p.speed;
    m_rtfWindow.clear();  // measured at the new speed only
  }
  if (p.runUntil) {
    m_runUntil = *p.runUntil;
    m_speed = 0.0;
  }
  if (p.isRunning) {
    m_isRunning = *p.isRunning;
    m_debt = 0.0;
  }
  if (p.scenario) playScenario(*p.scenario);
  if (p.affect) pushAffect(p.affect->first, p.affect->second);
  if (p.exportRun) exportRun(*p.exportRun);
  if (p.exportGltf) exportGltf(*p.exportGltf);
  if (p.doBake) {
    QString error;
    try {
      bake();
    } catch (const std::exception& e) {
      error = e.what();
    }
    emit morphTargetsReady(error);
  }
  if (p.doStep) {
    m_isRunning = false;
    m_sim->stepOnce();
    collect(*m_sim);
  }
  if (p.simulation || p.doReset || p.doStep || p.settings) publish(false);
  if (p.scrubTime && !m_isRunning) {
    m_scrubTime = *p.scrubTime;
    publish(true);
  }
}

void SimWorker::applySettings(const RunSettings& settings) {
  m_sim->setOptions(settings.options);
  // a changed style restarts the open-loop controller
  if (sim::serializeBreathStyle(settings.style) != sim::serializeBreathStyle(m_settings.style)) {
    m_sim->setController(std::make_unique<sim::BreathStyleController>(settings.style));
    m_pattern = nullptr;
  }
  m_settings = settings;
}

PlotSample plotSample(const sim::Simulation& simulation, double previousTime, double previousVolume) {
  const sim::Metrics& m = simulation.latestMetrics();
  PlotSample s;
  s.time = m.time;
  s.lungVolume = m.lungVolume;
  s.rightLungVolume = m.rightLungVolume;
  s.leftLungVolume = m.leftLungVolume;
  s.gutVolumeError = m.gutVolumeError;
  if (m.time > previousTime) s.flow = (m.lungVolume - previousVolume) / (m.time - previousTime);
  s.gutPressure = m.gutPressure;
  if (simulation.model().cavity.compliance > 0.0)
    s.transdiaphragmaticPressure = m.gutPressure - simulation.stepWork().outputs.pleuralPressure;
  s.trackingRmsPercent = simulation.controller().trackingRmsPercent();
  s.activations = m.activations;
  s.groupMeanTension = m.groupMeanTension;
  return s;
}

void SimWorker::collect(const sim::Simulation& simulation) {
  const sim::Metrics& m = simulation.latestMetrics();
  PlotSample s = plotSample(simulation, m_previousTime, m_previousVolume);
  m_previousTime = m.time;
  m_previousVolume = m.lungVolume;
  s.targetVolume = m_pattern ? m_pattern->fractionToVolume(m_pattern->targetFraction())
                             : std::numeric_limits<double>::quiet_NaN();
  s.elementForce.assign(m.elementForce.data(), m.elementForce.data() + m.elementForce.size());
  m_samples.push_back(std::move(s));
  findEndExpiration(simulation);
}

void SimWorker::clearEndExpirations() {
  m_endExpirations.clear();
  m_previousTime = std::numeric_limits<double>::quiet_NaN();
  m_endExpirationFinder.clear();
}

void SimWorker::findEndExpiration(const sim::Simulation& simulation) {
  auto found = m_endExpirationFinder.add(simulation);
  if (!found) return;
  // that breath's end-expiration; forget those older than the recording
  m_endExpirations.push_back(std::move(found));
  const sim::Recorder& rec = simulation.recorder();
  const double oldest = rec.empty() ? 0.0 : rec.frame(0).time;
  while (m_endExpirations.size() > 1 && m_endExpirations[1]->time <= oldest)
    m_endExpirations.erase(m_endExpirations.begin());
}

std::shared_ptr<const sim::State> EndExpirationFinder::add(const sim::Simulation& simulation) {
  const double v = simulation.latestMetrics().lungVolume;
  if (simulation.state().time < simulation.options().settleTime || !std::isfinite(v)) return nullptr;
  const double rise = kEndExpirationRise * v;
  std::shared_ptr<const sim::State> found;
  if (m_isSeekingMinimum) {
    if (!(v >= m_extremeVolume)) {
      m_extremeVolume = v;
      m_atMinimum = simulation.state();
    } else if (v > m_extremeVolume + rise) {
      // the minimum is past: that breath's end-expiration
      found = std::make_shared<const sim::State>(m_atMinimum);
      m_isSeekingMinimum = false;
      m_extremeVolume = v;
    }
  } else if (v > m_extremeVolume) {
    m_extremeVolume = v;
  } else if (v < m_extremeVolume - rise) {
    m_isSeekingMinimum = true;
    m_extremeVolume = v;
    m_atMinimum = simulation.state();
  }
  return found;
}

void EndExpirationFinder::clear() {
  m_isSeekingMinimum = true;
  m_extremeVolume = std::numeric_limits<double>::quiet_NaN();
}

void SimWorker::pushAffect(const std::string& name, sim::pattern::SwitchMode mode) {
  const std::string resources = sim::resourceDir();
  if (m_pattern) {
    m_pattern->push(sim::pattern::loadAffect(name, resources).layers, mode);
    return;
  }
  emit status(QString("Calibrating the muscle drive for affect patterns (a few simulated seconds)\u2026"));
  const sim::pattern::DriveCalibration calibration = sim::pattern::calibrateDrive(m_model, m_sim->options());
  auto controller = sim::pattern::makeAffectController(name, resources, 1, calibration);
  m_pattern = controller.get();
  m_sim->setController(std::move(controller));
  emit status(QString("Playing affect '%1'").arg(QString::fromStdString(name)));
}

void SimWorker::playScenario(const sim::Scenario& scenario) {
  emit status(QString("Calibrating the muscle drive for '%1' (a few simulated seconds)\u2026")
                  .arg(QString::fromStdString(scenario.name)));
  auto controller = sim::makeController(scenario, m_model, sim::resourceDir());
  m_pattern = dynamic_cast<sim::pattern::PatternController*>(controller.get());
  m_sim->setController(std::move(controller));
  emit status(QString("Playing scenario '%1'").arg(QString::fromStdString(scenario.name)));
}

void SimWorker::restoreRecorded(std::size_t i, sim::State& state, sim::Metrics& metrics) const {
  m_sim->recorder().restore(i, state, metrics);
}

void SimWorker::exportRun(const SeriesRequest& request) {
  QString error;
  try {
    const sim::Recorder& rec = m_sim->recorder();
    if (rec.empty()) throw std::runtime_error("nothing recorded yet: run the simulation first");
    const int total = request.range.count(rec.size(), rec.frame(0).time, rec.frame(rec.size() - 1).time);
    if (total == 0) throw std::runtime_error("no recorded frame in the range asked for");
    // destroyed unfinished (cancelled, failed), the writer removes what it wrote
    viz::VtkSeriesWriter writer(*m_model, request.modelDir, request.outDir, request.baseName,
                                viz::VtkSeriesWriter::Staging::TemporaryFolder);
    viz::SeriesSelector selector(request.range);
    sim::State state;
    sim::Metrics metrics = m_sim->latestMetrics();
    for (std::size_t i = 0; i < rec.size(); ++i) {
      if (!selector.take(rec.frame(i).time)) continue;
      if (m_isExportCancelled) throw std::runtime_error(kCancelled);
      restoreRecorded(i, state, metrics);
      writer.writeFrame(state, metrics);
      emit exportProgress(writer.frameCount(), total);
    }
    if (m_isExportCancelled) throw std::runtime_error(kCancelled);
    writer.finish();
  } catch (const std::exception& e) {
    error = e.what();
  }
  emit exportDone(error);
}

void SimWorker::exportGltf(const GltfRequest& request) {
  QString error;
  try {
    const sim::Recorder& rec = m_sim->recorder();
    if (m_model->skin.vertexCount() == 0) bake();  // the no-skin error before any other (bake() throws it)
    if (!request.isBakeOnly && rec.size() < 2)
      throw std::runtime_error("nothing recorded yet: run the simulation first");
    viz::AtomicFileWriter probe(request.path);  // a folder that cannot be written fails before the bake
    bake();
    std::vector<viz::GltfAnimation> animations{viz::breathingDemo(*m_morphs)};
    if (!request.isBakeOnly) {
      viz::GltfAnimationBuilder builder(*m_model, *m_morphs);
      sim::State state;
      sim::Metrics metrics = m_sim->latestMetrics();
      for (std::size_t i = 0; i < rec.size(); ++i) {
        restoreRecorded(i, state, metrics);
        builder.add(state.time - rec.frame(0).time, state);
      }
      animations = {builder.animation("recording")};
    }
    viz::writeGltf(request.path, *m_model, request.modelDir, *m_morphs, animations);
  } catch (const std::exception& e) {
    error = e.what();
  }
  emit exportDone(error);
}

void SimWorker::bake() {
  if (m_model->skin.vertexCount() == 0)
    throw std::runtime_error("model '" + m_model->name +
                             "' has no skin (rebuild it with pneuma-cli model build)");
  if (m_morphs) return;
  emit status("Baking morph targets from deep, panting and supine runs (a few seconds)\u2026");
  auto morphs = std::make_shared<const sim::MorphTargets>(sim::bakeMorphTargets(m_model, sim::resourceDir()));
  std::lock_guard lock(m_morphsMutex);
  m_morphs = std::move(morphs);
}

void SimWorker::tick() {
  const double wall = secondsSince(m_lastTick);
  m_lastTick = Clock::now();
  try {
    sync();
    if (!m_isRunning) {
      m_rtfWindow.clear();
      return;
    }

    // how much simulated time this batch owes: real-time pacing, or as much as fits the budget
    const double t0 = m_sim->state().time;
    double duration = 0.0;
    if (m_speed > 0.0) {
      m_debt = std::min(m_debt + m_speed * wall, m_speed * kWallBudget * 4.0);
      duration = m_debt;
    } else {
      duration = 1.0;  // cut short by the wall budget below
    }
    if (m_runUntil >= 0.0) duration = std::min(duration, std::max(m_runUntil - t0, 0.0));

    const auto start = Clock::now();
    if (duration > 0.0) {
      m_sim->advance(duration, [&](const sim::Simulation& s) {
        collect(s);
        return secondsSince(start) < kWallBudget;
      });
    }
    const double advanced = m_sim->state().time - t0;
    if (m_speed > 0.0) m_debt = std::max(0.0, m_debt - advanced);

    // real-time factor: simulated seconds per wall second over the last ticks (one tick's ratio swings with
    // the batch's whole steps and the timer's jitter)
    const auto now = Clock::now();
    m_rtfWindow.emplace_back(now, m_sim->state().time);
    while (m_rtfWindow.size() > 2 &&
           std::chrono::duration<double>(now - m_rtfWindow.front().first).count() > kRealTimeFactorWindow)
      m_rtfWindow.pop_front();
    const double span = std::chrono::duration<double>(now - m_rtfWindow.front().first).count();
    if (span > 0.0) m_rtf = (m_rtfWindow.back().second - m_rtfWindow.front().second) / span;

    const bool reached = m_runUntil >= 0.0 && m_sim->state().time >= m_runUntil - 1e-9;
    if (reached) {
      m_isRunning = false;
      m_runUntil = -1.0;
    }
    publish(false);
    if (reached) emit targetReached();
  } catch (const sim::Error& e) {
    m_isRunning = false;
    m_runUntil = -1.0;
    publish(false);
    emit failed(QString::fromStdString(e.what()));
  }
}

void SimWorker::publish(bool isScrubbed) {
  auto snap = std::make_shared<Snapshot>();
  snap->model = m_model;
  snap->realTimeFactor = m_isRunning ? m_rtf : 0.0;
  snap->isRunning = m_isRunning;
  snap->generation = m_generation;
  const sim::Recorder& rec = m_sim->recorder();
  if (!rec.empty()) {
    snap->recordedFrom = rec.frame(0).time;
    snap->recordedTo = rec.frame(rec.size() - 1).time;
    snap->recordedFrames = rec.size();
  }
  snap->metrics = m_sim->latestMetrics();
  // the last breaths' figures, once per simulated second
  const double now = m_sim->state().time;
  if (now < m_breathingAt || now >= m_breathingAt + 1.0) {
    const double from = std::max(m_sim->options().settleTime, now - kBreathingWindow);
    auto breathing =
        std::make_shared<sim::Summary>(sim::summarize(m_sim->trace(), m_model->landmarks.name, from));
    m_breathing = breathing->cycles > 0 ? std::move(breathing) : nullptr;
    m_breathingAt = now;
  }
  snap->breathing = m_breathing;
  if (isScrubbed && !rec.empty()) {
    // the recorded frame nearest to the requested time, for display
    restoreRecorded(rec.indexAt(m_scrubTime), snap->state, snap->metrics);
    snap->isScrubbed = true;
  } else {
    snap->state = m_sim->state();
  }
  // the end-expiration the shown instant's breath started from
  for (const auto& e : m_endExpirations) {
    if (e->time <= snap->state.time) snap->endExpiration = e;
    snap->endExpirationTimes.push_back(e->time);
  }

  std::lock_guard lock(m_outboxMutex);
  if (m_outbox.snapshot && m_outbox.snapshot->generation != m_generation) m_outbox.samples.clear();
  m_outbox.snapshot = std::move(snap);
  for (PlotSample& s : m_samples) m_outbox.samples.push_back(std::move(s));
  m_samples.clear();
  emit snapshotReady();
}

}  // namespace pneuma::app
