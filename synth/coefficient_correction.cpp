#include "synth/coefficient_correction.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>

#include "core/image_io.h"
#include "core/srgb.h"
#include "ptm/coefficient_space.h"
#include "synth/detail_transfer.h"
#include "synth/photo_blur.h"

namespace texlume::synth {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Row6d = Eigen::Matrix<double, 1, 6>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

}  // namespace

// One patch's photo-consistency pass: the state the Gauss-Newton rounds share.
class CoefficientCorrection::PatchPass {
 public:
  // A cell's coefficients as a prediction reads them: the patch's luminance
  // coefficients (raw PTM) and LRGB colour there.
  struct CellCoefficients {
    float a[6];
    float colour[3];
  };

  PatchPass(const PtmSample& sample, TrianglePatch& patch, const std::vector<RectifiedView>& views,
            const ReducedPlanes& reduced, const CoefficientPrior& prior,
            const std::vector<double>& photo_gains, const MeshSynthesisOptions& options)
      : sample_(sample),
        patch_(patch),
        views_(views),
        red0_(reduced),
        prior_(prior),
        gains_(photo_gains),
        options_(options),
        gw_(views[0].mask.cols),
        gh_(views[0].mask.rows),
        known_(cv::Mat::zeros(gh_, gw_, CV_8UC1)) {
    patch.correction_density = Eigen::Vector2d(red0_.rx, red0_.ry);
    patch.correction.assign(6, cv::Mat());
    for (cv::Mat& m : patch.correction) m = cv::Mat::zeros(gh_, gw_, CV_32FC1);
    patch.channel_gain.assign(3, cv::Mat());
    for (cv::Mat& m : patch.channel_gain) m = cv::Mat::ones(gh_, gw_, CV_32FC1);
    ComputeWayToMean();
    ComputeCellsAtPatch();
    for (const RectifiedView& r : views_) texel_lights_.push_back(sample_.LightsOf(r.lighting));
    ComputeLightRows();
  }

  void Run() {
    const double shrink = PriorShrink();
    patch_.prior_shrink = shrink;
    for (int it = 0; it < options_.correction_iterations; ++it) {
      if (options_.channel_correction) UpdateChannelFactors();
      if (options_.additive_correction) UpdateAdditiveChange(shrink);
    }
    ExtendIntoStrip();
  }

 private:
  static bool Seen(const RectifiedView& r, int i, int j) { return r.mask.at<float>(j, i) > 0; }
  static double PhotoLuminance(const RectifiedView& r, int i, int j) {
    return (r.planes[0].at<float>(j, i) + r.planes[1].at<float>(j, i) +
            r.planes[2].at<float>(j, i)) /
           3.0;
  }
  Vector6d CorrectionAt(int i, int j) const {
    Vector6d q;
    for (int m = 0; m < 6; ++m)
      q[m] = patch_.correction[static_cast<std::size_t>(m)].at<float>(j, i);
    return q;
  }
  const Vector6d& ToMean(int i, int j) const {
    return to_mean_of_cell_[static_cast<std::size_t>(j * gw_ + i)];
  }
  std::size_t Cell(int i, int j) const { return static_cast<std::size_t>(j * gw_ + i); }

  // Cell (i, j)'s centre in the reduced sample's pixel coordinates (centres at
  // integers), (sample_x + (i + 0.5) / rx) rx - 0.5, clamped to the planes.
  cv::Point2d SamplePoint(int i, int j) const {
    const cv::Mat& p0 = red0_.planes[0];
    return {std::clamp(patch_.sample_x * red0_.rx + i, 0.0, p0.cols - 1.0),
            std::clamp(patch_.sample_y * red0_.ry + j, 0.0, p0.rows - 1.0)};
  }

