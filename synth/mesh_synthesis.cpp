#include "synth/mesh_synthesis.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <opencv2/flann.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "ptm/coefficient_space.h"
#include "sfm/errors.h"
#include "synth/planar_synthesis.h"
#include "synth/tangent_field.h"
#include "synth/template_match.h"

namespace texlume::synth {
namespace {

using LightList = std::vector<std::pair<Eigen::Vector3d, double>>;  // (tangent-frame dir, I)

// The sample's raw coefficient planes (a0..a5 per polynomial, then LRGB colour),
// for relighting at reduced resolutions (evaluation is linear in the coefficients,
// so reducing the planes equals reducing the relit image, up to the clamp).
std::vector<cv::Mat> RawPlanes(const ptm::Ptm& p) {
  const int polys = p.NumPolynomials();
  const int count = polys * 6 + (p.format == ptm::PtmFormat::kLrgb ? 3 : 0);
  std::vector<cv::Mat> planes(static_cast<std::size_t>(count));
  for (cv::Mat& m : planes) m = cv::Mat(p.height, p.width, CV_32FC1);
  for (int y = 0; y < p.height; ++y) {
    for (int x = 0; x < p.width; ++x) {
      const std::size_t t = static_cast<std::size_t>(y) * p.width + x;
      for (int q = 0; q < polys; ++q)
        for (int i = 0; i < 6; ++i)
          planes[static_cast<std::size_t>(q * 6 + i)].at<float>(y, x) = p.Coefficients(t, q)[i];
      if (p.format == ptm::PtmFormat::kLrgb)
        for (int c = 0; c < 3; ++c)
          planes[static_cast<std::size_t>(6 + c)].at<float>(y, x) = p.colour[t * 3 + c];
    }
  }
  return planes;
}

// Bilinear value of a CV_32FC1 plane at (x, y) (pixel centres at integers),
// clamped to the plane.
double BilinearClamped(const cv::Mat& m, double x, double y) {
  x = std::clamp(x, 0.0, m.cols - 1.0);
  y = std::clamp(y, 0.0, m.rows - 1.0);
  const int x0 = std::min(static_cast<int>(x), std::max(m.cols - 2, 0));
  const int y0 = std::min(static_cast<int>(y), std::max(m.rows - 2, 0));
  const int x1 = std::min(x0 + 1, m.cols - 1), y1 = std::min(y0 + 1, m.rows - 1);
  const double fx = x - x0, fy = y - y0;
  const float* r0 = m.ptr<float>(y0);
  const float* r1 = m.ptr<float>(y1);
  return (1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x1]) + fy * ((1 - fx) * r1[x0] + fx * r1[x1]);
}

// Detail transfer: a window of 3 x 3 points (dx, dy) texels apart around
// (x, y), 6 orthonormal luminance coefficients each (5 x 5 matched worse on the
// demo: SSIM 0.536 against 0.538).
constexpr int kDetailWindowRadius = 1;
constexpr int kDetailWindowLength =
    (2 * kDetailWindowRadius + 1) * (2 * kDetailWindowRadius + 1) * 6;
// Leaves visited per query (FLANN checks): 8 matches as well as 32 on the demo
// (SSIM 0.538 either way) in 60 % of the time.
constexpr int kDetailChecks = 8;
constexpr int kDetailTrees = 4;
// At most this many sample points per dictionary (2^16 windows take 14 MiB;
// a 256 x 256 sample has about 62 000).
constexpr std::size_t kDetailMaxPoints = std::size_t{1} << 16;
void CoarseWindow(const std::vector<cv::Mat>& coarse, double x, double y, double dx, double dy,
                  float* window) {
  for (int b = -kDetailWindowRadius; b <= kDetailWindowRadius; ++b)
    for (int a = -kDetailWindowRadius; a <= kDetailWindowRadius; ++a)
      for (int m = 0; m < 6; ++m)
        *window++ = static_cast<float>(
            BilinearClamped(coarse[static_cast<std::size_t>(m)], x + a * dx, y + b * dy));
}

// The sample reduced to a photo density r = 2^(-level/4) photo pixels per texel.
struct ReducedSample {
  std::vector<cv::Mat> raw;   // raw coefficient (+ colour) planes
  double rx = 1.0, ry = 1.0;  // effective density along x and y
};

}  // namespace

