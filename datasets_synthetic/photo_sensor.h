#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <random>

namespace texlume::datasets {

/// What a real camera adds to a photo between the radiance and the file
/// (issue 29: scenes that do not flatter the pipeline). All off by default, so
/// the clean scenes stay the regression baseline.
struct SensorOptions {
  /// Shot (photon) noise: the variance of the linear signal x is
  /// shot_noise * x + read_noise^2 (the photon-transfer model). 0 = off. [0, 0.01].
  double shot_noise = 0.0;
  /// Read noise: standard deviation in linear units. 0 = off. [0, 0.05].
  double read_noise = 0.0;
  /// Vignetting: the brightness lost at the image corners, falling off as
  /// cos^4 of the angle to the optical axis, scaled so the corners lose this
  /// share. 0 = off. [0, 0.9].
  double vignetting = 0.0;
  /// Per-photo white balance: each channel's gain drawn uniformly in
  /// [1 - spread, 1 + spread] (recorded per photo). 0 = off. [0, 0.5].
  double white_balance_spread = 0.0;
  /// The photo as a JPEG of this quality would store it (encoded and decoded;
  /// the file stays a PNG under the model's image name). 0 = lossless. [0, 100].
  int jpeg_quality = 0;

  /// Whether any effect is on.
  bool Active() const;
  /// Throws OptionError naming the first setting out of range.
  void Check() const;
  nlohmann::json ToJson() const;
};

/// What one photo drew.
struct SensorDraw {
  Eigen::Vector3d white_balance = Eigen::Vector3d::Ones();  ///< R, G, B gains
};

/// The 8-bit sRGB photo (CV_8UC3, B G R as LinearToSrgb8) a camera with
/// `options` stores of `linear_rgb` (CV_32FC3, R G B radiance): vignetting,
/// white balance, shot and read noise in the linear domain, clamping to [0, 1],
/// sRGB quantisation, then the JPEG round trip. Draws from `rng` only for the
/// effects that are on.
cv::Mat ExposeOnSensor(const cv::Mat& linear_rgb, const SensorOptions& options,
                       std::mt19937_64& rng, SensorDraw* draw = nullptr);

}  // namespace texlume::datasets