  // The patch's luminance coefficients and colour at every cell, bilinear in the
  // reduced sample (the patch is fixed during the pass, so once).
  void ComputeCellsAtPatch() {
    const cv::Mat& p0 = red0_.planes[0];
    cells_at_patch_.resize(static_cast<std::size_t>(gw_ * gh_));
    for (int j = 0; j < gh_; ++j)
      for (int i = 0; i < gw_; ++i) {
        const cv::Point2d s = SamplePoint(i, j);
        const int x0 = static_cast<int>(s.x), y0 = static_cast<int>(s.y);
        const int x1 = std::min(x0 + 1, p0.cols - 1), y1 = std::min(y0 + 1, p0.rows - 1);
        const float fx = static_cast<float>(s.x - x0), fy = static_cast<float>(s.y - y0);
        const auto sample_at = [&](std::size_t m) {
          const cv::Mat& plane = red0_.planes[m];
          return (1 - fy) * ((1 - fx) * plane.at<float>(y0, x0) + fx * plane.at<float>(y0, x1)) +
                 fy * ((1 - fx) * plane.at<float>(y1, x0) + fx * plane.at<float>(y1, x1));
        };
        CellCoefficients& cell = cells_at_patch_[Cell(i, j)];
        for (std::size_t m = 0; m < 6; ++m) cell.a[m] = sample_at(m);
        for (std::size_t c = 0; c < 3; ++c) cell.colour[c] = sample_at(6 + c);
      }
  }

  // Cell (i, j)'s coefficients as the pass has them now: with its change (q,
  // orthonormal) added and its colour times the channel factors found so far, so
  // that each round's factors answer what the last left.
  CellCoefficients CellNow(int i, int j) const {
    const Eigen::Matrix<double, 6, 6>& from_orthonormal =
        ptm::OrthonormalBasis::Hemisphere().FromOrthonormal();
    const Vector6d a_delta = from_orthonormal * CorrectionAt(i, j);
    const CellCoefficients& at_patch = cells_at_patch_[Cell(i, j)];
    CellCoefficients now;
    for (std::size_t m = 0; m < 6; ++m)
      now.a[m] = at_patch.a[m] + static_cast<float>(a_delta[static_cast<Eigen::Index>(m)]);
    for (std::size_t c = 0; c < 3; ++c)
      now.colour[c] = at_patch.colour[c] * patch_.channel_gain[c].at<float>(j, i);
    return now;
  }
  std::vector<CellCoefficients> CellsNow() const {
    std::vector<CellCoefficients> cells(static_cast<std::size_t>(gw_ * gh_));
    for (int j = 0; j < gh_; ++j)
      for (int i = 0; i < gw_; ++i) cells[Cell(i, j)] = CellNow(i, j);
    return cells;
  }

  // The way from the patch's coefficients to the prior's mean, per cell (the
  // patch is fixed during the pass, so once).
  void ComputeWayToMean() {
    const Eigen::Matrix<double, 6, 6>& to_orthonormal =
        ptm::OrthonormalBasis::Hemisphere().ToOrthonormal();
    to_mean_of_cell_.resize(static_cast<std::size_t>(gw_ * gh_));
    for (int j = 0; j < gh_; ++j)
      for (int i = 0; i < gw_; ++i) {
        const cv::Point2d s = SamplePoint(i, j);
        const BilinearTaps at(red0_.planes[0].size(), s.x, s.y);
        Vector6d a_patch;
        for (int m = 0; m < 6; ++m) a_patch[m] = at.Of(red0_.planes[static_cast<std::size_t>(m)]);
        to_mean_of_cell_[static_cast<std::size_t>(j * gw_ + i)] =
            prior_.mean - to_orthonormal * a_patch;
      }
  }

  // Per view and light, the polynomial's basis at the light in orthonormal
  // coefficients (d luminance / d q): the same at every cell, so once.
  void ComputeLightRows() {
    const Eigen::Matrix<double, 6, 6>& from_orthonormal =
        ptm::OrthonormalBasis::Hemisphere().FromOrthonormal();
    for (const PtmSample::TexelLights& view : texel_lights_) {
      std::vector<Row6d>& rows = light_rows_.emplace_back();
      for (const ptm::EffectiveLight& e : view.lights) {
        const std::array<double, 6> phi = ptm::PtmBasis(e.direction.x(), e.direction.y());
        rows.push_back(Eigen::Map<const Row6d>(phi.data()) * from_orthonormal);
      }
    }
  }

