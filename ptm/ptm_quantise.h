#pragma once

// The quantisation of a .ptm file's coefficients (HP PTM 1.2, docs/ptm_format.md):
// each coefficient index's range over the image and the bytes that encode it.

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>

#include "ptm/ptm.h"

namespace texlume::ptm {

// x rounded half away from zero (as std::lround) and clamped to 0..255; NaN is 0.
// Exact in float: the fraction x - trunc(x) of a float in [0, 255] needs no
// rounding (Sterbenz), and branch-free so that the encoding loops vectorise.
inline std::uint8_t RoundToByte(float x) {
  const float clamped = std::min(x > 0.0f ? x : 0.0f, 255.0f);
  const int whole = static_cast<int>(clamped);
  return static_cast<std::uint8_t>(whole + (clamped - static_cast<float>(whole) >= 0.5f ? 1 : 0));
}

// Quantisation of one coefficient index: coefficient = (byte - bias) * scale.
struct Quantiser {
  float scale = 1.0f;
  int bias = 0;
  std::uint8_t Encode(float v) const { return RoundToByte(v / scale + static_cast<float>(bias)); }
};

// Quantisers per coefficient index, over every texel (and channel for RGB), in
// 0-255 units: the range between the 0.1 % and 99.9 % quantiles, widened to hold 0,
// in 255 steps.
std::array<Quantiser, 6> Quantisers(const Ptm& ptm);

// Encodes groups of a polynomial's 6 coefficients (display values) as a .ptm's bytes,
// four groups at a time in fixed-length loops that the compiler vectorises: the
// same bytes as Quantiser::Encode.
class GroupEncoder {
 public:
  explicit GroupEncoder(const std::array<Quantiser, 6>& q) {
    for (std::size_t j = 0; j < kValues; ++j) {
      scale_[j] = q[j % 6].scale;
      bias_[j] = static_cast<float>(q[j % 6].bias);
    }
  }

  // The groups a[t * stride, t * stride + 6) for t < count, into out[t * 6 + i].
  void Encode(const float* a, std::size_t stride, std::size_t count, std::uint8_t* out) const;

 private:
  static constexpr std::size_t kGroups = 4, kValues = kGroups * 6;
  float scale_[kValues], bias_[kValues];
};

}  // namespace texlume::ptm