float SrgbToLinear(float v) {
  v = std::clamp(v, 0.0f, 1.0f);
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

float LinearToSrgb(float v) {
  v = std::clamp(v, 0.0f, 1.0f);
  return v <= 0.0031308f ? v * 12.92f : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

Eigen::Vector3f RelightMixture(const float* coefficients, const float* colour,
                               ptm::PtmFormat format, const LightList& lights, double gain) {
  Eigen::Vector3f linear = Eigen::Vector3f::Zero();
  static const double z_horizon = std::sin(kHorizonElevationDeg * std::numbers::pi / 180.0);
  for (const auto& [l_in, intensity] : lights) {
    if (l_in.z() <= 0.0) continue;
    // Below kHorizonElevationDeg the biquadratic is extrapolated beyond any
    // capture light and overshoots: take its value at that elevation (same
    // azimuth) fading linearly with l_z to 0 at the horizon.
    Eigen::Vector3d l = l_in;
    double fall = 1.0;
    if (l.z() < z_horizon) {
      fall = l.z() / z_horizon;
      const double r = std::hypot(l.x(), l.y());
      const double s = std::sqrt(1.0 - z_horizon * z_horizon) / r;
      l = Eigen::Vector3d(l.x() * s, l.y() * s, z_horizon);
    }
    for (int c = 0; c < 3; ++c) {
      double v;
      if (format == ptm::PtmFormat::kLrgb) {
        v = ptm::EvaluatePolynomial(coefficients, l.x(), l.y()) * colour[c];
      } else {
        v = ptm::EvaluatePolynomial(coefficients + 6 * c, l.x(), l.y());
      }
      linear[c] += static_cast<float>(intensity * fall) * SrgbToLinear(static_cast<float>(v));
    }
  }
  Eigen::Vector3f out;
  for (int c = 0; c < 3; ++c) out[c] = LinearToSrgb(static_cast<float>(gain) * linear[c]);
  return out;
}

void MeshSynthesisOptions::Check() const {
  if (!(sample_texel_size > 0.0) || !std::isfinite(sample_texel_size))
    throw OptionError("sample texel size must be a positive number of world units");
  if (strip < 2 || strip > 32) throw OptionError("strip (W_e) must be in [2, 32] texels");
  if (top_k < 1) throw OptionError("top_k must be >= 1");
  if (max_views < 1) throw OptionError("max_views must be >= 1");
  if (!(tolerance >= 0.0)) throw OptionError("tolerance must be >= 0");
  if (min_photo_pixels < 1) throw OptionError("min_photo_pixels must be >= 1");
  if (!(correction_sigma > 0.0)) throw OptionError("correction_sigma must be > 0");
  if (!(correction_prior_shrink <= 1.0))
    throw OptionError("correction_prior_shrink must be in [0, 1], or < 0 to estimate it");
  if (!(correction_noise > 0.0) || !std::isfinite(correction_noise))
    throw OptionError("correction_noise must be > 0");
  if (correction_iterations < 0 || correction_iterations > 5)
    throw OptionError("correction_iterations must be in [0, 5]");
  if (max_texels < 1) throw OptionError("max_texels must be >= 1");
  if (!(field_direction_in_world.norm() > 0.0))
    throw OptionError("field direction must be nonzero");
}

bool MeshSynthesis::SamplePatch(int face, const Eigen::Vector2d& p, float* out) const {
  const TrianglePatch& patch = patches[static_cast<std::size_t>(face)];
  const double u = (p.x() - patch.x_min) / texel_size - 0.5;
  const double v = (patch.y_max - p.y()) / texel_size - 0.5;
  if (u < -0.5 || v < -0.5 || u > patch.width - 0.5 || v > patch.height - 0.5) return false;
  const double uc = std::clamp(u, 0.0, patch.width - 1.0),
               vc = std::clamp(v, 0.0, patch.height - 1.0);
  const int x0 = std::min(static_cast<int>(uc), patch.width - 2 < 0 ? 0 : patch.width - 2);
  const int y0 = std::min(static_cast<int>(vc), patch.height - 2 < 0 ? 0 : patch.height - 2);
  const int x1 = std::min(x0 + 1, patch.width - 1), y1 = std::min(y0 + 1, patch.height - 1);
  const float fx = static_cast<float>(uc - x0), fy = static_cast<float>(vc - y0);
  for (std::size_t c = 0; c < sample_planes.size(); ++c) {
    const cv::Mat& m = sample_planes[c];
    const float a = m.at<float>(patch.sample_y + y0, patch.sample_x + x0);
    const float b = m.at<float>(patch.sample_y + y0, patch.sample_x + x1);
    const float d = m.at<float>(patch.sample_y + y1, patch.sample_x + x0);
    const float e = m.at<float>(patch.sample_y + y1, patch.sample_x + x1);
    out[c] = (1 - fy) * ((1 - fx) * a + fx * b) + fy * ((1 - fx) * d + fx * e);
  }
  if (!patch.correction.empty()) {
    const cv::Mat& c0 = patch.correction[0];
    const double gu =
        std::clamp((u + 0.5) * patch.correction_density.x() - 0.5, 0.0, c0.cols - 1.0);
    const double gv =
        std::clamp((v + 0.5) * patch.correction_density.y() - 0.5, 0.0, c0.rows - 1.0);
    const int gx0 = static_cast<int>(gu), gy0 = static_cast<int>(gv);
    const int gx1 = std::min(gx0 + 1, c0.cols - 1), gy1 = std::min(gy0 + 1, c0.rows - 1);
    const float gfx = static_cast<float>(gu - gx0), gfy = static_cast<float>(gv - gy0);
    auto at = [&](const cv::Mat& m) {
      return (1 - gfy) * ((1 - gfx) * m.at<float>(gy0, gx0) + gfx * m.at<float>(gy0, gx1)) +
             gfy * ((1 - gfx) * m.at<float>(gy1, gx0) + gfx * m.at<float>(gy1, gx1));
    };
    if (!patch.detail_source.empty()) {
      // Detail transfer (on the correction's grid): the patch's own detail band
      // out, the band around each of the 4 nearest cells' matched sample points
      // in, weighted bilinearly.
      const std::vector<cv::Mat>& band = detail_bands.at(patch.detail_level);
      const double rx = patch.correction_density.x(), ry = patch.correction_density.y();
      const std::array<std::pair<cv::Point, float>, 4> cells = {
          std::pair{cv::Point(gx0, gy0), (1 - gfx) * (1 - gfy)},
          std::pair{cv::Point(gx1, gy0), gfx * (1 - gfy)},
          std::pair{cv::Point(gx0, gy1), (1 - gfx) * gfy},
          std::pair{cv::Point(gx1, gy1), gfx * gfy}};
      for (std::size_t c = 0; c < band.size(); ++c)
        out[c] -=
            static_cast<float>(BilinearClamped(band[c], patch.sample_x + uc, patch.sample_y + vc));
      for (const auto& [cell, w] : cells) {
        if (w <= 0.0f) continue;
        const cv::Vec2f s = patch.detail_source.at<cv::Vec2f>(cell.y, cell.x);
        const double x = s[0] + uc - ((cell.x + 0.5) / rx - 0.5);
        const double y = s[1] + vc - ((cell.y + 0.5) / ry - 0.5);
        for (std::size_t c = 0; c < band.size(); ++c)
          out[c] += static_cast<float>(w * BilinearClamped(band[c], x, y));
      }
    }
    {
      // The additive change: Catmull-Rom (bicubic) over the 4 x 4 nearest cells,
      // which keeps the photo's detail sharper than bilinear.
      const int bx = static_cast<int>(std::floor(gu)), by = static_cast<int>(std::floor(gv));
      auto weights = [](double t, double w[4]) {
        const double t2 = t * t, t3 = t2 * t;
        w[0] = -0.5 * t3 + t2 - 0.5 * t;
        w[1] = 1.5 * t3 - 2.5 * t2 + 1.0;
        w[2] = -1.5 * t3 + 2.0 * t2 + 0.5 * t;
        w[3] = 0.5 * t3 - 0.5 * t2;
      };
      double wx[4], wy[4];
      weights(gu - bx, wx);
      weights(gv - by, wy);
      for (int i = 0; i < 6; ++i) {
        const cv::Mat& m = patch.correction[static_cast<std::size_t>(i)];
        double acc = 0.0;
        for (int a = 0; a < 4; ++a) {
          const float* row = m.ptr<float>(std::clamp(by - 1 + a, 0, m.rows - 1));
          double r = 0.0;
          for (int b = 0; b < 4; ++b) r += wx[b] * row[std::clamp(bx - 1 + b, 0, m.cols - 1)];
          acc += wy[a] * r;
        }
        out[i] += static_cast<float>(acc);
      }
    }
    for (int c = 0; c < 3 && c < static_cast<int>(patch.channel_gain.size()); ++c) {
      const float k = at(patch.channel_gain[static_cast<std::size_t>(c)]);
      if (format == ptm::PtmFormat::kLrgb) {
        out[6 + c] *= k;
      } else {
        for (int i = 0; i < 6; ++i) out[6 * c + i] *= k;
      }
    }
  }
  return true;
}

void MeshSynthesis::SampleBlended(int face, const Eigen::Vector2d& p, int strip, float* out) const {
  const std::size_t n = sample_planes.size();  // <= kMaxPlanes
  std::array<float, kMaxPlanes> own{}, other{};
  if (!SamplePatch(face, p, own.data())) own.fill(0.0f);
  std::array<double, kMaxPlanes> sum{};
  double own_weight = 1.0;
  const TrianglePatch& patch = patches[static_cast<std::size_t>(face)];
  const double half_width = 0.5 * strip * texel_size;
  const int coefficient_planes = CoefficientPlanes();
  for (int k = 0; k < 3; ++k) {
    const Unfolding& u = unfoldings[static_cast<std::size_t>(face)][static_cast<std::size_t>(k)];
    if (u.face < 0) continue;
    const Eigen::Vector2d& a = patch.corners_in_frame[static_cast<std::size_t>(k)];
    const Eigen::Vector2d& b = patch.corners_in_frame[static_cast<std::size_t>((k + 1) % 3)];
    const double d = DistanceToSegment(a, b, p);
    if (d >= half_width) continue;
    if (!SamplePatch(u.face, u.rotation * p + u.translation, other.data())) continue;
    const double w = 0.5 * (1.0 - d / half_width);  // 1/2 at the edge, 0 at W_e / 2
    for (int q = 0; q < coefficient_planes / 6; ++q) {
      Eigen::Matrix<double, 6, 1> c;
      for (int i = 0; i < 6; ++i) c[i] = other[static_cast<std::size_t>(q * 6 + i)];
      c = u.coefficients_to_this * c;
      for (int i = 0; i < 6; ++i) sum[static_cast<std::size_t>(q * 6 + i)] += w * c[i];
    }
    for (std::size_t c = static_cast<std::size_t>(coefficient_planes); c < n; ++c)
      sum[c] += w * other[c];
    own_weight -= w;
  }
  for (std::size_t c = 0; c < n; ++c) out[c] = static_cast<float>(own_weight * own[c] + sum[c]);
}

ReducedPlanes ReduceToDensityLevel(const std::vector<cv::Mat>& planes, int level) {
  ReducedPlanes r;
  const int width = planes[0].cols, height = planes[0].rows;
  const double density = std::pow(2.0, -level / 4.0);
  const int rw = std::max(1, static_cast<int>(std::lround(width * density)));
  const int rh = std::max(1, static_cast<int>(std::lround(height * density)));
  for (const cv::Mat& m : planes) {
    cv::Mat small;
    cv::resize(m, small, cv::Size(rw, rh), 0, 0, cv::INTER_AREA);
    r.planes.push_back(small);
  }
  r.rx = static_cast<double>(rw) / width;
  r.ry = static_cast<double>(rh) / height;
  return r;
}

const char* TangentFrameName(TangentFrame frame) {
  switch (frame) {
    case TangentFrame::kFirstEdge:
      return "first_edge";
    case TangentFrame::kSmoothField:
      return "smooth_field";
    case TangentFrame::kPhotos:
      return "photos";
    case TangentFrame::kAuto:
      return "auto";
  }
  return "first_edge";
}

int PhotoDensityLevel(const TrianglePatch& patch, const sfm::TriangleView& view, double t) {
  const auto& c = patch.corners_in_frame;
  const double area =
      0.5 * std::abs((c[1] - c[0]).x() * (c[2] - c[0]).y() - (c[1] - c[0]).y() * (c[2] - c[0]).x());
  const double density = std::sqrt(std::max(view.projected_area_px, 1e-6f) / (area / (t * t)));
  return std::clamp(static_cast<int>(std::lround(-4.0 * std::log2(density))), 0, 40);
}

int RectificationMaps(const TrianglePatch& patch, double t, double rx, double ry, cv::Size grid,
                      const sfm::Camera& camera, const sfm::Rigid3d& cam_from_world,
                      cv::Size image_size, double mask_margin, cv::Mat& map_x, cv::Mat& map_y,
                      cv::Mat& mask) {
  map_x.create(grid, CV_32FC1);
  map_y.create(grid, CV_32FC1);
  mask = cv::Mat::zeros(grid, CV_32FC1);
  int count = 0;
  for (int j = 0; j < grid.height; ++j) {
    for (int i = 0; i < grid.width; ++i) {
      const Eigen::Vector2d p(patch.x_min + (i + 0.5) / rx * t, patch.y_max - (j + 0.5) / ry * t);
      const Eigen::Vector3d world =
          patch.frame.origin_in_world + p.x() * patch.frame.x_axis + p.y() * patch.frame.y_axis;
      const Eigen::Vector3d cam = cam_from_world.rotation * world + cam_from_world.translation;
      const std::optional<Eigen::Vector2d> px = camera.ImageFromCam(cam);
      map_x.at<float>(j, i) = px ? static_cast<float>(px->x() - 0.5) : -1e6f;  // OpenCV centres
      map_y.at<float>(j, i) = px ? static_cast<float>(px->y() - 0.5) : -1e6f;
      if (px && SignedDistanceToTriangle(patch.corners_in_frame, p) <= mask_margin &&
          px->x() >= 0.5 && px->y() >= 0.5 && px->x() <= image_size.width - 0.5 &&
          px->y() <= image_size.height - 0.5) {
        mask.at<float>(j, i) = 1.0f;
        ++count;
      }
    }
  }
  return count;
}

std::vector<sfm::TriangleView> ConstrainingViews(const sfm::TriangleVisibility& tv, bool all_views,
                                                 int max_views) {
  std::vector<sfm::TriangleView> v;
  if (tv.best_view_source != sfm::BestViewSource::kFullyVisible) return v;
  for (const sfm::TriangleView& view : tv.views)
    if (view.fully_visible && view.image_id == tv.best_view) v.push_back(view);
  if (all_views) {
    std::vector<sfm::TriangleView> others;
    for (const sfm::TriangleView& view : tv.views)
      if (view.fully_visible && view.image_id != tv.best_view) others.push_back(view);
    std::sort(others.begin(), others.end(),
              [](const auto& a, const auto& b) { return a.angle_rad < b.angle_rad; });
    for (const auto& view : others)
      if (static_cast<int>(v.size()) < max_views) v.push_back(view);
  }
  return v;
}

std::vector<double> SolvePhotoGains(const std::vector<GainObservation>& ratios,
                                    std::size_t num_faces, std::size_t num_photos) {
  std::vector<double> log_gain(num_photos, 0.0), log_albedo(num_faces, 0.0);
  for (int it = 0; it < 20; ++it) {
    std::vector<double> sum(num_faces, 0.0), weight(num_faces, 0.0);
    for (const GainObservation& r : ratios) {
      sum[r.face] += r.weight * (r.log_m - log_gain[r.photo]);
      weight[r.face] += r.weight;
    }
    double mean = 0.0, total = 0.0;
    for (std::size_t f = 0; f < num_faces; ++f)
      if (weight[f] > 0)
        log_albedo[f] = sum[f] / weight[f], mean += weight[f] * log_albedo[f], total += weight[f];
    if (total > 0) mean /= total;
    for (double& v : log_albedo) v -= mean;
    std::vector<double> gsum(num_photos, 0.0), gweight(num_photos, 0.0);
    for (const GainObservation& r : ratios) {
      gsum[r.photo] += r.weight * (r.log_m - log_albedo[r.face]);
      gweight[r.photo] += r.weight;
    }
    for (std::size_t n = 0; n < num_photos; ++n)
      if (gweight[n] > 0) log_gain[n] = gsum[n] / gweight[n];
  }
  std::vector<double> gains(num_photos, 1.0);
  for (std::size_t n = 0; n < num_photos; ++n) gains[n] = std::exp(log_gain[n]);
  return gains;
}

int BestSeenFace(const sfm::VisibilityResult& visibility) {
  int seed_face = 0;
  float best_area = -1.0f;
  for (std::size_t f = 0; f < visibility.triangles.size(); ++f) {
    const auto& tv = visibility.triangles[f];
    if (tv.best_view_source != sfm::BestViewSource::kFullyVisible) continue;
    for (const auto& v : tv.views)
      if (v.image_id == tv.best_view && v.projected_area_px > best_area) {
        best_area = v.projected_area_px;
        seed_face = static_cast<int>(f);
      }
  }
  return seed_face;
}

void AddImageScore(const cv::Mat& ssd, int count, double rx, double ry, cv::Mat& total) {
  for (int sy = 0; sy < total.rows; ++sy) {
    const int py = std::min(static_cast<int>(std::lround(sy * ry)), ssd.rows - 1);
    for (int sx = 0; sx < total.cols; ++sx) {
      const int px = std::min(static_cast<int>(std::lround(sx * rx)), ssd.cols - 1);
      total.at<float>(sy, sx) += std::sqrt(ssd.at<float>(py, px) / (3.0f * count));
    }
  }
}

std::vector<std::pair<float, cv::Point>> BestPlacements(const cv::Mat& score, int stride, int k) {
  std::vector<std::pair<float, cv::Point>> all;
  for (int sy = 0; sy < score.rows; sy += stride)
    for (int sx = 0; sx < score.cols; sx += stride)
      all.emplace_back(score.at<float>(sy, sx), cv::Point(sx, sy));
  const std::size_t kept = std::min<std::size_t>(static_cast<std::size_t>(k), all.size());
  std::partial_sort(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(kept), all.end(),
                    [](const auto& a, const auto& b) { return a.first < b.first; });
  all.resize(kept);
  return all;
}

void KeepClosestToNeighbours(const std::vector<std::pair<float, cv::Point>>& candidates,
                             const std::function<double(int, int)>& overlap_error,
                             TrianglePatch& patch) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& [score, at] : candidates) {
    const double e = overlap_error(at.x, at.y);
    if (e < best) {
      best = e;
      patch.sample_x = at.x;
      patch.sample_y = at.y;
      patch.image_score = score;
      patch.overlap_error = e;
    }
  }
}