  // Prediction (displayed luminance) of view `view` at cell (i, j), whose
  // coefficients are `cell` (CellNow); its luminance Jacobian into `jac` and the
  // linear value per channel into `channel_linear`, each unless null.
  double Predict(std::size_t view, int i, int j, const CellCoefficients& cell, Row6d* jac,
                 Eigen::Vector3d* channel_linear = nullptr) const {
    const float* a = cell.a;
    const float* colour = cell.colour;
    Eigen::Vector3d linear = Eigen::Vector3d::Zero();
    Eigen::Matrix<double, 3, 6> dlinear = Eigen::Matrix<double, 3, 6>::Zero();
    // The lights as the texel answers them (horizon fade, light response and
    // ambient, the relief's shadows), as PtmSample::Relight relights.
    const std::vector<ptm::EffectiveLight>* lights = &texel_lights_[view].lights;
    if (sample_.CastsShadows()) {  // else the lights are the view's, unchanged
      const cv::Point2d s = SamplePoint(i, j);
      sample_.ShadowLights(texel_lights_[view], red0_,
                           BilinearTaps(red0_.planes[0].size(), s.x, s.y), shadowed_lights_);
      lights = &shadowed_lights_;
    }
    for (std::size_t k = 0; k < lights->size(); ++k) {
      const Eigen::Vector3d& l = (*lights)[k].direction;
      const double intensity = (*lights)[k].weight;
      const double lum = ptm::EvaluatePolynomial(a, l.x(), l.y());
      const Row6d& row = light_rows_[view][k];
      for (int c = 0; c < 3; ++c) {
        const double v = lum * colour[c];
        double dlin = 0.0;
        linear[c] += intensity * RelitLinearShare(v, jac ? &dlin : nullptr);
        if (dlin != 0.0) dlinear.row(c) += intensity * dlin * colour[c] * row;
      }
    }
    const double g = gains_[views_[view].photo];
    double y_pred = 0.0;
    if (jac) jac->setZero();
    for (int c = 0; c < 3; ++c) {
      const double lin = g * linear[c];
      if (channel_linear) (*channel_linear)[c] = lin;
      const float d = LinearToSrgb(static_cast<float>(lin));
      y_pred += d / 3.0;
      if (!jac) continue;
      const double dsrgb = srgb::FromLinearSlope(static_cast<float>(lin), d);
      *jac += dsrgb * g * dlinear.row(c) / 3.0;
    }
    return y_pred;
  }

  // How far the prior mean moves from the patch toward the sample's mean. With
  // the option < 0, estimated: 1 - rho, rho the least-squares slope of the
  // photos' departure from the mean's prediction on the patch's departure from
  // it, over the patch's cells and views (how much of the patch's own structure
  // the photos confirm where they see it), clamped to [0, 1]. The departure is
  // linearised at the patch, d = -J (mean - patch), and like the prediction
  // seen through the photo's blur. Keeps the linear values predicted at the
  // patch for the first round's channel factors (linear_at_patch_).
  double PriorShrink() {
    if (options_.correction_prior_shrink >= 0.0) return options_.correction_prior_shrink;
    double photo_dot_patch = 0.0, patch_dot_patch = 0.0;
    Row6d jac;
    const std::vector<CellCoefficients> cells = CellsNow();  // the patch's own
    linear_at_patch_.assign(views_.size() * cells.size(), Eigen::Vector3d::Zero());
    for (std::size_t v = 0; v < views_.size(); ++v) {
      const RectifiedView& r = views_[v];
      // The prediction at the patch and the patch's departure, per cell, both
      // as the photo sees them (through its blur, as the additive change).
      cv::Mat at_patch = cv::Mat::zeros(gh_, gw_, CV_32FC1);
      cv::Mat departure = cv::Mat::zeros(gh_, gw_, CV_32FC1);
      cv::Mat seen = cv::Mat::zeros(gh_, gw_, CV_32FC1);
      for (int j = 0; j < gh_; ++j)
        for (int i = 0; i < gw_; ++i) {
          if (!Seen(r, i, j)) continue;
          at_patch.at<float>(j, i) = static_cast<float>(Predict(
              v, i, j, cells[Cell(i, j)], &jac, &linear_at_patch_[v * cells.size() + Cell(i, j)]));
          departure.at<float>(j, i) = static_cast<float>(-(jac * ToMean(i, j))(0));
          seen.at<float>(j, i) = 1.0f;
        }
      at_patch = MaskedGaussian(at_patch, seen, r.blur_cells);
      departure = MaskedGaussian(departure, seen, r.blur_cells);
      for (int j = 0; j < gh_; ++j)
        for (int i = 0; i < gw_; ++i) {
          if (!Seen(r, i, j)) continue;
          const double d = departure.at<float>(j, i);
          photo_dot_patch += (PhotoLuminance(r, i, j) - at_patch.at<float>(j, i) + d) * d;
          patch_dot_patch += d * d;
        }
    }
    const double rho = patch_dot_patch > 1e-12 ? photo_dot_patch / patch_dot_patch : 0.0;
    return 1.0 - std::clamp(rho, 0.0, 1.0);
  }

