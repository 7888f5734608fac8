// Exact restarts on the default model: a run saved at time t and resumed, in the same process
// (Simulation::checkpoint() / restore()) or through a file (save() / load()), continues bit-identically to
// the run that was not interrupted, for every breath style and for an affect (the pattern controller's state
// and random stream included). The checkpoint is taken where the implicit solver holds a factorization it has
// already reused, so a restart that dropped the solver memory (SolverMemory, Step.h) would not match; the
// last test shows that it does not.
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <memory>
#include <sstream>
#include <string>

#include "DefaultModel.h"
#include "ToyTorso.h"
#include "pneuma/sim/BreathStyleController.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/Recorder.h"
#include "pneuma/sim/Simulation.h"
#include "pneuma/sim/pattern/PatternController.h"

namespace pneuma::sim {
namespace {

using test::defaultModel;
using ControllerFactory = std::function<std::unique_ptr<Controller>()>;

const std::string kResources = PNEUMA_RESOURCE_DIR;

// [s] the run: a short settling, then breathing up to the checkpoint, then on
constexpr double kSettle = 0.3;
constexpr double kBefore = 1.2;  // [s] simulated before the checkpoint
constexpr double kAfter = 1.5;   // [s] simulated after it

SimulationOptions runOptions() {
  SimulationOptions o;
  o.settleTime = kSettle;
  o.recordSeconds = kTraceOnlyRecordSeconds;
  return o;
}

// number of entries of a and b that are not bit-identical (shapes must agree), and the first one
template <typename M>
long long differences(const M& a, const M& b, std::string& first) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) {
    first = "shapes differ";
    return a.size() + b.size();
  }
  long long n = 0;
  for (Eigen::Index j = 0; j < a.cols(); ++j)
    for (Eigen::Index i = 0; i < a.rows(); ++i)
      if (!(a(i, j) == b(i, j))) {
        if (n++ == 0) {
          std::ostringstream os;
          os.precision(17);
          os << "(" << i << ", " << j << "): " << a(i, j) << " vs " << b(i, j);
          first = os.str();
        }
      }
  return n;
}

// every position, orientation and velocity bit-identical
void expectSameState(const State& a, const State& b, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(a.time, b.time);
  EXPECT_EQ(a.steps, b.steps);
  Eigen::Matrix4Xd qa(4, static_cast<Eigen::Index>(a.bodyOrientation.size())),
      qb(4, static_cast<Eigen::Index>(b.bodyOrientation.size()));
  for (std::size_t i = 0; i < a.bodyOrientation.size(); ++i)
    qa.col(static_cast<Eigen::Index>(i)) = a.bodyOrientation[i].coeffs();
  for (std::size_t i = 0; i < b.bodyOrientation.size(); ++i)
    qb.col(static_cast<Eigen::Index>(i)) = b.bodyOrientation[i].coeffs();
  std::string first;
  EXPECT_EQ(differences(a.bodyPosition, b.bodyPosition, first), 0) << "bodyPosition " << first;
  EXPECT_EQ(differences(qa, qb, first), 0) << "bodyOrientation " << first;
  EXPECT_EQ(differences(a.bodyVelocity, b.bodyVelocity, first), 0) << "bodyVelocity " << first;
  EXPECT_EQ(differences(a.bodyAngularVelocity, b.bodyAngularVelocity, first), 0)
      << "bodyAngularVelocity " << first;
  EXPECT_EQ(differences(a.nodePosition, b.nodePosition, first), 0) << "nodePosition " << first;
  EXPECT_EQ(differences(a.nodeVelocity, b.nodeVelocity, first), 0) << "nodeVelocity " << first;
}

// runs `sim` to kSettle + kBefore and on, step by step, until the step after a checkpoint reuses the solver's
// factorization (its age reaches 2), so that a restart that refactored there would not match; returns that
// checkpoint and, in `text`, its file (save()). `sim` has taken that step.
SimulationCheckpoint runToCheckpoint(Simulation& sim, std::string& text) {
  sim.advance(kSettle + kBefore);
  SimulationCheckpoint checkpoint;
  for (int i = 0; i < 40; ++i) {
    checkpoint = sim.checkpoint();
    std::ostringstream file;
    sim.save(file);
    text = file.str();
    sim.stepOnce();
    if (sim.stepWork().memory.factorAge >= 2) return checkpoint;
  }
  ADD_FAILURE() << "no step near the checkpoint reuses the factorization";
  return checkpoint;
}

