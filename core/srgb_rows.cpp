#include "core/srgb_rows.h"

#include "core/srgb.h"
#include "core/srgb_avx2.h"

namespace texlume::srgb {

#ifdef TEXLUME_SRGB_AVX2
namespace {

#define TEXLUME_AVX2 TEXLUME_AVX2_TARGET
using avx2::FromLinear8;
using avx2::ToLinear8;

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