  // Per cell and channel, the photos' linear values summed over the views that
  // see it (the same every round, so once); marks those cells known.
  void SumPhotosLinear() {
    photo_linear_sum_.assign(3, cv::Mat());
    for (cv::Mat& m : photo_linear_sum_) m = cv::Mat::zeros(gh_, gw_, CV_32FC1);
    for (int j = 0; j < gh_; ++j)
      for (int i = 0; i < gw_; ++i)
        for (const RectifiedView& r : views_) {
          if (!Seen(r, i, j)) continue;
          for (std::size_t c = 0; c < 3; ++c)
            photo_linear_sum_[c].at<float>(j, i) += SrgbToLinear(r.planes[c].at<float>(j, i));
          known_.at<std::uint8_t>(j, i) = 1;
        }
  }

  // Per-channel factors at low frequency (stains, colour): photo over
  // prediction in the linear domain, summed over the views and smoothed over a
  // few photo pixels (normalised convolution), taken back to display values
  // (x^(1/2.2)), chromaticity only. Finer detail stays the sample's.
  void UpdateChannelFactors() {
    if (photo_linear_sum_.empty()) SumPhotosLinear();
    std::vector<cv::Mat> model_sum(3);
    for (cv::Mat& m : model_sum) m = cv::Mat::zeros(gh_, gw_, CV_32FC1);
    // The first round's cells are still the patch's: PriorShrink predicted them.
    const bool predicted = !linear_at_patch_.empty();
    for (int j = 0; j < gh_; ++j) {
      for (int i = 0; i < gw_; ++i) {
        if (!known_.at<std::uint8_t>(j, i)) continue;  // seen by no view
        const CellCoefficients cell = predicted ? CellCoefficients{} : CellNow(i, j);
        for (std::size_t v = 0; v < views_.size(); ++v) {
          if (!Seen(views_[v], i, j)) continue;
          Eigen::Vector3d lin;
          if (predicted)
            lin = linear_at_patch_[v * static_cast<std::size_t>(gw_ * gh_) + Cell(i, j)];
          else
            Predict(v, i, j, cell, nullptr, &lin);
          for (std::size_t c = 0; c < 3; ++c)
            model_sum[c].at<float>(j, i) += static_cast<float>(lin[static_cast<Eigen::Index>(c)]);
        }
      }
    }
    linear_at_patch_.clear();
    const std::vector<cv::Mat>& photo_sum = photo_linear_sum_;
    std::vector<cv::Mat> pb(3), mb(3);
    for (std::size_t c = 0; c < 3; ++c) {
      cv::GaussianBlur(photo_sum[c], pb[c], cv::Size(0, 0), options_.correction_sigma);
      cv::GaussianBlur(model_sum[c], mb[c], cv::Size(0, 0), options_.correction_sigma);
    }
    for (int j = 0; j < gh_; ++j)
      for (int i = 0; i < gw_; ++i) {
        if (!known_.at<std::uint8_t>(j, i)) continue;
        double ratio[3];
        bool ok = true;
        for (std::size_t c = 0; c < 3; ++c) {
          const float p = pb[c].at<float>(j, i), m = mb[c].at<float>(j, i);
          ok = ok && m > 1e-4f && p > 1e-4f;
          ratio[c] = ok ? std::pow(p / m, 1.0 / 2.2) : 1.0;
        }
        if (!ok) continue;
        // Chromaticity only: the luminance is the additive change's.
        const double mean = (ratio[0] + ratio[1] + ratio[2]) / 3.0;
        for (double& r : ratio) r /= mean;
        for (std::size_t c = 0; c < 3; ++c) {
          float& k = patch_.channel_gain[c].at<float>(j, i);
          k = std::clamp(k * static_cast<float>(ratio[c]), 0.25f, 4.0f);
        }
      }
  }

