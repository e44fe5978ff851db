#include "synth/relight_rows.h"

#include <cstddef>
#include <utility>

#include "core/srgb_avx2.h"
#include "core/srgb_rows.h"

namespace texlume::synth {
namespace {

// ptm::EvaluatePolynomial of light (lu, lv) at `cols` cells (paper 003 eq. 1).
void EvaluateRow(const float* const* a, double lu, double lv, int cols, double* __restrict out) {
  const float *a0 = a[0], *a1 = a[1], *a2 = a[2], *a3 = a[3], *a4 = a[4], *a5 = a[5];
  for (int x = 0; x < cols; ++x)
    out[x] = ptm::EvaluatePolynomial(a0[x], a1[x], a2[x], a3[x], a4[x], a5[x], lu, lv);
}

// The display values of a light: the polynomial's, times the colour (LRGB) when given.
void DisplayValues(const double* polynomial, const float* colour, int cols, float* __restrict out) {
  if (colour)
    for (int x = 0; x < cols; ++x) out[x] = static_cast<float>(polynomial[x] * colour[x]);
  else
    for (int x = 0; x < cols; ++x) out[x] = static_cast<float>(polynomial[x]);
}

#ifdef TEXLUME_SRGB_AVX2
// Four cells' polynomial (eq. 1) from cell x on, in doubles, as ptm::EvaluatePolynomial
// sums it: ((a0 lu) lu + (a1 lv) lv + (a2 lu) lv + a3 lu + a4 lv) + a5, left to right.
TEXLUME_AVX2_TARGET __m256d Polynomial4(const float* const* a, int x, __m256d lu, __m256d lv) {
  __m256d p = _mm256_mul_pd(_mm256_mul_pd(_mm256_cvtps_pd(_mm_loadu_ps(a[0] + x)), lu), lu);
  p = _mm256_add_pd(p,
                    _mm256_mul_pd(_mm256_mul_pd(_mm256_cvtps_pd(_mm_loadu_ps(a[1] + x)), lv), lv));
  p = _mm256_add_pd(p,
                    _mm256_mul_pd(_mm256_mul_pd(_mm256_cvtps_pd(_mm_loadu_ps(a[2] + x)), lu), lv));
  p = _mm256_add_pd(p, _mm256_mul_pd(_mm256_cvtps_pd(_mm_loadu_ps(a[3] + x)), lu));
  p = _mm256_add_pd(p, _mm256_mul_pd(_mm256_cvtps_pd(_mm_loadu_ps(a[4] + x)), lv));
  return _mm256_add_pd(p, _mm256_cvtps_pd(_mm_loadu_ps(a[5] + x)));
}

// Eight cells' display values (DisplayValues): the polynomial's two halves, times
// the colour when given, rounded to floats.
TEXLUME_AVX2_TARGET __m256 Display8(__m256d lo, __m256d hi, const float* colour, int x) {
  if (colour) {
    lo = _mm256_mul_pd(lo, _mm256_cvtps_pd(_mm_loadu_ps(colour + x)));
    hi = _mm256_mul_pd(hi, _mm256_cvtps_pd(_mm_loadu_ps(colour + x + 4)));
  }
  return _mm256_set_m128(_mm256_cvtpd_ps(hi), _mm256_cvtpd_ps(lo));
}

// PtmRowRelighter::Relight's steps for eight cells at a time, the lights' linear
// sums kept in registers: the same operations in the same order, so the same
// values. Returns the cells done (a multiple of 8).
TEXLUME_AVX2_TARGET int RelightRowAvx2(bool lrgb, const std::vector<ptm::EffectiveLight>& lights,
                                       float gain, const float* const* planes, int cols,
                                       const std::array<float*, 3>& out) {
  const srgb::Tables& tables = srgb::TheTables();
  int x = 0;
  for (; x + 8 <= cols; x += 8) {
    __m256 linear[3] = {_mm256_setzero_ps(), _mm256_setzero_ps(), _mm256_setzero_ps()};
    for (const ptm::EffectiveLight& e : lights) {
      const __m256 weight = _mm256_set1_ps(static_cast<float>(e.weight));
      const __m256d lu = _mm256_set1_pd(e.direction.x()), lv = _mm256_set1_pd(e.direction.y());
      __m256d lo = _mm256_setzero_pd(), hi = _mm256_setzero_pd();
      if (lrgb) lo = Polynomial4(planes, x, lu, lv), hi = Polynomial4(planes, x + 4, lu, lv);
      for (std::size_t c = 0; c < 3; ++c) {
        if (!lrgb)
          lo = Polynomial4(planes + 6 * c, x, lu, lv),
          hi = Polynomial4(planes + 6 * c, x + 4, lu, lv);
        const __m256 display = Display8(lo, hi, lrgb ? planes[6 + c] : nullptr, x);
        linear[c] =
            _mm256_add_ps(linear[c], _mm256_mul_ps(weight, srgb::avx2::ToLinear8(tables, display)));
      }
    }
    for (std::size_t c = 0; c < 3; ++c)
      _mm256_storeu_ps(out[c] + x, srgb::avx2::FromLinear8(
                                       tables, _mm256_mul_ps(_mm256_set1_ps(gain), linear[c])));
  }
  return x;
}
#endif

}  // namespace

PtmRowRelighter::PtmRowRelighter(ptm::PtmFormat format, std::vector<ptm::EffectiveLight> lights,
                                 double gain)
    : format_(format), lights_(std::move(lights)), gain_(static_cast<float>(gain)) {}

void PtmRowRelighter::Relight(const float* const* planes, int cols,
                              const std::array<float*, 3>& out) {
  int done = 0;
#ifdef TEXLUME_SRGB_AVX2
  if (srgb::RowsUseAvx2())
    done = RelightRowAvx2(format_ == ptm::PtmFormat::kLrgb, lights_, gain_, planes, cols, out);
#endif
  if (done == cols) return;
  // The cells left (all of them without AVX2), a light at a time over the row.
  std::array<const float*, kMaxPlanes> rest{};
  const int count = format_ == ptm::PtmFormat::kLrgb ? 9 : 18;
  for (int k = 0; k < count; ++k) rest[static_cast<std::size_t>(k)] = planes[k] + done;
  RelightByLight(rest.data(), cols - done, {out[0] + done, out[1] + done, out[2] + done});
}

void PtmRowRelighter::RelightByLight(const float* const* planes, int cols,
                                     const std::array<float*, 3>& out) {
  const auto n = static_cast<std::size_t>(cols);
  polynomial_.resize(n);
  display_.resize(n);
  for (std::vector<float>& l : linear_) l.assign(n, 0.0f);
  const bool lrgb = format_ == ptm::PtmFormat::kLrgb;
  for (const ptm::EffectiveLight& e : lights_) {
    const float weight = static_cast<float>(e.weight);
    const double lu = e.direction.x(), lv = e.direction.y();
    // LRGB: one luminance polynomial scaled by each channel's colour (Malzbender et
    // al. 2001, eq. 2); RGB: a polynomial per channel.
    if (lrgb) EvaluateRow(planes, lu, lv, cols, polynomial_.data());
    for (std::size_t c = 0; c < 3; ++c) {
      if (!lrgb) EvaluateRow(planes + 6 * c, lu, lv, cols, polynomial_.data());
      DisplayValues(polynomial_.data(), lrgb ? planes[6 + c] : nullptr, cols, display_.data());
      srgb::AddWeightedLinear(display_.data(), weight, cols, linear_[c].data());
    }
  }
  for (std::size_t c = 0; c < 3; ++c)
    srgb::ScaledFromLinear(linear_[c].data(), gain_, cols, out[c]);
}

}  // namespace texlume::synth