PatchGeometry MakePatchGeometry(const sfm::TriangleMesh& mesh, double t, int strip,
                                TangentFrame tangent_frame,
                                const Eigen::Vector3d& field_direction_in_world) {
  std::vector<Eigen::Vector3d> tangents(mesh.faces.size());
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    tangents[f] = mesh.Corner(f, 1) - mesh.Corner(f, 0);
    if (tangent_frame != TangentFrame::kSmoothField) continue;
    const Eigen::Vector3d n = (mesh.Corner(f, 1) - mesh.Corner(f, 0))
                                  .cross(mesh.Corner(f, 2) - mesh.Corner(f, 0))
                                  .normalized();
    Eigen::Vector3d d = field_direction_in_world.normalized();
    if ((d - n * n.dot(d)).norm() < 0.3) {
      // Near the field's poles: the world axis least aligned with the normal.
      Eigen::Index axis;
      n.cwiseAbs().minCoeff(&axis);
      d = Eigen::Vector3d::Unit(axis);
    }
    tangents[f] = d;
  }
  return MakePatchGeometry(mesh, t, strip, tangents);
}

PatchGeometry MakePatchGeometry(const sfm::TriangleMesh& mesh, double t, int strip,
                                const std::vector<Eigen::Vector3d>& tangents_in_world) {
  const std::size_t num_faces = mesh.faces.size();
  PatchGeometry result;
  std::int64_t& total_texels = result.total_texels;
  int& widest = result.widest;
  int& tallest = result.tallest;
  result.patches.resize(num_faces);
  for (std::size_t f = 0; f < num_faces; ++f) {
    TrianglePatch& patch = result.patches[f];
    patch.frame = MakeTriangleFrame(mesh, f, tangents_in_world[f]);
    Eigen::Vector2d lo(std::numeric_limits<double>::max(), std::numeric_limits<double>::max());
    Eigen::Vector2d hi = -lo;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d p = patch.frame.PointInFrame(mesh.Corner(f, k));
      patch.corners_in_frame[static_cast<std::size_t>(k)] = p.head<2>();
      lo = lo.cwiseMin(p.head<2>());
      hi = hi.cwiseMax(p.head<2>());
    }
    patch.x_min = lo.x() - strip * t;
    patch.y_max = hi.y() + strip * t;
    const double w = std::ceil((hi.x() - lo.x()) / t) + 2.0 * strip;
    const double h = std::ceil((hi.y() - lo.y()) / t) + 2.0 * strip;
    if (!(w < 1e7 && h < 1e7)) {
      throw InputError("mesh", "face " + std::to_string(f) + " needs a patch of " +
                                   std::to_string(w) + " x " + std::to_string(h) +
                                   " texels; is the sample texel size in the model's units?");
    }
    patch.width = static_cast<int>(w);
    patch.height = static_cast<int>(h);
    widest = std::max(widest, patch.width);
    tallest = std::max(tallest, patch.height);
    total_texels += static_cast<std::int64_t>(patch.width) * patch.height;
  }
  // Unfoldings across every shared edge.
  const std::vector<std::array<int, 3>> neighbours = sfm::FaceNeighbours(mesh);
  result.unfoldings.resize(num_faces);
  for (std::size_t f = 0; f < num_faces; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int nb = neighbours[f][static_cast<std::size_t>(k)];
      Unfolding& u = result.unfoldings[f][static_cast<std::size_t>(k)];
      if (nb < 0) continue;
      const int va = mesh.faces[f][static_cast<std::size_t>(k)];
      const int vb = mesh.faces[f][static_cast<std::size_t>((k + 1) % 3)];
      const TrianglePatch& other = result.patches[static_cast<std::size_t>(nb)];
      const Eigen::Vector2d a_this =
          result.patches[f].corners_in_frame[static_cast<std::size_t>(k)];
      const Eigen::Vector2d b_this =
          result.patches[f].corners_in_frame[static_cast<std::size_t>((k + 1) % 3)];
      const Eigen::Vector2d a_nb =
          other.frame.PointInFrame(mesh.vertices[static_cast<std::size_t>(va)]).head<2>();
      const Eigen::Vector2d b_nb =
          other.frame.PointInFrame(mesh.vertices[static_cast<std::size_t>(vb)]).head<2>();
      const double angle = std::atan2((b_nb - a_nb).y(), (b_nb - a_nb).x()) -
                           std::atan2((b_this - a_this).y(), (b_this - a_this).x());
      u.face = nb;
      u.rotation = Eigen::Rotation2Dd(angle).toRotationMatrix();
      u.translation = a_nb - u.rotation * a_this;
      // This frame's x axis is (cos angle, sin angle) in the neighbour's frame.
      u.coefficients_to_this = ptm::OrthonormalFrameRotation(angle);
    }
  }

  return result;
}

