#pragma once
/// @file Step.h
/// One simulation step, written as a pipeline of named stages (as MuJoCo's mj_step); docs/integrator.md has
/// the design, the integrators, the linear solve and the reasons for them.
///   1. forces      muscles (Eq. 2), cartilage springs, gut and volume-body pressure (Eq. 4, 5; Gut,
///                  VolumeBodies), pleural pressure (Cavity),
///                  joint friction (Eq. 3), joint stiffness (spine; rib-neck hinges, Joints), visceral drag
///                  (Gut::drag), gravity                                            (StepForces.cpp)
///   2. integrate   velocities: SymplecticEuler, the paper's explicit scheme (Step.cpp), or the default
///                  ImplicitEulerJoints, linearly implicit Euler in the joint tree's coordinates by CG with
///                  a kept block LDL^T factorization as preconditioner (StepImplicit.cpp); then positions
///   3. joints      ball-joint constraints: velocity impulses, then position projection (error < 0.1 mm)
///                                                                                  (StepJoints.cpp)
/// Metrics are computed separately, at the output rate (computeMetrics(), Metrics.cpp). StepWork splits what
/// a step works with into model constants, the solver memory a restart saves with the State, scratch and
/// outputs.

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "pneuma/sim/Activation.h"
#include "pneuma/sim/BlockLdlt.h"
#include "pneuma/sim/Metrics.h"
#include "pneuma/sim/Model.h"
#include "pneuma/sim/State.h"

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
/// symplectic-euler 10 us (the paper's explicit scheme needs it for the stiffest spring);
/// implicit-euler-joints 1/60 s, one step per 60 Hz display and output frame: with the smoothed diaphragm
/// step the breath styles' tidal volumes agree within 1 % with dt 5 ms (docs/validation figures), and it is
/// the real-time factor's budget.
double defaultTimeStep(IntegratorKind k);

/// The body's posture: which way gravity points in the body (model) frame, RAS (+x right, +y anterior,
/// +z superior). The model's rest pose is built upright and Model::gravity is the upright gravity; another
/// posture turns it (postureGravity()), and the settling phase lets the viscera and the dome find their new
/// rest.
///   upright        gravity -z (caudal): the paper's seated subject (the default)
///   supine         gravity -y (posterior): lying on the back
///   prone          gravity +y (anterior): lying on the front
///   left-lateral   gravity -x: lying on the left side
///   right-lateral  gravity +x: lying on the right side
enum class Posture { Upright, Supine, Prone, LeftLateral, RightLateral };

/// "upright", "supine", "prone", "left-lateral" or "right-lateral".
const char* postureName(Posture p);
/// All valid names, comma separated (for error messages).
std::string postureNames();
/// Inverse of postureName(); returns false when unknown.
bool postureFromName(const std::string& name, Posture& out);

