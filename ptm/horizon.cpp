#include "ptm/horizon.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <numbers>
#include <stdexcept>
#include <string>

#include "core/errors.h"
#include "ptm/exr_io.h"

namespace texlume::ptm {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// The slopes of the height field per texel: p = dH/dcolumn = -n_x / n_z and
// q = dH/drow = +n_y / n_z (rows run down, y up).
void SlopesFromNormals(const std::vector<float>& normals_xyz, int width, int height,
                       double min_normal_z, cv::Mat& p, cv::Mat& q) {
  p.create(height, width, CV_64FC1);
  q.create(height, width, CV_64FC1);
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) {
      const float* n = normals_xyz.data() + (static_cast<std::size_t>(r) * width + c) * 3;
      const double nz = std::max(static_cast<double>(n[2]), min_normal_z);
      p.at<double>(r, c) = -n[0] / nz;
      q.at<double>(r, c) = n[1] / nz;
    }
}

// The divergence of the slopes taken at the half-texel edges (the mean of the two
// texels' slopes), with no flux across the map's border: the right-hand side of
// the least-squares normal equations L H = f.
cv::Mat EdgeDivergence(const cv::Mat& p, const cv::Mat& q) {
  cv::Mat f = cv::Mat::zeros(p.size(), CV_64FC1);
  for (int r = 0; r < p.rows; ++r)
    for (int c = 0; c + 1 < p.cols; ++c) {
      const double edge = 0.5 * (p.at<double>(r, c) + p.at<double>(r, c + 1));
      f.at<double>(r, c) += edge;
      f.at<double>(r, c + 1) -= edge;
    }
  for (int r = 0; r + 1 < p.rows; ++r)
    for (int c = 0; c < p.cols; ++c) {
      const double edge = 0.5 * (q.at<double>(r, c) + q.at<double>(r + 1, c));
      f.at<double>(r, c) += edge;
      f.at<double>(r + 1, c) -= edge;
    }
  return f;
}

// Solves L H = f, L the Neumann Laplacian, in the cosine basis where L is
// diagonal: eigenvalue (2 cos(pi k / W) - 2) + (2 cos(pi l / H) - 2).
cv::Mat SolveNeumannPoisson(const cv::Mat& f) {
  cv::Mat coefficients;
  cv::dct(f, coefficients);
  for (int l = 0; l < f.rows; ++l)
    for (int k = 0; k < f.cols; ++k) {
      const double eigenvalue = 2.0 * std::cos(std::numbers::pi * k / f.cols) - 2.0 +
                                2.0 * std::cos(std::numbers::pi * l / f.rows) - 2.0;
      double& a = coefficients.at<double>(l, k);
      a = (k == 0 && l == 0) ? 0.0 : a / eigenvalue;
    }
  cv::Mat height_texels;
  cv::dct(coefficients, height_texels, cv::DCT_INVERSE);
  return height_texels;
}

double Bilinear(const cv::Mat& map, double column, double row) {
  const int c0 = std::min(static_cast<int>(column), map.cols - 2);
  const int r0 = std::min(static_cast<int>(row), map.rows - 2);
  const double fc = column - c0, fr = row - r0;
  const double top = map.at<double>(r0, c0) * (1 - fc) + map.at<double>(r0, c0 + 1) * fc;
  const double bottom = map.at<double>(r0 + 1, c0) * (1 - fc) + map.at<double>(r0 + 1, c0 + 1) * fc;
  return top * (1 - fr) + bottom * fr;
}

// The largest elevation of the relief seen from texel (row, column) along the
// image-space direction (d_column, d_row), up to `max_distance` texels.
// `regions` (CV_32SC1 or empty): the ray stops where the nearest texel's region is
// not its origin's (an origin in region < 0 goes on everywhere).
double HorizonAlong(const cv::Mat& height_texels, const cv::Mat& regions, int row, int column,
                    double d_column, double d_row, int max_distance) {
  const double h0 = height_texels.at<double>(row, column);
  const int region = regions.empty() ? -1 : regions.at<std::int32_t>(row, column);
  double best_slope = 0.0;
  for (int t = 1; t <= max_distance; ++t) {
    const double c = column + t * d_column, r = row + t * d_row;
    if (c < 0 || r < 0 || c > height_texels.cols - 1 || r > height_texels.rows - 1) break;
    if (region >= 0 && regions.at<std::int32_t>(static_cast<int>(std::lround(r)),
                                                static_cast<int>(std::lround(c))) != region)
      break;
    best_slope = std::max(best_slope, (Bilinear(height_texels, c, r) - h0) / t);
  }
  return std::atan(best_slope);
}

}  // namespace

