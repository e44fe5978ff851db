#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "core/image_io.h"
#include "core/photo_cache.h"
#include "core/srgb.h"
#include "mesh/mesh.h"
#include "mesh/triangle_frame.h"
#include "ptm/ptm.h"
#include "sfm/lights.h"
#include "sfm/reconstruction.h"
#include "sfm/visibility.h"

// The parts of paper 003 Algorithm 2 that every per-triangle engine shares: the
// photos, each face's frame and patch rectangle, the unfoldings across its
// edges, photo density levels, rectification, view choice, photo gains, the
// image score and placement.
namespace texlume::synth {

/// An object photo with its light(s), as used to constrain the synthesis.
struct MeshPhoto {
  sfm::ImageId image_id;
  std::string name;
  /// CV_32FC3, RGB, display domain (sRGB-encoded) in [0, 1]; held in memory or
  /// decoded on demand through the job's PhotoCache (core/photo_cache.h).
  PhotoPixels pixels;
  std::vector<sfm::ObjectLight> lights;
};

/// Where the tangent frame's X axis of each triangle comes from.
enum class TangentFrame {
  kFirstEdge,    ///< v0 -> v1 (paper 003 §3.0.2)
  kSmoothField,  ///< a fixed world direction projected onto each face, so anisotropic
                 ///< materials keep their direction across triangles
  kPhotos,       ///< turned so the sample's texture runs the way the photos show it, as a
                 ///< smooth line field over the mesh (synth/tangent_field.h)
  kAuto,         ///< kPhotos for an anisotropic sample (brick, grooves), else kFirstEdge
};

/// kAuto takes kPhotos when the sample's structure-tensor coherence (MeshSynthesis::
/// sample_coherence) is at least this.
inline constexpr double kAnisotropicSampleCoherence = 0.2;

/// "first_edge", "smooth_field", "photos" or "auto" (the manifest's names).
const char* TangentFrameName(TangentFrame frame);

/// How a triangle's patch was chosen.
enum class PatchSource {
  kPhotos,      ///< image score, then neighbours (Algorithm 2 step 2)
  kNeighbours,  ///< fully visible in no photo: overlap constraint alone
  kRandom,      ///< no photo and no synthesised neighbour (first of an unseen component)
};

/// One triangle's patch: the sample PTM's rectangle [sample_x, sample_x + width)
/// x [sample_y, sample_y + height) (texels, rows down) laid over the triangle's
/// frame so that texel (i, j) has its centre at frame coordinates
/// (x_min + (i + 0.5) t, y_max - (j + 0.5) t), t the texel size. The rectangle is
/// the triangle's bounding box plus W_e texels of strip on every side.
struct TrianglePatch {
  mesh::TriangleFrame frame;
  std::array<Eigen::Vector2d, 3> corners_in_frame;  ///< world units
  double x_min = 0.0, y_max = 0.0;                  ///< world units, frame coordinates
  int width = 0, height = 0;                        ///< texels
  int sample_x = 0, sample_y = 0;                   ///< texels, top-left in the sample
  PatchSource source = PatchSource::kRandom;
  int views_used = 0;
  double image_score = 0.0;  ///< summed RMS photo difference of the chosen patch
  /// The photo-consistency pass's prior shrink used (see the option); -1 uncorrected.
  double prior_shrink = -1.0;
  double overlap_error = 0.0;  ///< mean squared orthonormal distance to the neighbours
  /// Photo-consistency correction of the luminance coefficients (orthonormal
  /// space, 6 planes, LRGB), on a grid of `correction_density` cells per texel
  /// over the patch rectangle; empty when none. Added by SamplePatch.
  std::vector<cv::Mat> correction;
  /// Per-channel factors (3 planes on the same grid) for albedo-like
  /// differences: LRGB colour times the factor, RGB polynomial times it.
  std::vector<cv::Mat> channel_gain;
  Eigen::Vector2d correction_density = Eigen::Vector2d::Ones();
  /// Detail transfer (beyond the paper): per cell of the correction grid, the
  /// sample point (texels, CV_32FC2 x, y) whose detail band replaces the
  /// patch's own around that cell; empty when none. The band is
  /// MeshSynthesis::detail_bands[detail_level].
  cv::Mat detail_source;
  int detail_level = -1;
};

/// The unfolding of neighbour `face` across a shared edge into a triangle's
/// frame: p_neighbour = rotation * p + translation (2D, world units), and the
/// coefficient map from the neighbour's frame to this one (orthonormal space).
struct Unfolding {
  int face = -1;  ///< -1: boundary edge
  Eigen::Matrix2d rotation = Eigen::Matrix2d::Identity();
  Eigen::Vector2d translation = Eigen::Vector2d::Zero();
  Eigen::Matrix<double, 6, 6> coefficients_to_this = Eigen::Matrix<double, 6, 6>::Identity();
};

/// Per-face frames, corners and patch rectangles (the bounding box plus `strip`
/// texels of size `texel_size` world units on every side; sample_x/y left 0),
/// and the unfoldings across every shared edge (Algorithm 2's set-up, shared by
/// the PTM and BTF synthesis). Throws InputError when a patch would be absurdly
/// large (a texel size in other units than the mesh).
struct PatchGeometry {
  std::vector<TrianglePatch> patches;
  std::vector<std::array<Unfolding, 3>> unfoldings;
  std::int64_t total_texels = 0;  ///< of the patch rectangles (strips included)
  double surface_texels = 0.0;    ///< of the triangles themselves: their area / texel size^2
  int widest = 0, tallest = 0;    ///< largest patch sides, texels
  double texel_size = 0.0;        ///< world units
};

/// What the patches and the atlases baked from them take, bytes (issue 33): 20
/// bytes per feature plane a texel for the patch texels up to 4 times the
/// triangles' own (the patches, the atlases, the bake: measured 66-122 bytes a
/// texel with a 6-plane sample, where patches are 2-4 times the triangles), and 3
/// bytes per plane for the rest, the strips of small triangles, which are held
/// only as correction grids at the photos' density (measured: 17 bytes a texel
/// with 6 planes, columns of 99280 and 300144 faces; docs/robustness.md).
double PatchMemoryBytes(const PatchGeometry& geometry, int feature_planes);
/// The same for the faces `held` marks (one flag a face): what one rank of a
/// distributed run holds (its region and the region borders).
double PatchMemoryBytes(const PatchGeometry& geometry, int feature_planes,
                        const std::vector<char>& held);
PatchGeometry MakePatchGeometry(const mesh::TriangleMesh& mesh, double texel_size, int strip,
                                TangentFrame tangent_frame,
                                const Eigen::Vector3d& field_direction_in_world);
/// The same with each face's frame x axis along its tangent (projected onto the
/// face; v0 -> v1 where it is nearly the normal). kPhotos and kAuto above give
/// first-edge frames, the start that SynthesizeMeshPtm turns.
PatchGeometry MakePatchGeometry(const mesh::TriangleMesh& mesh, double texel_size, int strip,
                                const std::vector<Eigen::Vector3d>& tangents_in_world);

/// cv::remap (bicubic, border replicated) of a photo's display RGB at `map_x`,
/// `map_y` (OpenCV pixel positions, as RectificationMaps makes them; shifted in
/// place), reading only the region of the photo the maps reach with the bicubic
/// taps' margin: the same values as remapping the whole photo, without converting
/// it all from the photo cache's stored samples.
void RemapPhotoRegion(const PhotoPixels& pixels, cv::Mat& map_x, cv::Mat& map_y, cv::Mat& out);

/// Helpers of Algorithm 2 shared by the PTM and BTF synthesis.
///
/// The photo density level of a face in a view: r = 2^(-level/4) photo pixels
/// per texel of `texel_size` world units, level in [0, 40].
int PhotoDensityLevel(const TrianglePatch& patch, const sfm::TriangleView& view, double texel_size);
/// Planes (one size, CV_32FC1) reduced by area to that density level, and the
/// effective density (reduced size over full size) along x and y.
struct ReducedPlanes {
  std::vector<cv::Mat> planes;
  double rx = 1.0, ry = 1.0;
  /// The window `cells` of every plane (views, not copies), at the same density.
  ReducedPlanes Window(cv::Rect cells) const {
    ReducedPlanes window{{}, rx, ry};
    for (const cv::Mat& plane : planes) window.planes.push_back(plane(cells));
    return window;
  }
};
ReducedPlanes ReduceToDensityLevel(const std::vector<cv::Mat>& planes, int level);
/// cv::remap maps that rectify a photo into the patch grid of `grid` cells at
/// density (rx, ry) cells per texel, and the mask (CV_32FC1) of cells within
/// `mask_margin` world units of the triangle whose photo pixel lies in the
/// image. Returns the number of masked cells.
int RectificationMaps(const TrianglePatch& patch, double texel_size, double rx, double ry,
                      cv::Size grid, const sfm::Camera& camera, const sfm::Rigid3d& cam_from_world,
                      cv::Size image_size, double mask_margin, cv::Mat& map_x, cv::Mat& map_y,
                      cv::Mat& mask);
/// The views that constrain a face: its best fully visible view, then (all_views)
/// the other fully visible ones by angle, up to max_views; none when the face
/// is fully visible nowhere.
std::vector<sfm::TriangleView> ConstrainingViews(const sfm::TriangleVisibility& visibility,
                                                 bool all_views, int max_views);
/// One face seen fully in one photo: log of the photo's mean over the sample's
/// mean relit there (m = a_T g_n), and its weight.
struct GainObservation {
  std::size_t face = 0, photo = 0;
  double log_m = 0.0, weight = 0.0;
};
/// Gains g_n per photo: log m = log a_T + log g_n solved by alternating least
/// squares (20 rounds) with the mean log a_T at 0, so the object's mean albedo is
/// the sample's and stains do not leak into the gains. 1 for unobserved photos.
/// `face_albedo`, when given, receives a_T per face (0 for unobserved faces).
std::vector<double> SolvePhotoGains(const std::vector<GainObservation>& observations,
                                    std::size_t num_faces, std::size_t num_photos,
                                    std::vector<double>* face_albedo = nullptr);
/// The face with the largest projected area in its best fully visible view (0
/// when there is none): where breadth-first synthesis starts.
int BestSeenFace(const sfm::VisibilityResult& visibility);
/// Adds eq. 3's RMS score of one photo (`ssd` from MaskedSsd at the photo's
/// density (rx, ry), over `count` masked cells (the mask's sum) and 3 channels) to
/// `total`, a map over sample placements in texels.
void AddImageScore(const cv::Mat& ssd, double count, double rx, double ry, cv::Mat& total);
/// The k lowest placements of a score map, looking every `stride` texels, best first.
std::vector<std::pair<float, cv::Point>> BestPlacements(const cv::Mat& score, int stride, int k);
/// Of the image score's candidates (BestPlacements), the index of the one with the
/// least `overlap_error(sample_x, sample_y)`, the first on a tie (and that error).
std::size_t ClosestToNeighbours(const std::vector<std::pair<float, cv::Point>>& candidates,
                                const std::function<double(int, int)>& overlap_error,
                                double* error = nullptr);
/// Algorithm 2's second constraint: of the image score's candidates (BestPlacements),
/// the one with the least `overlap_error(sample_x, sample_y)` (the first on a tie)
/// becomes the patch's placement, with its image score and overlap error.
void KeepClosestToNeighbours(const std::vector<std::pair<float, cv::Point>>& candidates,
                             const std::function<double(int, int)>& overlap_error,
                             TrianglePatch& patch);

/// The display value of a PTM texel under several lights (tangent frame) with
/// intensities, times a gain: the sum is taken in the linear domain,
/// srgb(gain * (sum_i w_i lin(clamp(f(l'_i))) + ambient lin(clamp(f(0, 0))))), l'_i
/// and w_i the lights as the texel answers them seen from `view` (ptm::Effective:
/// horizon fade, the response's elevation factor and view factor), ambient the
/// response's.
Eigen::Vector3f RelightMixture(const float* coefficients_or_l, const float* colour,
                               ptm::PtmFormat format,
                               const std::vector<std::pair<Eigen::Vector3d, double>>& lights,
                               double gain, const ptm::LightResponse& response,
                               const Eigen::Vector3d& view);
/// RelightMixture with the lights already as the texel answers them
/// (ptm::EffectiveLights): for many texels under one lighting. Inline: the
/// sample's relighting (MaterialSample::Relight) calls it per cell.
inline Eigen::Vector3f RelightEffective(const float* coefficients_or_l, const float* colour,
                                        ptm::PtmFormat format,
                                        const std::vector<ptm::EffectiveLight>& lights,
                                        double gain) {
  const bool lrgb = format == ptm::PtmFormat::kLrgb;
  Eigen::Vector3f linear = Eigen::Vector3f::Zero();
  for (const ptm::EffectiveLight& e : lights) {
    const Eigen::Vector3d& l = e.direction;
    // LRGB: one luminance polynomial scaled by each channel's colour (Malzbender et
    // al. 2001, eq. 2), evaluated once for the three channels.
    const double luminance = lrgb ? ptm::EvaluatePolynomial(coefficients_or_l, l.x(), l.y()) : 0.0;
    for (int c = 0; c < 3; ++c) {
      const double v = lrgb ? luminance * colour[c]
                            : ptm::EvaluatePolynomial(coefficients_or_l + 6 * c, l.x(), l.y());
      linear[c] += static_cast<float>(e.weight) * srgb::ToLinear(static_cast<float>(v));
    }
  }
  Eigen::Vector3f out;
  for (int c = 0; c < 3; ++c) out[c] = srgb::FromLinear(static_cast<float>(gain) * linear[c]);
  return out;
}

}  // namespace texlume::synth
