#pragma once
// The hot loop of BlockLdlt::factorize() on raw memory, for a build with AVX2 and FMA (BlockLdltAvx2.cpp).
// Blocks are 3x3 matrices padded to 4 rows (BlockLdlt::Block: column-major, 12 doubles, row 3 zero in l).

namespace pneuma::sim::kernels {

/// y[rows[q]] -= l[q] * b for q < count, with y and l padded 4x3 blocks and b a column-major 3x3 matrix.
void subtractProductsAvx2(double* y, const double* l, const int* rows, int count, const double* b);

/// True when the CPU runs AVX2 and FMA.
bool hasAvx2();

}  // namespace pneuma::sim::kernels