/// Per-run physical switches and solver settings.
struct StepOptions {
  IntegratorKind integrator = IntegratorKind::ImplicitEulerJoints;
  bool gravity = true;                 ///< apply gravity (postureGravity()) to bodies and nodes
  Posture posture = Posture::Upright;  ///< direction of gravity relative to the body
  double jointFrictionScale = 1.0;     ///< [-] multiplies every joint's mu (Eq. 3); 0 = frictionless
  double gutDragScale = 1.0;           ///< [-] multiplies the visceral drag Model::gut.drag; 0 = none
  std::optional<double> kappa;         ///< [Pa] gut bulk modulus of Eq. 4, > 0; unset: Model::gut.kappa
  std::array<double, kElementGroupCount> activeGainScale{1, 1, 1, 1, 1, 1};  ///< [-] multiplies kac per group
  std::array<double, kElementGroupCount> passiveGainScale{1, 1, 1,
                                                          1, 1, 1};  ///< [-] multiplies kpe and b per group
  /// [-] {left, right}: multiplies kac of each half of the diaphragm on top of activeGainScale; each
  /// hemidiaphragm has its own phrenic nerve, so 0 on one side is a paralysed hemidiaphragm (its passive
  /// stiffness stays). The halves are split by StepConstants::elementRightShare.
  std::array<double, 2> hemidiaphragmActiveScale{1, 1};
  int jointIterations = 30;      ///< [-] max Gauss-Seidel sweeps of the joint solver
  double jointTolerance = 1e-5;  ///< [m] position projection stops below this joint error
  int cgMaxIterations = 200;  ///< [-] implicit Euler: max CG iterations (typically 0-8; up to ~90 in the step
                              ///< where many muscles go slack at once, before the refactorization)
  int preconditionerRefresh = 10;  ///< [-] implicit Euler: refactor the preconditioner at least every n steps
  int refactorIterations = 4;  ///< [-] implicit Euler: refactor when the last solve needed more CG iterations
  int refactorElementChanges =
      4;  ///< [-] implicit Euler: refactor when the 3x3 stiffness of more elements changed
          ///< by a quarter (slack/taut, activation, rotation) since the last factorization
  double cgTolerance =
      1e-2;  ///< [-] implicit Euler: relative residual of the CG solve (preconditioner norm);
             ///< 1e-2 changes validate figures by at most 0.3 % against 1e-4 (docs/cli.md)
};

/// [m] Half-width of the midline band: a strand whose rest midpoint lies within it belongs to both halves.
constexpr double kMidlineHalfWidth = 1e-3;

/// [-] Share of a strand in the body's right half from the x [m] of its rest midpoint (RAS: +x is the
/// subject's right): 1 for x > kMidlineHalfWidth, 0 for x < -kMidlineHalfWidth, 0.5 in between (the strands
/// on the midline, to the xiphoid and along the crura, are driven half by each side; their x is 0 up to
/// rounding, so its sign alone would split them at random).
inline double rightShare(double x) {
  return x > kMidlineHalfWidth ? 1.0 : x < -kMidlineHalfWidth ? 0.0 : 0.5;
}

struct StepConstants;

/// [-] The factor on kac of element `e` for the hemidiaphragm it belongs to,
/// left (1 - s) + right s with s = StepConstants::elementRightShare(e) and {left, right} =
/// StepOptions::hemidiaphragmActiveScale; exactly 1 when both halves are at 1, and 1 for every other group.
double hemidiaphragmScale(const Model& model, const StepConstants& c, int e, const StepOptions& o);

/// [Pa] The gut's bulk modulus kappa of Eq. 4 a step uses: StepOptions::kappa when set, else
/// Model::gut.kappa. The one rule for it; resolveOptions() (Simulation.h) reports it with the time step to
/// the CLI and the app.
inline double effectiveKappa(const Model& model, const StepOptions& o) {
  return o.kappa.value_or(model.gut.kappa);
}

/// [m] The rest length l0 element `e` works at in a run: Elements::restLength, shortened by the abdominal
/// wall's postural tone for the transversus and obliques upright, l0' = (1 - Gut::wallToneUpright) l0; lying
/// postures (supine, prone, lateral) have no tone. The one rule for it (the step's forces, the elastic energy
/// of computeMetrics()).
double effectiveRestLength(const Model& model, int e, const StepOptions& o);

/// [m/s^2] The gravity a run applies, in the body frame: zero when `o.gravity` is off, else Model::gravity
/// (the upright gravity) turned by a quarter turn for the lying postures, g = R(o.posture) Model::gravity:
/// supine R_x(-90 deg), prone R_x(+90 deg), left-lateral R_y(+90 deg), right-lateral R_y(-90 deg). The one
/// rule every reader of gravity uses (the step's forces, the gravity energy of computeMetrics()).
Eigen::Vector3d postureGravity(const Model& model, const StepOptions& o);

/// [N] The postural support of body `b` (Bodies::isSupported): f = -m_b postureGravity(), the body's weight
/// carried by the neck and back muscles in the run's posture; zero for a body without one. The step adds it
/// to the body's force, so a supported body feels no net gravity in any posture, at the body point
/// postureSupportPoint().
Eigen::Vector3d postureSupport(const Model& model, int b, const StepOptions& o);