cv::Mat HeightFromNormals(const std::vector<float>& normals_xyz, int width, int height,
                          double min_normal_z) {
  if (width < 2 || height < 2)
    throw std::invalid_argument("HeightFromNormals: the map must be at least 2 x 2 texels");
  if (normals_xyz.size() != static_cast<std::size_t>(width) * height * 3)
    throw std::invalid_argument("HeightFromNormals: " + std::to_string(normals_xyz.size()) +
                                " floats for a " + std::to_string(width) + " x " +
                                std::to_string(height) + " normal map");
  // cv::dct takes even sizes only: an odd side is solved with its last texels
  // repeated once, then cropped.
  const int solve_width = width + width % 2, solve_height = height + height % 2;
  std::vector<float> padded(static_cast<std::size_t>(solve_width) * solve_height * 3);
  for (int r = 0; r < solve_height; ++r)
    for (int c = 0; c < solve_width; ++c)
      std::copy_n(normals_xyz.data() + (static_cast<std::size_t>(std::min(r, height - 1)) * width +
                                        std::min(c, width - 1)) *
                                           3,
                  3, padded.data() + (static_cast<std::size_t>(r) * solve_width + c) * 3);
  cv::Mat p, q;
  SlopesFromNormals(padded, solve_width, solve_height, min_normal_z, p, q);
  cv::Mat height_texels =
      SolveNeumannPoisson(EdgeDivergence(p, q))(cv::Rect(0, 0, width, height)).clone();
  height_texels -= cv::mean(height_texels)[0];
  return height_texels;
}

namespace {

// The sectors either side of an azimuth (phi_s = 2 pi s / sectors) and the second's weight.
void SectorsOfAzimuth(double azimuth_rad, int sectors, int& s0, int& s1, double& f) {
  double at = azimuth_rad / kTwoPi * sectors;
  at -= std::floor(at / sectors) * sectors;
  s0 = std::min(static_cast<int>(at), sectors - 1);
  s1 = (s0 + 1) % sectors;
  f = at - s0;
}

}  // namespace

double HorizonMap::ElevationAt(std::size_t texel, double azimuth_rad) const {
  int s0 = 0, s1 = 0;
  double f = 0.0;
  SectorsOfAzimuth(azimuth_rad, sectors, s0, s1, f);
  const float* e = elevation_rad.data() + texel * static_cast<std::size_t>(sectors);
  return e[s0] * (1 - f) + e[s1] * f;
}

LightAmongSectors::LightAmongSectors(const Eigen::Vector3d& light, int sectors)
    : elevation_rad(std::asin(std::clamp(light.normalized().z(), -1.0, 1.0))) {
  SectorsOfAzimuth(std::atan2(light.y(), light.x()), sectors, s0, s1, f);
}

HorizonMap ComputeHorizonMap(const cv::Mat& height_texels, int sectors, int max_distance_texels,
                             const cv::Mat& regions) {
  if (sectors < 4 || sectors > 64)
    throw std::invalid_argument("ComputeHorizonMap: sectors " + std::to_string(sectors) +
                                " outside [4, 64]");
  if (max_distance_texels < 1 || max_distance_texels > 4096)
    throw std::invalid_argument("ComputeHorizonMap: distance " +
                                std::to_string(max_distance_texels) + " outside [1, 4096]");
  if (height_texels.type() != CV_64FC1 || height_texels.cols < 2 || height_texels.rows < 2)
    throw std::invalid_argument(
        "ComputeHorizonMap: expects a CV_64FC1 height map of 2 x 2 or more");
  if (!regions.empty() && (regions.type() != CV_32SC1 || regions.size() != height_texels.size()))
    throw std::invalid_argument("ComputeHorizonMap: regions must be CV_32SC1 of the map's size");
  HorizonMap horizon;
  horizon.width = height_texels.cols;
  horizon.height = height_texels.rows;
  horizon.sectors = sectors;
  horizon.elevation_rad.resize(horizon.NumTexels() * static_cast<std::size_t>(sectors));
#pragma omp parallel for schedule(dynamic, 8)
  for (int r = 0; r < horizon.height; ++r)
    for (int c = 0; c < horizon.width; ++c)
      for (int s = 0; s < sectors; ++s) {
        const double phi = kTwoPi * s / sectors;
        // Texel frame (cos phi, sin phi) is image (column +cos, row -sin).
        horizon.elevation_rad[(static_cast<std::size_t>(r) * horizon.width + c) * sectors +
                              static_cast<std::size_t>(s)] =
            static_cast<float>(HorizonAlong(height_texels, regions, r, c, std::cos(phi),
                                            -std::sin(phi), max_distance_texels));
      }
  return horizon;
}

double VisibilityAboveHorizon(double light_elevation_rad, double horizon_elevation_rad,
                              double penumbra_rad) {
  return std::clamp((light_elevation_rad - horizon_elevation_rad) / penumbra_rad + 0.5, 0.0, 1.0);
}