  // A view's prediction over the grid as the photo sees it, through its blur
  // (a Gaussian of RectifiedView::blur_cells, synth/photo_blur.h), and the
  // luminance Jacobian per cell (of the change at that cell alone).
  struct ViewPrediction {
    cv::Mat seen_by_photo;  // CV_32FC1
    std::vector<Row6d> jacobian;
  };
  ViewPrediction PredictThroughBlur(std::size_t v,
                                    const std::vector<CellCoefficients>& cells) const {
    const RectifiedView& r = views_[v];
    ViewPrediction p{cv::Mat::zeros(gh_, gw_, CV_32FC1),
                     std::vector<Row6d>(static_cast<std::size_t>(gw_ * gh_), Row6d::Zero())};
    cv::Mat seen = cv::Mat::zeros(gh_, gw_, CV_32FC1);
    for (int j = 0; j < gh_; ++j)
      for (int i = 0; i < gw_; ++i) {
        if (!Seen(r, i, j)) continue;
        p.seen_by_photo.at<float>(j, i) =
            static_cast<float>(Predict(v, i, j, cells[Cell(i, j)], &p.jacobian[Cell(i, j)]));
        seen.at<float>(j, i) = 1.0f;
      }
    p.seen_by_photo = MaskedGaussian(p.seen_by_photo, seen, r.blur_cells);
    return p;
  }

  // One Gauss-Newton step of the MAP estimate per seen cell:
  // q = m + Sigma J^T (J Sigma J^T + s^2 I)^-1 (r + J (q0 - m)), with m the
  // way to the sample's mean times `shrink` and s^2 = correction_noise x the
  // mean predicted variance. The residual r is the photo's against the
  // prediction through the photo's blur: detail the photo blurs away is no
  // error, so the change does not take it out. Solved in the coefficients' 6
  // dimensions whatever the number of views (Woodbury's identity):
  // q = m + (s^2 Sigma^-1 + J^T J)^-1 J^T (r + J (q0 - m)).
  void UpdateAdditiveChange(double shrink) {
    linear_at_patch_.clear();  // the first channel factors' alone
    const std::vector<CellCoefficients> cells = CellsNow();
    std::vector<ViewPrediction> predicted;
    for (std::size_t v = 0; v < views_.size(); ++v)
      predicted.push_back(PredictThroughBlur(v, cells));
    for (int j = 0; j < gh_; ++j) {
      for (int i = 0; i < gw_; ++i) {
        const Vector6d q0 = CorrectionAt(i, j);
        const Vector6d q_mean = shrink * ToMean(i, j);
        Matrix6d jtj = Matrix6d::Zero();
        Vector6d jtb = Vector6d::Zero();
        int rows = 0;
        for (std::size_t v = 0; v < views_.size(); ++v) {
          if (!Seen(views_[v], i, j)) continue;
          const Row6d& jv = predicted[v].jacobian[Cell(i, j)];
          const double r =
              PhotoLuminance(views_[v], i, j) - predicted[v].seen_by_photo.at<float>(j, i);
          jtj.noalias() += jv.transpose() * jv;
          jtb += jv.transpose() * (r + jv.dot(q0 - q_mean));
          ++rows;
        }
        if (rows == 0) continue;
        known_.at<std::uint8_t>(j, i) = 1;
        // The mean predicted variance: trace(J Sigma J^T) / rows = <J^T J, Sigma> / rows.
        const double scale = jtj.cwiseProduct(prior_.covariance).sum() / rows;
        if (!(scale > 1e-12)) continue;
        const Vector6d q_new =
            q_mean + (options_.correction_noise * scale * prior_.precision + jtj).ldlt().solve(jtb);
        for (int m = 0; m < 6; ++m)
          patch_.correction[static_cast<std::size_t>(m)].at<float>(j, i) =
              static_cast<float>(q_new[m]);
      }
    }
  }