/// [m] Where the postural support acts on body `b`, in its body frame relative to its centre of mass:
/// p = -h_b g/|g| (Bodies::supportHeight, g = postureGravity()), straight above the centre of mass in the
/// rest pose of the run's posture; zero without gravity or height. The step adds the torque (R p) x f of the
/// force f = postureSupport() at it; computeMetrics() counts its potential -f . (R p - p), m |g| h (1 - cos
/// of the angle the body turned from the vertical it rested on), with gravity's, whose translational part it
/// cancels.
Eigen::Vector3d postureSupportPoint(const Model& model, int b, const StepOptions& o);

/// Checks the options (finite, non-negative scales, kappa, iteration counts).
/// @throws Error naming the field and value.
void validateStepOptions(const StepOptions& o);

/// Constants of step() derived once from the model by makeStepWork() (MuJoCo's mj_setConst): rest volumes,
/// the endpoint classification, the joint tree and the sparsity of the implicit system. Never written while
/// stepping.
struct StepConstants {
  double restGutVolume = 0.0;                                 ///< [m^3] V0, gut volume at the rest pose
  Eigen::Vector3d restGutCentroid = Eigen::Vector3d::Zero();  ///< [m] centroid of the gut nodes at rest
  /// gut faces with at least two Wall nodes (the abdominal wall) (3 x #F')
  Eigen::Matrix3Xi wallTriangles;
  double restCavityVolume = 0.0;   ///< [m^3] Vr, the cavity's volume at the rest pose (Cavity)
  Eigen::VectorXd restBodyVolume;  ///< [m^3] V0_k of each soft-tissue volume body (Model::volumes) (#K)
  /// [-] each element's share in the body's right half, rightShare() of the x of its rest midpoint (#E)
  Eigen::VectorXd elementRightShare;
  /// body of endpoint A (row 0) / B (row 1), -1 for node endpoints (2 x #E)
  Eigen::Matrix2Xi endpointBody;
  /// the node when an endpoint is exactly one node (weight 1), else -1 (2 x #E)
  Eigen::Matrix2Xi endpointNode;
  /// indices of fixed-body and fixed-node entries of the implicit solver vectors
  Eigen::VectorXi fixedDofs;
  /// [1/(kg m^2)] I^-1 in the body frame, zero for fixed bodies (#B)
  std::vector<Eigen::Matrix3d> inverseInertiaBody;
  Eigen::Matrix3Xd jointLocalParent;  ///< [m] joint anchor in the parent's body frame (3 x #J)
  Eigen::Matrix3Xd jointLocalChild;   ///< [m] joint anchor in the child's body frame (3 x #J)
  std::vector<int> treeJoints;        ///< joints solved exactly by the implicit step, parents first (#tree)
  std::vector<int> attachedNodes;     ///< nodes sharing an element with a body (#attached)
  Eigen::VectorXi attachedColumn;     ///< node -> its index in attachedNodes, or -1 (#N)
  /// (row, col) of the 3 x 3 blocks of bodyBlock that can be nonzero, first entries in free coordinates,
  /// lower triangle (2 x #blocks)
  Eigen::Matrix2Xi bodyEntries;
  /// (node entry, body entry) of the 3 x 3 body-node coupling blocks that can be nonzero, the body entry in
  /// free coordinates (2 x #coupling blocks)
  Eigen::Matrix2Xi couplingEntries;
  /// the coupling block of body block row r (entries 3 r .. 3 r + 2: a body's translation at 2 b, its
  /// rotation at 2 b + 1) and attached node k, as a column of couplingEntries, or -1 ((2 #B) x #attached)
  Eigen::MatrixXi couplingSlot;
  std::vector<int> treeJointOfChild;  ///< body -> the tree joint it is the child of, or -1 (#B)
  /// implicit solver entry -> free coordinate, or -1 (fixed or dependent)
  Eigen::VectorXi freeIndex;
  Eigen::VectorXi freeCoordinates;  ///< free coordinate -> implicit solver entry (#free)
  /// SolverMemory::system's value slot of every streamed 3 x 3 block, -1 if dropped (see StepImplicit.cpp)
  std::vector<int> systemPattern;
};