double HorizonVisibility(const HorizonMap& horizon, std::size_t texel, const Eigen::Vector3d& light,
                         double penumbra_rad) {
  return VisibilityAboveHorizon(std::asin(std::clamp(light.z(), -1.0, 1.0)),
                                horizon.ElevationAt(texel, std::atan2(light.y(), light.x())),
                                penumbra_rad);
}

double SelfShadowing::LightFactor(std::size_t texel, const Eigen::Vector3d& light) const {
  return LightFactorAt(HorizonVisibility(horizon, texel, light, penumbra_rad));
}

double SelfShadowing::CellLightFactor(double light_elevation_rad, double horizon_mean_rad,
                                      double horizon_variance) const {
  const double width =
      std::sqrt(penumbra_rad * penumbra_rad + 12.0 * std::max(0.0, horizon_variance));
  return LightFactorAt(VisibilityAboveHorizon(light_elevation_rad, horizon_mean_rad, width));
}

namespace {

// The light elevations (degrees) whose shadows LowLightShadowLoss measures.
constexpr double kLowLightElevationsDeg[] = {10.0, 15.0, 20.0, 25.0, 30.0};
// Histogram bins over a horizon's tangent, [0, kMaxTangent): the loss at any gain is
// read from it (elevations above atan(kMaxTangent) = 84 degrees share the last bin).
constexpr int kTangentBins = 4096;
constexpr double kMaxTangent = 10.0;

// The tangent of a horizon elevation kept within [0, pi / 2) (a float pi / 2 is just
// above it).
double HorizonTangent(float elevation_rad) {
  constexpr double kSteepest = std::numbers::pi / 2 - 1e-6;
  return std::tan(std::clamp(static_cast<double>(elevation_rad), 0.0, kSteepest));
}

// How many (texel, sector) pairs of `counted` texels have a horizon tangent in each bin.
std::vector<double> TangentHistogram(const HorizonMap& h, const std::vector<char>& counted) {
  std::vector<double> bins(kTangentBins, 0.0);
  const auto sectors = static_cast<std::size_t>(h.sectors);
  for (std::size_t t = 0; t < h.NumTexels(); ++t) {
    if (!counted.empty() && !counted[t]) continue;
    for (std::size_t s = 0; s < sectors; ++s) {
      const double tangent =
          std::clamp(HorizonTangent(h.elevation_rad[t * sectors + s]), 0.0, kMaxTangent);
      const int bin =
          std::min(kTangentBins - 1, static_cast<int>(tangent / kMaxTangent * kTangentBins));
      bins[static_cast<std::size_t>(bin)] += 1.0;
    }
  }
  return bins;
}

// LowLightShadowLoss from a tangent histogram: each bin at its centre.
double LossOfHistogram(const std::vector<double>& bins, const SelfShadowing& s, double gain) {
  double loss = 0.0, count = 0.0;
  for (int b = 0; b < kTangentBins; ++b) {
    const double n = bins[static_cast<std::size_t>(b)];
    if (n == 0.0) continue;
    const double tangent = b == 0 ? 0.0 : (b + 0.5) * kMaxTangent / kTangentBins;
    const double horizon = std::atan(gain * tangent);
    for (const double e : kLowLightElevationsDeg) {
      const double v =
          VisibilityAboveHorizon(e * std::numbers::pi / 180.0, horizon, s.penumbra_rad);
      loss += n * (1.0 - v) * (1.0 - s.shadow_floor);
    }
    count += n * std::size(kLowLightElevationsDeg);
  }
  return count > 0.0 ? loss / count : 0.0;
}

}  // namespace

double LowLightShadowLoss(const SelfShadowing& shadowing, const std::vector<char>& counted,
                          double relief_gain) {
  return LossOfHistogram(TangentHistogram(shadowing.horizon, counted), shadowing, relief_gain);
}

double MatchLowLightShadowLoss(SelfShadowing& shadowing, const std::vector<char>& counted,
                               double target_loss) {
  const std::vector<double> bins = TangentHistogram(shadowing.horizon, counted);
  // Nothing to match (a flat sample, or an atlas that casts no shadow at any gain): the
  // relief as it is.
  if (!(target_loss > 0.0) || LossOfHistogram(bins, shadowing, 4.0) <= 0.0) return 1.0;
  // The loss rises with the gain: bisection on log m over [1/4, 4].
  double low = std::log(0.25), high = std::log(4.0);
  for (int it = 0; it < 40; ++it) {
    const double mid = 0.5 * (low + high);
    (LossOfHistogram(bins, shadowing, std::exp(mid)) < target_loss ? low : high) = mid;
  }
  return ScaleRelief(shadowing, std::exp(0.5 * (low + high)));
}

