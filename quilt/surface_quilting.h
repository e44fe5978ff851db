#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <map>
#include <random>
#include <vector>

#include "core/progress.h"
#include "quilt/dense_surface.h"
#include "quilt/patch_matching.h"
#include "synth/material_sample.h"

// The quilting loop of paper 004 §III-B (Fig. 4) on a dense surface: pick the
// most constrained sample, build the work patch and its work image, match the
// whole (rotated) sample against the work image, fit the patch by a graph cut,
// and accept it when the seam is cheap enough, or shrink the patch and retry.

namespace texlume::quilt {

struct QuiltOptions {
  /// r_w: levels of the breadth-first work patch (paper: 32 for a 512^2 image).
  int work_patch_levels = 32;
  int min_work_patch_levels = 4;  ///< the hierarchical search stops here (paper)
  double shrink = 0.8;            ///< r_w factor per retry (paper)
  /// T_d: largest area distortion of a work image (paper: 4): the patch's
  /// summed squared link lengths in the work image over those on the surface,
  /// either way round.
  double max_area_distortion = 4.0;
  /// A work patch across charts is flattened by the least-squares conformal
  /// map of the faces under it (the paper); false: the charts' rigid maps
  /// chained across their borders (an ablation).
  bool conformal_work_images = true;
  /// T_c: largest mean seam cost per cut link, as a fraction of the cost of a
  /// cut between two unrelated sample texels (the sample's own feature spread).
  double seam_threshold = 0.6;
  /// Orientation: true turns each patch to a random one of the 72 rotations
  /// (isotropic samples); false aligns the sample's x axis with the field:
  /// `field_in_world` (per face, in its plane; InterpolateField), or when that
  /// is empty each face frame's x axis (the tangent field the patch geometry
  /// was made with: synth::TangentFrame::kSmoothField gives a coherent one).
  bool random_orientation = false;
  std::vector<Eigen::Vector3d> field_in_world;
  /// A baseline, not the paper: each patch placed at random in the sample (no
  /// matching) and accepted whatever its seam costs.
  bool random_placement = false;
  /// Old seams kept as nodes of later cuts (Kwatra et al. 2003); false: a cut
  /// sees only the values there now (an ablation).
  bool keep_old_seams = true;
  /// With an image term (PatchImageTerm): the placements the photos score best
  /// that the overlap then chooses among (paper 003's top_k, Algorithm 2).
  int image_top_k = 12;
  std::uint64_t seed = 1;
  void Check() const;
};

/// What one dense sample shows: the sample position (texels, x right, y down,
/// centres at +0.5) and how the sample is turned there, counter-clockwise from
/// the atlas frame of the sample's chart (x right, y up).
struct SampleLookup {
  Eigen::Vector2f sample_px = Eigen::Vector2f::Zero();
  float angle_rad = 0;
  bool synthesised = false;
};

struct QuiltStats {
  std::size_t given = 0;  ///< samples given before quilting (GivenSamples)
  std::size_t patches = 0;
  std::map<int, std::size_t> accepted_at_levels;  ///< r_w -> patches accepted there
  std::size_t forced = 0;                         ///< accepted at the smallest r_w above T_c
  std::size_t photo_patches = 0;                  ///< placed among the photos' best (an image term)
  std::size_t cut_links = 0;    ///< links whose two samples came from different patches
  double seam_cost = 0;         ///< summed over the cut links (feature units)
  double random_pair_cost = 0;  ///< T_c's unit: a cut between unrelated texels
  double seconds = 0;
};

/// The mean seam cost per cut link as a share of T_c's unit (a cut between
/// unrelated texels); 0 without cuts.
double SeamShare(const QuiltStats& stats);

struct QuiltResult {
  std::vector<SampleLookup> lookups;  ///< per dense sample
  std::vector<int> patch_of;          ///< per dense sample: the patch that wrote it
  QuiltStats stats;
};

/// Samples whose texture is given before quilting (the faces the photos placed,
/// when the quilt fills those no photo sees): they count as synthesised from
/// the start, so the quilt grows out from them and matches against them, and
/// every cut keeps them. Their lookups stay unsynthesised (not the quilt's).
struct GivenSamples {
  std::vector<bool> given;      ///< per dense sample
  std::vector<float> features;  ///< per dense sample, NumFeatures() values, chart's atlas frame
};

/// A sample of a work patch as an image term sees it: the dense sample and its
/// pixel in the work image (rows down). The work frame is the atlas frame of
/// the seed's chart (AtlasAxesOf the seed's face).
struct WorkImageSample {
  int sample = 0;
  int x = 0, y = 0;
  bool synthesised = false;  ///< before this patch (given, or an earlier patch's)
};

/// Paper 003's image term (eq. 3) on a work patch, beyond paper 004: how far
/// the sample relit under the photos' lights differs from the photos at every
/// placement of a rotated copy over the work image (quilt/image_term.h).
class PatchImageTerm {
 public:
  virtual ~PatchImageTerm() = default;
  struct Score {
    cv::Mat rms;     ///< CV_32FC1 over placements, as EntirePatchCosts; empty: no photo
    int stride = 1;  ///< placements one photo pixel spans (BestPlacements' stride)
  };
  virtual Score Placements(int seed, const std::vector<WorkImageSample>& samples,
                           cv::Size work_size, int rotation, const RotatedSample& rotated) = 0;
};

/// Quilts `sample` over `surface`. `layout` is the layout the surface was built
/// from (chart frames). `given`: samples that keep their texture (may be null).
/// `image_term` (may be null): each patch is placed, of the image term's
/// image_top_k best placements, at the one whose overlap costs least
/// (Algorithm 2 of paper 003 on the work patch); a patch no photo sees is
/// matched as without. Deterministic for a seed.
QuiltResult QuiltSurface(const DenseSurface& surface, const atlas::AtlasLayout& layout,
                         const synth::MaterialSample& sample, const QuiltOptions& options,
                         const ProgressCallback& progress = {}, const GivenSamples* given = nullptr,
                         PatchImageTerm* image_term = nullptr);

}  // namespace texlume::quilt