// the uninterrupted run against three restarts from the checkpoint: a copy in a new Simulation, the same
// Simulation sent back, and a file written, read back and loaded into a new Simulation (the default model
// unless `model` is given)
void expectExactRestarts(const ControllerFactory& makeController, const std::string& name,
                         const SimulationOptions& options = runOptions(),
                         std::shared_ptr<const Model> model = nullptr) {
  if (!model) model = defaultModel();
  Simulation whole(model, makeController(), options);
  std::string text;
  const SimulationCheckpoint checkpoint = runToCheckpoint(whole, text);
  // per process: worktrees' test runs share the temporary folder
  const std::string path =
      ::testing::TempDir() + "pneuma_restart_" + std::to_string(::getpid()) + "_" + name + ".txt";
  std::ofstream(path) << text;
  whole.advance(checkpoint.state.time + kAfter - whole.state().time);
  const State uninterrupted = whole.state();
  const double lungVolume = whole.latestMetrics().lungVolume;
  ASSERT_NE(uninterrupted.nodePosition, checkpoint.state.nodePosition);

  Simulation copy(model, makeController(), options);
  copy.restore(checkpoint);
  copy.advance(kAfter);
  expectSameState(copy.state(), uninterrupted, name + ": in-process copy");
  EXPECT_EQ(copy.latestMetrics().lungVolume, lungVolume);

  whole.restore(checkpoint);
  whole.advance(kAfter);
  expectSameState(whole.state(), uninterrupted, name + ": the same Simulation sent back");

  Simulation resumed(model, makeController(), options);
  {
    std::ifstream file(path);
    ASSERT_TRUE(file) << path;
    resumed.load(file, path);
  }
  expectSameState(resumed.state(), checkpoint.state, name + ": state read back");
  resumed.advance(kAfter);
  expectSameState(resumed.state(), uninterrupted, name + ": resumed from the file");
  EXPECT_EQ(resumed.latestMetrics().lungVolume, lungVolume);
  std::remove(path.c_str());
}

class BreathStyleRestart : public ::testing::TestWithParam<const char*> {
 protected:
  void SetUp() override { REQUIRE_DEFAULT_MODEL(); }
};

TEST_P(BreathStyleRestart, ContinuesBitIdentically) {
  const BreathStyle style = loadBreathStyle(GetParam());
  expectExactRestarts([&] { return std::make_unique<BreathStyleController>(style); }, GetParam());
}

INSTANTIATE_TEST_SUITE_P(EveryStyle, BreathStyleRestart,
                         ::testing::Values("calm", "deep", "panting", "forced-exhale"), [](const auto& info) {
                           std::string n = info.param;
                           for (char& c : n)
                             if (c == '-') c = '_';
                           return n;
                         });

// the toy torso with two soft-tissue volume bodies (VolumeBodies): their rank-one terms in the solver memory
// and their volumes in the step outputs travel with the checkpoint
TEST(ExactRestart, VolumeBodiesContinueBitIdentically) {
  Model toy = test::makeToyTorso(1);
  test::addToyTissueBody(toy);
  test::addToyTissueBody(toy, 5e4);
  const BreathStyle calm = loadBreathStyle("calm");
  expectExactRestarts([&] { return std::make_unique<BreathStyleController>(calm); }, "volume_bodies",
                      runOptions(), std::make_shared<const Model>(std::move(toy)));
}

// lying on the back (gravity posterior, StepOptions::posture): the file carries the posture and the run goes
// on bit-identically
TEST(ExactRestart, SupineCalmContinuesBitIdentically) {
  REQUIRE_DEFAULT_MODEL();
  SimulationOptions supine = runOptions();
  supine.step.posture = Posture::Supine;
  const BreathStyle calm = loadBreathStyle("calm");
  expectExactRestarts([&] { return std::make_unique<BreathStyleController>(calm); }, "supine", supine);
}

// a plausible drive calibration (concave responses), so that the affect test needs no calibration run; the
// rest volume is learned while settling, which the checkpoint must carry
pattern::DriveCalibration testCalibration() {
  std::array<double, kElementGroupCount> gain{};
  gain[static_cast<std::size_t>(ElementGroup::IntercostalExternal)] = 0.3;
  gain[static_cast<std::size_t>(ElementGroup::Diaphragm)] = 0.6;
  gain[static_cast<std::size_t>(ElementGroup::IntercostalInternal)] = -0.1;
  gain[static_cast<std::size_t>(ElementGroup::Rectus)] = -0.05;
  gain[static_cast<std::size_t>(ElementGroup::TransversusObliques)] = -0.05;
  pattern::DriveCalibration c;
  c.restVolume = 0.0;
  for (std::size_t g = 0; g < gain.size(); ++g)
    for (std::size_t k = 0; k < pattern::kCalibrationAlphas.size(); ++k)
      c.response[g][k] =
          gain[g] * (1.0 - std::exp(-3.0 * pattern::kCalibrationAlphas[k])) / (1.0 - std::exp(-3.0));
  c.timeConstant[static_cast<std::size_t>(ElementGroup::IntercostalExternal)] = 0.2;
  return c;
}

TEST(ExactRestart, AffectPanicContinuesBitIdentically) {
  REQUIRE_DEFAULT_MODEL();
  expectExactRestarts([] { return pattern::makeAffectController("panic", kResources, 7, testCalibration()); },
                      "panic");
}