double ScaleRelief(SelfShadowing& shadowing, double gain) {
  for (float& e : shadowing.horizon.elevation_rad)
    e = static_cast<float>(std::atan(gain * HorizonTangent(e)));
  shadowing.height_scale *= gain;
  return gain;
}

namespace {

// "horizon.00" to "horizon.63": zero-padded so that name order is sector order.
std::string SectorChannel(int s) {
  return std::string("horizon.") + static_cast<char>('0' + s / 10) +
         static_cast<char>('0' + s % 10);
}

double RequireAttribute(const std::map<std::string, float>& attributes, const std::string& name,
                        double low, double high, const std::string& label) {
  const auto it = attributes.find(name);
  if (it == attributes.end())
    throw InputError(label, "is not a texlume horizon file: no " + name + " attribute");
  if (!(it->second >= low && it->second <= high))
    throw InputError(label, name + " " + std::to_string(it->second) + " is outside [" +
                                std::to_string(low) + ", " + std::to_string(high) + "]");
  return it->second;
}

}  // namespace

void WriteSelfShadowingExr(const SelfShadowing& shadowing, const std::filesystem::path& path) {
  const HorizonMap& h = shadowing.horizon;
  std::vector<cv::Mat> planes;
  std::vector<std::string> names;
  for (int s = 0; s < h.sectors; ++s) {
    cv::Mat plane(h.height, h.width, CV_32FC1);
    for (std::size_t t = 0; t < h.NumTexels(); ++t)
      plane.at<float>(static_cast<int>(t / static_cast<std::size_t>(h.width)),
                      static_cast<int>(t % static_cast<std::size_t>(h.width))) =
          h.elevation_rad[t * static_cast<std::size_t>(h.sectors) + static_cast<std::size_t>(s)];
    planes.push_back(plane);
    names.push_back(SectorChannel(s));
  }
  WriteExr(path, planes, names,
           {{"texlume:height_scale", static_cast<float>(shadowing.height_scale)},
            {"texlume:shadow_floor", static_cast<float>(shadowing.shadow_floor)},
            {"texlume:penumbra_rad", static_cast<float>(shadowing.penumbra_rad)}});
}

SelfShadowing ReadSelfShadowingExr(const std::filesystem::path& path) {
  const std::string label = path.string();
  std::vector<std::string> names;
  std::map<std::string, float> attributes;
  const std::vector<cv::Mat> planes = ReadExr(path, &names, &attributes);
  const int sectors = static_cast<int>(planes.size());
  if (sectors < 4 || sectors > 64)
    throw InputError(label, "is not a texlume horizon file: " + std::to_string(sectors) +
                                " channels, not 4 to 64 sectors");
  SelfShadowing out;
  HorizonMap& h = out.horizon;
  h.width = planes[0].cols;
  h.height = planes[0].rows;
  h.sectors = sectors;
  h.elevation_rad.resize(h.NumTexels() * static_cast<std::size_t>(sectors));
  for (int s = 0; s < sectors; ++s) {
    // The reader may order channels by name: find each sector's.
    const auto it = std::find(names.begin(), names.end(), SectorChannel(s));
    if (it == names.end())
      throw InputError(label, "is not a texlume horizon file: no channel " + SectorChannel(s));
    const cv::Mat& plane = planes[static_cast<std::size_t>(it - names.begin())];
    for (std::size_t t = 0; t < h.NumTexels(); ++t) {
      const float e = plane.at<float>(static_cast<int>(t / static_cast<std::size_t>(h.width)),
                                      static_cast<int>(t % static_cast<std::size_t>(h.width)));
      if (!(e >= 0.0f && e <= static_cast<float>(std::numbers::pi / 2)))
        throw InputError(label, SectorChannel(s) + " holds " + std::to_string(e) +
                                    ", not an elevation in [0, pi / 2]");
      h.elevation_rad[t * static_cast<std::size_t>(sectors) + static_cast<std::size_t>(s)] = e;
    }
  }
  out.height_scale = RequireAttribute(attributes, "texlume:height_scale", 0.0, 100.0, label);
  out.shadow_floor = RequireAttribute(attributes, "texlume:shadow_floor", 0.0, 1.0, label);
  out.penumbra_rad =
      RequireAttribute(attributes, "texlume:penumbra_rad", 1e-6, std::numbers::pi / 4, label);
  return out;
}

SelfShadowing ReadSelfShadowingExr(const std::filesystem::path& path, int width, int height,
                                   const std::string& of_what) {
  SelfShadowing shadowing = ReadSelfShadowingExr(path);
  const HorizonMap& h = shadowing.horizon;
  if (h.width != width || h.height != height)
    throw InputError(path.string(), "a " + std::to_string(h.width) + " x " +
                                        std::to_string(h.height) + " horizon map for " + of_what +
                                        " of " + std::to_string(width) + " x " +
                                        std::to_string(height));
  return shadowing;
}

}  // namespace texlume::ptm
