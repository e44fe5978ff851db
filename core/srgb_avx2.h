#pragma once

// The sRGB conversions of srgb.h on eight floats in AVX2 registers, for row kernels
// (core/srgb_rows.cpp, synth/relight_rows.cpp) that keep their values in registers.
// Each step is the scalar code's expression in its order, so that the lanes round
// as ToLinear and FromLinear do: AVX2 alone has no fused multiply-add, and the
// scalar code is not fused either. A build for processors with fused multiply-add
// (-march=native, x86-64-v3) may fuse the scalar conversions' products and sums:
// TEXLUME_SRGB_AVX2 is then left undefined and the kernels take the scalar path,
// so that they keep the scalar values. Callers ask srgb::RowsUseAvx2() (srgb_rows.h)
// before they run these.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__FMA__)
#include <immintrin.h>

#include "core/srgb.h"

#define TEXLUME_SRGB_AVX2 1
#define TEXLUME_AVX2_TARGET __attribute__((target("avx2")))

namespace texlume::srgb::avx2 {

/// Tables::Interpolate: table[i] + f (table[i + 1] - table[i]) at x kIntervals = i + f.
TEXLUME_AVX2_TARGET inline __m256 Interpolate(const float* table, __m256 x) {
  const __m256 at = _mm256_mul_ps(x, _mm256_set1_ps(static_cast<float>(Tables::kIntervals)));
  const __m256i i =
      _mm256_min_epi32(_mm256_cvttps_epi32(at), _mm256_set1_epi32(Tables::kIntervals - 1));
  const __m256 f = _mm256_sub_ps(at, _mm256_cvtepi32_ps(i));
  const __m256 t0 = _mm256_i32gather_ps(table, i, 4);
  const __m256 t1 = _mm256_i32gather_ps(table + 1, i, 4);
  return _mm256_add_ps(t0, _mm256_mul_ps(f, _mm256_sub_ps(t1, t0)));
}

/// v > 0 ? min(v, 1) : 0 (NaN: 0). _mm256_min_ps(a, b) is a < b ? a : b, and
/// _mm256_max_ps(a, b) is a > b ? a : b, as std::min(v, 1) and the test of v > 0.
TEXLUME_AVX2_TARGET inline __m256 Clamp01(__m256 v) {
  return _mm256_max_ps(_mm256_min_ps(_mm256_set1_ps(1.0f), v), _mm256_setzero_ps());
}

/// ToLinear of eight display values.
TEXLUME_AVX2_TARGET inline __m256 ToLinear8(const Tables& tables, __m256 v) {
  v = Clamp01(v);
  const __m256 proportional = _mm256_div_ps(v, _mm256_set1_ps(kLinearSlope));
  const __m256 low = _mm256_cmp_ps(v, _mm256_set1_ps(kDisplayLinearUpTo), _CMP_LE_OQ);
  return _mm256_blendv_ps(Interpolate(tables.DecodeTable(), v), proportional, low);
}

/// FromLinear of eight linear values.
TEXLUME_AVX2_TARGET inline __m256 FromLinear8(const Tables& tables, __m256 v) {
  v = Clamp01(v);
  const __m256 proportional = _mm256_mul_ps(v, _mm256_set1_ps(kLinearSlope));
  const __m256 low = _mm256_cmp_ps(v, _mm256_set1_ps(kLinearUpTo), _CMP_LE_OQ);
  return _mm256_blendv_ps(Interpolate(tables.EncodeTable(), _mm256_sqrt_ps(v)), proportional, low);
}

}  // namespace texlume::srgb::avx2
#endif
