// Atlas horizons at chart borders (issue 29): a model's atlas horizons
// (texlume synth --sample-horizon) computed again from its atlases' own normals
// (ptm::ShadowingOfPtm at the model's height scale), once with rays that cross
// gutters into other charts and once with rays that stop at their chart's edge
// (model::AtlasChartRegions). For texels binned by their distance to their chart's
// edge, the mean light factor (SelfShadowing::LightFactor, 16 azimuths) at a few
// low light elevations: a stationary material's shadows do not depend on where a
// chart ends, so each bin should match the charts' inner texels.
// Usage: chart_horizon_bench MODEL_DIR
#include <cmath>
#include <cstdio>
#include <exception>
#include <iterator>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "model/model_io.h"
#include "model/web_model.h"
#include "ptm/horizon.h"
#include "ptm/shadowed_fit.h"

namespace {

using texlume::ptm::SelfShadowing;

constexpr double kElevationsDeg[] = {10.0, 20.0, 30.0};
constexpr int kAzimuths = 16;
constexpr int kReachTexels = 48;  // ShadowingOfPtm's default
// Bins of the distance to the chart's edge, texels: [edge[b], edge[b + 1]).
constexpr double kBinEdges[] = {0.0, 2.0, 8.0, 24.0, 48.0, 1e9};
constexpr int kBins = static_cast<int>(std::size(kBinEdges)) - 1;

// Per texel, its distance (texels) to the nearest edge texel: a texel with a 4-neighbour
// of another region (0 on the chart's own outer row; the atlas's border is no edge).
cv::Mat DistanceToChartEdge(const cv::Mat& charts) {
  cv::Mat inner(charts.size(), CV_8UC1, cv::Scalar(255));
  for (int r = 0; r < charts.rows; ++r)
    for (int c = 0; c < charts.cols; ++c) {
      const int own = charts.at<int>(r, c);
      const bool edge = (r > 0 && charts.at<int>(r - 1, c) != own) ||
                        (c > 0 && charts.at<int>(r, c - 1) != own) ||
                        (r + 1 < charts.rows && charts.at<int>(r + 1, c) != own) ||
                        (c + 1 < charts.cols && charts.at<int>(r, c + 1) != own);
      if (edge) inner.at<unsigned char>(r, c) = 0;
    }
  cv::Mat distance;
  cv::distanceTransform(inner, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  return distance;
}

// Sums of the light factor per bin and elevation, and texels per bin.
struct BinnedLight {
  std::vector<double> sum = std::vector<double>(kBins * std::size(kElevationsDeg), 0.0);
  std::vector<double> texels = std::vector<double>(kBins, 0.0);

  void Add(const SelfShadowing& s, const cv::Mat& charts, const cv::Mat& distance) {
    for (int r = 0; r < charts.rows; ++r)
      for (int c = 0; c < charts.cols; ++c) {
        if (charts.at<int>(r, c) < 0) continue;
        int b = 0;
        while (b + 1 < kBins && distance.at<float>(r, c) >= kBinEdges[b + 1]) ++b;
        texels[static_cast<std::size_t>(b)] += 1.0;
        const auto t = static_cast<std::size_t>(r) * static_cast<std::size_t>(charts.cols) +
                       static_cast<std::size_t>(c);
        for (std::size_t e = 0; e < std::size(kElevationsDeg); ++e) {
          const double el = kElevationsDeg[e] * std::numbers::pi / 180.0;
          double light = 0.0;
          for (int a = 0; a < kAzimuths; ++a) {
            const double az = 2.0 * std::numbers::pi * a / kAzimuths;
            light += s.LightFactor(t, Eigen::Vector3d(std::cos(el) * std::cos(az),
                                                      std::cos(el) * std::sin(az), std::sin(el)));
          }
          sum[static_cast<std::size_t>(b) * std::size(kElevationsDeg) + e] += light / kAzimuths;
        }
      }
  }
  double Mean(int b, std::size_t e) const {
    const auto bin = static_cast<std::size_t>(b);
    return texels[bin] > 0 ? sum[bin * std::size(kElevationsDeg) + e] / texels[bin] : 0.0;
  }
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s MODEL_DIR\n", argv[0]);
    return 2;
  }
  try {
    using namespace texlume;
    const model::TexturedModel m = model::ReadModelFolder(argv[1]);
    if (m.shadowing.empty())
      throw std::runtime_error("the model has no horizon (--sample-horizon)");
    const std::vector<cv::Mat> charts = model::AtlasChartRegions(m);
    BinnedLight crossing, stopping;
    for (std::size_t a = 0; a < m.atlases.size(); ++a) {
      const cv::Mat distance = DistanceToChartEdge(charts[a]);
      crossing.Add(ptm::ShadowingOfPtm(m.atlases[a], m.shadowing[a], kReachTexels), charts[a],
                   distance);
      stopping.Add(ptm::ShadowingOfPtm(m.atlases[a], m.shadowing[a], kReachTexels, charts[a]),
                   charts[a], distance);
    }
    std::printf("| distance to the chart's edge (texels) | texels |");
    for (const double e : kElevationsDeg)
      std::printf(" light at %.0f deg: crossing / stopping |", e);
    std::printf("\n|---|---|");
    for (std::size_t e = 0; e < std::size(kElevationsDeg); ++e) std::printf("---|");
    std::printf("\n");
    for (int b = 0; b < kBins; ++b) {
      std::printf("| %g-%s | %.0f |", kBinEdges[b],
                  b + 1 < kBins ? std::to_string(static_cast<int>(kBinEdges[b + 1])).c_str() : "",
                  crossing.texels[static_cast<std::size_t>(b)]);
      for (std::size_t e = 0; e < std::size(kElevationsDeg); ++e)
        std::printf(" %.4f / %.4f |", crossing.Mean(b, e), stopping.Mean(b, e));
      std::printf("\n");
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "chart_horizon_bench: %s\n", e.what());
    return 1;
  }
}
