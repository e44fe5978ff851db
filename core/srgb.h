#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

namespace texlume::srgb {

/// The sRGB curves' power segments, tabulated once and read by linear
/// interpolation: decoding over v in [0, 1], encoding over t = sqrt(v) (where
/// v^(1/2.4) = t^(1/1.2) bends gently), 4096 intervals each. Interpolation error
/// below 4e-8 (the curves' second derivatives are at most 3 and 4.2), a float's
/// rounding at 1; a call costs a square root and two loads instead of a power.
/// Inline here so that the relighting loops (synth/) inline the conversions;
/// core/image_io.h's SrgbToLinear and LinearToSrgb are these.
class Tables {
 public:
  static constexpr int kIntervals = 4096;

  Tables() {
    for (int i = 0; i <= kIntervals; ++i) {
      const double x = static_cast<double>(i) / kIntervals;
      decode_[static_cast<std::size_t>(i)] = static_cast<float>(std::pow((x + 0.055) / 1.055, 2.4));
      encode_[static_cast<std::size_t>(i)] =
          static_cast<float>(1.055 * std::pow(x, 2.0 / 2.4) - 0.055);
    }
  }
  float Decode(float v) const { return Interpolate(decode_, v); }
  float Encode(float v) const { return Interpolate(encode_, std::sqrt(v)); }
  /// The tables themselves (kIntervals + 1 values each), for the row kernels (srgb_rows.h).
  const float* DecodeTable() const { return decode_.data(); }
  const float* EncodeTable() const { return encode_.data(); }

 private:
  static float Interpolate(const std::array<float, kIntervals + 1>& table, float x) {
    const float at = x * kIntervals;
    const int i = std::min(static_cast<int>(at), kIntervals - 1);
    const float f = at - static_cast<float>(i);
    return table[static_cast<std::size_t>(i)] +
           f * (table[static_cast<std::size_t>(i) + 1] - table[static_cast<std::size_t>(i)]);
  }

  std::array<float, kIntervals + 1> decode_, encode_;
};

/// The curves' linear segments: display values up to kDisplayLinearUpTo (linear
/// values up to kLinearUpTo) are proportional, with slope kLinearSlope.
inline constexpr float kDisplayLinearUpTo = 0.04045f;
inline constexpr float kLinearUpTo = 0.0031308f;
inline constexpr float kLinearSlope = 12.92f;

inline const Tables& TheTables() {
  static const Tables tables;
  return tables;
}

/// sRGB display value in [0, 1] (clamped; NaN: 0) to linear, with the tables given
/// (a loop that takes them once checks no initialisation guard per value).
inline float ToLinear(float v, const Tables& tables) {
  v = v > 0.0f ? std::min(v, 1.0f) : 0.0f;
  return v <= kDisplayLinearUpTo ? v / kLinearSlope : tables.Decode(v);
}
inline float ToLinear(float v) { return ToLinear(v, TheTables()); }

/// Linear value in [0, 1] (clamped; NaN: 0) to sRGB display, with the tables given.
inline float FromLinear(float v, const Tables& tables) {
  v = v > 0.0f ? std::min(v, 1.0f) : 0.0f;
  return v <= kLinearUpTo ? v * kLinearSlope : tables.Encode(v);
}
inline float FromLinear(float v) { return FromLinear(v, TheTables()); }

/// d linear / d display at display value v, given its linear value (ToLinear(v)):
/// the power segment's derivative 2.4 / 1.055 ((v + 0.055) / 1.055)^1.4 written as
/// 2.4 linear / (v + 0.055), so no power is taken; 0 outside (0, 1).
inline float ToLinearSlope(float v, float linear) {
  if (!(v > 0.0f) || v >= 1.0f) return 0.0f;
  return v <= kDisplayLinearUpTo ? 1.0f / kLinearSlope : 2.4f * linear / (v + 0.055f);
}

/// d display / d linear at linear value v, given its display value (FromLinear(v)):
/// the power segment's derivative (1.055 / 2.4) v^(1 / 2.4 - 1) written as
/// (display + 0.055) / (2.4 v); 0 outside (0, 1).
inline float FromLinearSlope(float v, float display) {
  if (!(v > 0.0f) || v >= 1.0f) return 0.0f;
  return v <= kLinearUpTo ? kLinearSlope : (display + 0.055f) / (2.4f * v);
}

}  // namespace texlume::srgb