  // Extend the change into the strip: rings of neighbour averages.
  void ExtendIntoStrip() {
    for (int ring = 0; ring < std::max(gw_, gh_); ++ring) {
      const cv::Mat before = known_.clone();
      bool any = false;
      for (int j = 0; j < gh_; ++j)
        for (int i = 0; i < gw_; ++i) {
          if (before.at<std::uint8_t>(j, i)) continue;
          double sum[6] = {0, 0, 0, 0, 0, 0};
          int n = 0;
          for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di) {
              const int jj = j + dj, ii = i + di;
              if (jj < 0 || ii < 0 || jj >= gh_ || ii >= gw_ || !before.at<std::uint8_t>(jj, ii))
                continue;
              for (int m = 0; m < 6; ++m)
                sum[m] += patch_.correction[static_cast<std::size_t>(m)].at<float>(jj, ii);
              ++n;
            }
          if (!n) continue;
          for (int m = 0; m < 6; ++m)
            patch_.correction[static_cast<std::size_t>(m)].at<float>(j, i) =
                static_cast<float>(sum[m] / n);
          known_.at<std::uint8_t>(j, i) = 1;
          any = true;
        }
      if (!any) break;
    }
  }

  const PtmSample& sample_;
  TrianglePatch& patch_;
  const std::vector<RectifiedView>& views_;
  const ReducedPlanes& red0_;
  const CoefficientPrior& prior_;
  const std::vector<double>& gains_;
  const MeshSynthesisOptions& options_;
  int gw_, gh_;
  std::vector<Vector6d> to_mean_of_cell_;
  std::vector<CellCoefficients> cells_at_patch_;  // ComputeCellsAtPatch
  std::vector<cv::Mat> photo_linear_sum_;         // SumPhotosLinear, per channel
  // PriorShrink's linear values per view and cell (view-major), until the first
  // channel factors use them.
  std::vector<Eigen::Vector3d> linear_at_patch_;
  // Per view, the lights as the texel answers them (PtmSample::LightsOf), once.
  std::vector<PtmSample::TexelLights> texel_lights_;
  std::vector<std::vector<Row6d>> light_rows_;  // per view and light: ComputeLightRows
  mutable std::vector<ptm::EffectiveLight> shadowed_lights_;  // Predict's, at one cell
  cv::Mat known_;                                             // CV_8UC1: cells with a change
};

CoefficientCorrection::CoefficientCorrection(const PtmSample& sample,
                                             const MeshSynthesisOptions& options)
    : sample_(sample), options_(options) {}

CoefficientCorrection::~CoefficientCorrection() = default;

const CoefficientCorrection::CoefficientPrior& CoefficientCorrection::PriorAt(int level) {
  auto it = priors_.find(level);
  if (it != priors_.end()) return it->second;
  const Eigen::Matrix<double, 6, 6>& to_orthonormal =
      ptm::OrthonormalBasis::Hemisphere().ToOrthonormal();
  const ReducedPlanes& red = sample_.Reduced(level);
  const int n = static_cast<int>(red.planes[0].total());
  Vector6d mean = Vector6d::Zero();
  Eigen::Matrix<double, 6, 6> second = Eigen::Matrix<double, 6, 6>::Zero();
  for (int y = 0; y < red.planes[0].rows; ++y)
    for (int x = 0; x < red.planes[0].cols; ++x) {
      Vector6d a;
      for (int m = 0; m < 6; ++m) a[m] = red.planes[static_cast<std::size_t>(m)].at<float>(y, x);
      const Vector6d q = to_orthonormal * a;
      mean += q;
      second += q * q.transpose();
    }
  mean /= n;
  Eigen::Matrix<double, 6, 6> cov = second / n - mean * mean.transpose();
  cov.diagonal().array() += 1e-6 * cov.trace() / 6.0;  // keeps it positive definite
  const Eigen::Matrix<double, 6, 6> precision =
      cov.ldlt().solve(Eigen::Matrix<double, 6, 6>::Identity());
  return priors_.emplace(level, CoefficientPrior{mean, cov, precision}).first->second;
}