/// What the implicit solver (ImplicitEulerJoints) carries from one step to the next: the preconditioner's
/// factorization, the element stiffness it was made with, its age and dt, and the last solve's CG iterations,
/// which together decide when it is refreshed. The next step depends on the State and on this, nothing else,
/// so a restart that saves the State and this continues bit-identically (Simulation::checkpoint(),
/// Checkpoint.h). Empty (hasFactorization false) in a fresh StepWork: the first implicit step then factors.
struct SolverMemory {
  bool hasFactorization = false;  ///< a factorization is held (false until the first implicit step)
  /// the preconditioner's matrix A0 and its factorization (#free / 3 blocks square); its symbolic analysis is
  /// made by makeStepWork()
  BlockLdlt system;
  /// [kg^1/2] u = dt sqrt(kappa V0) / V g over the free coordinates, at the factorization
  Eigen::VectorXd rankOne;
  Eigen::VectorXd rankOneSolve;  ///< [1/kg^1/2] A0^-1 u (#free)
  double rankOneScale = 1.0;     ///< [-] 1 / (1 + u^T A0^-1 u)
  /// [kg^1/2] v = dt J^T g_c / sqrt(C) over the free coordinates, the pleural stiffness at the factorization;
  /// empty when it had none
  Eigen::VectorXd rankTwo;
  Eigen::VectorXd rankTwoSolve;  ///< [1/kg^1/2] (A0 + u u^T)^-1 v (#free)
  double rankTwoScale = 1.0;     ///< [-] 1 / (1 + v^T (A0 + u u^T)^-1 v)
  /// [kg^1/2] u_k = dt sqrt(kappa_k V0_k) / V_k g_k of each volume body k (Model::volumes), the rank-one
  /// pressure stiffness like the gut's, over the free coordinates (#free x #K); added after the gut's and
  /// before the pleural term by Sherman-Morrison, in order
  Eigen::MatrixXd volumeRank;
  Eigen::MatrixXd volumeRankSolve;   ///< [1/kg^1/2] (A0 + u u^T + sum_{j<k} u_j u_j^T)^-1 u_k (#free x #K)
  Eigen::VectorXd volumeRankScale;   ///< [-] 1 / (1 + u_k^T volumeRankSolve_k) (#K)
  double factorDt = 0.0;             ///< [s] dt of the factorization
  Eigen::VectorXd factorAxial;       ///< [kg] dt^2 k + dt b of every element at the factorization (#E)
  Eigen::VectorXd factorTransverse;  ///< [kg] dt^2 |F| / l at the factorization (#E)
  Eigen::Matrix3Xd factorDirection;  ///< [-] elementDirection at the factorization (3 x #E)
  int factorAge = 0;                 ///< [-] steps solved with the current factorization
  /// [-] CG iterations of the last implicit step (0 after a refactorization)
  int cgIterations = 0;
};

