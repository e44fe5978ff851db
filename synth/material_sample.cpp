#include "synth/material_sample.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/check.h"
#include "core/cubic_interpolation.h"
#include "core/image_io.h"
#include "core/srgb.h"
#include "ptm/coefficient_space.h"
#include "synth/planar_synthesis.h"
#include "synth/relight_rows.h"
#include "synth/template_match.h"

namespace texlume::synth {

FaceLighting LightingInFrame(const mesh::TriangleFrame& frame,
                             const Eigen::Vector3d& camera_centre_in_world,
                             const std::vector<sfm::ObjectLight>& lights,
                             const ptm::LightResponse& response) {
  const Eigen::Vector3d& origin = frame.origin_in_world;
  FaceLighting lighting;
  lighting.view_in_frame = frame.DirectionInFrame((camera_centre_in_world - origin).normalized());
  for (const sfm::ObjectLight& light : lights)
    lighting.lights.emplace_back(frame.DirectionInFrame(light.DirectionFrom(origin)),
                                 light.intensity);
  lighting.response = response;
  return lighting;
}
namespace {

// The PTM's raw coefficient planes (a0..a5 per polynomial, then LRGB colour).
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

// A horizon map as planes: per sector its elevation (radians), then per sector its
// square (what a reduction averages into the horizon's spread over a cell).
std::vector<cv::Mat> HorizonPlanes(const ptm::HorizonMap& h) {
  const auto sectors = static_cast<std::size_t>(h.sectors);
  std::vector<cv::Mat> planes(2 * sectors);
  for (cv::Mat& m : planes) m = cv::Mat(h.height, h.width, CV_32FC1);
  for (int y = 0; y < h.height; ++y)
    for (int x = 0; x < h.width; ++x) {
      const std::size_t t = static_cast<std::size_t>(y) * h.width + x;
      for (std::size_t s = 0; s < sectors; ++s) {
        const float e = h.elevation_rad[t * sectors + s];
        planes[s].at<float>(y, x) = e;
        planes[sectors + s].at<float>(y, x) = e * e;
      }
    }
  return planes;
}

// RelitLinearSum's texels of a shadowed sample: at most this many a side.
constexpr int kShadowedSumGrid = 64;

// The planes' texels at the centres of a grid of at most `side` x `side` cells over
// them, each its own texel's value (no average).
ReducedPlanes TexelsOnAGrid(const std::vector<cv::Mat>& planes, int side) {
  const int w = planes[0].cols, h = planes[0].rows;
  const int gw = std::min(w, side), gh = std::min(h, side);
  ReducedPlanes out{{}, static_cast<double>(gw) / w, static_cast<double>(gh) / h};
  for (const cv::Mat& plane : planes) {
    cv::Mat grid(gh, gw, CV_32FC1);
    for (int j = 0; j < gh; ++j)
      for (int i = 0; i < gw; ++i)
        grid.at<float>(j, i) =
            plane.at<float>((2 * j + 1) * h / (2 * gh), (2 * i + 1) * w / (2 * gw));
    out.planes.push_back(grid);
  }
  return out;
}

// A patch texel position (u, v) (texels, centres at integers) on the patch's
// correction grid: the cell coordinates, clamped, and the 2 x 2 cells around.
struct GridPoint {
  double gu = 0.0, gv = 0.0;
  int gx0 = 0, gy0 = 0, gx1 = 0, gy1 = 0;
  float gfx = 0.0f, gfy = 0.0f;
  float Bilinear(const cv::Mat& m) const {
    return (1 - gfy) * ((1 - gfx) * m.at<float>(gy0, gx0) + gfx * m.at<float>(gy0, gx1)) +
           gfy * ((1 - gfx) * m.at<float>(gy1, gx0) + gfx * m.at<float>(gy1, gx1));
  }
};

GridPoint OnCorrectionGrid(const TrianglePatch& patch, double u, double v) {
  const cv::Mat& c0 = patch.correction[0];
  GridPoint g;
  g.gu = std::clamp((u + 0.5) * patch.correction_density.x() - 0.5, 0.0, c0.cols - 1.0);
  g.gv = std::clamp((v + 0.5) * patch.correction_density.y() - 0.5, 0.0, c0.rows - 1.0);
  g.gx0 = static_cast<int>(g.gu), g.gy0 = static_cast<int>(g.gv);
  g.gx1 = std::min(g.gx0 + 1, c0.cols - 1), g.gy1 = std::min(g.gy0 + 1, c0.rows - 1);
  g.gfx = static_cast<float>(g.gu - g.gx0), g.gfy = static_cast<float>(g.gv - g.gy0);
  return g;
}

// Detail transfer (on the correction's grid): the patch's own detail band out,
// the band around each of the 4 nearest cells' matched sample points in,
// weighted bilinearly and blended so that the detail keeps its contrast.
// (uc, vc): the patch texel position, clamped.
void TransferredDetail(const TrianglePatch& patch, const cv::Mat& band, const GridPoint& g,
                       double uc, double vc, float* out) {
  const double rx = patch.correction_density.x(), ry = patch.correction_density.y();
  const std::array<std::pair<cv::Point, float>, 4> cells = {
      std::pair{cv::Point(g.gx0, g.gy0), (1 - g.gfx) * (1 - g.gfy)},
      std::pair{cv::Point(g.gx1, g.gy0), g.gfx * (1 - g.gfy)},
      std::pair{cv::Point(g.gx0, g.gy1), (1 - g.gfx) * g.gfy},
      std::pair{cv::Point(g.gx1, g.gy1), g.gfx * g.gfy}};
  CatmullRomTaps(band.size(), patch.sample_x + uc, patch.sample_y + vc)
      .AddScaledChannels(band, -1.0, out);
  // The band read at each cell's match, blended so that it keeps its contrast
  // (after Heitz and Neyret 2018's variance-preserving blend; the bands are
  // zero-mean): sum_k w_k b_k / sqrt(sum_jk w_j w_k rho_jk), the standard
  // deviation of the weighted sum of unit bands whose correlation falls with
  // the distance d between their matches, rho = exp(-d^2 / (2 l^2)), l one
  // cell (the band's coarsest detail). Coinciding matches (a coherent piece
  // moved by a cell) count once; unrelated ones are not averaged flat.
  std::array<std::pair<Eigen::Vector2d, double>, 4> sources;
  std::size_t n = 0;
  for (const auto& [cell, w] : cells) {
    if (w <= 0.0f) continue;
    const cv::Vec2f s = patch.detail_source.at<cv::Vec2f>(cell.y, cell.x);
    sources[n++] = {Eigen::Vector2d(s[0] + uc - ((cell.x + 0.5) / rx - 0.5),
                                    s[1] + vc - ((cell.y + 0.5) / ry - 0.5)),
                    w};
  }
  const double cell_texels_squared = 0.5 * (1.0 / (rx * rx) + 1.0 / (ry * ry));
  // rho per pair, once (it is symmetric, and 1 on the diagonal).
  std::array<std::array<double, 4>, 4> rho;
  for (std::size_t j = 0; j < n; ++j) {
    rho[j][j] = 1.0;
    for (std::size_t k = j + 1; k < n; ++k)
      rho[j][k] = rho[k][j] = std::exp(-(sources[j].first - sources[k].first).squaredNorm() /
                                       (2.0 * cell_texels_squared));
  }
  double variance = 0.0;
  for (std::size_t j = 0; j < n; ++j)
    for (std::size_t k = 0; k < n; ++k)
      variance += sources[j].second * sources[k].second * rho[j][k];
  if (n == 0 || !(variance > 0.0)) return;
  const double norm = 1.0 / std::sqrt(variance);
  for (std::size_t k = 0; k < n; ++k)
    CatmullRomTaps(band.size(), sources[k].first.x(), sources[k].first.y())
        .AddScaledChannels(band, sources[k].second * norm, out);
}

// The additive change of the 6 luminance coefficients: Catmull-Rom (bicubic)
// over the 4 x 4 nearest cells, which keeps the photo's detail sharper than
// bilinear.
void AddCorrection(const TrianglePatch& patch, const GridPoint& g, float* out) {
  const CatmullRomTaps taps(patch.correction[0].size(), g.gu, g.gv);
  for (std::size_t i = 0; i < 6; ++i) out[i] += static_cast<float>(taps.Of(patch.correction[i]));
}

// Any sample's windows relit by its Relight, then copied into place.
class WindowByRelight : public WindowRelighter {
 public:
  WindowByRelight(const MaterialSample& sample, const ReducedPlanes& reduced, FaceLighting lighting,
                  double gain)
      : sample_(sample), reduced_(reduced), lighting_(std::move(lighting)), gain_(gain) {}
  void Relight(cv::Rect cells, std::array<cv::Mat, 3>& out) override {
    const std::vector<cv::Mat> relit = sample_.Relight(reduced_.Window(cells), lighting_, gain_);
    for (std::size_t c = 0; c < out.size(); ++c) relit[c].copyTo(out[c](cells));
  }

