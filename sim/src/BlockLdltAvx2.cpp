// Compiled with -mavx2 -mfma (sim/CMakeLists.txt) and called only when hasAvx2(). No Eigen in this file: its
// inline functions must not be compiled for two instruction sets in one program.
#include <immintrin.h>

#include "BlockLdltKernels.h"

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

void forwardColumnAvx2(double* x, const double* l, const int* rows, int count, const double* z) {
  // l's columns are full registers; x's segment is read and written as 2 + 1 entries (a 4-entry access would
  // overlap the next segment and stall store forwarding)
  const __m256d z0 = _mm256_broadcast_sd(z), z1 = _mm256_broadcast_sd(z + 1), z2 = _mm256_broadcast_sd(z + 2);
  for (int q = 0; q < count; ++q) {
    const double* lq = l + 12 * q;
    double* xq = x + 3 * rows[q];
    __m256d product = _mm256_mul_pd(_mm256_loadu_pd(lq), z0);
    product = _mm256_fmadd_pd(_mm256_loadu_pd(lq + 4), z1, product);
    product = _mm256_fmadd_pd(_mm256_loadu_pd(lq + 8), z2, product);
    _mm_storeu_pd(xq, _mm_sub_pd(_mm_loadu_pd(xq), _mm256_castpd256_pd128(product)));
    _mm_store_sd(xq + 2, _mm_sub_sd(_mm_load_sd(xq + 2), _mm256_extractf128_pd(product, 1)));
  }
}

namespace {
double sum4(__m256d v) {
  const __m128d pair = _mm_add_pd(_mm256_castpd256_pd128(v), _mm256_extractf128_pd(v, 1));
  return _mm_cvtsd_f64(_mm_add_sd(pair, _mm_unpackhi_pd(pair, pair)));
}
}  // namespace

void backwardColumnAvx2(double* xi, const double* x, const double* l, const int* rows, int count) {
  // column k of l[q] dotted with x's segment, summed over q; lane 3 multiplies l's zero row
  __m256d acc0 = _mm256_setzero_pd(), acc1 = _mm256_setzero_pd(), acc2 = _mm256_setzero_pd();
  for (int q = 0; q < count; ++q) {
    const double* lq = l + 12 * q;
    const __m256d xq = _mm256_loadu_pd(x + 3 * rows[q]);
    acc0 = _mm256_fmadd_pd(_mm256_loadu_pd(lq), xq, acc0);
    acc1 = _mm256_fmadd_pd(_mm256_loadu_pd(lq + 4), xq, acc1);
    acc2 = _mm256_fmadd_pd(_mm256_loadu_pd(lq + 8), xq, acc2);
  }
  xi[0] -= sum4(acc0);
  xi[1] -= sum4(acc1);
  xi[2] -= sum4(acc2);
}

bool hasAvx2() { return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"); }

}  // namespace pneuma::sim::kernels