/// Working memory of step(), overwritten within every step before it is read; no allocation per step.
struct StepScratch {
  /// [-] body rotation matrices of the step's State (#B), set first thing in step()
  std::vector<Eigen::Matrix3d> rotation;
  /// [1/(kg m^2)] R I^-1 R^T, zero for fixed bodies (#B), as rotation
  std::vector<Eigen::Matrix3d> inverseInertiaWorld;
  Eigen::Matrix3Xd bodyForce, bodyTorque;  ///< [N], [N m] world, stage 1's sums (3 x #B)
  Eigen::Matrix3Xd nodeForce;              ///< [N] stage 1's sums (3 x #N)
  Eigen::Matrix3Xd gutGradient;            ///< [m^2] dV/dx per node (3 x #N)
  /// [m^2] dV_k/dx per node of each volume body k (Model::volumes) (#K of 3 x #N)
  std::vector<Eigen::Matrix3Xd> volumeGradient;
  Eigen::Matrix3Xd cavityPosition;  ///< [m] cavity vertices at the start of the step (3 x #C)
  Eigen::Matrix3Xd cavityGradient;  ///< [m^2] dV/dx per cavity vertex (3 x #C)
  /// [m^2, m^3] dV/dq of the cavity over the implicit solver's entries (6 #B + 3 #N) at the start of the
  /// step, filled while Ppl < 0
  Eigen::VectorXd cavityGeneralized;
  double pleuralStiffness = 0.0;      ///< [Pa/m^3] 1/C while the pleural pressure acts (Ppl < 0), else 0
  Eigen::VectorXd cavityReduced;      ///< [m^2, m^3] J^T dV/dq, scratch of the factorization (6 #B + 3 #N)
  Eigen::Matrix3Xd elementDirection;  ///< [-] unit A->B direction (3 x #E)
  /// [m] endpoint minus body com, world; unused for node endpoints (3 x #E)
  Eigen::Matrix3Xd leverA, leverB;
  Eigen::VectorXd elementStiffness;  ///< [N/m] |dF/dl| of taut elements, 0 when slack (#E)
  Eigen::VectorXd elementGeometric;  ///< [N/m] transverse stiffness |F| / l of elements in tension (#E)
  Eigen::VectorXd elementDamping;    ///< [N s/m] b of taut elements, 0 when slack (#E)
  double linearKScale = 0.0;         ///< [s^2] scale of K in the packed linearisation (dt^2)
  double linearDScale = 0.0;         ///< [s] scale of D in it (dt, or 0 for the right-hand side)
  int linearNodeCount = 0;           ///< [-] packed elements between two single nodes
  /// their implicit solver offsets, A and B (2 x #E, first linearNodeCount used)
  Eigen::Matrix2Xi linearNodes;
  /// [kg] kScale k + dScale b, kScale |F| / l, then [-] the direction (5 x #E)
  Eigen::Matrix<double, 5, Eigen::Dynamic> linearNodeCoeffs;
  int linearBodyCount = 0;  ///< [-] packed elements between two bodies
  /// their implicit solver offsets 6 b, A and B (2 x #E, first linearBodyCount used)
  Eigen::Matrix2Xi linearBodies;
  /// [kg] kScale k + dScale b, kScale |F| / l, then [-] the direction and [m] the levers A and B (11 x #E)
  Eigen::Matrix<double, 11, Eigen::Dynamic> linearBodyCoeffs;
  /// [-] packed elements with a weighted-node end or a body and a node end
  int linearOtherCount = 0;
  Eigen::VectorXi linearOther;         ///< their element indices (#E, first linearOtherCount used)
  Eigen::Matrix2Xd linearOtherCoeffs;  ///< [kg] kScale k + dScale b, kScale |F| / l (2 x #E)
  /// [kg] inverse effective mass of each joint's point constraint (#J)
  std::vector<Eigen::Matrix3d> jointMassInverse;
  /// [kg, kg m, kg m^2] body block of the implicit system, J^T . J (6 #B x 6 #B)
  Eigen::MatrixXd bodyBlock;
  /// [kg, kg m] its coupling to the attached nodes, J^T ., by 3 x 3 blocks (body rows, node columns), one per
  /// column of couplingEntries (#coupling blocks)
  std::vector<Eigen::Matrix3d> couplingBlock;
  Eigen::VectorXd compactR, compactZ;  ///< preconditioner scratch over the free coordinates (#free)
  /// [kg^1/2] the factorization's right-hand sides, solved together: the gut's u, each volume body's u_k and
  /// the pleural v (#free x (#K + 2))
  Eigen::MatrixXd factorRhs;
  /// implicit solver vectors (6 #B + 3 #N); cgX starts each solve at P^-1 b and ends as dv' of the step
  Eigen::VectorXd cgX, cgR, cgZ, cgP, cgQ, cgB, cgT;
  /// [m] joint anchor minus com, world, at the step start (3 x #J)
  Eigen::Matrix3Xd treeLeverParent, treeLeverChild;
};

