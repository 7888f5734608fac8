// Stage 2 of step() for ImplicitEulerJoints: the linearly implicit Euler solve in the joint tree's
// coordinates, its matrix-free product, the assembly of the preconditioner, its factorization with the
// Sherman-Morrison updates, and the preconditioned conjugate gradient (docs/integrator.md, "Linear solve").
// Generalized velocities: u = [v_b, w_b]_b ++ [v_n]_n.
#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>

#include "StepInternal.h"
#include "pneuma/sim/Error.h"

namespace pneuma::sim::detail {

namespace {

// velocity of a weighted-node endpoint (the rare case of anchorVelocity)
Vector3d weightedNodeVelocity(const Model& m, const AnchorSet& a, int e, const double* x) {
  Vector3d v = Vector3d::Zero();
  for (int k = 0; k < 3; ++k) {
    const int nk = a.nodes(k, e);
    if (nk >= 0) v += a.weights(k, e) * Eigen::Map<const Vector3d>(x + nodeOffset(m, nk));
  }
  return v;
}

// velocity of endpoint `side` (0 = A, 1 = B) of element e under generalized velocity u, using the
// per-element endpoint classification of StepWork (body, single node, or weighted nodes)
inline Vector3d anchorVelocity(const Model& m, const StepWork& w, int side, int e, const Vector3d& lever,
                               const Eigen::VectorXd& u) {
  const double* x = u.data();
  const int b = w.constants.endpointBody(side, e);
  if (b >= 0)
    return Eigen::Map<const Vector3d>(x + 6 * b) + Eigen::Map<const Vector3d>(x + 6 * b + 3).cross(lever);
  const int n = w.constants.endpointNode(side, e);
  if (n >= 0) return Eigen::Map<const Vector3d>(x + nodeOffset(m, n));
  return weightedNodeVelocity(m, side == 0 ? m.elements.endA : m.elements.endB, e, x);
}

// adds a point force f at a weighted-node endpoint to the generalized force out (the rare case of
// addAnchorGeneralized)
void addWeightedNodeForce(const Model& m, const AnchorSet& a, int e, const Vector3d& f, double* out) {
  for (int k = 0; k < 3; ++k) {
    const int nk = a.nodes(k, e);
    if (nk >= 0) Eigen::Map<Vector3d>(out + nodeOffset(m, nk)) += a.weights(k, e) * f;
  }
}

// adds the generalized force of a point force f at endpoint `side` of element e to out
inline void addAnchorGeneralized(const Model& m, const StepWork& w, int side, int e, const Vector3d& lever,
                                 const Vector3d& f, Eigen::VectorXd& out) {
  double* x = out.data();
  const int b = w.constants.endpointBody(side, e);
  if (b >= 0) {
    Eigen::Map<Vector3d>(x + 6 * b) += f;
    Eigen::Map<Vector3d>(x + 6 * b + 3) += lever.cross(f);
    return;
  }
  const int n = w.constants.endpointNode(side, e);
  if (n >= 0) {
    Eigen::Map<Vector3d>(x + nodeOffset(m, n)) += f;
    return;
  }
  addWeightedNodeForce(m, side == 0 ? m.elements.endA : m.elements.endB, e, f, x);
}

// what the body stiffness blocks need of an element end with lever r and direction d: g = J^T d = [d; r x d]
// and [r]x, for the point Jacobian J = [I, -[r]x]
struct EndJacobian {
  Eigen::Matrix<double, 6, 1> g;
  Matrix3d s;
};

EndJacobian endJacobian(const Vector3d& d, const Vector3d& r) {
  EndJacobian e;
  e.g << d, r.cross(d);
  e.s = skew(r);
  return e;
}

// J_i^T K_e J_j (6 x 6) for the ends i, j and the element stiffness K_e = ka d d^T + kg (I - d d^T):
// (ka - kg) g_i g_j^T + kg J_i^T J_j with J_i^T J_j = [I, -[rj]x; [ri]x, -[ri]x [rj]x]
Eigen::Matrix<double, 6, 6> pointStiffness(double ka, double kg, const EndJacobian& i, const EndJacobian& j) {
  Eigen::Matrix<double, 6, 6> m = (ka - kg) * i.g * j.g.transpose();
  if (kg == 0.0) return m;
  m.block<3, 3>(0, 0).diagonal().array() += kg;
  m.block<3, 3>(0, 3) -= kg * j.s;
  m.block<3, 3>(3, 0) += kg * i.s;
  m.block<3, 3>(3, 3) -= kg * i.s * j.s;
  return m;
}

// packs the elements that take part in kScale K + dScale D (taut or in tension) for applyStiffnessDamping:
// elements between two single nodes with their solver offsets, the others by index
void linearizeElements(const Model& model, double kScale, double dScale, StepWork& w) {
  w.scratch.linearKScale = kScale;
  w.scratch.linearDScale = dScale;
  w.scratch.linearNodeCount = 0;
  w.scratch.linearBodyCount = 0;
  w.scratch.linearOtherCount = 0;
  for (int e = 0; e < model.elements.size(); ++e) {
    const double ka = kScale * w.scratch.elementStiffness(e) + dScale * w.scratch.elementDamping(e);
    const double kg = kScale * w.scratch.elementGeometric(e);
    if (ka == 0.0 && kg == 0.0) continue;
    const int na = w.constants.endpointNode(0, e), nb = w.constants.endpointNode(1, e);
    const int ba = w.constants.endpointBody(0, e), bb = w.constants.endpointBody(1, e);
    if (na >= 0 && nb >= 0) {
      const int i = w.scratch.linearNodeCount++;
      w.scratch.linearNodes.col(i) << static_cast<int>(nodeOffset(model, na)),
          static_cast<int>(nodeOffset(model, nb));
      w.scratch.linearNodeCoeffs.col(i) << ka, kg, w.scratch.elementDirection.col(e);
    } else if (ba >= 0 && bb >= 0) {
      const int i = w.scratch.linearBodyCount++;
      w.scratch.linearBodies.col(i) << 6 * ba, 6 * bb;
      w.scratch.linearBodyCoeffs.col(i) << ka, kg, w.scratch.elementDirection.col(e), w.scratch.leverA.col(e),
          w.scratch.leverB.col(e);
    } else {
      const int i = w.scratch.linearOtherCount++;
      w.scratch.linearOther(i) = e;
      w.scratch.linearOtherCoeffs.col(i) << ka, kg;
    }
  }
}

// out = kScale K u + dScale D u: the linearised stiffness and damping of elements, gut pressure and joints,
// with the scales and elements packed by linearizeElements()
void applyStiffnessDamping(const Model& model, const StepOptions& o, const StepWork& w,
                           const Eigen::VectorXd& u, Eigen::VectorXd& out) {
  const double kScale = w.scratch.linearKScale, dScale = w.scratch.linearDScale;
  out.setZero();
  // elements between two single nodes (most gut strands)
  for (int i = 0; i < w.scratch.linearNodeCount; ++i) {
    const double* c = w.scratch.linearNodeCoeffs.col(i).data();
    const Eigen::Index oa = w.scratch.linearNodes(0, i), ob = w.scratch.linearNodes(1, i);
    const Vector3d d(c[2], c[3], c[4]);
    const Vector3d du = Eigen::Map<const Vector3d>(u.data() + ob) - Eigen::Map<const Vector3d>(u.data() + oa);
    const double along = d.dot(du);
    const Vector3d y = c[0] * along * d + c[1] * (du - along * d);
    Eigen::Map<Vector3d>(out.data() + oa) -= y;
    Eigen::Map<Vector3d>(out.data() + ob) += y;
  }
  // elements between two bodies (intercostals, shoulder): the anchor velocity is v + w x r
  for (int i = 0; i < w.scratch.linearBodyCount; ++i) {
    const double* c = w.scratch.linearBodyCoeffs.col(i).data();
    const Eigen::Index oa = w.scratch.linearBodies(0, i), ob = w.scratch.linearBodies(1, i);
    const Vector3d d(c[2], c[3], c[4]), ra(c[5], c[6], c[7]), rb(c[8], c[9], c[10]);
    const Vector3d va =
        Eigen::Map<const Vector3d>(u.data() + oa) + Eigen::Map<const Vector3d>(u.data() + oa + 3).cross(ra);
    const Vector3d vb =
        Eigen::Map<const Vector3d>(u.data() + ob) + Eigen::Map<const Vector3d>(u.data() + ob + 3).cross(rb);
    const Vector3d du = vb - va;
    const double along = d.dot(du);
    const Vector3d y = c[0] * along * d + c[1] * (du - along * d);
    Eigen::Map<Vector3d>(out.data() + oa) -= y;
    Eigen::Map<Vector3d>(out.data() + oa + 3) -= ra.cross(y);
    Eigen::Map<Vector3d>(out.data() + ob) += y;
    Eigen::Map<Vector3d>(out.data() + ob + 3) += rb.cross(y);
  }
  // elements with a weighted-node end or a body and a node end
  for (int i = 0; i < w.scratch.linearOtherCount; ++i) {
    const int e = w.scratch.linearOther(i);
    const double ka = w.scratch.linearOtherCoeffs(0, i), kg = w.scratch.linearOtherCoeffs(1, i);
    const Vector3d d = w.scratch.elementDirection.col(e);
    const Vector3d ra = w.scratch.leverA.col(e), rb = w.scratch.leverB.col(e);
    const Vector3d du = anchorVelocity(model, w, 1, e, rb, u) - anchorVelocity(model, w, 0, e, ra, u);
    const double along = d.dot(du);
    const Vector3d y = ka * along * d + kg * (du - along * d);
    addAnchorGeneralized(model, w, 0, e, ra, -y, out);
    addAnchorGeneralized(model, w, 1, e, rb, y, out);
  }
  // rank-one gut pressure stiffness kappa V0 / V^2 g g^T, kept while the gut is over-full (V >= V0, where
  // Eq. 5 clamps the force to 0): the step then sees the pressure that compressing the gut raises; without
  // it one step of a suddenly contracting rectus squeezed the gut by 10 % at dt 20 ms
  if (w.constants.restGutVolume > 0.0 && kScale != 0.0) {
    const double kp = kScale * effectiveKappa(model, o) * w.constants.restGutVolume /
                      (w.outputs.gutVolume * w.outputs.gutVolume);
    const Eigen::Index nodes = 3 * static_cast<Eigen::Index>(model.nodes.size());
    const Eigen::Map<const Eigen::VectorXd> g(w.scratch.gutGradient.data(), nodes);
    const double gu = g.dot(u.tail(nodes));
    out.tail(nodes) += (kp * gu) * g;
  }
  // and each volume body's, kappa_k V0_k / V_k^2 g_k g_k^T, likewise
  for (int k = 0; k < model.volumes.size() && kScale != 0.0; ++k) {
    const double v = w.outputs.volumeBodyVolume(k);
    const double kp = kScale * model.volumes.kappa(k) * w.constants.restBodyVolume(k) / (v * v);
    const Eigen::Index nodes = 3 * static_cast<Eigen::Index>(model.nodes.size());
    const Eigen::Map<const Eigen::VectorXd> g(w.scratch.volumeGradient[at(k)].data(), nodes);
    out.tail(nodes) += (kp * g.dot(u.tail(nodes))) * g;
  }
  // rank-one pleural stiffness g_c g_c^T / C while the lungs pull (Ppl < 0), g_c = dV/dq of the cavity (its
  // geometric part -Ppl A^T H A, like the gut pressure's, is left out: it changed no energy figure
  // measurably)
  if (w.scratch.pleuralStiffness > 0.0 && kScale != 0.0)
    out += (kScale * w.scratch.pleuralStiffness * w.scratch.cavityGeneralized.dot(u)) *
           w.scratch.cavityGeneralized;
  // joint springs and friction act on the relative angular velocity
  const Joints& j = model.joints;
  for (int i = 0; i < j.size(); ++i) {
    const double mu = dScale * j.friction(i) * o.jointFrictionScale;
    if (mu == 0.0 && (kScale == 0.0 || (j.stiffness(i) == 0.0 && j.lockStiffness(i) == 0.0))) continue;
    const int p = j.parent[at(i)], c = j.child[at(i)];
    const Matrix3d kj = kScale * jointStiffness(j, i, w.scratch.rotation[at(p)]) + mu * Matrix3d::Identity();
    const Vector3d y = kj * (u.segment<3>(6 * c + 3) - u.segment<3>(6 * p + 3));
    out.segment<3>(6 * c + 3) += y;
    out.segment<3>(6 * p + 3) -= y;
  }
  maskFixed(w, out);
}

// out = (M + dt D_drag) u (block diagonal: m I for translations, world inertia for rotations; the visceral
// drag is mass-proportional, so it scales the node masses by 1 + dt beta, dt as packed by linearizeElements)
void applyMass(const Model& model, const StepOptions& o, const StepWork& w, const Eigen::VectorXd& u,
               Eigen::VectorXd& out) {
  const double nodeScale = 1.0 + w.scratch.linearDScale * effectiveDrag(model, o);
  for (int b = 0; b < model.bodies.size(); ++b) {
    const Matrix3d& r = w.scratch.rotation[at(b)];
    out.segment<3>(6 * b) = model.bodies.mass(b) * u.segment<3>(6 * b);
    out.segment<3>(6 * b + 3) = r * (model.bodies.inertia[at(b)] * (r.transpose() * u.segment<3>(6 * b + 3)));
  }
  for (int n = 0; n < model.nodes.size(); ++n)
    out.segment<3>(nodeOffset(model, n)) =
        nodeScale * model.nodes.mass(n) * u.segment<3>(nodeOffset(model, n));
}

// the dense body block of M + dt D + dt^2 K (6 #B square) and the coupling of the body entries to the
// attached nodes' entries (6 #B x 3 #attached), both restricted to the joint tree (J^T . J on the free rows,
// J^T .)
void assembleBodyBlocks(const Model& model, const StepOptions& o, const std::vector<int>& tree, StepWork& w,
                        double dt) {
  const int nb = model.bodies.size();
  Eigen::MatrixXd& a = w.scratch.bodyBlock;
  a.setZero();
  std::fill(w.scratch.couplingBlock.begin(), w.scratch.couplingBlock.end(), Matrix3d::Zero());
  // the coupling of body b's force f and torque t (3 x 3 blocks, one column per coordinate of attached node
  // `column`) to that node, gathered along the joint tree as gatherJointForces() gathers a force: up the tree
  // the force moves to the parent with the torque of its levers about both coms
  const auto couple = [&](int b, int column, const Matrix3d& f, const Matrix3d& t) {
    const auto add = [&](int row, const Matrix3d& block) {
      const int slot = w.constants.couplingSlot(row, column);
      if (slot >= 0) w.scratch.couplingBlock[at(slot)] += block;
    };
    add(2 * b + 1, t);
    int x = b;
    for (int j = w.constants.treeJointOfChild[at(x)]; j >= 0; j = w.constants.treeJointOfChild[at(x)]) {
      add(2 * x + 1, -skew(w.scratch.treeLeverChild.col(j)) * f);
      x = model.joints.parent[at(j)];
      add(2 * x + 1, skew(w.scratch.treeLeverParent.col(j)) * f);
    }
    add(2 * x, f);
  };
  for (int b = 0; b < nb; ++b) {
    const Matrix3d& r = w.scratch.rotation[at(b)];
    a.block<3, 3>(6 * b, 6 * b) = model.bodies.mass(b) * Matrix3d::Identity();
    a.block<3, 3>(6 * b + 3, 6 * b + 3) = r * model.bodies.inertia[at(b)] * r.transpose();
  }
  // elements: J_i^T K_e J_j with J = [I, -[lever]x] for body endpoints, w_k I for node k, sign -1 across the
  // ends (fixed bodies do not move)
  const Elements& el = model.elements;
  for (int e = 0; e < el.size(); ++e) {
    const int ba = w.constants.endpointBody(0, e), bb = w.constants.endpointBody(1, e);
    if (ba < 0 && bb < 0) continue;
    const double ka = dt * dt * w.scratch.elementStiffness(e) + dt * w.scratch.elementDamping(e),
                 kg = dt * dt * w.scratch.elementGeometric(e);
    if (ka == 0.0 && kg == 0.0) continue;
    const Vector3d d = w.scratch.elementDirection.col(e), ra = w.scratch.leverA.col(e),
                   rb = w.scratch.leverB.col(e);
    const bool movingA = ba >= 0 && !model.bodies.isFixed[at(ba)],
               movingB = bb >= 0 && !model.bodies.isFixed[at(bb)];
    const EndJacobian ea = endJacobian(d, ra), eb = endJacobian(d, rb);
    if (movingA) a.block<6, 6>(6 * ba, 6 * ba) += pointStiffness(ka, kg, ea, ea);
    if (movingB) a.block<6, 6>(6 * bb, 6 * bb) += pointStiffness(ka, kg, eb, eb);
    if (movingA && movingB) {
      const Eigen::Matrix<double, 6, 6> cab = pointStiffness(ka, kg, ea, eb);
      a.block<6, 6>(6 * ba, 6 * bb) -= cab;
      a.block<6, 6>(6 * bb, 6 * ba) -= cab.transpose();
    }
    // a moving body at one end, nodes at the other: -J_b^T K_e w_k = -[K_e; [lever]x K_e] w_k
    if ((ba >= 0) == (bb >= 0) || !(movingA || movingB)) continue;
    const int b = movingA ? ba : bb;
    const AnchorSet& nodes = movingA ? el.endB : el.endA;
    const Matrix3d ke = (ka - kg) * d * d.transpose() + kg * Matrix3d::Identity();
    const Matrix3d te = skew(movingA ? ra : rb) * ke;
    for (int k = 0; k < 3; ++k) {
      const int n = nodes.nodes(k, e);
      if (n >= 0)
        couple(b, w.constants.attachedColumn(n), -nodes.weights(k, e) * ke, -nodes.weights(k, e) * te);
    }
  }
  // joint springs and friction on relative angular velocity
  const Joints& j = model.joints;
  for (int i = 0; i < j.size(); ++i) {
    const int p = j.parent[at(i)], ch = j.child[at(i)];
    const Matrix3d kj = dt * dt * jointStiffness(j, i, w.scratch.rotation[at(p)]) +
                        dt * j.friction(i) * o.jointFrictionScale * Matrix3d::Identity();
    a.block<3, 3>(6 * ch + 3, 6 * ch + 3) += kj;
    a.block<3, 3>(6 * p + 3, 6 * p + 3) += kj;
    a.block<3, 3>(6 * ch + 3, 6 * p + 3) -= kj;
    a.block<3, 3>(6 * p + 3, 6 * ch + 3) -= kj;
  }
  // restrict the body block to the joint tree's coordinates: J^T A by columns (fixed bodies' columns are not
  // needed), then J^T A J as the gathered columns of its transpose (the free columns only)
  if (!tree.empty()) {
    for (int b = 0; b < nb; ++b)
      for (int k = 6 * b; k < 6 * b + 6 && !model.bodies.isFixed[at(b)]; ++k)
        gatherJointForces(model.joints, w, tree, a.col(k));
    a.transposeInPlace();  // (J^T A)^T = A J: its columns, gathered, are those of J^T A J
    for (Eigen::Index k = 0;
         k < w.constants.freeCoordinates.size() && w.constants.freeCoordinates(k) < a.rows(); ++k)
      gatherJointForces(model.joints, w, tree, a.col(w.constants.freeCoordinates(k)));
  }
}

// streams the lower triangle of the implicit system without the gut's rank-one term, J^T (M + dt D + dt^2 K0)
// J, by 3 x 3 blocks as add(row, col, block) with row >= col the first entries of the block in full
// coordinates (a diagonal block is passed whole); the sequence of (row, col) depends on the model's topology
// only
template <typename Sink>
void streamSystem(const Model& model, const StepOptions& o, const StepWork& w, double dt, Sink&& add) {
  // bodies, where they can couple
  for (Eigen::Index i = 0; i < w.constants.bodyEntries.cols(); ++i)
    add(w.constants.bodyEntries(0, i), w.constants.bodyEntries(1, i),
        w.scratch.bodyBlock.block<3, 3>(w.constants.bodyEntries(0, i), w.constants.bodyEntries(1, i)));
  // attached nodes and bodies, where they can couple (couplingBlock holds body rows, node columns)
  for (Eigen::Index i = 0; i < w.constants.couplingEntries.cols(); ++i)
    add(w.constants.couplingEntries(0, i), w.constants.couplingEntries(1, i),
        w.scratch.couplingBlock[static_cast<std::size_t>(i)].transpose());
  // node masses and the visceral drag, (1 + dt beta) m I
  const double dragScale = 1.0 + dt * effectiveDrag(model, o);
  for (int n = 0; n < model.nodes.size(); ++n)
    add(nodeOffset(model, n), nodeOffset(model, n), dragScale * model.nodes.mass(n) * Matrix3d::Identity());
  // elements between nodes: w_k w_l s_k s_l K_e for every pair of node terms of the two endpoints
  const Elements& el = model.elements;
  for (int e = 0; e < el.size(); ++e) {
    if (w.constants.endpointBody(0, e) >= 0 && w.constants.endpointBody(1, e) >= 0) continue;
    const double ka = dt * dt * w.scratch.elementStiffness(e) + dt * w.scratch.elementDamping(e),
                 kg = dt * dt * w.scratch.elementGeometric(e);
    const Vector3d d = w.scratch.elementDirection.col(e);
    const Matrix3d ke = (ka - kg) * d * d.transpose() + kg * Matrix3d::Identity();
    // two distinct single nodes (most elements): K_e on both diagonals, -K_e between them
    const int n0 = w.constants.endpointNode(0, e), n1 = w.constants.endpointNode(1, e);
    if (n0 >= 0 && n1 >= 0 && n0 != n1) {
      add(nodeOffset(model, n0), nodeOffset(model, n0), ke);
      add(nodeOffset(model, n1), nodeOffset(model, n1), ke);
      add(nodeOffset(model, std::max(n0, n1)), nodeOffset(model, std::min(n0, n1)), -ke);
      continue;
    }
    for (int sa = 0; sa < 2; ++sa) {
      if (w.constants.endpointBody(sa, e) >= 0) continue;
      const AnchorSet& a = sa == 0 ? el.endA : el.endB;
      for (int sb = 0; sb < 2; ++sb) {
        if (w.constants.endpointBody(sb, e) >= 0) continue;
        const AnchorSet& b = sb == 0 ? el.endA : el.endB;
        for (int ka3 = 0; ka3 < 3; ++ka3) {
          for (int kb3 = 0; kb3 < 3; ++kb3) {
            const int na = a.nodes(ka3, e), nb = b.nodes(kb3, e);
            if (na < 0 || nb < 0 || na < nb) continue;
            const double s = (sa == sb ? 1.0 : -1.0) * a.weights(ka3, e) * b.weights(kb3, e);
            add(nodeOffset(model, na), nodeOffset(model, nb), s * ke);
          }
        }
      }
    }
  }
}

// the volume bodies' Sherman-Morrison corrections j < n, in order: z = (A0 + u u^T)^-1 r (the gut's term
// applied) becomes (A0 + u u^T + sum_{j<n} u_j u_j^T)^-1 r
void applyVolumeCorrections(const StepWork& w, int n, Eigen::VectorXd& z) {
  for (int j = 0; j < n; ++j)
    z -= (w.memory.volumeRankScale(j) * w.memory.volumeRank.col(j).dot(z)) * w.memory.volumeRankSolve.col(j);
}

// the preconditioner: a sparse LDLT factorization of the reduced system without the gut's rank-one term,
// kept for several steps, plus that term by Sherman-Morrison; u = sqrt(kp) g over the free coordinates
void factorSystem(const Model& model, const StepOptions& o, const std::vector<int>& tree, StepWork& w,
                  double dt) {
  // values (the free coordinates and the pattern are analyzeSystem()'s), then the numeric factorization
  assembleBodyBlocks(model, o, tree, w, dt);
  w.memory.system.clearValues();
  std::size_t slot = 0;
  streamSystem(model, o, w, dt, [&](Eigen::Index, Eigen::Index, const auto& block) {
    const int k = w.constants.systemPattern[slot++];
    if (k >= 0) w.memory.system.value(k) += block;
  });
  if (!w.memory.system.factorize())
    throw Error(
        "implicit solve: the system matrix is not positive definite (likely cause: a negative stiffness or "
        "mass)");
  // the rank-one terms on top, by Sherman-Morrison, (A + u u^T)^-1 = A^-1 - A^-1 u u^T A^-1 / (1 + u^T A^-1
  // u): the gut pressure's kp g g^T = u u^T, then each volume body's u_k u_k^T, then the pleural v v^T with v
  // = dt J^T g_c / sqrt(C); their solves with A0 first, together (columns 0, 1 .. #K, #K + 1 of factorRhs)
  const Eigen::Index nf = w.constants.freeCoordinates.size();
  const int nk = model.volumes.size();
  const auto bodyEntries = 6 * static_cast<Eigen::Index>(model.bodies.size());
  Eigen::MatrixXd& rhs = w.scratch.factorRhs;
  rhs.setZero();
  const auto gather = [&](Eigen::Index column, double scale, const Eigen::Matrix3Xd& gradient) {
    for (Eigen::Index k = 0; k < nf; ++k) {
      const Eigen::Index i = w.constants.freeCoordinates(k) - bodyEntries;
      if (i >= 0) rhs(k, column) = scale * gradient(i % 3, i / 3);
    }
  };
  if (w.constants.restGutVolume > 0.0)
    gather(0, dt * std::sqrt(effectiveKappa(model, o) * w.constants.restGutVolume) / w.outputs.gutVolume,
           w.scratch.gutGradient);
  for (int b = 0; b < nk; ++b)
    gather(1 + b,
           dt * std::sqrt(model.volumes.kappa(b) * w.constants.restBodyVolume(b)) /
               w.outputs.volumeBodyVolume(b),
           w.scratch.volumeGradient[at(b)]);
  const bool pleural = w.scratch.pleuralStiffness > 0.0;
  if (pleural) {
    Eigen::VectorXd& v = w.scratch.cavityReduced;
    v = w.scratch.cavityGeneralized;
    gatherJointForces(model.joints, w, tree, v);
    maskReduced(model.joints, w, tree, v);
    const double sv = dt * std::sqrt(w.scratch.pleuralStiffness);
    for (Eigen::Index k = 0; k < nf; ++k) rhs(k, nk + 1) = sv * v(w.constants.freeCoordinates(k));
  }
  w.memory.rankOne = rhs.col(0);
  w.memory.volumeRank = rhs.middleCols(1, nk);
  if (pleural)
    w.memory.rankTwo = rhs.col(nk + 1);
  else
    w.memory.rankTwo.resize(0);
  w.memory.system.solveColumns(rhs.leftCols(nk + (pleural ? 2 : 1)));
  w.memory.rankOneSolve = rhs.col(0);
  w.memory.rankOneScale = 1.0 / (1.0 + w.memory.rankOne.dot(w.memory.rankOneSolve));
  w.memory.volumeRankSolve.setZero(nf, nk);
  w.memory.volumeRankScale.setZero(nk);
  for (int b = 0; b < nk; ++b) {
    w.scratch.compactZ = rhs.col(1 + b);
    w.scratch.compactZ -=
        (w.memory.rankOneScale * w.memory.rankOne.dot(w.scratch.compactZ)) * w.memory.rankOneSolve;
    applyVolumeCorrections(w, b, w.scratch.compactZ);
    w.memory.volumeRankSolve.col(b) = w.scratch.compactZ;
    w.memory.volumeRankScale(b) = 1.0 / (1.0 + w.memory.volumeRank.col(b).dot(w.scratch.compactZ));
  }
  if (pleural) {
    w.memory.rankTwoSolve = rhs.col(nk + 1);
    w.memory.rankTwoSolve -=
        (w.memory.rankOneScale * w.memory.rankOne.dot(w.memory.rankTwoSolve)) * w.memory.rankOneSolve;
    applyVolumeCorrections(w, nk, w.memory.rankTwoSolve);
    w.memory.rankTwoScale = 1.0 / (1.0 + w.memory.rankTwo.dot(w.memory.rankTwoSolve));
  }
  w.memory.hasFactorization = true;
  w.memory.factorDt = dt;
  w.memory.factorAge = 0;
  w.memory.factorAxial = dt * dt * w.scratch.elementStiffness + dt * w.scratch.elementDamping;
  w.memory.factorTransverse = dt * dt * w.scratch.elementGeometric;
  w.memory.factorDirection = w.scratch.elementDirection;
}

// z = P^-1 r with the factored system (zero on the masked coordinates)
void applyPreconditioner(StepWork& w, const Eigen::VectorXd& r, Eigen::VectorXd& z) {
  const Eigen::Index nf = w.constants.freeCoordinates.size();
  for (Eigen::Index k = 0; k < nf; ++k) w.scratch.compactR(k) = r(w.constants.freeCoordinates(k));
  w.scratch.compactZ = w.scratch.compactR;
  w.memory.system.solve(w.scratch.compactZ);
  w.scratch.compactZ -=
      (w.memory.rankOneScale * w.memory.rankOne.dot(w.scratch.compactZ)) * w.memory.rankOneSolve;
  applyVolumeCorrections(w, static_cast<int>(w.memory.volumeRankScale.size()), w.scratch.compactZ);
  if (w.memory.rankTwo.size() > 0)
    w.scratch.compactZ -=
        (w.memory.rankTwoScale * w.memory.rankTwo.dot(w.scratch.compactZ)) * w.memory.rankTwoSolve;
  z.setZero();
  for (Eigen::Index k = 0; k < nf; ++k) z(w.constants.freeCoordinates(k)) = w.scratch.compactZ(k);
}

// out = J^T (M + dt D + dt^2 K) J u in the joint tree's coordinates, dt as packed by linearizeElements (t, z:
// scratch)
void applySystem(const Model& model, const StepOptions& o, const StepWork& w, const std::vector<int>& tree,
                 const Eigen::VectorXd& u, Eigen::VectorXd& t, Eigen::VectorXd& z, Eigen::VectorXd& out) {
  t = u;
  expandJointVelocities(model.joints, w, tree, t);
  applyStiffnessDamping(model, o, w, t, out);
  applyMass(model, o, w, t, z);
  out += z;
  gatherJointForces(model.joints, w, tree, out);
  maskReduced(model.joints, w, tree, out);
}

}  // namespace

void updateTreeLevers(const Model& model, StepWork& w) {
  for (int j : w.constants.treeJoints) {
    w.scratch.treeLeverParent.col(j) =
        w.scratch.rotation[at(model.joints.parent[at(j)])] * w.constants.jointLocalParent.col(j);
    w.scratch.treeLeverChild.col(j) =
        w.scratch.rotation[at(model.joints.child[at(j)])] * w.constants.jointLocalChild.col(j);
  }
}

void stiffnessProduct(const Model& model, const StepOptions& o, StepWork& w, const Eigen::VectorXd& u,
                      Eigen::VectorXd& out) {
  linearizeElements(model, 1.0, 0.0, w);
  out.resize(u.size());
  applyStiffnessDamping(model, o, w, u, out);
}

Eigen::MatrixXd assembledSystem(const Model& model, const StepOptions& o, StepWork& w, double dt) {
  updateTreeLevers(model, w);
  assembleBodyBlocks(model, o, w.constants.treeJoints, w, dt);
  const Eigen::Index n = w.scratch.cgX.size();
  Eigen::MatrixXd full = Eigen::MatrixXd::Zero(n, n);
  streamSystem(model, o, w, dt, [&](Eigen::Index row, Eigen::Index col, const auto& block) {
    full.block<3, 3>(row, col) += block;
    if (row != col) full.block<3, 3>(col, row) += block.transpose();
  });
  const Eigen::VectorXi& free = w.constants.freeCoordinates;
  Eigen::MatrixXd a(free.size(), free.size());
  for (Eigen::Index i = 0; i < free.size(); ++i)
    for (Eigen::Index j = 0; j < free.size(); ++j) a(i, j) = full(free(i), free(j));
  return a;
}

// the free coordinates of the implicit solve and the pattern of its matrix, from the model's topology (the
// joint tree, the elements' endpoints): once per model, by makeStepWork(); the streamed values do not matter
// here
void analyzeSystem(const Model& model, StepWork& w) {
  const std::vector<int>& tree = w.constants.treeJoints;
  const StepOptions o;
  const double dt = 0.0;
  Eigen::VectorXd mask = Eigen::VectorXd::Ones(w.scratch.cgX.size());
  maskReduced(model.joints, w, tree, mask);
  w.constants.freeIndex.setConstant(mask.size(), -1);
  std::vector<int> free;
  for (Eigen::Index i = 0; i < mask.size(); ++i)
    if (mask(i) != 0.0) {
      w.constants.freeIndex(i) = static_cast<int>(free.size());
      free.push_back(static_cast<int>(i));
    }
  w.constants.freeCoordinates =
      Eigen::Map<const Eigen::VectorXi>(free.data(), static_cast<Eigen::Index>(free.size()));
  // which entries can be nonzero: a body couples to the bodies it shares an element or a joint with, an
  // attached node to the bodies of its elements; in the joint tree's coordinates each body stands for
  // itself and its ancestors (its motion is theirs plus its own)
  const int nb = model.bodies.size();
  std::vector<int> parentOf(at(nb), -1);
  w.constants.treeJointOfChild.assign(at(nb), -1);
  for (int j : tree) {
    parentOf[at(model.joints.child[at(j)])] = model.joints.parent[at(j)];
    w.constants.treeJointOfChild[at(model.joints.child[at(j)])] = j;
  }
  Eigen::Matrix<char, Eigen::Dynamic, Eigen::Dynamic> bodyMask, couplingMask;  // #B x #B, #B x #attached
  bodyMask.setZero(nb, nb);
  const auto coupleBodies = [&](int b1, int b2) {
    for (int x = b1; x >= 0; x = parentOf[at(x)])
      for (int y = b2; y >= 0; y = parentOf[at(y)]) bodyMask(x, y) = bodyMask(y, x) = 1;
  };
  for (int b = 0; b < nb; ++b) coupleBodies(b, b);
  for (int i = 0; i < model.joints.size(); ++i)
    coupleBodies(model.joints.parent[at(i)], model.joints.child[at(i)]);
  couplingMask.setZero(nb, static_cast<Eigen::Index>(w.constants.attachedNodes.size()));
  const Elements& el = model.elements;
  for (int e = 0; e < el.size(); ++e) {
    if (w.constants.endpointBody(0, e) >= 0 && w.constants.endpointBody(1, e) >= 0)
      coupleBodies(w.constants.endpointBody(0, e), w.constants.endpointBody(1, e));
    for (int side = 0; side < 2; ++side) {
      const int body = w.constants.endpointBody(1 - side, e);
      if (w.constants.endpointBody(side, e) >= 0 || body < 0 || model.bodies.isFixed[at(body)]) continue;
      const AnchorSet& a = side == 0 ? el.endA : el.endB;
      for (int k = 0; k < 3; ++k)
        for (int b = body; b >= 0 && a.nodes(k, e) >= 0; b = parentOf[at(b)])
          couplingMask(b, w.constants.attachedColumn(a.nodes(k, e))) = 1;
    }
  }
  // the masks as lists of 3 x 3 blocks over the free body coordinates (which come first, by whole blocks)
  std::vector<int> bodyEntries, couplingEntries;
  std::size_t freeBodies = 0;
  while (freeBodies < free.size() && free[freeBodies] < 6 * nb) freeBodies += 3;
  for (std::size_t c = 0; c < freeBodies; c += 3)
    for (std::size_t r = c; r < freeBodies; r += 3)
      if (bodyMask(free[r] / 6, free[c] / 6)) bodyEntries.insert(bodyEntries.end(), {free[r], free[c]});
  const auto attached = static_cast<Eigen::Index>(w.constants.attachedNodes.size());
  w.constants.couplingSlot.setConstant(2 * nb, attached, -1);
  for (Eigen::Index k = 0; k < attached; ++k) {
    const int row =
        static_cast<int>(nodeOffset(model, w.constants.attachedNodes[static_cast<std::size_t>(k)]));
    for (std::size_t c = 0; c < freeBodies; c += 3)
      if (couplingMask(free[c] / 6, k)) {
        w.constants.couplingSlot(free[c] / 3, k) = static_cast<int>(couplingEntries.size() / 2);
        couplingEntries.insert(couplingEntries.end(), {row, free[c]});
      }
  }
  w.constants.bodyEntries = Eigen::Map<const Eigen::Matrix2Xi>(
      bodyEntries.data(), 2, static_cast<Eigen::Index>(bodyEntries.size() / 2));
  w.constants.couplingEntries = Eigen::Map<const Eigen::Matrix2Xi>(
      couplingEntries.data(), 2, static_cast<Eigen::Index>(couplingEntries.size() / 2));
  w.scratch.couplingBlock.assign(couplingEntries.size() / 2, Matrix3d::Zero());
  // every streamed block in free blocks, (-1, -1) when fixed or dependent (free coordinates come in whole
  // blocks: a node's three, a jointed body's rotation, a free body's translation and rotation)
  std::vector<std::array<int, 2>> blocks;
  streamSystem(model, o, w, dt, [&](Eigen::Index r, Eigen::Index c, const auto&) {
    const int fr = w.constants.freeIndex(r), fc = w.constants.freeIndex(c);
    blocks.push_back(fr >= 0 && fc >= 0 ? std::array<int, 2>{fr / 3, fc / 3} : std::array<int, 2>{-1, -1});
  });
  const Eigen::Index nf = w.constants.freeCoordinates.size();
  std::vector<std::array<int, 2>> pattern;
  std::copy_if(blocks.begin(), blocks.end(), std::back_inserter(pattern),
               [](const auto& b) { return b[0] >= 0; });
  w.memory.system.analyze(static_cast<int>(nf / 3), pattern);
  // the value slot of every streamed block, -1 when dropped
  w.constants.systemPattern.clear();
  for (const auto& [r, c] : blocks)
    w.constants.systemPattern.push_back(r >= 0 ? w.memory.system.slot(r, c) : -1);
  w.scratch.compactR.setZero(nf);
  w.scratch.compactZ.setZero(nf);
  w.scratch.factorRhs.setZero(nf, model.volumes.size() + 2);
}

// linearly implicit Euler (Baraff & Witkin 1998): (M + dt D + dt^2 K) dv = dt (f - dt K v), by PCG, in the
// coordinates of the joint tree (dv = J dv': the tree joints hold exactly in the linearised step)
void implicitVelocityUpdate(const Model& model, State& s, double dt, const StepOptions& o, StepWork& w) {
  const int nb = model.bodies.size(), nn = model.nodes.size();
  Eigen::VectorXd &x = w.scratch.cgX, &r = w.scratch.cgR, &z = w.scratch.cgZ, &p = w.scratch.cgP,
                  &q = w.scratch.cgQ, &rhs = w.scratch.cgB, &t = w.scratch.cgT;
  const std::vector<int>& tree = w.constants.treeJoints;
  updateTreeLevers(model, w);

  // current generalized velocity and forces
  for (int b = 0; b < nb; ++b) {
    p.segment<3>(6 * b) = s.bodyVelocity.col(b);
    p.segment<3>(6 * b + 3) = s.bodyAngularVelocity.col(b);
    rhs.segment<3>(6 * b) = w.scratch.bodyForce.col(b);
    rhs.segment<3>(6 * b + 3) = w.scratch.bodyTorque.col(b);
  }
  for (int n = 0; n < nn; ++n) {
    p.segment<3>(nodeOffset(model, n)) = s.nodeVelocity.col(n);
    rhs.segment<3>(nodeOffset(model, n)) = w.scratch.nodeForce.col(n);
  }
  linearizeElements(model, dt * dt, 0.0, w);
  applyStiffnessDamping(model, o, w, p, q);
  rhs = dt * rhs - q;
  gatherJointForces(model.joints, w, tree, rhs);
  maskReduced(model.joints, w, tree, rhs);

  // preconditioned conjugate gradient on M + dt D + dt^2 K; a stale factorization is a good preconditioner
  // for a few steps: refresh it when it has aged, when the last solve needed many iterations, when the
  // stiffness of several elements changed much (muscles going slack or taut, activation steps, fast
  // rotation), or when dt changed
  int changed = 0;
  for (Eigen::Index e = 0; e < w.memory.factorAxial.size(); ++e) {
    // |K_e - K_e0| <= |a - a0| + |g - g0| + 2 max(a, a0) |d - d0| for K_e = a d d^T + g (I - d d^T)
    const double a = dt * dt * w.scratch.elementStiffness(e) + dt * w.scratch.elementDamping(e),
                 g = dt * dt * w.scratch.elementGeometric(e);
    const double a0 = w.memory.factorAxial(e), g0 = w.memory.factorTransverse(e);
    const double change =
        std::abs(a - a0) + std::abs(g - g0) +
        2.0 * std::max(a, a0) * (w.scratch.elementDirection.col(e) - w.memory.factorDirection.col(e)).norm();
    changed += change > 0.25 * std::max(a0, g0) && change > 0.0;
  }
  const bool stale = !w.memory.hasFactorization || w.memory.factorAge >= o.preconditionerRefresh ||
                     w.memory.cgIterations > o.refactorIterations || changed > o.refactorElementChanges ||
                     dt != w.memory.factorDt ||
                     (w.scratch.pleuralStiffness > 0.0) != (w.memory.rankTwo.size() > 0);
  if (stale) factorSystem(model, o, tree, w, dt);
  ++w.memory.factorAge;
  linearizeElements(model, dt * dt, dt, w);
  // start from x = P^-1 rhs, which is the solution right after a refactorization (P is then the system
  // itself); else rhs^T P^-1 rhs scales the stop test: a relative residual, or the residual's energy norm
  // r^T P^-1 r below 1e-12 J
  applyPreconditioner(w, rhs, x);
  int it = 0;
  if (!stale) {
    const double stop = std::max(o.cgTolerance * o.cgTolerance * rhs.dot(x), 1e-24);
    applySystem(model, o, w, tree, x, t, z, q);
    r = rhs - q;
    applyPreconditioner(w, r, z);
    p = z;
    double rz = r.dot(z);
    for (; it < o.cgMaxIterations && rz > stop; ++it) {
      applySystem(model, o, w, tree, p, t, z, q);
      const double alpha = rz / p.dot(q);
      x += alpha * p;
      r -= alpha * q;
      applyPreconditioner(w, r, z);
      const double rzNew = r.dot(z);
      p = z + (rzNew / rz) * p;
      rz = rzNew;
    }
  }
  w.memory.cgIterations = it;

  // v += J dv'
  t = x;
  expandJointVelocities(model.joints, w, tree, t);
  for (int b = 0; b < nb; ++b) {
    if (model.bodies.isFixed[at(b)]) continue;
    s.bodyVelocity.col(b) += t.segment<3>(6 * b);
    s.bodyAngularVelocity.col(b) += t.segment<3>(6 * b + 3);
  }
  for (int n = 0; n < nn; ++n) {
    if (!model.nodes.isFixed(n)) s.nodeVelocity.col(n) += t.segment<3>(nodeOffset(model, n));
  }
}

}  // namespace pneuma::sim::detail