MeshSynthesis SynthesizeMeshPtm(const sfm::TriangleMesh& mesh,
                                const sfm::Reconstruction& reconstruction,
                                const sfm::VisibilityResult& visibility,
                                const std::vector<MeshPhoto>& photos, const ptm::Ptm& sample,
                                const MeshSynthesisOptions& options,
                                const ProgressCallback& progress) {
  options.Check();
  const auto start = std::chrono::steady_clock::now();
  const std::size_t num_faces = mesh.faces.size();
  if (visibility.triangles.size() != num_faces)
    throw InputError("visibility", "does not match the mesh's face count");
  const double t = options.sample_texel_size;
  MeshSynthesis result;
  result.format = sample.format;
  result.texel_size = t;
  result.sample_planes = ToOrthonormalPlanes(sample);
  const int coefficient_planes = result.CoefficientPlanes();
  const std::vector<cv::Mat> sample_coefficients(result.sample_planes.begin(),
                                                 result.sample_planes.begin() + coefficient_planes);
  const cv::Mat sample_energy = PlaneEnergy(sample_coefficients);
  const std::vector<cv::Mat> sample_raw = RawPlanes(sample);

  // 1. Frames, patch rectangles, and the memory they need (refused up front).
  auto take_geometry = [&](PatchGeometry geometry) {
    if (geometry.total_texels > options.max_texels) {
      throw InputError(
          "mesh", "at a texel size of " + std::to_string(t) + " world units the " +
                      std::to_string(num_faces) + " patches need " +
                      std::to_string(geometry.total_texels) + " texels (about " +
                      std::to_string(geometry.total_texels * 4 *
                                         static_cast<std::int64_t>(result.sample_planes.size()) >>
                                     20) +
                      " MiB per copy), more than the limit of " +
                      std::to_string(options.max_texels) +
                      "; use a larger texel size or a finer mesh");
    }
    if (geometry.widest > sample.width || geometry.tallest > sample.height) {
      throw InputError(
          "mesh", "the largest triangle needs a patch of " + std::to_string(geometry.widest) +
                      " x " + std::to_string(geometry.tallest) +
                      " texels (strip included) but the sample is " + std::to_string(sample.width) +
                      " x " + std::to_string(sample.height) +
                      "; subdivide the mesh (texlume synth --max-subdivisions) or capture "
                      "a larger sample");
    }
    result.patches = std::move(geometry.patches);
    result.unfoldings = std::move(geometry.unfoldings);
  };
  take_geometry(MakePatchGeometry(mesh, t, options.strip, options.tangent_frame,
                                  options.field_direction_in_world));

  // Photos by image id, and the reduced samples by density level.
  std::map<sfm::ImageId, std::size_t> photo_index;
  for (std::size_t n = 0; n < photos.size(); ++n) photo_index[photos[n].image_id] = n;
  std::map<int, ReducedSample> reduced;
  auto reduced_at = [&](int level) -> const ReducedSample& {
    auto it = reduced.find(level);
    if (it != reduced.end()) return it->second;
    ReducedPlanes r = ReduceToDensityLevel(sample_raw, level);
    return reduced.emplace(level, ReducedSample{std::move(r.planes), r.rx, r.ry}).first->second;
  };
  // Detail transfer (beyond the paper): per density level, the sample's coarse
  // luminance coefficients brought back to full size (orthonormal), and the
  // window of them around every sample point, 3 x 3 points one photo cell
  // apart, indexed for nearest-neighbour search. Its detail band (planes minus
  // coarse) goes into the result.
  struct DetailDictionary {
    std::vector<cv::Mat> coarse;    // 6 orthonormal luminance planes, full size
    cv::Mat windows;                // CV_32FC1, one kDetailWindowLength row per point
    std::vector<cv::Point> points;  // window centres, texels
    std::unique_ptr<cv::flann::Index> index;
  };
  std::map<int, DetailDictionary> dictionaries;
  // Fills d and the band of a level whose reduced sample exists (touches no map,
  // so levels can be built in parallel).
  auto build_dictionary = [&](int level, const ReducedSample& red, DetailDictionary& d,
                              std::vector<cv::Mat>& band) {
    const cv::Size full(sample.width, sample.height);
    std::vector<cv::Mat> coarse_raw(red.raw.size());
    for (std::size_t c = 0; c < red.raw.size(); ++c)
      cv::resize(red.raw[c], coarse_raw[c], full, 0, 0, cv::INTER_LINEAR);
    const Eigen::Matrix<double, 6, 6>& to = ptm::OrthonormalBasis::Hemisphere().ToOrthonormal();
    d.coarse.assign(6, cv::Mat());
    for (cv::Mat& m : d.coarse) m = cv::Mat::zeros(full, CV_32FC1);
    for (int y = 0; y < full.height; ++y)
      for (int x = 0; x < full.width; ++x)
        for (int m = 0; m < 6; ++m) {
          double v = 0.0;
          for (int k = 0; k < 6; ++k)
            v += to(m, k) * coarse_raw[static_cast<std::size_t>(k)].at<float>(y, x);
          d.coarse[static_cast<std::size_t>(m)].at<float>(y, x) = static_cast<float>(v);
        }
    band.resize(result.sample_planes.size());
    for (std::size_t c = 0; c < band.size(); ++c)
      band[c] = result.sample_planes[c] - (c < 6 ? d.coarse[c] : coarse_raw[c]);
    const double dx = 1.0 / red.rx, dy = 1.0 / red.ry;
    const int bx = static_cast<int>(std::ceil(kDetailWindowRadius * dx)),
              by = static_cast<int>(std::ceil(kDetailWindowRadius * dy));
    const int nx = full.width - 2 * bx, ny = full.height - 2 * by;
    if (nx < 4 || ny < 4) return;  // windows wider than the sample: no transfer
    // Large samples: points on a coarser grid, so a dictionary stays under
    // kDetailMaxPoints windows.
    const int stride = static_cast<int>(
        std::ceil(std::sqrt(static_cast<double>(nx) * ny / static_cast<double>(kDetailMaxPoints))));
    for (int y = by; y < full.height - by; y += stride)
      for (int x = bx; x < full.width - bx; x += stride) d.points.emplace_back(x, y);
    d.windows = cv::Mat(static_cast<int>(d.points.size()), kDetailWindowLength, CV_32FC1);
    for (std::size_t n = 0; n < d.points.size(); ++n)
      CoarseWindow(d.coarse, d.points[n].x, d.points[n].y, dx, dy,
                   d.windows.ptr<float>(static_cast<int>(n)));
    // The randomised trees draw from this thread's cv::theRNG(): seeded per
    // level, so that the matches do not depend on threads or earlier draws.
    cv::RNG& rng_of_thread = cv::theRNG();
    const std::uint64_t saved_state = rng_of_thread.state;
    rng_of_thread.state = 0x7e41u + static_cast<std::uint64_t>(level) + options.seed * 1000003u;
    d.index =
        std::make_unique<cv::flann::Index>(d.windows, cv::flann::KDTreeIndexParams(kDetailTrees));
    rng_of_thread.state = saved_state;
  };
  const int polys = sample.NumPolynomials();
  auto relit_planes = [&](const ReducedSample& r, const LightList& lights, double gain) {
    std::vector<cv::Mat> out(3);
    for (cv::Mat& m : out) m = cv::Mat(r.raw[0].size(), CV_32FC1);
    std::vector<float> a(static_cast<std::size_t>(polys * 6)), colour(3, 1.0f);
    for (int y = 0; y < r.raw[0].rows; ++y) {
      for (int x = 0; x < r.raw[0].cols; ++x) {
        for (int i = 0; i < polys * 6; ++i)
          a[static_cast<std::size_t>(i)] = r.raw[static_cast<std::size_t>(i)].at<float>(y, x);
        if (sample.format == ptm::PtmFormat::kLrgb)
          for (int c = 0; c < 3; ++c)
            colour[static_cast<std::size_t>(c)] =
                r.raw[static_cast<std::size_t>(6 + c)].at<float>(y, x);
        const Eigen::Vector3f v =
            RelightMixture(a.data(), colour.data(), sample.format, lights, gain);
        for (int c = 0; c < 3; ++c) out[static_cast<std::size_t>(c)].at<float>(y, x) = v[c];
      }
    }
    return out;
  };

  // A triangle as seen in one photo: the photo rectified into the triangle frame
  // at the photo's own surface density, the triangle mask, the local lights.
  struct Rectified {
    std::size_t photo = 0;
    sfm::TriangleView view;
    int level = 0;
    std::vector<cv::Mat> planes;  // RGB display
    cv::Mat mask;                 // CV_32FC1, 1 inside the triangle and the image
    int count = 0;
    LightList lights;
  };
  // Cells within W_e / 2 of the triangle (its blending zone) are constrained
  // too, so that the blend across an edge mixes two photo-corrected patches.
  const double mask_margin = 0.5 * options.strip * t;
  // level < 0: at the photo's own density level.
  auto rectify = [&](std::size_t f, const sfm::TriangleView& view, Rectified& out,
                     int level = -1) -> bool {
    const auto it = photo_index.find(view.image_id);
    if (it == photo_index.end()) return false;
    const MeshPhoto& photo = photos[it->second];
    const sfm::Image& image = reconstruction.images.at(view.image_id);
    const sfm::Camera& camera = reconstruction.cameras.at(image.camera_id);
    const TrianglePatch& patch = result.patches[f];
    if (level < 0) level = PhotoDensityLevel(patch, view, t);
    const ReducedSample& r = reduced_at(level);
    const int tw = std::max(1, static_cast<int>(std::lround(patch.width * r.rx)));
    const int th = std::max(1, static_cast<int>(std::lround(patch.height * r.ry)));
    if (tw > r.raw[0].cols || th > r.raw[0].rows) return false;
    cv::Mat map_x, map_y;
    out.count =
        RectificationMaps(patch, t, r.rx, r.ry, cv::Size(tw, th), camera, image.cam_from_world,
                          photo.image.size(), mask_margin, map_x, map_y, out.mask);
    if (out.count < options.min_photo_pixels) return false;
    cv::Mat rectified;
    cv::remap(photo.image, rectified, map_x, map_y, cv::INTER_CUBIC, cv::BORDER_REPLICATE);
    cv::split(rectified, out.planes);
    out.lights.clear();
    for (const sfm::ObjectLight& light : photo.lights) {
      const Eigen::Vector3d l =
          patch.frame.DirectionInFrame(light.DirectionFrom(patch.frame.origin_in_world));
      out.lights.emplace_back(l, light.intensity);
    }
    out.photo = it->second;
    out.view = view;
    out.level = level;
    return true;
  };

  // Views used per face: the best fully visible view, or every fully visible one.
  auto views_of = [&](std::size_t f) {
    return ConstrainingViews(visibility.triangles[f], options.all_views, options.max_views);
  };

  // 1b. Frames turned to the photos (beyond the paper; synth/tangent_field.h):
  // the sample's structure tensor at the photos' median density against each
  // face's photos' tensor in its first-edge frame; kAuto does so only for an
  // anisotropic sample.
  result.tangent_frame = options.tangent_frame;
  if (options.tangent_frame == TangentFrame::kPhotos ||
      options.tangent_frame == TangentFrame::kAuto) {
    std::vector<int> face_levels(num_faces, -1);
    for (std::size_t f = 0; f < num_faces; ++f) {
      const std::vector<sfm::TriangleView> views = views_of(f);
      if (!views.empty()) face_levels[f] = PhotoDensityLevel(result.patches[f], views[0], t);
    }
    const FrameChoice choice = ChoosePhotoFrames(
        options.tangent_frame, result.patches, result.unfoldings, face_levels,
        [&](int level) {
          const ReducedSample& red = reduced_at(level);
          return SampleStructureTensor(
              [&](const Eigen::Vector3d& l) {
                return relit_planes(red, {{l, 1.0}}, 1.0);
              },
              red.rx, red.ry);
        },
        [&](std::size_t f) {
          Eigen::Matrix2d tensor = Eigen::Matrix2d::Zero();
          for (const sfm::TriangleView& view : views_of(f)) {
            Rectified rect;
            if (!rectify(f, view, rect)) continue;
            const ReducedSample& r = reduced_at(rect.level);
            tensor += LuminanceStructureTensor(rect.planes, rect.mask, r.rx, r.ry);
          }
          return tensor;
        });
    result.tangent_frame = choice.tangent_frame;
    result.sample_coherence = choice.sample_coherence;
    if (choice.tangent_frame == TangentFrame::kPhotos)
      take_geometry(MakePatchGeometry(mesh, t, options.strip, choice.field.tangents_in_world));
  }

  // 2a. Per-photo gain (exposure x light intensity, linear domain). For every
  // triangle fully visible in a photo, m = photo mean / sample mean relit at the
  // triangle's lights = a_T g_n (a_T the triangle's albedo relative to the
  // sample's). log m = log a_T + log g_n is solved by alternating least squares
  // over all such pairs, with the mean log a_T fixed at 0 (the object's mean
  // albedo is the sample's), so stains and colour do not leak into the gains.
  std::vector<GainObservation> ratios;
  {
    const int coarse_level = std::max(
        0,
        static_cast<int>(std::ceil(4.0 * std::log2(std::max(sample.width, sample.height) / 16.0))));
    const ReducedSample& coarse = reduced_at(coarse_level);
    for (std::size_t f = 0; f < num_faces; ++f) {
      int used = 0;
      for (const sfm::TriangleView& view : visibility.triangles[f].views) {
        if (!view.fully_visible || used >= 8) continue;
        Rectified rect;
        if (!rectify(f, view, rect)) continue;
        // Grazing or hidden lights: the PTM is least reliable there (and shadows).
        bool steep = true;
        for (const auto& [l, intensity] : rect.lights) steep = steep && l.z() > 0.5;
        if (!steep) continue;
        double photo_linear = 0.0;
        for (int j = 0; j < rect.mask.rows; ++j)
          for (int i = 0; i < rect.mask.cols; ++i)
            if (rect.mask.at<float>(j, i) > 0)
              for (int c = 0; c < 3; ++c)
                photo_linear +=
                    SrgbToLinear(rect.planes[static_cast<std::size_t>(c)].at<float>(j, i));
        const std::vector<cv::Mat> relit = relit_planes(coarse, rect.lights, 1.0);
        double model_linear = 0.0;
        for (int c = 0; c < 3; ++c) {
          for (int j = 0; j < relit[0].rows; ++j)
            for (int i = 0; i < relit[0].cols; ++i)
              model_linear += SrgbToLinear(relit[static_cast<std::size_t>(c)].at<float>(j, i));
        }
        model_linear *= rect.count / static_cast<double>(relit[0].total());
        // Dim triangles (grazing light, shadow) say little about the gain.
        if (!(model_linear > 0.02 * 3 * rect.count) || !(photo_linear > 1e-6)) continue;
        ratios.push_back({f, rect.photo, std::log(photo_linear / model_linear), model_linear});
        ++used;
      }
    }
  }
  result.photo_gains = SolvePhotoGains(ratios, num_faces, photos.size());

  // 2b. Breadth-first synthesis from a seed (the best-seen triangle).
  const int seed_face = BestSeenFace(visibility);
  // Photo-consistency pass of one patch (LRGB): per cell of the primary view's
  // grid (every view rectified on it), the MAP change of the orthonormal
  // luminance coefficients, q = m + Sigma J^T (J Sigma J^T + s^2 I)^-1 (r + J (q0 - m)),
  // J_n the derivative of the displayed luminance under photo n's lights (sRGB,
  // gain and light mixture linearised at the current value), r_n the photo's
  // luminance minus the prediction (eq. 3's residual), m the prior mean (the
  // patch moved toward the sample's mean). Cells outside the triangle take
  // their neighbours' change.
  const Eigen::Matrix<double, 6, 6>& from_orthonormal =
      ptm::OrthonormalBasis::Hemisphere().FromOrthonormal();
  // The prior at a density level: the mean and covariance of the reduced
  // sample's orthonormal luminance coefficients.
  struct CoefficientPrior {
    Eigen::Matrix<double, 6, 1> mean;
    Eigen::Matrix<double, 6, 6> covariance;
  };
  const Eigen::Matrix<double, 6, 6>& to_orthonormal =
      ptm::OrthonormalBasis::Hemisphere().ToOrthonormal();
  std::map<int, CoefficientPrior> priors;
  auto prior_at = [&](int level) -> const CoefficientPrior& {
    auto it = priors.find(level);
    if (it != priors.end()) return it->second;
    const ReducedSample& red = reduced_at(level);
    const int n = static_cast<int>(red.raw[0].total());
    Eigen::Matrix<double, 6, 1> mean = Eigen::Matrix<double, 6, 1>::Zero();
    Eigen::Matrix<double, 6, 6> second = Eigen::Matrix<double, 6, 6>::Zero();
    for (int y = 0; y < red.raw[0].rows; ++y)
      for (int x = 0; x < red.raw[0].cols; ++x) {
        Eigen::Matrix<double, 6, 1> a;
        for (int m = 0; m < 6; ++m) a[m] = red.raw[static_cast<std::size_t>(m)].at<float>(y, x);
        const Eigen::Matrix<double, 6, 1> q = to_orthonormal * a;
        mean += q;
        second += q * q.transpose();
      }
    mean /= n;
    Eigen::Matrix<double, 6, 6> cov = second / n - mean * mean.transpose();
    cov.diagonal().array() += 1e-6 * cov.trace() / 6.0;  // keeps it positive definite
    return priors.emplace(level, CoefficientPrior{mean, cov}).first->second;
  };
  auto CorrectPatch = [&](TrianglePatch& patch, const std::vector<Rectified>& rects) {
    const Rectified& primary = rects[0];
    const ReducedSample& red0 = reduced_at(primary.level);
    const int gw = primary.mask.cols, gh = primary.mask.rows;
    patch.correction_density = Eigen::Vector2d(red0.rx, red0.ry);
    const CoefficientPrior& prior = prior_at(primary.level);
    patch.correction.assign(6, cv::Mat());
    for (cv::Mat& m : patch.correction) m = cv::Mat::zeros(gh, gw, CV_32FC1);
    patch.channel_gain.assign(3, cv::Mat());
    for (cv::Mat& m : patch.channel_gain) m = cv::Mat::ones(gh, gw, CV_32FC1);
    // Every view is rectified on the primary view's grid (the caller's part).
    auto seen = [&](const Rectified& r, int i, int j) { return r.mask.at<float>(j, i) > 0; };
    // Prediction and luminance Jacobian of view r at cell (i, j), with the
    // change q_delta (orthonormal) added to the patch's coefficients.
    auto predict_with = [&](const Rectified& r, int i, int j,
                            const Eigen::Matrix<double, 6, 1>& q_delta,
                            Eigen::Matrix<double, 1, 6>& jac,
                            Eigen::Vector3d* channel_linear = nullptr) {
      // Cell (i, j)'s centre in the reduced sample's pixel coordinates (centres
      // at integers): (sample_x + (i + 0.5) / rx) rx - 0.5; bilinear there.
      const double sx = std::clamp(patch.sample_x * red0.rx + i, 0.0, red0.raw[0].cols - 1.0);
      const double sy = std::clamp(patch.sample_y * red0.ry + j, 0.0, red0.raw[0].rows - 1.0);
      const int x0 = static_cast<int>(sx), y0 = static_cast<int>(sy);
      const int x1 = std::min(x0 + 1, red0.raw[0].cols - 1),
                y1 = std::min(y0 + 1, red0.raw[0].rows - 1);
      const float fx = static_cast<float>(sx - x0), fy = static_cast<float>(sy - y0);
      auto sample_at = [&](const cv::Mat& m) {
        return (1 - fy) * ((1 - fx) * m.at<float>(y0, x0) + fx * m.at<float>(y0, x1)) +
               fy * ((1 - fx) * m.at<float>(y1, x0) + fx * m.at<float>(y1, x1));
      };
      const Eigen::Matrix<double, 6, 1> a_delta = from_orthonormal * q_delta;
      float a[6], colour[3];
      for (int m = 0; m < 6; ++m)
        a[m] = sample_at(red0.raw[static_cast<std::size_t>(m)]) + static_cast<float>(a_delta[m]);
      for (int c = 0; c < 3; ++c) colour[c] = sample_at(red0.raw[static_cast<std::size_t>(6 + c)]);
      const double g = result.photo_gains[r.photo];
      Eigen::Vector3d linear = Eigen::Vector3d::Zero();
      Eigen::Matrix<double, 3, 6> dlinear = Eigen::Matrix<double, 3, 6>::Zero();
      for (const auto& [l, intensity] : r.lights) {
        if (l.z() <= 0) continue;
        const double lum = ptm::EvaluatePolynomial(a, l.x(), l.y());
        const std::array<double, 6> phi = ptm::PtmBasis(l.x(), l.y());
        const Eigen::Matrix<double, 1, 6> row =
            Eigen::Map<const Eigen::Matrix<double, 1, 6>>(phi.data()) * from_orthonormal;
        for (int c = 0; c < 3; ++c) {
          const double v = lum * colour[c];
          if (v <= 0.0 || v >= 1.0) continue;  // clamped: no derivative
          const double h = 1e-3;
          const double dlin = (SrgbToLinear(static_cast<float>(std::min(1.0, v + h))) -
                               SrgbToLinear(static_cast<float>(std::max(0.0, v - h)))) /
                              (std::min(1.0, v + h) - std::max(0.0, v - h));
          linear[c] += intensity * SrgbToLinear(static_cast<float>(v));
          dlinear.row(c) += intensity * dlin * colour[c] * row;
        }
      }
      double y_pred = 0.0;
      jac.setZero();
      for (int c = 0; c < 3; ++c) {
        const double lin = g * linear[c];
        if (channel_linear) (*channel_linear)[c] = lin;
        const double d = LinearToSrgb(static_cast<float>(lin));
        const double h = 1e-4;
        const double dsrgb = (LinearToSrgb(static_cast<float>(lin + h)) -
                              LinearToSrgb(static_cast<float>(std::max(0.0, lin - h)))) /
                             (lin + h - std::max(0.0, lin - h));
        y_pred += d / 3.0;
        jac += dsrgb * g * dlinear.row(c) / 3.0;
      }
      return y_pred;
    };
    auto correction_at = [&](int i, int j) {
      Eigen::Matrix<double, 6, 1> q;
      for (int m = 0; m < 6; ++m)
        q[m] = patch.correction[static_cast<std::size_t>(m)].at<float>(j, i);
      return q;
    };
    auto predict = [&](const Rectified& r, int i, int j, Eigen::Matrix<double, 1, 6>& jac,
                       Eigen::Vector3d* channel_linear = nullptr) {
      return predict_with(r, i, j, correction_at(i, j), jac, channel_linear);
    };
    // The way from the patch's coefficients to the prior's mean, per cell (the
    // patch is fixed during the pass, so once).
    std::vector<Eigen::Matrix<double, 6, 1>> to_mean_of_cell(static_cast<std::size_t>(gw * gh));
    for (int j = 0; j < gh; ++j)
      for (int i = 0; i < gw; ++i) {
        Eigen::Matrix<double, 6, 1> a_patch;
        for (int m = 0; m < 6; ++m)
          a_patch[m] = BilinearClamped(
              red0.raw[static_cast<std::size_t>(m)],
              std::clamp(patch.sample_x * red0.rx + i, 0.0, red0.raw[0].cols - 1.0),
              std::clamp(patch.sample_y * red0.ry + j, 0.0, red0.raw[0].rows - 1.0));
        to_mean_of_cell[static_cast<std::size_t>(j * gw + i)] =
            prior.mean - to_orthonormal * a_patch;
      }
    auto to_mean = [&](int i, int j) -> const Eigen::Matrix<double, 6, 1>& {
      return to_mean_of_cell[static_cast<std::size_t>(j * gw + i)];
    };
    auto photo_luminance = [](const Rectified& r, int i, int j) {
      return (r.planes[0].at<float>(j, i) + r.planes[1].at<float>(j, i) +
              r.planes[2].at<float>(j, i)) /
             3.0;
    };
    // How far the prior mean moves from the patch toward the sample's mean.
    // Estimated: 1 - rho, rho the least-squares slope of the photos' departure
    // from the mean's prediction on the patch's departure from it, over the
    // patch's cells and views (how much of the patch's own structure the
    // photos confirm where they see it), clamped to [0, 1]. The departure is
    // linearised at the patch: d = -J (mean - patch).
    double shrink = options.correction_prior_shrink;
    if (shrink < 0.0) {
      double photo_dot_patch = 0.0, patch_dot_patch = 0.0;
      Eigen::Matrix<double, 1, 6> jac;
      for (int j = 0; j < gh; ++j)
        for (int i = 0; i < gw; ++i) {
          const Eigen::Matrix<double, 6, 1> q_to_mean = to_mean(i, j);
          for (const Rectified& r : rects) {
            if (!seen(r, i, j)) continue;
            const double at_patch = predict_with(r, i, j, Eigen::Matrix<double, 6, 1>::Zero(), jac);
            const double patch_departure = -(jac * q_to_mean)(0);
            photo_dot_patch +=
                (photo_luminance(r, i, j) - at_patch + patch_departure) * patch_departure;
            patch_dot_patch += patch_departure * patch_departure;
          }
        }
      const double rho = patch_dot_patch > 1e-12 ? photo_dot_patch / patch_dot_patch : 0.0;
      shrink = 1.0 - std::clamp(rho, 0.0, 1.0);
    }
    patch.prior_shrink = shrink;
    cv::Mat known = cv::Mat::zeros(gh, gw, CV_8UC1);
    for (int it = 0; it < options.correction_iterations; ++it) {
      // Per-channel factors at low frequency (stains, colour): photo over
      // prediction in the linear domain, summed over the views and smoothed over
      // a few photo pixels (normalised convolution), taken back to display values
      // (x^(1/2.2)). Finer detail stays the sample's.
      std::vector<cv::Mat> photo_sum(3), model_sum(3);
      if (options.channel_correction) {
        for (int c = 0; c < 3; ++c)
          photo_sum[static_cast<std::size_t>(c)] = cv::Mat::zeros(gh, gw, CV_32FC1),
          model_sum[static_cast<std::size_t>(c)] = cv::Mat::zeros(gh, gw, CV_32FC1);
        for (int j = 0; j < gh; ++j) {
          for (int i = 0; i < gw; ++i) {
            for (const Rectified& r : rects) {
              if (!seen(r, i, j)) continue;
              Eigen::Matrix<double, 1, 6> row;
              Eigen::Vector3d lin;
              predict(r, i, j, row, &lin);
              for (int c = 0; c < 3; ++c) {
                photo_sum[static_cast<std::size_t>(c)].at<float>(j, i) +=
                    SrgbToLinear(r.planes[static_cast<std::size_t>(c)].at<float>(j, i));
                model_sum[static_cast<std::size_t>(c)].at<float>(j, i) +=
                    static_cast<float>(lin[c]);
              }
              known.at<std::uint8_t>(j, i) = 1;
            }
          }
        }
        std::vector<cv::Mat> pb(3), mb(3);
        for (int c = 0; c < 3; ++c) {
          cv::GaussianBlur(photo_sum[static_cast<std::size_t>(c)], pb[c], cv::Size(0, 0),
                           options.correction_sigma);
          cv::GaussianBlur(model_sum[static_cast<std::size_t>(c)], mb[c], cv::Size(0, 0),
                           options.correction_sigma);
        }
        for (int j = 0; j < gh; ++j)
          for (int i = 0; i < gw; ++i) {
            if (!known.at<std::uint8_t>(j, i)) continue;
            double ratio[3];
            bool ok = true;
            for (int c = 0; c < 3; ++c) {
              const float p = pb[c].at<float>(j, i), m = mb[c].at<float>(j, i);
              ok = ok && m > 1e-4f && p > 1e-4f;
              ratio[c] = ok ? std::pow(p / m, 1.0 / 2.2) : 1.0;
            }
            if (!ok) continue;
            // Chromaticity only: the luminance is the additive change's.
            const double mean = (ratio[0] + ratio[1] + ratio[2]) / 3.0;
            for (double& r : ratio) r /= mean;
            for (int c = 0; c < 3; ++c) {
              float& k = patch.channel_gain[static_cast<std::size_t>(c)].at<float>(j, i);
              k = std::clamp(k * static_cast<float>(ratio[c]), 0.25f, 4.0f);
            }
          }
      }
      if (!options.additive_correction) continue;
      for (int j = 0; j < gh; ++j) {
        for (int i = 0; i < gw; ++i) {
          Eigen::Matrix<double, Eigen::Dynamic, 6> jac(static_cast<int>(rects.size()), 6);
          Eigen::VectorXd res(static_cast<int>(rects.size()));
          int rows = 0;
          for (const Rectified& r : rects) {
            if (!seen(r, i, j)) continue;
            Eigen::Matrix<double, 1, 6> row;
            res[rows] = photo_luminance(r, i, j) - predict(r, i, j, row);
            jac.row(rows) = row;
            ++rows;
          }
          if (rows == 0) continue;
          known.at<std::uint8_t>(j, i) = 1;
          const auto jr = jac.topRows(rows);
          const Eigen::Matrix<double, 6, 1> q0 = correction_at(i, j);
          // Prior mean of the change, m: the way from the patch's coefficients
          // to the sample's mean, correction_prior_shrink of it.
          const Eigen::Matrix<double, 6, 1> q_mean = shrink * to_mean(i, j);
          // Gauss-Newton step of the MAP estimate: q = m + Sigma J^T (J Sigma J^T +
          // s^2 I)^-1 (r + J (q0 - m)), s^2 = correction_noise x the mean predicted
          // variance.
          const Eigen::MatrixXd js = jr * prior.covariance;
          Eigen::MatrixXd a = js * jr.transpose();
          const double scale = a.trace() / rows;
          if (!(scale > 1e-12)) continue;
          a.diagonal().array() += options.correction_noise * scale;
          const Eigen::Matrix<double, 6, 1> q_new =
              q_mean + js.transpose() * a.ldlt().solve(res.head(rows) + jr * (q0 - q_mean));
          for (int m = 0; m < 6; ++m)
            patch.correction[static_cast<std::size_t>(m)].at<float>(j, i) =
                static_cast<float>(q_new[m]);
        }
      }
    }
    // Extend the change into the strip: rings of neighbour averages.
    for (int ring = 0; ring < std::max(gw, gh); ++ring) {
      const cv::Mat before = known.clone();
      bool any = false;
      for (int j = 0; j < gh; ++j)
        for (int i = 0; i < gw; ++i) {
          if (before.at<std::uint8_t>(j, i)) continue;
          double sum[6] = {0, 0, 0, 0, 0, 0};
          int n = 0;
          for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di) {
              const int jj = j + dj, ii = i + di;
              if (jj < 0 || ii < 0 || jj >= gh || ii >= gw || !before.at<std::uint8_t>(jj, ii))
                continue;
              for (int m = 0; m < 6; ++m)
                sum[m] += patch.correction[static_cast<std::size_t>(m)].at<float>(jj, ii);
              ++n;
            }
          if (!n) continue;
          for (int m = 0; m < 6; ++m)
            patch.correction[static_cast<std::size_t>(m)].at<float>(j, i) =
                static_cast<float>(sum[m] / n);
          known.at<std::uint8_t>(j, i) = 1;
          any = true;
        }
      if (!any) break;
    }
  };

  // Detail transfer of a corrected patch: per cell of its correction grid, the
  // sample point whose coarse window (3 x 3 cells) is nearest the corrected
  // coarse values (k-d tree), then two passes that take a neighbour cell's
  // match moved by one cell wherever it is nearer (coherent matches keep the
  // detail whole where their bands are blended).
  auto TransferDetail = [&](TrianglePatch& patch, int level) {
    const DetailDictionary& d = dictionaries.at(level);  // built before; read only here
    const ReducedSample& red = reduced.at(level);
    const double dx = 1.0 / red.rx, dy = 1.0 / red.ry;
    const int gw = patch.correction[0].cols, gh = patch.correction[0].rows;
    std::vector<cv::Mat> corrected(6);
    for (std::size_t m = 0; m < 6; ++m) {
      corrected[m] = cv::Mat(gh, gw, CV_32FC1);
      for (int j = 0; j < gh; ++j)
        for (int i = 0; i < gw; ++i)
          corrected[m].at<float>(j, i) =
              static_cast<float>(BilinearClamped(d.coarse[m], patch.sample_x + (i + 0.5) * dx - 0.5,
                                                 patch.sample_y + (j + 0.5) * dy - 0.5) +
                                 patch.correction[m].at<float>(j, i));
    }
    cv::Mat queries(gh * gw, kDetailWindowLength, CV_32FC1);
    for (int j = 0; j < gh; ++j)
      for (int i = 0; i < gw; ++i) {
        float* q = queries.ptr<float>(j * gw + i);
        for (int b = -kDetailWindowRadius; b <= kDetailWindowRadius; ++b)
          for (int a = -kDetailWindowRadius; a <= kDetailWindowRadius; ++a)
            for (std::size_t m = 0; m < 6; ++m)
              *q++ = corrected[m].at<float>(std::clamp(j + b, 0, gh - 1),
                                            std::clamp(i + a, 0, gw - 1));
      }
    cv::Mat indices, distances;
    d.index->knnSearch(queries, indices, distances, 1, cv::flann::SearchParams(kDetailChecks));
    patch.detail_source = cv::Mat(gh, gw, CV_32FC2);
    cv::Mat best(gh, gw, CV_32FC1);
    for (int j = 0; j < gh; ++j)
      for (int i = 0; i < gw; ++i) {
        const cv::Point p = d.points[static_cast<std::size_t>(indices.at<int>(j * gw + i, 0))];
        patch.detail_source.at<cv::Vec2f>(j, i) =
            cv::Vec2f(static_cast<float>(p.x), static_cast<float>(p.y));
        best.at<float>(j, i) = distances.at<float>(j * gw + i, 0);
      }
    const double x_lo = kDetailWindowRadius * dx, x_hi = sample.width - 1 - x_lo;
    const double y_lo = kDetailWindowRadius * dy, y_hi = sample.height - 1 - y_lo;
    std::array<float, kDetailWindowLength> window;
    auto try_shift = [&](int i, int j, int ni, int nj) {
      if (ni < 0 || nj < 0 || ni >= gw || nj >= gh) return;
      const cv::Vec2f n = patch.detail_source.at<cv::Vec2f>(nj, ni);
      const double x = n[0] + (i - ni) * dx, y = n[1] + (j - nj) * dy;
      if (x < x_lo || x > x_hi || y < y_lo || y > y_hi) return;
      CoarseWindow(d.coarse, x, y, dx, dy, window.data());
      const float* q = queries.ptr<float>(j * gw + i);
      double e = 0.0;
      for (int k = 0; k < kDetailWindowLength; ++k) e += (window[k] - q[k]) * (window[k] - q[k]);
      if (e < best.at<float>(j, i)) {
        best.at<float>(j, i) = static_cast<float>(e);
        patch.detail_source.at<cv::Vec2f>(j, i) =
            cv::Vec2f(static_cast<float>(x), static_cast<float>(y));
      }
    };
    for (int j = 0; j < gh; ++j)
      for (int i = 0; i < gw; ++i) try_shift(i, j, i - 1, j), try_shift(i, j, i, j - 1);
    for (int j = gh - 1; j >= 0; --j)
      for (int i = gw - 1; i >= 0; --i) try_shift(i, j, i + 1, j), try_shift(i, j, i, j + 1);
    patch.detail_level = level;
  };

  const std::vector<int> order =
      sfm::BreadthFirstFaceOrder(mesh, sfm::FaceNeighbours(mesh), seed_face);
  std::vector<char> done(num_faces, 0);
  std::vector<int> correction_level(num_faces, -1);  // the primary view's density level
  std::mt19937_64 rng(options.seed);
  std::size_t processed = 0;
  for (const int face : order) {
    const std::size_t f = static_cast<std::size_t>(face);
    TrianglePatch& patch = result.patches[f];
    const int w = patch.width, h = patch.height;

    // Overlap targets: processed neighbours' patches unfolded into this frame,
    // on the texels within W_e of the shared edge.
    std::vector<int> target_texels;
    std::vector<float> targets;  // coefficient_planes per target texel
    std::vector<float> value(result.sample_planes.size());
    for (int j = 0; j < h; ++j) {
      for (int i = 0; i < w; ++i) {
        const Eigen::Vector2d p(patch.x_min + (i + 0.5) * t, patch.y_max - (j + 0.5) * t);
        for (int k = 0; k < 3; ++k) {
          const Unfolding& u = result.unfoldings[f][static_cast<std::size_t>(k)];
          if (u.face < 0 || !done[static_cast<std::size_t>(u.face)]) continue;
          const double d =
              DistanceToSegment(patch.corners_in_frame[static_cast<std::size_t>(k)],
                                patch.corners_in_frame[static_cast<std::size_t>((k + 1) % 3)], p);
          if (d > options.strip * t) continue;
          if (!result.SamplePatch(u.face, u.rotation * p + u.translation, value.data())) continue;
          target_texels.push_back(j * w + i);
          for (int q = 0; q < coefficient_planes / 6; ++q) {
            Eigen::Matrix<double, 6, 1> c;
            for (int m = 0; m < 6; ++m) c[m] = value[static_cast<std::size_t>(q * 6 + m)];
            c = u.coefficients_to_this * c;
            for (int m = 0; m < 6; ++m) targets.push_back(static_cast<float>(c[m]));
          }
          break;
        }
      }
    }
    auto overlap_error = [&](int sx, int sy) {
      if (target_texels.empty()) return 0.0;
      double e = 0.0;
      for (std::size_t n = 0; n < target_texels.size(); ++n) {
        const int i = target_texels[n] % w, j = target_texels[n] / w;
        for (int c = 0; c < coefficient_planes; ++c) {
          const double d =
              result.sample_planes[static_cast<std::size_t>(c)].at<float>(sy + j, sx + i) -
              targets[n * static_cast<std::size_t>(coefficient_planes) +
                      static_cast<std::size_t>(c)];
          e += d * d;
        }
      }
      return e / static_cast<double>(target_texels.size());
    };

    // Image constraint: S summed over the views (eq. 3 at each photo's density).
    std::vector<Rectified> rects;
    for (const sfm::TriangleView& view : views_of(f)) {
      Rectified r;
      if (rectify(f, view, r)) rects.push_back(std::move(r));
    }
    const int max_sx = sample.width - w, max_sy = sample.height - h;
    if (!rects.empty()) {
      cv::Mat total;  // summed RMS score over sample positions (texels)
      total = cv::Mat::zeros(max_sy + 1, max_sx + 1, CV_32FC1);
      for (const Rectified& r : rects) {
        const ReducedSample& red = reduced_at(r.level);
        const std::vector<cv::Mat> relit = relit_planes(red, r.lights, result.photo_gains[r.photo]);
        AddImageScore(MaskedSsd(relit, PlaneEnergy(relit), r.planes, r.mask), r.count, red.rx,
                      red.ry, total);
      }
      // Top-k distinct positions at the coarsest density used (neighbouring texel
      // positions share one photo-density cell and score alike).
      KeepClosestToNeighbours(
          BestPlacements(
              total, std::max(1, static_cast<int>(std::floor(1.0 / reduced_at(rects[0].level).rx))),
              options.top_k),
          overlap_error, patch);
      patch.source = PatchSource::kPhotos;
      patch.views_used = static_cast<int>(rects.size());
      ++result.num_from_photos;
    } else if (!target_texels.empty()) {
      // Overlap constraint alone, at every position of the sample (FFT).
      std::vector<cv::Mat> target_planes(static_cast<std::size_t>(coefficient_planes));
      for (cv::Mat& m : target_planes) m = cv::Mat::zeros(h, w, CV_32FC1);
      cv::Mat mask = cv::Mat::zeros(h, w, CV_32FC1);
      for (std::size_t n = 0; n < target_texels.size(); ++n) {
        const int i = target_texels[n] % w, j = target_texels[n] / w;
        mask.at<float>(j, i) = 1.0f;
        for (int c = 0; c < coefficient_planes; ++c)
          target_planes[static_cast<std::size_t>(c)].at<float>(j, i) =
              targets[n * static_cast<std::size_t>(coefficient_planes) +
                      static_cast<std::size_t>(c)];
      }
      const cv::Mat errors = MaskedSsd(sample_coefficients, sample_energy, target_planes, mask);
      const cv::Point p = PickWithinTolerance(errors, options.tolerance, rng);
      patch.sample_x = p.x;
      patch.sample_y = p.y;
      patch.overlap_error = errors.at<float>(p.y, p.x) / static_cast<double>(target_texels.size());
      patch.source = PatchSource::kNeighbours;
      ++result.num_from_neighbours;
    } else {
      patch.sample_x = std::uniform_int_distribution<int>(0, max_sx)(rng);
      patch.sample_y = std::uniform_int_distribution<int>(0, max_sy)(rng);
      patch.source = PatchSource::kRandom;
      ++result.num_random;
    }
    if (!rects.empty() && options.correction_iterations > 0 &&
        sample.format == ptm::PtmFormat::kLrgb) {
      // The correction's views on the primary view's grid: a coarser photo,
      // upsampled there, constrains each cell at its place instead of one of
      // its own pixels constraining several cells alike.
      const int primary_level = rects.front().level;
      std::vector<Rectified> on_grid;
      on_grid.reserve(rects.size());
      for (Rectified& r : rects) {
        Rectified again;
        if (r.level == primary_level)
          on_grid.push_back(std::move(r));
        else if (rectify(f, r.view, again, primary_level))
          on_grid.push_back(std::move(again));
      }
      CorrectPatch(patch, on_grid);
      correction_level[f] = primary_level;
    }
    done[f] = 1;
    ++processed;
    if (progress && (processed % 64 == 0 || processed == num_faces))
      progress("synthesis", processed, num_faces);
  }
  // 2c. Detail transfer of the corrected patches: independent of one another,
  // so in parallel once the dictionaries of their levels are built.
  std::vector<int> levels;
  for (std::size_t f = 0; f < num_faces && options.detail_transfer; ++f) {
    if (correction_level[f] >= 0 && !dictionaries.count(correction_level[f])) {
      dictionaries[correction_level[f]];
      result.detail_bands[correction_level[f]];
      reduced_at(correction_level[f]);
      levels.push_back(correction_level[f]);
    }
  }
#pragma omp parallel for schedule(dynamic, 1)
  for (std::size_t n = 0; n < levels.size(); ++n) {
    const int level = levels[n];
    build_dictionary(level, reduced.at(level), dictionaries.at(level),
                     result.detail_bands.at(level));
  }
  std::vector<int> transferred;
  for (std::size_t f = 0; f < num_faces && options.detail_transfer; ++f)
    if (correction_level[f] >= 0 && dictionaries.at(correction_level[f]).index)
      transferred.push_back(static_cast<int>(f));
  std::atomic<std::size_t> transfers_done{0};
#pragma omp parallel for schedule(dynamic, 8)
  for (std::size_t n = 0; n < transferred.size(); ++n) {
    const std::size_t f = static_cast<std::size_t>(transferred[n]);
    TransferDetail(result.patches[f], correction_level[f]);
    const std::size_t done_now = ++transfers_done;
    if (progress && (done_now % 64 == 0 || done_now == transferred.size())) {
#pragma omp critical(texlume_detail_progress)
      progress("detail transfer", done_now, transferred.size());
    }
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace texlume::synth
