#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "ptm/fit.h"
#include "ptm/ptm.h"

namespace texlume::synth {

/// A photo of the planar surface, covering the whole output extent at
/// 1/scale of its resolution, under a known light.
struct PlanarPhoto {
  ptm::ImageRgb image;  ///< display-domain RGB in [0, 1]
  /// Unit direction towards the light in the surface's texture frame (x right,
  /// y up, z out), as in an .lp file.
  Eigen::Vector3d light = Eigen::Vector3d::UnitZ();
  std::string name;
};

/// How neighbouring blocks are joined in their overlap.
enum class Stitch {
  kBlend,    ///< linear alpha blend in the orthonormal coefficient space (paper 003 §2.3)
  kSeamCut,  ///< minimum-cost seam through the overlap (dynamic programming, Efros & Freeman)
};

/// Settings of SynthesizePlanarPtm.
struct PlanarSynthesisOptions {
  /// The largest width or height Check() accepts (a 16k x 16k PTM is 2.3 GB).
  static constexpr int kMaxOutputSide = 16384;
  int width = 0;   ///< PTM_out texels; 0 = photo width x scale
  int height = 0;  ///< PTM_out texels; 0 = photo height x scale
  /// PTM_out texels per photo pixel when width is 0 (photos are of lower
  /// resolution than the output, paper 003 Fig. 3). >= 1.
  int scale = 1;
  int block_size = 32;  ///< texels, square blocks; a multiple of the photo scale
  int overlap = 8;      ///< W_e, texels; block - overlap must be a multiple of the scale
  /// Candidates kept by the image score S (eq. 3) before the overlap constraint. >= 1.
  int top_k = 12;
  /// false: classic unconstrained PTM quilting (overlap only), for comparison.
  bool use_photos = true;
  Stitch stitch = Stitch::kBlend;
  /// Estimate a gain per photo (exposure x light intensity) from the ratio of
  /// mean photo intensity to mean sample intensity under the photo's light.
  bool estimate_gain = true;
  /// Unconstrained mode: pick at random among candidates whose overlap error is
  /// within (1 + tolerance) of the best. >= 0.
  double tolerance = 0.1;
  std::uint32_t seed = 1;
  /// After quilting, the photo-consistency pass (PhotoConsistencyCorrection):
  /// 0 = off (the paper's output).
  int correction_iterations = 2;

  void Check() const;
};

/// One pasted block: where it went in PTM_out and where it came from in PTM_in
/// (top-left corners, texels, image rows down).
struct BlockPlacement {
  int out_x = 0, out_y = 0;
  int sample_x = 0, sample_y = 0;
  double image_score = 0.0;    ///< S of eq. 3 (0 unconstrained)
  double overlap_error = 0.0;  ///< mean squared orthonormal-coefficient distance per overlap texel
};

/// The synthesised PTM and what it took.
struct PlanarSynthesisResult {
  ptm::Ptm ptm;
  std::vector<BlockPlacement> blocks;
  std::vector<double> photo_gains;  ///< per photo
  int scale = 1;                    ///< PTM_out texels per photo pixel
  /// Mean squared orthonormal-coefficient difference of the two joined blocks on
  /// the seam texels (the cut path, or the overlap's centre line when blending).
  double seam_cost_per_texel = 0.0;
  /// RMS luminance residual against the photos at their resolution, after
  /// quilting and after the photo-consistency pass (equal when it is off).
  double photo_rms_quilted = 0.0, photo_rms_corrected = 0.0;
  double seconds = 0.0;
};

/// Image-constrained planar PTM synthesis (paper 003 Algorithm 1): raster-scan
/// block quilting from the lower-left corner; candidate blocks of PTM_in ranked by
/// the image score S (eq. 3) summed over the photos (PTM_in relit at each photo's
/// light, at the photo's resolution, times the photo's gain), found with FFT
/// template matching over all positions; among the top_k, the one that best
/// agrees with what is already synthesised (L2 in the orthonormal coefficient
/// space); pasted and stitched in that space. Throws InputError for photos whose
/// size does not fit the output extent and scale, and OptionError for blocks or
/// overlaps that do not fit the sample or the scale.
PlanarSynthesisResult SynthesizePlanarPtm(const ptm::Ptm& sample,
                                          const std::vector<PlanarPhoto>& photos,
                                          const PlanarSynthesisOptions& options);

/// Photo-consistency pass (beyond paper 003, which stops at quilting): quilted
/// blocks agree with the photos only as well as the best block of the sample
/// does. This adds to PTM_out the smallest coefficient change (in the orthonormal
/// space, i.e. the smallest change of the function over the hemisphere) that
/// makes PTM_out, relit at each photo's light, reduced to the photo's resolution
/// and times its gain, equal the photo in luminance:
///   psi(l_n)^T dq = (Y_n - g_n Y(f(l_n))) / (g_n Y(c)),   da = L^-T dq,
/// solved per photo pixel (Tikhonov-regularised minimum norm: with fewer than
/// six photos the coefficients the photos do not see keep the sample's), and
/// upsampled bicubically to the texels. The fine detail of the quilted blocks is
/// kept; their low frequencies come from the photos. `iterations` rounds (the
/// clamp of relighting makes one round approximate). Returns the RMS luminance
/// residual at photo resolution after the last round.
double PhotoConsistencyCorrection(ptm::Ptm& ptm, const std::vector<PlanarPhoto>& photos,
                                  const std::vector<double>& gains, int iterations);

/// Nearest-patch energy (DESIGN.md, synthesis quality): for patches of `patch`
/// texels on a grid over `output`, the mean squared orthonormal-coefficient
/// distance per texel to the closest patch of `sample` (FFT search).
double NearestPatchEnergy(const ptm::Ptm& output, const ptm::Ptm& sample, int patch);

/// The orthonormal coefficient planes of a PTM (LRGB: 6 luminance planes and 3
/// colour planes; RGB: 18), and back.
std::vector<cv::Mat> ToOrthonormalPlanes(const ptm::Ptm& ptm);
ptm::Ptm FromOrthonormalPlanes(const std::vector<cv::Mat>& planes, ptm::PtmFormat format);

}  // namespace texlume::synth
