#include "synth/relight_rows.h"

#include <cstddef>
#include <utility>

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

}  // namespace

PtmRowRelighter::PtmRowRelighter(ptm::PtmFormat format, std::vector<ptm::EffectiveLight> lights,
                                 double gain)
    : format_(format), lights_(std::move(lights)), gain_(static_cast<float>(gain)) {}

void PtmRowRelighter::Relight(const float* const* planes, int cols,
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
