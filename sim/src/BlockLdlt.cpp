#include "pneuma/sim/BlockLdlt.h"

#include <Eigen/LU>
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCore>
#include <algorithm>

#include "BlockLdltKernels.h"

namespace pneuma::sim {

namespace {
std::size_t at(int i) { return static_cast<std::size_t>(i); }
}  // namespace

void BlockLdlt::analyze(int blocks, const std::vector<std::array<int, 2>>& pattern) {
  m_n = blocks;
  // ordering: approximate minimum degree of the block graph
  std::vector<Eigen::Triplet<double>> graph;
  graph.reserve(pattern.size() + at(blocks));
  for (const auto& [r, c] : pattern) graph.emplace_back(std::max(r, c), std::min(r, c), 1.0);
  for (int k = 0; k < blocks; ++k) graph.emplace_back(k, k, 1.0);
  Eigen::SparseMatrix<double> g(blocks, blocks);
  g.setFromTriplets(graph.begin(), graph.end());
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> amd;
  Eigen::AMDOrdering<int>()(g, amd);
  m_perm.assign(amd.indices().data(), amd.indices().data() + blocks);
  m_permInverse.assign(at(blocks), 0);
  for (int k = 0; k < blocks; ++k) m_permInverse[at(m_perm[at(k)])] = k;

  // A's upper triangle by permuted blocks, column-compressed, rows sorted
  std::vector<std::vector<int>> rows(at(blocks));
  for (int k = 0; k < blocks; ++k) rows[at(k)].push_back(k);
  for (const auto& [r, c] : pattern) {
    const int pr = m_permInverse[at(r)], pc = m_permInverse[at(c)];
    rows[at(std::max(pr, pc))].push_back(std::min(pr, pc));
  }
  m_ap.assign(1, 0);
  m_ai.clear();
  for (auto& col : rows) {
    std::sort(col.begin(), col.end());
    col.erase(std::unique(col.begin(), col.end()), col.end());
    m_ai.insert(m_ai.end(), col.begin(), col.end());
    m_ap.push_back(static_cast<int>(m_ai.size()));
  }
  m_a.assign(m_ai.size(), Eigen::Matrix3d::Zero());
  // a block stored as A(original row >= original col) is A(permuted) transposed when the permutation flips it
  m_aTransposed.assign(m_ai.size(), 0);
  for (int k = 0; k < blocks; ++k)
    for (int p = m_ap[at(k)]; p < m_ap[at(k) + 1]; ++p)
      m_aTransposed[at(p)] = m_perm[at(m_ai[at(p)])] < m_perm[at(k)] ? 1 : 0;

  // elimination tree and column counts of L (Davis' ldl_symbolic)
  m_parent.assign(at(blocks), -1);
  m_flag.assign(at(blocks), -1);
  m_lnz.assign(at(blocks), 0);
  for (int k = 0; k < blocks; ++k) {
    m_flag[at(k)] = k;
    for (int p = m_ap[at(k)]; p < m_ap[at(k) + 1]; ++p) {
      for (int i = m_ai[at(p)]; i < k && m_flag[at(i)] != k; i = m_parent[at(i)]) {
        if (m_parent[at(i)] == -1) m_parent[at(i)] = k;
        ++m_lnz[at(i)];
        m_flag[at(i)] = k;
      }
    }
  }
  m_lp.assign(at(blocks) + 1, 0);
  for (int k = 0; k < blocks; ++k) m_lp[at(k) + 1] = m_lp[at(k)] + m_lnz[at(k)];
  m_li.assign(at(m_lp.back()), 0);
  m_l.assign(at(m_lp.back()), Block::Zero());
  m_dInverse.assign(at(blocks), Eigen::Matrix3d::Zero());
  m_y.assign(at(blocks), Block::Zero());
  setVectorKernel(true);
  m_pattern.assign(at(blocks), 0);
  m_x.setZero(3 * blocks + 1, 1);
}

int BlockLdlt::slot(int r, int c) const {
  const int pr = m_permInverse[at(r)], pc = m_permInverse[at(c)];
  const int col = std::max(pr, pc), row = std::min(pr, pc);
  const auto begin = m_ai.begin() + m_ap[at(col)], end = m_ai.begin() + m_ap[at(col) + 1];
  return static_cast<int>(std::lower_bound(begin, end, row) - m_ai.begin());
}

void BlockLdlt::clearValues() { std::fill(m_a.begin(), m_a.end(), Eigen::Matrix3d::Zero()); }

void BlockLdlt::setVectorKernel(bool allowed) {
#ifdef PNEUMA_AVX2_KERNELS
  m_avx2 = allowed && kernels::hasAvx2();
#else
  m_avx2 = false;
  (void)allowed;
#endif
}

bool BlockLdlt::factorize() {
  using Eigen::Matrix3d;
  const int n = m_n;
  for (int k = 0; k < n; ++k) {
    // scatter column k of A's upper triangle into y and find the pattern of row k of L (etree reach)
    int top = n;
    m_flag[at(k)] = k;
    m_lnz[at(k)] = 0;
    Matrix3d d = Matrix3d::Zero();
    for (int p = m_ap[at(k)]; p < m_ap[at(k) + 1]; ++p) {
      int i = m_ai[at(p)];
      const Matrix3d& a = m_a[at(p)];
      if (i == k) {
        // diagonal block: the lower triangle is stored
        d = a.triangularView<Eigen::Lower>();
        d.triangularView<Eigen::StrictlyUpper>() = a.triangularView<Eigen::StrictlyLower>().transpose();
        continue;
      }
      m_y[at(i)].topRows<3>() = m_aTransposed[at(p)] ? Matrix3d(a.transpose()) : a;
      int len = 0;
      for (; m_flag[at(i)] != k; i = m_parent[at(i)]) {
        m_pattern[at(len++)] = i;
        m_flag[at(i)] = k;
      }
      while (len > 0) m_pattern[at(--top)] = m_pattern[at(--len)];
    }
    // sparse triangular solve along the pattern; y_i = D_i L(k, i)^T
    for (; top < n; ++top) {
      const int i = m_pattern[at(top)];
      const Matrix3d yi = m_y[at(i)].topRows<3>();
      m_y[at(i)].setZero();
      const int begin = m_lp[at(i)], end = begin + m_lnz[at(i)];
      if (m_avx2)
        kernels::subtractProductsAvx2(m_y.data()->data(), m_l.data()->data() + 12 * begin,
                                      m_li.data() + begin, end - begin, yi.data());
      else
        for (int p = begin; p < end; ++p)
          m_y[at(m_li[at(p)])].topRows<3>().noalias() -= m_l[at(p)].topRows<3>() * yi;
      // L(k, i) = Y_i^T D_i^-1 = (D_i^-1 Y_i)^T (D_i^-1 is symmetric): column products, no horizontal sums
      const Matrix3d lki = (m_dInverse[at(i)] * yi).transpose();
      d.noalias() -= lki * yi;
      m_li[at(end)] = k;
      m_l[at(end)].topRows<3>() = lki;
      ++m_lnz[at(i)];
    }
    // the pivot block must be symmetric positive definite (Sylvester: positive leading minors); then its
    // closed-form inverse
    const Matrix3d pivot = 0.5 * (d + d.transpose());
    const double minor2 = pivot(0, 0) * pivot(1, 1) - pivot(0, 1) * pivot(1, 0);
    if (!(pivot(0, 0) > 0.0 && minor2 > 0.0 && pivot.determinant() > 0.0)) return false;
    m_dInverse[at(k)] = pivot.inverse();
  }
  return true;
}

void BlockLdlt::solve(Eigen::VectorXd& x) const { substitute(x.data(), x.size(), 1); }

void BlockLdlt::solveColumns(Eigen::Ref<Eigen::MatrixXd> x) const {
  substitute(x.data(), x.outerStride(), x.cols());
}

void BlockLdlt::substitute(double* x, Eigen::Index stride, Eigen::Index columns) const {
  const int n = m_n;
  if (m_x.cols() < columns) m_x.setZero(3 * n + 1, columns);
  const auto in = [&](Eigen::Index c) { return Eigen::Map<Eigen::VectorXd>(x + c * stride, 3 * n); };
  for (Eigen::Index c = 0; c < columns; ++c)
    for (int k = 0; k < n; ++k) m_x.col(c).segment<3>(3 * k) = in(c).segment<3>(3 * m_perm[at(k)]);
  // L z = b (column by column), then D
  for (int i = 0; i < n; ++i) {
    const int begin = m_lp[at(i)], end = m_lp[at(i) + 1];
    for (Eigen::Index c = 0; c < columns; ++c) {
      auto z = m_x.col(c);
      const Eigen::Vector3d zi = z.segment<3>(3 * i);
      if (m_avx2)
        kernels::forwardColumnAvx2(z.data(), m_l.data()->data() + 12 * begin, m_li.data() + begin,
                                   end - begin, zi.data());
      else
        for (int p = begin; p < end; ++p)
          z.segment<3>(3 * m_li[at(p)]).noalias() -= m_l[at(p)].topRows<3>() * zi;
    }
  }
  for (Eigen::Index c = 0; c < columns; ++c)
    for (int i = 0; i < n; ++i)
      m_x.col(c).segment<3>(3 * i) = m_dInverse[at(i)] * m_x.col(c).segment<3>(3 * i).eval();
  // L^T x = z
  for (int i = n - 1; i >= 0; --i) {
    const int begin = m_lp[at(i)], end = m_lp[at(i) + 1];
    for (Eigen::Index c = 0; c < columns; ++c) {
      auto z = m_x.col(c);
      Eigen::Vector3d xi = z.segment<3>(3 * i);
      if (m_avx2)
        kernels::backwardColumnAvx2(xi.data(), z.data(), m_l.data()->data() + 12 * begin, m_li.data() + begin,
                                    end - begin);
      else
        for (int p = begin; p < end; ++p)
          xi.noalias() -= m_l[at(p)].topRows<3>().transpose() * z.segment<3>(3 * m_li[at(p)]);
      z.segment<3>(3 * i) = xi;
    }
  }
  for (Eigen::Index c = 0; c < columns; ++c)
    for (int k = 0; k < n; ++k) in(c).segment<3>(3 * m_perm[at(k)]) = m_x.col(c).segment<3>(3 * k);
}

}  // namespace pneuma::sim
