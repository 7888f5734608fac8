// BlockLdlt, the 3x3-block sparse LDL^T behind the implicit integrator's preconditioner: on the
// linearised implicit system of a spring network (M + dt^2 K, SPD) it solves like a dense LDL^T, and it
// reports an indefinite matrix instead of returning garbage.
#include "pneuma/sim/BlockLdlt.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <random>
#include <string>
#include <vector>

namespace pneuma::sim {
namespace {

struct SpringNetwork {
  int nodes = 0;
  std::vector<std::array<int, 2>> springs;
  Eigen::Matrix3Xd direction;  // [-] unit spring directions (3 x #springs)
  Eigen::VectorXd mass;        // [kg] (#nodes)
};

// a jittered 4 x 4 x 4 lattice of nodes with springs to the next node along each axis and the diagonals
SpringNetwork lattice(unsigned seed) {
  SpringNetwork net;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2), m(0.01, 0.1);
  const int side = 4;
  net.nodes = side * side * side;
  Eigen::Matrix3Xd p(3, net.nodes);
  const auto id = [&](int x, int y, int z) { return x + side * (y + side * z); };
  for (int z = 0; z < side; ++z)
    for (int y = 0; y < side; ++y)
      for (int x = 0; x < side; ++x) p.col(id(x, y, z)) << x + jitter(rng), y + jitter(rng), z + jitter(rng);
  for (int z = 0; z < side; ++z)
    for (int y = 0; y < side; ++y)
      for (int x = 0; x < side; ++x)
        for (const auto& [dx, dy, dz] :
             {std::array<int, 3>{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {0, 1, 1}}) {
          if (x + dx >= side || y + dy >= side || z + dz >= side) continue;
          net.springs.push_back({id(x, y, z), id(x + dx, y + dy, z + dz)});
        }
  net.direction.resize(3, static_cast<Eigen::Index>(net.springs.size()));
  for (std::size_t s = 0; s < net.springs.size(); ++s)
    net.direction.col(static_cast<Eigen::Index>(s)) =
        (p.col(net.springs[s][1]) - p.col(net.springs[s][0])).normalized();
  net.mass = Eigen::VectorXd::NullaryExpr(net.nodes, [&] { return m(rng); });
  return net;
}

// M + dt^2 K of the network (k [N/m] per spring, dt [s]) into `ldlt` (lower triangle) and as a dense matrix
Eigen::MatrixXd assemble(const SpringNetwork& net, double k, double dt, BlockLdlt& ldlt) {
  std::vector<std::array<int, 2>> pattern;
  for (const auto& [a, b] : net.springs) pattern.push_back({b, a});
  ldlt.analyze(net.nodes, pattern);
  ldlt.clearValues();
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(3 * net.nodes, 3 * net.nodes);
  // block (r, c), r >= c, of the lower triangle
  const auto add = [&](int r, int c, const Eigen::Matrix3d& v) {
    dense.block<3, 3>(3 * r, 3 * c) += v;
    if (r != c) dense.block<3, 3>(3 * c, 3 * r) += v.transpose();
    ldlt.value(ldlt.slot(r, c)) += v;
  };
  for (int n = 0; n < net.nodes; ++n) add(n, n, net.mass(n) * Eigen::Matrix3d::Identity());
  for (std::size_t s = 0; s < net.springs.size(); ++s) {
    const Eigen::Matrix3d ke = dt * dt * k * net.direction.col(static_cast<Eigen::Index>(s)) *
                               net.direction.col(static_cast<Eigen::Index>(s)).transpose();
    const int a = net.springs[s][0], b = net.springs[s][1];
    add(a, a, ke);
    add(b, b, ke);
    add(b, a, -ke);  // b > a: the coupling block is in the lower triangle
  }
  return dense;
}

// both kernels of the factorization's inner loop (the portable one, and AVX2 + FMA where the CPU has it)
class BlockLdltKernel : public ::testing::TestWithParam<bool> {};

TEST_P(BlockLdltKernel, SolvesAStiffSpringNetworkLikeADenseLdlt) {
  // stiff springs at a large step: dt^2 k / m up to 4e4, the regime of the gut strands at dt = 20 ms
  const SpringNetwork net = lattice(7);
  BlockLdlt ldlt;
  const Eigen::MatrixXd a = assemble(net, 1e4, 0.02, ldlt);
  ldlt.setVectorKernel(GetParam());
  if (GetParam() && !ldlt.vectorKernel()) GTEST_SKIP() << "this CPU or build has no AVX2 + FMA";
  ASSERT_TRUE(ldlt.factorize());
  EXPECT_LT(ldlt.factorBlocks(), net.nodes * (net.nodes - 1) / 2) << "the factor should stay sparse";
  std::mt19937 rng(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  const Eigen::VectorXd b = Eigen::VectorXd::NullaryExpr(3 * net.nodes, [&] { return normal(rng); });
  Eigen::VectorXd x = b;
  ldlt.solve(x);
  const Eigen::VectorXd reference = a.ldlt().solve(b);
  EXPECT_LT((x - reference).norm(), 1e-10 * reference.norm());
  EXPECT_LT((a * x - b).norm(), 1e-10 * b.norm());
}

// several right-hand sides at once (the factorization's Sherman-Morrison solves): each column bit for bit as
// a solve of its own, also after a wider call has grown the workspace
TEST_P(BlockLdltKernel, SolvesColumnsTogetherAsEachAlone) {
  const SpringNetwork net = lattice(5);
  BlockLdlt ldlt;
  const Eigen::MatrixXd a = assemble(net, 1e4, 0.02, ldlt);
  ldlt.setVectorKernel(GetParam());
  if (GetParam() && !ldlt.vectorKernel()) GTEST_SKIP() << "this CPU or build has no AVX2 + FMA";
  ASSERT_TRUE(ldlt.factorize());
  std::mt19937 rng(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  const Eigen::MatrixXd b = Eigen::MatrixXd::NullaryExpr(3 * net.nodes, 4, [&] { return normal(rng); });
  for (const Eigen::Index k : {Eigen::Index(4), Eigen::Index(2)}) {
    Eigen::MatrixXd x = b;
    ldlt.solveColumns(x.leftCols(k));
    for (Eigen::Index c = 0; c < 4; ++c) {
      Eigen::VectorXd alone = b.col(c);
      if (c < k) ldlt.solve(alone);
      EXPECT_EQ(x.col(c), alone) << "column " << c << " of " << k;
    }
    EXPECT_LT((a * x.leftCols(k) - b.leftCols(k)).norm(), 1e-10 * b.leftCols(k).norm());
  }
}

INSTANTIATE_TEST_SUITE_P(Kernels, BlockLdltKernel, ::testing::Values(false, true),
                         [](const ::testing::TestParamInfo<bool>& info) {
                           return info.param ? std::string("Avx2") : std::string("Portable");
                         });

TEST(BlockLdlt, RefactorsNewValuesOnTheSamePattern) {
  const SpringNetwork net = lattice(3);
  BlockLdlt ldlt;
  assemble(net, 1e2, 0.01, ldlt);
  ASSERT_TRUE(ldlt.factorize());
  // the same pattern with other values: the second factorization must not remember the first
  BlockLdlt fresh;
  const Eigen::MatrixXd a = assemble(net, 5e3, 0.01, fresh);
  for (int i = 0; i < fresh.valueBlocks(); ++i) ldlt.value(i) = fresh.value(i);
  ASSERT_TRUE(ldlt.factorize());
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(3 * net.nodes, -1.0, 1.0);
  Eigen::VectorXd x = b;
  ldlt.solve(x);
  EXPECT_LT((a * x - b).norm(), 1e-10 * b.norm());
}

TEST(BlockLdlt, ReportsAnIndefiniteMatrix) {
  SpringNetwork net = lattice(5);
  net.mass(17) = -1.0;  // [kg] a negative mass makes M + dt^2 K indefinite
  BlockLdlt ldlt;
  assemble(net, 1e2, 0.01, ldlt);
  EXPECT_FALSE(ldlt.factorize());
}

}  // namespace
}  // namespace pneuma::sim