/// By-products of the last step that the metrics, the blow-up check and the views read.
struct StepOutputs {
  Eigen::VectorXd elementForce;        ///< [N] scalar force per element of the last step (#E)
  Eigen::VectorXd elementLength;       ///< [m] length per element at the start of the last step (#E)
  double gutVolume = 0.0;              ///< [m^3] V at the start of the last step
  double gutPressure = 0.0;            ///< [Pa] P of Eq. 4 at the start of the last step (unclamped)
  double pleuralPressure = 0.0;        ///< [Pa] Ppl of Cavity at the start of the last step (<= 0)
  Eigen::VectorXd volumeBodyVolume;    ///< [m^3] V_k of each volume body at the start of the last step (#K)
  Eigen::VectorXd volumeBodyPressure;  ///< [Pa] P_k of Eq. 4 of each volume body, unclamped (#K)
  double maxJointError = 0.0;          ///< [m] largest joint separation after the last step
};

/// Everything step() works with besides the Model and the State, split as MuJoCo splits mjModel from mjData:
/// constants of the model, the solver memory a restart needs, scratch, and outputs. Make one per (Model,
/// State) pair with makeStepWork(); a copy continues exactly like the original.
struct StepWork {
  StepConstants constants;  ///< from the model, once
  SolverMemory memory;      ///< carried from step to step; saved with the State for an exact restart
  StepScratch scratch;      ///< overwritten within each step
  StepOutputs outputs;      ///< of the last step
};

/// Computes the constants of `model` (rest volumes, joint tree, the implicit system's pattern) and allocates
/// the scratch; the solver memory starts empty.
StepWork makeStepWork(const Model& model);

/// Stage 1 alone: clears and accumulates work.scratch.bodyForce [N], bodyTorque [N m] (world, about each com)
/// and nodeForce [N] from muscles (Eq. 2), cartilage springs, gut pressure (Eq. 4, 5), the pleural pressure
/// (Cavity), joint friction (Eq. 3) and stiffness, gravity and the gyroscopic term; also fills the
/// per-element, gut and cavity by-products. Joint friction and joint stiffness are included for
/// ImplicitEulerJoints only; SymplecticEuler integrates both by backward Euler together with the ball-joint
/// constraint, after the velocity update (docs/integrator.md: unconditionally stable for light bones).
void computeForces(const Model& model, const State& state, const Activations& act, const StepOptions& options,
                   StepWork& work);

/// Advances `state` by `dt` [s] under activations `act` (forces -> integrate -> joints).
/// Reads `state`, work.constants, work.memory and the body frames of work.scratch; rewrites work.scratch and
/// work.outputs; updates work.memory.
/// Does not check for blow-ups (Simulation does) and does not compute metrics.
void step(const Model& model, State& state, double dt, const Activations& act, const StepOptions& options,
          StepWork& work);

/// Metrics of `state` (lung and gut volume, element forces of the last step, energies, landmarks).
/// Element forces come from `work.outputs` (the last step); call after step().
void computeMetrics(const Model& model, const State& state, const Activations& act,
                    const StepOptions& options, const StepWork& work, Metrics& out);

/// Checks `state` for NaN/Inf and blow-up (speeds above 100 m/s, joint error above 1 cm).
/// @throws Error naming the time, the body / node / element and a likely cause, e.g.
///   "simulation blew up at t = 1.234 s: node 17 speed 3.2e4 m/s (likely cause: dt too large for stiffness)".
void checkState(const Model& model, const State& state, const StepWork& work, double dt);

}  // namespace pneuma::sim
