#include "datasets_synthetic/photo_sensor.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "core/errors.h"
#include "datasets_synthetic/renderer.h"

namespace texlume::datasets {

bool SensorOptions::Active() const {
  return shot_noise > 0 || read_noise > 0 || vignetting > 0 || white_balance_spread > 0 ||
         jpeg_quality > 0;
}

void SensorOptions::Check() const {
  RequireInRange(shot_noise, 0, 0.01, "shot noise");
  RequireInRange(read_noise, 0, 0.05, "read noise");
  RequireInRange(vignetting, 0, 0.9, "vignetting");
  RequireInRange(white_balance_spread, 0, 0.5, "white balance spread");
  RequireInRange(jpeg_quality, 0, 100, "JPEG quality");
}

nlohmann::json SensorOptions::ToJson() const {
  return {{"shot_noise", shot_noise},
          {"read_noise", read_noise},
          {"vignetting", vignetting},
          {"white_balance_spread", white_balance_spread},
          {"jpeg_quality", jpeg_quality},
          {"noise_model", "variance = shot_noise * x + read_noise^2, linear x"}};
}

namespace {

// cos^4 falloff from the image centre, scaled so the corners keep 1 - vignetting.
void Vignette(cv::Mat& linear_rgb, double vignetting) {
  const double cx = 0.5 * linear_rgb.cols, cy = 0.5 * linear_rgb.rows;
  const double corner_r2 = cx * cx + cy * cy;
  // The half-angle at the corner whose cos^4 is 1 - vignetting.
  const double tan2_corner = 1.0 / std::sqrt(1.0 - vignetting) - 1.0;
  for (int y = 0; y < linear_rgb.rows; ++y) {
    auto* p = linear_rgb.ptr<cv::Vec3f>(y);
    for (int x = 0; x < linear_rgb.cols; ++x) {
      const double dx = x + 0.5 - cx, dy = y + 0.5 - cy;
      const double tan2 = tan2_corner * (dx * dx + dy * dy) / corner_r2;
      const double cos2 = 1.0 / (1.0 + tan2);
      p[x] *= static_cast<float>(cos2 * cos2);
    }
  }
}

void AddNoise(cv::Mat& linear_rgb, double shot_noise, double read_noise, std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int y = 0; y < linear_rgb.rows; ++y) {
    auto* p = linear_rgb.ptr<cv::Vec3f>(y);
    for (int x = 0; x < linear_rgb.cols; ++x)
      for (int c = 0; c < 3; ++c) {
        const double signal = std::max(0.0, static_cast<double>(p[x][c]));
        const double sigma = std::sqrt(shot_noise * signal + read_noise * read_noise);
        p[x][c] = static_cast<float>(signal + sigma * normal(rng));
      }
  }
}

cv::Mat JpegRoundTrip(const cv::Mat& bgr8, int quality) {
  std::vector<unsigned char> bytes;
  cv::imencode(".jpg", bgr8, bytes, {cv::IMWRITE_JPEG_QUALITY, quality});
  return cv::imdecode(bytes, cv::IMREAD_COLOR);
}

}  // namespace

cv::Mat ExposeOnSensor(const cv::Mat& linear_rgb, const SensorOptions& options,
                       std::mt19937_64& rng, SensorDraw* draw) {
  options.Check();
  cv::Mat signal = linear_rgb.clone();
  if (options.vignetting > 0) Vignette(signal, options.vignetting);
  SensorDraw drawn;
  if (options.white_balance_spread > 0) {
    std::uniform_real_distribution<double> gain(1.0 - options.white_balance_spread,
                                                1.0 + options.white_balance_spread);
    for (int c = 0; c < 3; ++c) drawn.white_balance[c] = gain(rng);
    signal = signal.mul(
        cv::Scalar(drawn.white_balance[0], drawn.white_balance[1], drawn.white_balance[2]));
  }
  if (options.shot_noise > 0 || options.read_noise > 0)
    AddNoise(signal, options.shot_noise, options.read_noise, rng);
  cv::Mat photo = LinearToSrgb8(cv::min(cv::max(signal, 0.0), 1.0));
  if (options.jpeg_quality > 0) photo = JpegRoundTrip(photo, options.jpeg_quality);
  if (draw) *draw = drawn;
  return photo;
}

}  // namespace texlume::datasets