void CoefficientCorrection::Correct(TriangleEngine& engine, std::size_t face,
                                    std::vector<RectifiedView>& views,
                                    const std::vector<RelitWindow>& /*relit*/) {
  // Every view on the best view's grid: a coarser photo, upsampled there,
  // constrains each cell at its place instead of one of its own pixels
  // constraining several cells alike.
  const int primary_level = views.front().level;
  std::vector<RectifiedView> on_grid;
  on_grid.reserve(views.size());
  for (RectifiedView& r : views) {
    RectifiedView again;
    if (r.level == primary_level)
      on_grid.push_back(std::move(r));
    else if (engine.Rectify(face, r.view, again, primary_level))
      on_grid.push_back(std::move(again));
  }
  TrianglePatch& patch = engine.result().patches[face];
  PatchPass(sample_, patch, on_grid, sample_.Reduced(primary_level), PriorAt(primary_level),
            engine.result().photo_gains, options_)
      .Run();
  if (correction_level_.empty()) correction_level_.assign(engine.result().patches.size(), -1);
  correction_level_[face] = primary_level;
}

void CoefficientCorrection::SaveFace(std::size_t face, ByteWriter& out) const {
  out.Put<std::int32_t>(correction_level_.empty() ? -1 : correction_level_[face]);
}

void CoefficientCorrection::LoadFace(TriangleEngine& engine, std::size_t face, ByteReader& in) {
  const auto level = in.Get<std::int32_t>();
  if (correction_level_.empty()) correction_level_.assign(engine.result().patches.size(), -1);
  correction_level_[face] = level;
}

void CoefficientCorrection::Finish(TriangleEngine& engine, const std::vector<std::size_t>& faces,
                                   const ProgressCallback& progress) {
  if (!options_.detail_transfer) return;
  std::vector<TrianglePatch>& patches = engine.result().patches;
  // The dictionaries of the levels any face used (their detail bands serve every
  // face), in parallel (each level is reduced once, by the thread that asks first).
  std::vector<int> levels;
  for (const int level : correction_level_) {
    if (level < 0 || dictionaries_.count(level)) continue;
    dictionaries_[level];
    detail_bands_[level];
    levels.push_back(level);
  }
#pragma omp parallel for schedule(dynamic, 1)
  for (std::size_t n = 0; n < levels.size(); ++n) {
    const int level = levels[n];
    dictionaries_.at(level) =
        std::make_unique<DetailDictionary>(sample_, level, detail_bands_.at(level));
  }
  // The corrected patches among `faces`, independent of one another.
  std::vector<std::size_t> transferred;
  for (const std::size_t f : faces)
    if (f < correction_level_.size() && correction_level_[f] >= 0 &&
        dictionaries_.at(correction_level_[f])->Usable())
      transferred.push_back(f);
  std::atomic<std::size_t> transfers_done{0};
#pragma omp parallel for schedule(dynamic, 8)
  for (std::size_t n = 0; n < transferred.size(); ++n) {
    const std::size_t f = transferred[n];
    dictionaries_.at(correction_level_[f])
        ->Transfer(
            patches[f], correction_level_[f],
            CellsReadWithin(patches[f], options_.sample_texel_size, options_.detail_reach_texels));
    const std::size_t done_now = ++transfers_done;
    if (progress && (done_now % 64 == 0 || done_now == transferred.size())) {
#pragma omp critical(texlume_detail_progress)
      progress("detail transfer", done_now, transferred.size());
    }
  }
}

}  // namespace texlume::synth
