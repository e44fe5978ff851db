#include "core/srgb_rows.h"

#include "core/srgb.h"

// A build for processors with fused multiply-add (-march=native, x86-64-v3) may fuse
// the scalar conversions' products and sums, which separate AVX2 steps do not: the
// rows then take the scalar path too, so that they keep the scalar values.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__FMA__)
#include <immintrin.h>
#define TEXLUME_SRGB_AVX2 1
#endif

namespace texlume::srgb {

#ifdef TEXLUME_SRGB_AVX2
namespace {

// Each step below is the scalar code's expression in its order, so that the lanes
// round as ToLinear and FromLinear do (AVX2 alone has no fused multiply-add, and the
// scalar code is not fused either: above).
#define TEXLUME_AVX2 __attribute__((target("avx2")))

// Tables::Interpolate: table[i] + f (table[i + 1] - table[i]) at x kIntervals = i + f.
TEXLUME_AVX2 __m256 Interpolate(const float* table, __m256 x) {
  const __m256 at = _mm256_mul_ps(x, _mm256_set1_ps(static_cast<float>(Tables::kIntervals)));
  const __m256i i =
      _mm256_min_epi32(_mm256_cvttps_epi32(at), _mm256_set1_epi32(Tables::kIntervals - 1));
  const __m256 f = _mm256_sub_ps(at, _mm256_cvtepi32_ps(i));
  const __m256 t0 = _mm256_i32gather_ps(table, i, 4);
  const __m256 t1 = _mm256_i32gather_ps(table + 1, i, 4);
  return _mm256_add_ps(t0, _mm256_mul_ps(f, _mm256_sub_ps(t1, t0)));
}

// v > 0 ? min(v, 1) : 0 (NaN: 0). _mm256_min_ps(a, b) is a < b ? a : b, and
// _mm256_max_ps(a, b) is a > b ? a : b, as std::min(v, 1) and the test of v > 0.
TEXLUME_AVX2 __m256 Clamp01(__m256 v) {
  return _mm256_max_ps(_mm256_min_ps(_mm256_set1_ps(1.0f), v), _mm256_setzero_ps());
}

TEXLUME_AVX2 __m256 ToLinear8(const Tables& tables, __m256 v) {
  v = Clamp01(v);
  const __m256 proportional = _mm256_div_ps(v, _mm256_set1_ps(kLinearSlope));
  const __m256 low = _mm256_cmp_ps(v, _mm256_set1_ps(kDisplayLinearUpTo), _CMP_LE_OQ);
  return _mm256_blendv_ps(Interpolate(tables.DecodeTable(), v), proportional, low);
}

TEXLUME_AVX2 __m256 FromLinear8(const Tables& tables, __m256 v) {
  v = Clamp01(v);
  const __m256 proportional = _mm256_mul_ps(v, _mm256_set1_ps(kLinearSlope));
  const __m256 low = _mm256_cmp_ps(v, _mm256_set1_ps(kLinearUpTo), _CMP_LE_OQ);
  return _mm256_blendv_ps(Interpolate(tables.EncodeTable(), _mm256_sqrt_ps(v)), proportional, low);
}

TEXLUME_AVX2 int AddWeightedLinearAvx2(const float* display, float weight, int n, float* linear) {
  const Tables& tables = TheTables();
  const __m256 w = _mm256_set1_ps(weight);
  int i = 0;
  for (; i + 8 <= n; i += 8) {
    const __m256 l = _mm256_mul_ps(w, ToLinear8(tables, _mm256_loadu_ps(display + i)));
    _mm256_storeu_ps(linear + i, _mm256_add_ps(_mm256_loadu_ps(linear + i), l));
  }
  return i;
}

TEXLUME_AVX2 int ScaledFromLinearAvx2(const float* linear, float scale, int n, float* display) {
  const Tables& tables = TheTables();
  const __m256 s = _mm256_set1_ps(scale);
  int i = 0;
  for (; i + 8 <= n; i += 8)
    _mm256_storeu_ps(display + i,
                     FromLinear8(tables, _mm256_mul_ps(s, _mm256_loadu_ps(linear + i))));
  return i;
}

}  // namespace

bool RowsUseAvx2() {
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return avx2;
}
#else
bool RowsUseAvx2() { return false; }
#endif

void AddWeightedLinear(const float* display, float weight, int n, float* linear) {
  int i = 0;
#ifdef TEXLUME_SRGB_AVX2
  if (RowsUseAvx2()) i = AddWeightedLinearAvx2(display, weight, n, linear);
#endif
  const Tables& tables = TheTables();
  for (; i < n; ++i) linear[i] += weight * ToLinear(display[i], tables);
}

void ScaledFromLinear(const float* linear, float scale, int n, float* display) {
  int i = 0;
#ifdef TEXLUME_SRGB_AVX2
  if (RowsUseAvx2()) i = ScaledFromLinearAvx2(linear, scale, n, display);
#endif
  const Tables& tables = TheTables();
  for (; i < n; ++i) display[i] = FromLinear(scale * linear[i], tables);
}

}  // namespace texlume::srgb

#undef TEXLUME_AVX2
#undef TEXLUME_SRGB_AVX2
