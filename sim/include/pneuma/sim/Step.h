#pragma once
/// @file Step.h
/// One simulation step, written as a pipeline of named stages (as MuJoCo's mj_step):
///   1. forces      muscles (Eq. 2), cartilage springs, gut pressure (Eq. 4, 5), joint friction (Eq. 3),
///                  passive spine stiffness, gravity
///   2. integrate   velocities and positions with the chosen integrator
///   3. joints      ball-joint constraints: velocity impulses, then position projection (error < 0.1 mm)
/// Metrics are computed separately, at the output rate (computeMetrics()).
///
/// Integrators
/// - SymplecticEuler: the paper's reference scheme (Section 6.1), v += F/m dt, then x += v dt, for
///   nodes and bodies (quaternions integrated with the new angular velocity). Explicit, so dt is
///   bounded by the stiffest spring / the gut's volumetric mode (dt < 2 / omega_max).
/// - ImplicitEulerJoints (the default): linearly implicit (backward) Euler of Baraff and Witkin (SIGGRAPH
///   1998), solving (M + dt D + dt^2 K) dv = dt (f - dt K v) in the coordinates of the joint tree: the linear
///   velocity of every body hanging on a ball joint is eliminated, v_c = v_p + w_p x r_p - w_c x r_c
///   (J: reduced -> full velocities), and a matrix-free conjugate gradient, warm-started from the previous
///   dv', solves J^T (M + dt D + dt^2 K) J dv' = J^T rhs. K holds the element stiffness along and across
///   each taut element, the rank-one gut-pressure stiffness kappa V0/V^2 g g^T (g = dV/dx) and the spine
///   joint springs; D holds element damping and joint friction. Preconditioner: the dense body block of
///   the reduced system, LDLT-factored every `preconditionerRefresh` steps (the light, stiffly coupled
///   ribcage), and block Jacobi (3x3 per node, with the gut pressure's diagonal blocks) for the gut nodes.
///   Why this one: the stiff parts of the model (cartilage, the gut's near-incompressibility kappa, joint
///   friction on 10-25 g ribs) are linear or nearly so, so backward Euler removes their step limit at the
///   cost of a few CG passes that are as cheap as one force evaluation; breathing is slow (0.2 - 1 Hz), so
///   its numerical damping of high frequencies is harmless, while a position-based (XPBD) scheme would not
///   follow the paper's force laws (Eq. 2, 4, 5) as directly. The joints hold inside the linear solve, so
///   joint friction (Eq. 3) couples a rib's spin to the spine about the joint rather than about the rib's
///   com: friction only dissipates (tested at 120 N m s/rad, 10x the calibrated mu) and the result does
///   not depend on dt (deep breathing: 916 / 912 / 915 mL at dt 10 / 5 / 2 ms). An earlier variant that solved in
///   the full space and imposed the joints afterwards was removed: it was not consistent in dt (1228 vs
///   1747 mL between 10 and 2 ms) and gained energy under rib friction above 0.5 N m s/rad. Default dt 10 ms
///   (20 ms still runs, but the gut volume error grows to 4 % and calm breathing by about 9 %).
/// With both integrators, after the velocity update sequential impulses remove the remaining relative velocity
/// at every joint (all of it for SymplecticEuler, the linearisation error for ImplicitEulerJoints) and a
/// mass-weighted projection removes the position drift.

#include "pneuma/sim/Activation.h"
#include "pneuma/sim/Metrics.h"
#include "pneuma/sim/Model.h"
#include "pneuma/sim/State.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

