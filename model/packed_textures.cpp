#include "model/packed_textures.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/core.hpp>

#include "core/image_io.h"

namespace texlume::model {

std::vector<unsigned char> PlanesPng(const std::vector<const QuantisedPlane*>& planes, int width,
                                     int height, const std::string& label) {
  cv::Mat bgra(height, width, CV_8UC4, cv::Scalar::all(0));
  constexpr int kBgraOfRgba[4] = {2, 1, 0, 3};
  for (std::size_t c = 0; c < planes.size(); ++c)
    for (int y = 0; y < height; ++y) {
      const unsigned char* in =
          planes[c]->bytes.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(width);
      unsigned char* out = bgra.ptr<unsigned char>(y) + kBgraOfRgba[c];
      for (int x = 0; x < width; ++x) out[4 * x] = in[x];
    }
  return EncodePng(bgra, label);
}

QuantisedPlane QuantisePlane(const std::vector<float>& values) {
  QuantisedPlane q;
  if (values.empty()) return q;
  const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
  q.bias = *lo;
  q.scale = *hi > *lo ? static_cast<double>(*hi) - *lo : 1.0;
  q.bytes.resize(values.size());
  for (std::size_t i = 0; i < values.size(); ++i)
    q.bytes[i] = static_cast<unsigned char>(
        std::clamp(std::lround((values[i] - q.bias) / q.scale * 255.0), 0L, 255L));
  return q;
}

namespace {

// The horizon's azimuths in the packed textures (4 RGBA PNGs).
constexpr int kWebHorizonSectors = 16;

}  // namespace

HorizonTextures EncodeHorizonTextures(const ptm::SelfShadowing& shadowing,
                                      const std::string& label) {
  const ptm::HorizonMap& h = shadowing.horizon;
  constexpr double kQuarterTurn = std::numbers::pi / 2.0;
  std::vector<QuantisedPlane> planes(kWebHorizonSectors);
  for (int s = 0; s < kWebHorizonSectors; ++s) {
    QuantisedPlane& q = planes[static_cast<std::size_t>(s)];
    q.scale = kQuarterTurn;
    q.bias = 0.0;
    q.bytes.resize(h.NumTexels());
    const double azimuth = 2.0 * std::numbers::pi * s / kWebHorizonSectors;
    for (std::size_t t = 0; t < h.NumTexels(); ++t)
      q.bytes[t] = static_cast<unsigned char>(
          std::clamp(std::lround(h.ElevationAt(t, azimuth) / kQuarterTurn * 255.0), 0L, 255L));
  }
  HorizonTextures out;
  for (int first = 0; first < kWebHorizonSectors; first += 4) {
    std::vector<const QuantisedPlane*> rgba;
    for (int s = first; s < first + 4; ++s) rgba.push_back(&planes[static_cast<std::size_t>(s)]);
    out.pngs.push_back(PlanesPng(rgba, h.width, h.height, label));
  }
  out.fields = {{"sectors", kWebHorizonSectors},
                {"elevation_scale", kQuarterTurn},
                {"shadow_floor", shadowing.shadow_floor},
                {"penumbra_rad", shadowing.penumbra_rad}};
  return out;
}

}  // namespace texlume::model
