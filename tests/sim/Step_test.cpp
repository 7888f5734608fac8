// The implicit integrator's linear solve (Step.h): the factorized preconditioner is the implicit system
// itself (so a fresh factorization solves backward Euler's linear step exactly), and reusing it over
// several steps changes only the CG iterations, not the motion.
#include "pneuma/sim/Step.h"

#include <gtest/gtest.h>

#include "DefaultModel.h"
#include "ToyTorso.h"
#include "pneuma/sim/BreathStyleController.h"

namespace pneuma::sim {
namespace {

// steps `model` through `seconds` of calm breathing with `o`; returns the largest CG count after the first
// step
int breathe(const Model& model, const StepOptions& o, double dt, double seconds, State& s) {
  BreathStyleController calm(loadBreathStyle("calm"));
  StepWork w = makeStepWork(model);
  int most = 0;
  for (int i = 0; s.time < seconds - 0.5 * dt; ++i) {
    step(model, s, dt, calm.activations(s.time, Metrics{}), o, w);
    if (i > 0) most = std::max(most, w.cgIterations);
  }
  return most;
}

// a fresh factorization solves the step directly (no CG): the assembled sparse system (bodies in the joint
// tree's coordinates, their coupling to the gut nodes, joints, the gut's rank-one pressure stiffness by
// Sherman-Morrison) must equal the matrix-free operator that CG solves; with the first factorization kept
// for the whole run and CG converged to 1e-10, the motion agrees with the direct solve of every step
TEST(ImplicitSolve, FreshFactorizationSolvesTheLinearStepExactly) {
  StepOptions fresh;
  fresh.integrator = IntegratorKind::ImplicitEulerJoints;
  fresh.preconditionerRefresh = 1;
  StepOptions cg = fresh;
  cg.preconditionerRefresh = 1000000;
  cg.refactorIterations = 1000000;
  cg.refactorElementChanges = 1000000;
  cg.cgMaxIterations = 2000;
  cg.cgTolerance = 1e-10;
  const auto agree = [&](const Model& model, double dt, double seconds) {
    State a = makeInitialState(model), b = makeInitialState(model);
    EXPECT_EQ(breathe(model, fresh, dt, seconds, a), 0) << "every step is solved directly";
    EXPECT_GT(breathe(model, cg, dt, seconds, b), 0) << "the kept factorization needs CG";
    const double motion = (a.nodePosition - model.nodes.rest).cwiseAbs().maxCoeff();  // [m]
    EXPECT_GT(motion, 1e-3);
    EXPECT_LT((a.nodePosition - b.nodePosition).cwiseAbs().maxCoeff(), 1e-5 * motion);
  };
  agree(test::makeToyTorso(2), defaultTimeStep(fresh.integrator), 1.0);
  if (const auto model = test::defaultModel()) agree(*model, 0.02, 0.6);
}

// the default refresh policy reuses a factorization for several steps: that changes the CG's path, not
// its answer; solved tightly (1e-7), the motion agrees with refactorizing every step
TEST(ImplicitSolve, StaleFactorizationGivesTheSameMotion) {
  const Model toy = test::makeToyTorso(2);
  StepOptions fresh;
  fresh.integrator = IntegratorKind::ImplicitEulerJoints;
  fresh.preconditionerRefresh = 1;
  fresh.cgTolerance = 1e-7;
  StepOptions reused = fresh;
  reused.preconditionerRefresh = StepOptions{}.preconditionerRefresh;
  const double dt = defaultTimeStep(fresh.integrator);
  State a = makeInitialState(toy), b = makeInitialState(toy);
  breathe(toy, fresh, dt, 2.0, a);
  const int most = breathe(toy, reused, dt, 2.0, b);
  EXPECT_GT(most, 0) << "the stale factorization should need some iterations";
  const double motion = (a.nodePosition - toy.nodes.rest).cwiseAbs().maxCoeff();  // [m]
  EXPECT_GT(motion, 1e-3);
  EXPECT_LT((a.nodePosition - b.nodePosition).cwiseAbs().maxCoeff(), 1e-5 * motion);
}

}  // namespace
}  // namespace pneuma::sim
