#pragma once
// The hot loops of BlockLdlt::factorize() and solve() on raw memory, for a build with AVX2 and FMA
// (BlockLdltAvx2.cpp). Blocks are 3x3 matrices padded to 4 rows (BlockLdlt::Block: column-major, 12 doubles,
// row 3 zero in l).

namespace pneuma::sim::kernels {

/// y[rows[q]] -= l[q] * b for q < count, with y and l padded 4x3 blocks and b a column-major 3x3 matrix.
void subtractProductsAvx2(double* y, const double* l, const int* rows, int count, const double* b);

/// x[3 rows[q] + (0..2)] -= l[q] * z for q < count (forward substitution of one column of L), with x a vector
/// of 3-entry segments.
void forwardColumnAvx2(double* x, const double* l, const int* rows, int count, const double* z);

/// xi[0..2] -= sum over q < count of l[q]^T x[3 rows[q] + (0..2)] (backward substitution of one column of L);
/// x as above, with one readable double after the last segment (l's row 3 is 0, so it counts for nothing).
void backwardColumnAvx2(double* xi, const double* x, const double* l, const int* rows, int count);

/// True when the CPU runs AVX2 and FMA.
bool hasAvx2();

}  // namespace pneuma::sim::kernels
