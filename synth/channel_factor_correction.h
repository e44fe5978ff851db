#pragma once

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>
#include <vector>

#include "synth/triangle_engine.h"

namespace texlume::synth {

/// The photo-consistency pass of a sample compared in the linear domain
/// (beyond paper 004, as the PTM pass is beyond paper 003): per face seen in
/// photos, a per-channel factor k on a grid at the best photo's density over
/// the whole patch, the most probable under a prior k = 1 given every
/// constraint photo,
///   k = (sum_r m_r p_r + lambda mu) / (sum_r m_r^2 + lambda mu),
/// m_r the placed patch relit under photo r (times its gain), p_r the photo,
/// mu the mean m^2: the photos' low frequencies (stains, colour, the exact
/// light and dark spots) on the sample's fine detail. The factors are smoothed
/// by a Gaussian normalised over the observed cells (which carries them into
/// the strip a seam may show), 1 where nothing is observed nearby.
class ChannelFactorCorrection : public PhotoCorrection {
 public:
  struct Options {
    /// lambda: photo noise as a share of the model's mean power. > 0.
    double noise = 0.05;
    /// Smoothing of the factors (Gaussian sigma, photo cells; 4 sigma where no
    /// observed cell is near). > 0.
    double sigma = 0.35;
    /// The observed cells reach this far beyond the triangle (world units).
    double wide_margin = 0.0;
  };
  explicit ChannelFactorCorrection(const Options& options) : options_(options) {}

  double WideMaskMargin() const override { return options_.wide_margin; }
  void Correct(TriangleEngine& engine, std::size_t face, std::vector<RectifiedView>& views,
               const std::vector<RelitWindow>& relit) override;
  /// The relit sample around the patch that the model seen through the photo's
  /// blur reads (3 sigma), and a cell for the bilinear read.
  /// A distributed run: the face's factors and their density; the residual sums.
  void SaveFace(std::size_t face, ByteWriter& out) const override;
  void LoadFace(TriangleEngine& engine, std::size_t face, ByteReader& in) override;
  void SaveSums(ByteWriter& out) const override;
  void AddSums(ByteReader& in) override;
  int RelitMarginCells(const RectifiedView& view) const override;

  /// Per face: the factors (CV_32FC3, linear R, G, B) on a grid over its patch
  /// rectangle at density()[face] cells per texel (x, y); empty: none.
  const std::vector<cv::Mat>& factors() const { return factors_; }
  const std::vector<Eigen::Vector2d>& density() const { return density_; }
  /// RMS linear difference to the constraint photos at their density over the
  /// triangles' cells, before and after the factors (0 when nothing was seen).
  double RmsQuilted() const;
  double RmsCorrected() const;

 private:
  // Placed patch and photo of one view on the best view's grid.
  struct OnGrid {
    std::array<cv::Mat, 3> model, photo;
    cv::Mat inside;  // the triangle's cells (for the residuals)
    cv::Mat wide;    // the observed cells
  };
  OnGrid ToGrid(const TrianglePatch& patch, const RectifiedView& view, const ReducedPlanes& reduced,
                const RelitWindow& relit, cv::Size grid) const;
  // The factors of one channel from the summed products (num = sum m p,
  // den = sum m^2) over the observed cells, and the observed cells smoothed
  // by sigma (`weight`) and 4 sigma (`wide_weight`).
  cv::Mat ChannelFactors(const cv::Mat& num, const cv::Mat& den, const cv::Mat& observed,
                         double observed_sum, const cv::Mat& weight,
                         const cv::Mat& wide_weight) const;

  Options options_;
  std::vector<cv::Mat> factors_;
  std::vector<Eigen::Vector2d> density_;
  double residual_quilted_ = 0.0, residual_corrected_ = 0.0, residual_count_ = 0.0;
};

}  // namespace texlume::synth
