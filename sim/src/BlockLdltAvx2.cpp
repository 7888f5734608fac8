// Compiled with -mavx2 -mfma (sim/CMakeLists.txt) and called only when hasAvx2(). No Eigen in this file: its
// inline functions must not be compiled for two instruction sets in one program.
#include "BlockLdltKernels.h"

#include <immintrin.h>

namespace pneuma::sim::kernels {

void subtractProductsAvx2(double* y, const double* l, const int* rows, int count, const double* b) {
  // a padded block's column is one 4-lane register; y's row 3 stays 0 because l's row 3 is 0
  __m256d bb[9];
  for (int t = 0; t < 9; ++t) bb[t] = _mm256_broadcast_sd(b + t);
  for (int q = 0; q < count; ++q) {
    const double* lq = l + 12 * q;
    double* yq = y + 12 * rows[q];
    const __m256d c0 = _mm256_loadu_pd(lq), c1 = _mm256_loadu_pd(lq + 4), c2 = _mm256_loadu_pd(lq + 8);
    for (int j = 0; j < 3; ++j) {
      __m256d acc = _mm256_loadu_pd(yq + 4 * j);
      acc = _mm256_fnmadd_pd(c0, bb[3 * j], acc);
      acc = _mm256_fnmadd_pd(c1, bb[3 * j + 1], acc);
      acc = _mm256_fnmadd_pd(c2, bb[3 * j + 2], acc);
      _mm256_storeu_pd(yq + 4 * j, acc);
    }
  }
}

bool hasAvx2() { return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"); }

}  // namespace pneuma::sim::kernels