// the file of a calm run saved after `seconds` [s]
std::string savedCalmRun(double seconds) {
  Simulation a(defaultModel(), std::make_unique<BreathStyleController>(loadBreathStyle("calm")),
               runOptions());
  a.advance(seconds);
  std::ostringstream file;
  a.save(file);
  return file.str();
}

// loading `text` into a fresh calm run with `options` throws an Error containing `needle`, and the run is
// left as it was
void expectLoadError(const SimulationOptions& options, const std::string& text, const std::string& needle) {
  Simulation b(defaultModel(), std::make_unique<BreathStyleController>(loadBreathStyle("calm")), options);
  const State before = b.state();
  std::istringstream in(text);
  try {
    b.load(in, "run.ckpt");
    ADD_FAILURE() << "no Error for " << needle;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
  expectSameState(b.state(), before, "after a failed load");
}

TEST(ExactRestart, LoadRefusesAnotherTimeStep) {
  REQUIRE_DEFAULT_MODEL();
  SimulationOptions other = runOptions();
  other.dt = 0.01;
  expectLoadError(other, savedCalmRun(0.1), "run.ckpt: checkpoint field 'simulation.dt'");
}

// a run saved upright does not continue lying down (gravity would turn at the restart), and the message names
// both
TEST(ExactRestart, LoadRefusesAnotherPosture) {
  REQUIRE_DEFAULT_MODEL();
  SimulationOptions supine = runOptions();
  supine.step.posture = Posture::Supine;
  expectLoadError(
      supine, savedCalmRun(0.1),
      "run.ckpt: checkpoint field 'simulation.posture': saved in posture 'upright', this run is supine");
}

// a damaged file fails with an Error naming the field, before anything is changed
TEST(ExactRestart, LoadRejectsADamagedFile) {
  REQUIRE_DEFAULT_MODEL();
  const std::string text = savedCalmRun(0.2);
  expectLoadError(runOptions(), text.substr(0, text.size() / 2), "run.ckpt: checkpoint field '");
  expectLoadError(runOptions(), text.substr(0, text.find("state.nodeVelocity")),
                  "'state.nodeVelocity': the file ends here");
  std::string renamed = text;
  renamed.replace(renamed.find("solver.factorAge"), 16, "solver.factorAgx");
  expectLoadError(runOptions(), renamed, "'solver.factorAge': found 'solver.factorAgx' instead");
  std::string notANumber = text;
  notANumber.replace(notANumber.find("state.time ") + 11, 1, "z");
  expectLoadError(runOptions(), notANumber, "'state.time': not a number");
}

// the control experiment: the same restart with the solver memory dropped (a fresh factorization at the
// restart) does not continue bit-identically, so the tests above see the memory
TEST(ExactRestart, WithoutTheSolverMemoryTheRunDiverges) {
  REQUIRE_DEFAULT_MODEL();
  const auto model = defaultModel();
  const BreathStyle calm = loadBreathStyle("calm");
  Simulation whole(model, std::make_unique<BreathStyleController>(calm), runOptions());
  std::string text;
  SimulationCheckpoint checkpoint = runToCheckpoint(whole, text);
  whole.advance(checkpoint.state.time + kAfter - whole.state().time);
  checkpoint.solver = makeStepWork(*model).memory;
  Simulation forgetful(model, std::make_unique<BreathStyleController>(calm), runOptions());
  forgetful.restore(checkpoint);
  forgetful.advance(kAfter);
  std::string first;
  EXPECT_GT(differences(forgetful.state().nodePosition, whole.state().nodePosition, first), 0);
}

// scrubbing shows a frame as it was measured: the gut pressure of the run's kappa, not one recomputed later
TEST(Recorder, RestoresTheFrameAsRecorded) {
  REQUIRE_DEFAULT_MODEL();
  const auto model = defaultModel();
  SimulationOptions o = runOptions();
  o.step.kappa = 2.0 * model->gut.kappa;
  Simulation sim(model, std::make_unique<BreathStyleController>(loadBreathStyle("deep")), o);
  sim.advance(kSettle + 0.5);
  const Recorder& rec = sim.recorder();
  ASSERT_GT(rec.size(), 1u);
  State state;
  Metrics shown;
  rec.restore(rec.size() - 1, state, shown);
  const Metrics& latest = sim.latestMetrics();
  EXPECT_EQ(shown.time, latest.time);
  EXPECT_EQ(shown.lungVolume, latest.lungVolume);
  EXPECT_EQ(shown.gutVolumeError, latest.gutVolumeError);
  EXPECT_EQ(shown.gutPressure, latest.gutPressure);
  EXPECT_NE(latest.gutPressure, 0.0);
  ASSERT_EQ(shown.elementForce.size(), latest.elementForce.size());
  EXPECT_EQ(shown.elementForce, Eigen::VectorXd(latest.elementForce.cast<float>().cast<double>()));
  EXPECT_EQ(state.nodePosition, Eigen::Matrix3Xd(sim.state().nodePosition.cast<float>().cast<double>()));
}

}  // namespace
}  // namespace pneuma::sim