 private:
  const MaterialSample& sample_;
  const ReducedPlanes& reduced_;
  FaceLighting lighting_;
  double gain_;
};

// A PTM sample without relief shadows: each window's rows relit in place, one light
// over the row (PtmRowRelighter), the lights worked out once.
class PtmWindowRelighter : public WindowRelighter {
 public:
  PtmWindowRelighter(const ReducedPlanes& reduced, ptm::PtmFormat format, int planes,
                     std::vector<ptm::EffectiveLight> lights, double gain)
      : reduced_(reduced),
        rows_(format, std::move(lights), gain),
        in_(static_cast<std::size_t>(planes)) {}
  void Relight(cv::Rect cells, std::array<cv::Mat, 3>& out) override {
    for (int y = cells.y; y < cells.br().y; ++y) {
      for (std::size_t i = 0; i < in_.size(); ++i)
        in_[i] = reduced_.planes[i].ptr<float>(y) + cells.x;
      std::array<float*, 3> row{};
      for (std::size_t c = 0; c < row.size(); ++c) row[c] = out[c].ptr<float>(y) + cells.x;
      rows_.Relight(in_.data(), cells.width, row);
    }
  }

 private:
  const ReducedPlanes& reduced_;
  PtmRowRelighter rows_;
  std::vector<const float*> in_;  // the planes' rows at the window
};

}  // namespace

const ReducedPlanes& MaterialSample::Reduced(int level) const {
  // Several threads search faces at once; a map's elements stay where they are, and
  // a level being reduced holds up only the threads that ask for it.
  ReducedLevel* entry = nullptr;
  {
    const std::lock_guard lock(reduced_mutex_);
    entry = &reduced_.try_emplace(level).first->second;
  }
  std::call_once(entry->once,
                 [&] { entry->planes = ReduceToDensityLevel(RelightPlanes(), level); });
  return entry->planes;
}

std::unique_ptr<WindowRelighter> MaterialSample::RelighterOf(const ReducedPlanes& reduced,
                                                             const FaceLighting& lighting,
                                                             double gain) const {
  return std::make_unique<WindowByRelight>(*this, reduced, lighting, gain);
}

bool MaterialSample::PatchFeatures(const TrianglePatch& patch, double t, const Eigen::Vector2d& p,
                                   float* out) const {
  const double sx = patch.sample_x + (p.x() - patch.x_min) / t;
  const double sy = patch.sample_y + (patch.y_max - p.y()) / t;
  if (sx < patch.sample_x || sy < patch.sample_y || sx > patch.sample_x + patch.width ||
      sy > patch.sample_y + patch.height)
    return false;
  FeaturesAt(Eigen::Vector2d(sx, sy), out);
  return true;
}

BilinearTaps::BilinearTaps(cv::Size planes, double x, double y) {
  x = std::clamp(x, 0.0, planes.width - 1.0);
  y = std::clamp(y, 0.0, planes.height - 1.0);
  x0_ = std::min(static_cast<int>(x), std::max(planes.width - 2, 0));
  y0_ = std::min(static_cast<int>(y), std::max(planes.height - 2, 0));
  x1_ = std::min(x0_ + 1, planes.width - 1), y1_ = std::min(y0_ + 1, planes.height - 1);
  fx_ = x - x0_, fy_ = y - y0_;
}

double BilinearClamped(const cv::Mat& m, double x, double y) {
  return BilinearTaps(m.size(), x, y).Of(m);
}

bool SamplePtmPatch(const std::vector<cv::Mat>& values, ptm::PtmFormat format,
                    const std::map<int, cv::Mat>& detail_bands, const TrianglePatch& patch,
                    double texel_size, const Eigen::Vector2d& p, float* out) {
  const double u = (p.x() - patch.x_min) / texel_size - 0.5;
  const double v = (patch.y_max - p.y()) / texel_size - 0.5;
  if (u < -0.5 || v < -0.5 || u > patch.width - 0.5 || v > patch.height - 0.5) return false;
  const double uc = std::clamp(u, 0.0, patch.width - 1.0),
               vc = std::clamp(v, 0.0, patch.height - 1.0);
  // Catmull-Rom, so the bake keeps the sample's finest detail (issue 29); the taps
  // past the patch's rectangle read the sample around it.
  const CatmullRomTaps taps(values[0].size(), patch.sample_x + uc, patch.sample_y + vc);
  for (std::size_t c = 0; c < values.size(); ++c) out[c] = static_cast<float>(taps.Of(values[c]));
  if (patch.correction.empty()) return true;
  const GridPoint g = OnCorrectionGrid(patch, u, v);
  if (!patch.detail_source.empty())
    TransferredDetail(patch, detail_bands.at(patch.detail_level), g, uc, vc, out);
  AddCorrection(patch, g, out);
  // Per-channel factors: LRGB colour times the factor, RGB polynomial times it.
  for (int c = 0; c < 3 && c < static_cast<int>(patch.channel_gain.size()); ++c) {
    const float k = g.Bilinear(patch.channel_gain[static_cast<std::size_t>(c)]);
    if (format == ptm::PtmFormat::kLrgb) {
      out[6 + c] *= k;
    } else {
      for (int i = 0; i < 6; ++i) out[6 * c + i] *= k;
    }
  }
  return true;
}

PtmSample::PtmSample(const ptm::Ptm& ptm, const ptm::SelfShadowing* shadowing)
    : ptm_(ptm), shadowing_(shadowing), values_(ToOrthonormalPlanes(ptm)), raw_(RawPlanes(ptm)) {
  if (shadowing_) {
    TEXLUME_CHECK(shadowing_->horizon.width == ptm.width &&
                      shadowing_->horizon.height == ptm.height && shadowing_->horizon.sectors > 0,
                  "a sample's horizon map of the sample's size");
    const std::vector<cv::Mat> horizon = HorizonPlanes(shadowing_->horizon);
    raw_.insert(raw_.end(), horizon.begin(), horizon.end());
  }
  const int coefficient_planes = ptm.format == ptm::PtmFormat::kLrgb ? 6 : 18;
  coefficients_.assign(values_.begin(), values_.begin() + coefficient_planes);
  coarse_level_ = std::max(
      0, static_cast<int>(std::ceil(4.0 * std::log2(std::max(ptm.width, ptm.height) / 16.0))));
  if (shadowing_) shadowed_sum_texels_ = TexelsOnAGrid(raw_, kShadowedSumGrid);
}

bool PtmSample::PatchFeatures(const TrianglePatch& patch, double texel_size,
                              const Eigen::Vector2d& p_in_frame, float* out) const {
  static const std::map<int, cv::Mat> kNoDetail;
  std::array<float, 18> all{};  // coefficients (+ LRGB colour): at most 18 values
  if (!SamplePtmPatch(values_, ptm_.format, kNoDetail, patch, texel_size, p_in_frame, all.data()))
    return false;
  std::copy(all.begin(), all.begin() + CoefficientPlanes(), out);
  return true;
}

void PtmSample::FeaturesAt(const Eigen::Vector2d& sample_px, float* out) const {
  for (std::size_t c = 0; c < coefficients_.size(); ++c)
    out[c] = static_cast<float>(
        BilinearClamped(coefficients_[c], sample_px.x() - 0.5, sample_px.y() - 0.5));
}

void PtmSample::TurnFeatures(const Unfolding& u, float* features) const {
  for (int q = 0; q < CoefficientPlanes() / 6; ++q) {
    Eigen::Matrix<double, 6, 1> c;
    for (int m = 0; m < 6; ++m) c[m] = features[q * 6 + m];
    c = u.coefficients_to_this * c;
    for (int m = 0; m < 6; ++m) features[q * 6 + m] = static_cast<float>(c[m]);
  }
}

PtmSample::TexelLights PtmSample::LightsOf(const FaceLighting& lighting) const {
  TexelLights out;
  std::vector<int> source;
  out.lights =
      ptm::EffectiveLights(lighting.lights, lighting.response, lighting.view_in_frame, &source);
  for (const int k : source)
    if (shadowing_ && k >= 0)
      out.among_sectors.emplace_back(ptm::LightAmongSectors(
          lighting.lights[static_cast<std::size_t>(k)].first, shadowing_->horizon.sectors));
    else
      out.among_sectors.emplace_back(std::nullopt);
  return out;
}

void PtmSample::ShadowLights(const TexelLights& lights, const ReducedPlanes& reduced,
                             const BilinearTaps& at, std::vector<ptm::EffectiveLight>& out) const {
  out = lights.lights;
  if (!shadowing_) return;
  // Planes from HorizonPlanesBegin(): per sector its elevation, then its square.
  const std::size_t begin = static_cast<std::size_t>(HorizonPlanesBegin());
  const std::size_t sectors = static_cast<std::size_t>(shadowing_->horizon.sectors);
  for (std::size_t k = 0; k < out.size(); ++k) {
    const std::optional<ptm::LightAmongSectors>& l = lights.among_sectors[k];
    if (!l) continue;
    // Each sector's mean and variance over the cell, then the two sectors' blend (a
    // texel's own horizon, at level 0, has variance 0 in every sector).
    const auto s0 = static_cast<std::size_t>(l->s0), s1 = static_cast<std::size_t>(l->s1);
    const double mean0 = at.Of(reduced.planes[begin + s0]);
    const double mean1 = at.Of(reduced.planes[begin + s1]);
    const double variance0 = at.Of(reduced.planes[begin + sectors + s0]) - mean0 * mean0;
    const double variance1 = at.Of(reduced.planes[begin + sectors + s1]) - mean1 * mean1;
    out[k].weight *= shadowing_->CellLightFactor(l->elevation_rad, l->Horizon(mean0, mean1),
                                                 l->Horizon(variance0, variance1));
  }
}

std::vector<cv::Mat> PtmSample::Relight(const ReducedPlanes& r, const FaceLighting& lighting,
                                        double gain) const {
  std::array<cv::Mat, 3> out;
  for (cv::Mat& m : out) m = cv::Mat(r.planes[0].size(), CV_32FC1);
  // Without shadows, the same lights everywhere: the whole sample as one window.
  if (!shadowing_) {
    RelighterOf(r, lighting, gain)->Relight(cv::Rect(cv::Point(0, 0), r.planes[0].size()), out);
    return {out.begin(), out.end()};
  }
  const int polys = ptm_.NumPolynomials();
  const bool lrgb = ptm_.format == ptm::PtmFormat::kLrgb;
  const auto read = static_cast<std::size_t>(HorizonPlanesBegin());
  std::vector<float> a(read), colour(3, 1.0f);
  const TexelLights texel_lights = LightsOf(lighting);
  std::vector<ptm::EffectiveLight> lights = texel_lights.lights;
  std::vector<const float*> in(read);  // the planes' rows
  for (int y = 0; y < r.planes[0].rows; ++y) {
    for (std::size_t i = 0; i < read; ++i) in[i] = r.planes[i].ptr<float>(y);
    std::array<float*, 3> row{};
    for (std::size_t c = 0; c < row.size(); ++c) row[c] = out[c].ptr<float>(y);
    for (int x = 0; x < r.planes[0].cols; ++x) {
      ShadowLights(texel_lights, r, BilinearTaps(r.planes[0].size(), x, y), lights);
      for (std::size_t i = 0; i < read; ++i) a[i] = in[i][x];
      const Eigen::Vector3f v = RelightEffective(
          a.data(), lrgb ? a.data() + polys * 6 : colour.data(), ptm_.format, lights, gain);
      for (std::size_t c = 0; c < row.size(); ++c) row[c][x] = v[static_cast<Eigen::Index>(c)];
    }
  }
  return {out.begin(), out.end()};
}

std::unique_ptr<WindowRelighter> PtmSample::RelighterOf(const ReducedPlanes& reduced,
                                                        const FaceLighting& lighting,
                                                        double gain) const {
  if (shadowing_) return MaterialSample::RelighterOf(reduced, lighting, gain);
  return std::make_unique<PtmWindowRelighter>(reduced, ptm_.format, HorizonPlanesBegin(),
                                              LightsOf(lighting).lights, gain);
}

double PtmSample::RelitLinearSum(const FaceLighting& lighting, int cells) const {
  const std::vector<cv::Mat> relit =
      Relight(shadowing_ ? shadowed_sum_texels_ : Reduced(coarse_level_), lighting, 1.0);
  double sum = 0.0;
  for (int c = 0; c < 3; ++c)
    for (int j = 0; j < relit[0].rows; ++j)
      for (int i = 0; i < relit[0].cols; ++i)
        sum += srgb::ToLinear(relit[static_cast<std::size_t>(c)].at<float>(j, i));
  return sum * (cells / static_cast<double>(relit[0].total()));
}

}  // namespace texlume::synth
