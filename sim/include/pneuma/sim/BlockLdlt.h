#pragma once
/// @file BlockLdlt.h
/// Sparse LDL^T factorization of a symmetric positive definite matrix made of 3x3 blocks, the direct
/// solver behind the implicit integrator's preconditioner (Step.h).
///   P A P^T = L D L^T,  L unit lower triangular by blocks, D block diagonal (3x3 SPD blocks),
///   P the approximate minimum degree ordering (Eigen::AMDOrdering) of the block graph.
/// Algorithm: the up-looking factorization of Davis' LDL (T. A. Davis, "Algorithm 849: A concise sparse
/// Cholesky factorization package", ACM TOMS 31(4), 2005) with every scalar replaced by a 3x3 block:
/// row k of L solves L(0:k, 0:k) D Y = A(0:k, k) along the elimination tree, L(k, i) = Y_i^T D_i^-1,
/// D_k = A(k, k) - sum_i L(k, i) Y_i. Why blocks: the mechanics has three coordinates per node or per body
/// rotation, so each block entry replaces nine indexed scalar entries by one fixed-size 3x3 product; the
/// factorization and the two triangular solves then run about three times faster than a scalar sparse LDL^T.
/// Memory is allocated by analyze() only; factorize() and solve() allocate nothing.
/// Speed: the factorization's inner loop, Y_j -= L_j Y_i over a column of L, takes about 75 % of its time; L
/// and Y are stored as 3x3 blocks padded to 4 rows, so that on x86-64 CPUs with AVX2 and FMA
/// (BlockLdltAvx2.cpp, chosen at run time) each block product is 9 four-lane multiply-adds, and each block of
/// the two substitutions 3. That halved the factorization on the build machine; padding alone, with the SSE2
/// of the portable build, gained nothing.

#include <Eigen/Core>
#include <array>
#include <vector>

namespace pneuma::sim {

class BlockLdlt {
 public:
  /// Symbolic analysis: the ordering and the block pattern of L for a matrix of `blocks` x `blocks` 3x3
  /// blocks whose nonzero blocks are `pattern` (block row, block col) pairs; either triangle, duplicates
  /// allowed; the diagonal is always included.
  void analyze(int blocks, const std::vector<std::array<int, 2>>& pattern);

  /// Slot of block (r, c) of A, r >= c (block row and column, 0 <= r < #blocks), for value(); the block must
  /// be in the analysed pattern.
  int slot(int r, int c) const;
  /// Block (r, c) of A's lower triangle at `slot` (rows of block row r, columns of block column c); of a
  /// diagonal block only the lower triangle is read.
  Eigen::Matrix3d& value(int slot) { return m_a[static_cast<std::size_t>(slot)]; }
  const Eigen::Matrix3d& value(int slot) const { return m_a[static_cast<std::size_t>(slot)]; }
  /// Number of stored blocks of A (slots 0 .. valueBlocks() - 1).
  int valueBlocks() const { return static_cast<int>(m_a.size()); }
  /// Sets every entry of A to zero (the pattern stays).
  void clearValues();

  /// Kernels of the inner loops of factorize() and solve(): AVX2 + FMA when allowed (the default) and the CPU
  /// has it, else portable Eigen loops. Both agree up to rounding (FMA rounds once per multiply-add); a
  /// machine gives bit-identical runs either way.
  void setVectorKernel(bool allowed);
  /// True when factorize() and solve() run the AVX2 + FMA kernels.
  bool vectorKernel() const { return m_avx2; }

  /// Numeric factorization of the current values. @return false when a pivot block is not positive definite.
  bool factorize();
  /// x <- A^-1 x (3 #blocks).
  void solve(Eigen::VectorXd& x) const;
  /// X <- A^-1 X for several right-hand sides at once (3 #blocks x k): each block column of L is read once
  /// for all k, which is where the substitutions spend their time; every column gets exactly solve()'s
  /// result. Allocates when k exceeds that of every earlier call.
  void solveColumns(Eigen::Ref<Eigen::MatrixXd> x) const;

  int blocks() const { return m_n; }
  /// Number of 3x3 blocks of L below the diagonal.
  int factorBlocks() const { return m_lp.empty() ? 0 : m_lp.back(); }

 private:
  int m_n = 0;                       ///< number of block rows
  std::vector<int> m_perm;           ///< permuted block -> original block (#blocks)
  std::vector<int> m_permInverse;    ///< original block -> permuted block (#blocks)
  std::vector<int> m_ap, m_ai;       ///< A's upper triangle by blocks, permuted, column-compressed
  std::vector<Eigen::Matrix3d> m_a;  ///< its blocks (lower triangle of A, original orientation per block)
  std::vector<char> m_aTransposed;   ///< 1 when a stored block is A(original) transposed by the permutation
  std::vector<int> m_parent;         ///< elimination tree (#blocks, -1 at roots)
  std::vector<int> m_lp, m_li;       ///< L's blocks below the diagonal, column-compressed
  /// a 3x3 block padded to 4 rows (row 3 zero), so that a column is one SIMD register
  using Block = Eigen::Matrix<double, 4, 3>;
  std::vector<Block> m_l;                   ///< their values (padded)
  std::vector<Eigen::Matrix3d> m_dInverse;  ///< D_k^-1 (#blocks)
  // factorization workspace (#blocks)
  std::vector<Block> m_y;
  bool m_avx2 = false;  ///< run the AVX2 + FMA kernel (BlockLdltKernels.h)
  std::vector<int> m_flag, m_pattern, m_lnz;
  /// the substitutions of `columns` right-hand sides, column c at x + c * stride
  void substitute(double* x, Eigen::Index stride, Eigen::Index columns) const;
  /// permuted right-hand sides of solve() (3 #blocks + 1 rows, the last 0: the AVX2 backward substitution
  /// reads one entry past a segment)
  mutable Eigen::MatrixXd m_x;
};

}  // namespace pneuma::sim