namespace pneuma::sim {

/// Time integration scheme.
enum class IntegratorKind { SymplecticEuler, ImplicitEulerJoints };

/// "symplectic-euler" or "implicit-euler-joints".
const char* integratorName(IntegratorKind k);
/// All valid names, comma separated (for error messages).
std::string integratorNames();
/// Inverse of integratorName(); returns false when unknown.
bool integratorFromName(const std::string& name, IntegratorKind& out);
/// Default time step [s] of each integrator: stable on the default model (see the validation tests).
double defaultTimeStep(IntegratorKind k);

/// Per-run physical switches and solver settings.
struct StepOptions {
  IntegratorKind integrator = IntegratorKind::ImplicitEulerJoints;
  bool gravity = true;                ///< apply Model::gravity to bodies and nodes
  double jointFrictionScale = 1.0;    ///< [-] multiplies every joint's mu (Eq. 3); 0 = frictionless
  double kappa = -1.0;                ///< [Pa] gut bulk modulus of Eq. 4; < 0 uses Model::gut.kappa
  std::array<double, kElementGroupCount> activeGainScale{1, 1, 1, 1, 1, 1};   ///< [-] multiplies kac per group
  std::array<double, kElementGroupCount> passiveGainScale{1, 1, 1, 1, 1, 1};  ///< [-] multiplies kpe and b per group
  int jointIterations = 30;           ///< [-] max Gauss-Seidel sweeps of the joint solver
  double jointTolerance = 1e-5;       ///< [m] position projection stops below this joint error
  int cgMaxIterations = 60;           ///< [-] implicit Euler: max CG iterations
  int preconditionerRefresh = 10;     ///< [-] implicit Euler: refactor the body-block preconditioner every n steps
  double cgTolerance = 1e-4;          ///< [-] implicit Euler: relative residual of the CG solve (preconditioner norm)
};

/// Checks the options (finite, non-negative scales, kappa, iteration counts).
/// @throws Error naming the field and value.
void validateStepOptions(const StepOptions& o);

/// Preallocated scratch memory of step() (no allocation per step) and the by-products of the last
/// step that metrics need. Make one per (Model, State) pair with makeStepWork().
struct StepWork {
  double restGutVolume = 0.0;          ///< [m^3] V0, gut volume at the rest pose
  double gutVolume = 0.0;              ///< [m^3] V at the start of the last step
  double gutPressure = 0.0;            ///< [Pa] P of Eq. 4 at the start of the last step (unclamped)
  Eigen::VectorXd elementForce;        ///< [N] scalar force per element of the last step (#E)
  Eigen::VectorXd elementLength;       ///< [m] (#E)
  Eigen::Matrix3Xd elementDirection;   ///< [-] unit A->B direction (3 x #E)
  Eigen::Matrix3Xd leverA, leverB;     ///< [m] endpoint minus body com, world; unused for node endpoints (3 x #E)
  Eigen::VectorXd elementStiffness;    ///< [N/m] |dF/dl| of taut elements, 0 when slack (#E)
  Eigen::VectorXd elementGeometric;    ///< [N/m] transverse stiffness |F| / l of elements in tension (#E)
  Eigen::VectorXd elementDamping;      ///< [N s/m] b of taut elements, 0 when slack (#E)
  Eigen::Matrix2Xi endpointBody;       ///< body of endpoint A (row 0) / B (row 1), -1 for node endpoints (2 x #E)
  Eigen::Matrix2Xi endpointNode;       ///< the node when an endpoint is exactly one node (weight 1), else -1 (2 x #E)
  Eigen::VectorXi fixedDofs;           ///< indices of fixed-body and fixed-node entries of the implicit solver vectors
  std::vector<Eigen::Matrix3d> inverseInertiaBody;  ///< [1/(kg m^2)] I^-1 in the body frame, zero for fixed bodies (#B)
  Eigen::Matrix3Xd jointLocalParent;   ///< [m] joint anchor in the parent's body frame (3 x #J)
  Eigen::Matrix3Xd jointLocalChild;    ///< [m] joint anchor in the child's body frame (3 x #J)
  std::vector<Eigen::Matrix3d> jointMassInverse;  ///< [kg] inverse effective mass of each joint's point constraint (#J)
  std::vector<Eigen::Matrix3d> rotation;  ///< [-] body rotation matrices (#B)
  std::vector<Eigen::Matrix3d> inverseInertiaWorld;  ///< [1/(kg m^2)] R I^-1 R^T, zero for fixed bodies (#B)
  Eigen::Matrix3Xd bodyForce, bodyTorque;  ///< [N], [N m] world (3 x #B)
  Eigen::Matrix3Xd nodeForce;          ///< [N] (3 x #N)
  Eigen::Matrix3Xd gutGradient;        ///< [m^2] dV/dx per node (3 x #N)
  double maxJointError = 0.0;          ///< [m] largest joint separation after the last step
  int cgIterations = 0;                ///< [-] CG iterations of the last implicit step
  Eigen::MatrixXd bodyBlock;           ///< body block of the implicit system, dense (6 #B x 6 #B)
  Eigen::LDLT<Eigen::MatrixXd> bodyFactor;  ///< its factorization, the CG preconditioner for body entries
  long long stepsSinceFactor = 0;      ///< [-] counts implicit steps to refresh bodyFactor
  std::vector<Eigen::Matrix3d> nodeBlockInverse;  ///< [1/kg] inverse 3x3 node blocks of M + dt D + dt^2 K (#N)
  Eigen::VectorXd cgX, cgR, cgZ, cgP, cgQ, cgB, cgT;  ///< implicit solver vectors (6 #B + 3 #N); cgX keeps
                                                      ///< dv' of the last step as the next warm start
  std::vector<int> treeJoints;         ///< joints solved exactly by the implicit step, parents first (#tree)
  Eigen::Matrix3Xd treeLeverParent, treeLeverChild;  ///< [m] joint anchor minus com, world, at the step start (3 x #J)
  Eigen::MatrixXd bodyTreeMap;         ///< [-, m] body part of the tree map J (6 #B x 6 #B), scratch
};

/// Allocates the scratch memory for `model` and computes its rest gut volume.
StepWork makeStepWork(const Model& model);

/// Stage 1 alone: clears and accumulates work.bodyForce [N], bodyTorque [N m] (world, about each com) and
/// nodeForce [N] from muscles (Eq. 2), cartilage springs, gut pressure (Eq. 4, 5), joint friction (Eq. 3)
/// and stiffness, gravity and the gyroscopic term; also fills the per-element and gut by-products.
/// Joint friction is included for ImplicitEulerJoints only; SymplecticEuler integrates it implicitly per joint
/// right after the velocity update (unconditionally stable for light bones).
void computeForces(const Model& model, const State& state, const Activations& act, const StepOptions& options,
                   StepWork& work);

/// Advances `state` by `dt` [s] under activations `act` (forces -> integrate -> joints).
/// Does not check for blow-ups (Simulation does) and does not compute metrics.
void step(const Model& model, State& state, double dt, const Activations& act, const StepOptions& options,
          StepWork& work);

/// Metrics of `state` (lung and gut volume, element forces of the last step, energies, landmarks).
/// Element forces come from `work` (the last step); call after step().
void computeMetrics(const Model& model, const State& state, const Activations& act, const StepOptions& options,
                    const StepWork& work, Metrics& out);

/// Checks `state` for NaN/Inf and blow-up (speeds above 100 m/s, joint error above 1 cm).
/// @throws Error naming the time, the body / node / element and a likely cause, e.g.
///   "simulation blew up at t = 1.234 s: node 17 speed 3.2e4 m/s (likely cause: dt too large for stiffness)".
void checkState(const Model& model, const State& state, const StepWork& work, double dt);

}  // namespace pneuma::sim
