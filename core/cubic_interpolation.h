#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/core.hpp>

#include "core/check.h"

namespace texlume {

/// Catmull-Rom weights (Keys 1981, cubic convolution with a = -1/2) of the four
/// taps floor(x) - 1 .. floor(x) + 2 around a point t in [0, 1] past floor(x).
/// They sum to 1, interpolate (t = 0 is the tap at floor(x) alone) and reproduce
/// quadratics; bilinear weights average the two middle taps and so flatten the
/// finest detail a texture holds (issue 29: a texel read at half a texel's offset
/// loses about half its contrast against its neighbours, twice over when an atlas
/// is baked from a sample and then read by the renderer).
inline std::array<double, 4> CatmullRomWeights(double t) {
  const double t2 = t * t, t3 = t2 * t;
  return {-0.5 * t3 + t2 - 0.5 * t, 1.5 * t3 - 2.5 * t2 + 1.0, -1.5 * t3 + 2.0 * t2 + 0.5 * t,
          0.5 * t3 - 0.5 * t2};
}

/// The 4 x 4 taps and weights of a Catmull-Rom read at (x, y) of planes of one
/// size (pixel centres at integers), the point clamped to the planes and the taps
/// beyond an edge reading the edge texel. Every texture read that carries a
/// sample's detail into a model or a model into a picture uses it: the atlas baker
/// (PTM, colour, BTF samples, every engine), `texlume render` and the viewer.
class CatmullRomTaps {
 public:
  static constexpr int kMaxChannels = 32;  ///< of AddScaledChannels' planes

  CatmullRomTaps(int width, int height, double x, double y) {
    x = std::clamp(x, 0.0, width - 1.0);
    y = std::clamp(y, 0.0, height - 1.0);
    const int bx = static_cast<int>(x), by = static_cast<int>(y);
    wx_ = CatmullRomWeights(x - bx), wy_ = CatmullRomWeights(y - by);
    for (int k = 0; k < 4; ++k) {
      columns_[k] = std::clamp(bx - 1 + k, 0, width - 1);
      rows_[k] = std::clamp(by - 1 + k, 0, height - 1);
    }
  }
  CatmullRomTaps(cv::Size planes, double x, double y)
      : CatmullRomTaps(planes.width, planes.height, x, y) {}

  /// out[c] = sum over the taps of weight x get(column, row, c), c < count.
  template <typename Get>
  void Read(int count, const Get& get, float* out) const {
    for (int c = 0; c < count; ++c) {
      double sum = 0.0;
      for (int a = 0; a < 4; ++a) {
        double row = 0.0;
        for (int b = 0; b < 4; ++b) row += wx_[b] * get(columns_[b], rows_[a], c);
        sum += wy_[a] * row;
      }
      out[c] = static_cast<float>(sum);
    }
  }
  /// The value of a CV_32FC1 plane of the size given.
  double Of(const cv::Mat& plane) const {
    double sum = 0.0;
    for (int a = 0; a < 4; ++a) {
      const float* r = plane.ptr<float>(rows_[a]);
      sum += wy_[a] * (wx_[0] * r[columns_[0]] + wx_[1] * r[columns_[1]] + wx_[2] * r[columns_[2]] +
                       wx_[3] * r[columns_[3]]);
    }
    return sum;
  }
  /// out[m] += scale x the value of channel m, for every channel of a CV_32FC(n)
  /// plane of the size given, each rounded to float as it is added.
  void AddScaledChannels(const cv::Mat& interleaved, double scale, float* out) const {
    CV_DbgAssert(interleaved.depth() == CV_32F);
    const int n = interleaved.channels();
    std::array<double, kMaxChannels> sum{};
    TEXLUME_CHECK(n <= kMaxChannels, "a plane of at most 32 channels");
    for (int a = 0; a < 4; ++a) {
      const float* r = interleaved.ptr<float>(rows_[a]);
      for (int b = 0; b < 4; ++b) {
        const double w = wy_[a] * wx_[b];
        const float* texel = r + static_cast<std::ptrdiff_t>(columns_[b]) * n;
        for (int m = 0; m < n; ++m) sum[static_cast<std::size_t>(m)] += w * texel[m];
      }
    }
    for (int m = 0; m < n; ++m)
      out[m] += static_cast<float>(scale * sum[static_cast<std::size_t>(m)]);
  }

 private:
  std::array<int, 4> columns_{}, rows_{};
  std::array<double, 4> wx_{}, wy_{};
};

}  // namespace texlume
