#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <random>
#include <vector>

#include "core/byte_buffer.h"
#include "core/progress.h"
#include "mesh/mesh.h"
#include "sfm/reconstruction.h"
#include "sfm/visibility.h"
#include "synth/face_regions.h"
#include "synth/material_sample.h"
#include "synth/overlap_placement.h"
#include "synth/photometry.h"
#include "synth/template_match.h"
#include "synth/triangle_parts.h"

namespace texlume::synth {

/// How the image score searches the sample for a face's placement
/// (synth/placement_search.h).
enum class PlacementSearchKind {
  kExhaustive,    ///< paper 003: every placement at the photos' density (FFT)
  kCoarseToFine,  ///< every placement at a coarser density, then refined near the best
};
/// "exhaustive" or "coarse-to-fine", as the command line spells it.
const char* PlacementSearchName(PlacementSearchKind kind);

/// Settings every sample shares in the per-triangle engine (paper 003
/// Algorithm 2). The PTM and BTF options add their photo-consistency passes.
struct TriangleEngineOptions {
  /// World units per texel of the sample (COLMAP models have arbitrary scale). > 0.
  double sample_texel_size = 0.0;
  /// W_e: texels of strip around each triangle's bounding box (paper: 5-10). [2, 32].
  int strip = 8;
  /// Candidates kept by the image score before the neighbour constraint. >= 1.
  int top_k = 12;
  /// How the image score searches the sample (issue 33: coarse to fine by default).
  PlacementSearchKind search = PlacementSearchKind::kCoarseToFine;
  /// Coarse to fine: placements kept at each coarser density and refined (at
  /// least top_k are). >= 1.
  int search_candidates = 16;
  /// Constrain with every photo in which the triangle is fully visible (scores
  /// summed, each under its own light), not only the best view (paper 003).
  bool all_views = true;
  /// Most views used per triangle with all_views. >= 1.
  int max_views = 4;
  /// Where each face's frame x axis points (the sample's texture is laid along
  /// it). kAuto: turned to the photos when the sample is anisotropic.
  TangentFrame tangent_frame = TangentFrame::kAuto;
  /// kSmoothField: the world direction projected onto each face (falls back to
  /// the orthogonal world axis of smallest normal component where it is nearly
  /// parallel to the normal).
  Eigen::Vector3d field_direction_in_world = Eigen::Vector3d::UnitZ();
  /// Triangles seen in no photo: pick at random among placements whose overlap
  /// error is within (1 + tolerance) of the best. >= 0.
  double tolerance = 0.1;
  /// Fewest rectified photo pixels inside a triangle for the photo to constrain it. >= 1.
  int min_photo_pixels = 6;
  /// Refuse up front when the patches would take more texels than this.
  std::int64_t max_texels = std::int64_t{1} << 30;
  /// Estimate the object's light response (elevation factors and ambient,
  /// ptm::LightResponse) from the photos with the gains, and relight under it
  /// (samples that apply one; synth/photometry.h). Off: the identity, and the
  /// gains with the object's mean albedo the sample's.
  bool light_response = true;
  /// With the light response, Oren and Nayar's view term too (ptm::OrenNayarTerm;
  /// never for a sample that holds the view's effect itself, a BTF).
  bool view_term = true;
  /// Estimate each photo's white balance against the others' and take it out
  /// of the photos before they are compared with the sample (SolveWhiteBalance).
  bool white_balance = true;
  /// Estimate how much blurrier each photo is than the sample at its density
  /// (synth/photo_blur.h), so that the photo-consistency pass compares the
  /// photo with the model seen through that blur. Off: no blur.
  bool photo_blur = true;
  /// Faces whose views the photometry observes (issue 33): all up to this many;
  /// beyond, every k-th face, k = ceil(faces / this), and for each photo left with
  /// fewer than kPhotometryFacesPerPhoto of its fully visible faces, that many of
  /// them spread over its list (so a few more than this may be observed). The
  /// photometry solves a few unknowns per photo, so a monument's million faces
  /// would add time, not precision. >= kPhotometryFacesPerPhoto.
  int photometry_faces = 16384;
  static constexpr int kPhotometryFacesPerPhoto = 64;
  std::uint32_t seed = 1;

  /// Throws OptionError naming the first invalid setting.
  void Check() const;
};

/// One face seen in one photo (the engine's "rectify" stage): the photo
/// rectified into the face frame on the patch grid at a photo density level,
/// in the sample's photo domain, with the face's lighting in that photo.
struct RectifiedView {
  std::size_t photo = 0;  ///< index into the engine's photos
  sfm::TriangleView view;
  int level = 0;                ///< photo density level of the grid (PhotoDensityLevel)
  std::vector<cv::Mat> planes;  ///< R, G, B (CV_32FC1), MaterialSample::Domain()
  /// CV_32FC1: 1 on the cells the score reads (within the score margin of the
  /// triangle, photo pixel inside the image), else 0.
  cv::Mat mask;
  /// The same within the photo correction's margin (empty unless it asks).
  cv::Mat wide_mask;
  int count = 0;  ///< cells of `mask`
  FaceLighting lighting;
  /// Every light, and the view for a view-dependent sample, above 60 degrees
  /// from the face's horizon (the photo gains trust only such views).
  bool steep = true;
  /// The photo's blur (TriangleSynthesis::photo_blur) in cells of this grid.
  double blur_cells = 0.0;
};

/// The sample relit under a view at the view's density over a window of the
/// reduced sample (the cells around a placed patch): R, G, B planes (CV_32FC1,
/// MaterialSample::Domain()) whose top-left cell is `origin` in the reduced sample.
struct RelitWindow {
  std::vector<cv::Mat> planes;
  cv::Point origin;
};

/// Memory for the relit samples the direct scores read, kept from one face's search
/// to the next: a fresh buffer per face and view costs a page fault per page it
/// touches (issue 33; docs/synth.md, "Relit buffers kept from face to face"). Grows
/// to the largest size asked until Release(). One search at a time may use it.
class RelitScratch {
 public:
  /// View `slot`'s three planes, `size` cells each: views into buffers that may
  /// hold an earlier search's values.
  std::array<cv::Mat, 3> Planes(std::size_t slot, cv::Size size);
  /// Frees the buffers (the next Planes() allocates again).
  void Release() { buffers_.clear(); }
  /// Columns the search's planes hold past the reduced sample's: the placements it
  /// scores side by side past the last one read there (synth/placement_search.h).
  static constexpr int kPastTheSample = 7;
  /// The most the buffers of a search over `views` views of a sample of `sample`
  /// texels can grow to: three float planes per view at the sample's full density.
  static double BytesAtMost(int views, cv::Size sample) {
    return 3.0 * sizeof(float) * views * static_cast<double>(sample.width + kPastTheSample) *
           sample.height;
  }

 private:
  std::vector<std::array<cv::Mat, 3>> buffers_;
};

/// What the engine produces: every face's placed patch in the sample (with
/// what the photo-consistency pass added to it), the unfoldings across its
/// edges, the photo gains, and the graph-cut labels for a sample that is cut.
struct TriangleSynthesis {
  double texel_size = 0.0;                           ///< world units
  std::vector<TrianglePatch> patches;                ///< per face
  std::vector<std::array<Unfolding, 3>> unfoldings;  ///< per face, edge k = (v_k, v_k+1)
  std::vector<double> photo_gains;  ///< per photo (linear-domain exposure x intensity)
  /// How the object answers light beyond the sample's model, as the photos
  /// showed it (TriangleEngineOptions::light_response; else the identity).
  ptm::LightResponse light_response;
  /// Per photo, its white balance against the others' (R, G, B linear factors,
  /// TriangleEngineOptions::white_balance; empty when not estimated).
  std::vector<std::array<double, 3>> white_balance;
  /// Per photo, the Gaussian blur it shows against the sample, sigma in cells
  /// of its own density level (about photo pixels; TriangleEngineOptions::
  /// photo_blur; empty when not estimated).
  std::vector<double> photo_blur;
  std::size_t num_from_photos = 0, num_from_neighbours = 0, num_random = 0;
  /// The frames the patches have (kAuto resolved to kPhotos or kFirstEdge).
  TangentFrame tangent_frame = TangentFrame::kFirstEdge;
  /// Coherence of the sample's structure tensor (0 isotropic, 1 one direction)
  /// at the photos' median density; -1 when not measured.
  double sample_coherence = -1.0;
  double seconds_synthesis = 0.0;  ///< set-up, placement and the photo pass
  /// A distributed run (TriangleEngine::DistributeOver) on a rank other than 0:
  /// its faces went to rank 0, which holds the result; this one holds only the
  /// set-up, the photometry and this rank's own faces.
  bool rank_share_only = false;
  /// A distributed run, at rank 0: what every rank did, by rank, the faces on
  /// region borders, the band rank 0 placed first (the borders and the faces
  /// next to them, BordersPlacedFirst) and the edges between regions.
  std::vector<RankRecord> rank_records;
  std::vector<int> region_of_face;  ///< the partition (mesh::FacePartition)
  std::size_t region_border_faces = 0, region_band_faces = 0, region_cut_edges = 0;
  /// Rank 0 of a distributed run: waiting for and reading the other ranks'
  /// faces; placing, sending and finishing the border faces.
  double seconds_gather = 0.0, seconds_region_borders = 0.0;
  /// The correction's pass after placement (detail transfer; a distributed
  /// run's rank 0: over its own and the border faces).
  double seconds_finish = 0.0;
  double seconds_prepare = 0.0;  ///< set-up, frames and photometry
  /// The patches' and atlases' memory this process was estimated to need
  /// (PatchMemoryBytes; a rank of a distributed run: of the faces it holds).
  double patch_memory_bytes = 0.0;
};

class TriangleEngine;
class PhotoBlurEstimator;

/// Divides a photo's R, G and B planes (in `domain`) by its white balance
/// (linear factors, TriangleSynthesis::white_balance).
void TakeOutWhiteBalance(const std::array<double, 3>& white_balance, PhotoDomain domain,
                         std::vector<cv::Mat>& planes);

/// The engine's "correct" and "transfer detail" stages for one kind of sample:
/// after a face seen in photos is placed, its patch is made to agree with the
/// photos (PTM: the most probable change of the luminance coefficients; BTF:
/// per-channel factors), then, once every face is placed, whatever needs all
/// of them (PTM: detail transfer).
class PhotoCorrection {
 public:
  virtual ~PhotoCorrection() = default;
  /// Margin (world units) of the wide mask the pass reads; < 0: none.
  virtual double WideMaskMargin() const { return -1.0; }
  /// Cells of the relit sample the pass reads around a placed patch's grid under
  /// `view`; < 0: it reads none.
  virtual int RelitMarginCells(const RectifiedView& /*view*/) const { return -1; }
  /// Corrects face `face`'s placed patch. `views` are the score's (best view
  /// first), `relit[r]` the sample relit under view r at its density with its
  /// photo's gain (what the score compared with the photo) around the placed
  /// patch (empty unless RelitMarginCells asks).
  virtual void Correct(TriangleEngine& engine, std::size_t face, std::vector<RectifiedView>& views,
                       const std::vector<RelitWindow>& relit) = 0;
  /// Once every face is placed, the pass over `faces` (PTM: detail transfer),
  /// each face's depending on its own patch alone (a distributed run's ranks
  /// finish their own faces).
  virtual void Finish(TriangleEngine& /*engine*/, const std::vector<std::size_t>& /*faces*/,
                      const ProgressCallback& /*progress*/) {}
  /// A distributed run: what Correct kept for face `face` (beyond its patch),
  /// written by the rank that corrected it and read at rank 0 in the same order.
  virtual void SaveFace(std::size_t /*face*/, ByteWriter& /*out*/) const {}
  virtual void LoadFace(TriangleEngine& /*engine*/, std::size_t /*face*/, ByteReader& /*in*/) {}
  /// Sums over this rank's faces (statistics), added to rank 0's.
  virtual void SaveSums(ByteWriter& /*out*/) const {}
  virtual void AddSums(ByteReader& /*in*/) {}
};

/// Paper 003 Algorithm 2 for any MaterialSample: each face's frame and patch
/// rectangle, frames turned to the photos, photo gains, then breadth first
/// from the best-seen face: rectify every photo that sees the face fully,
/// score every placement of the patch in the sample by eq. 3 summed over the
/// photos (FFT), keep of the top_k the one closest to the synthesised
/// neighbours in feature space (place), and correct it with the photos; faces
/// seen in no photo take the overlap constraint alone, or a random placement.
/// Stitching (blending or graph-cut seams) follows from the sample's kind.
class TriangleEngine {
 public:
  /// All references must outlive the engine. `correction` may be null (no pass).
  TriangleEngine(const mesh::TriangleMesh& mesh, const sfm::Reconstruction& reconstruction,
                 const sfm::VisibilityResult& visibility, const std::vector<MeshPhoto>& photos,
                 const MaterialSample& sample, const TriangleEngineOptions& options,
                 PhotoCorrection* correction);

  /// Makes Run distributed over `regions.ranks` (synth/face_regions.h): rank 0
  /// places the band along the region borders (BordersPlacedFirst) and sends it to
  /// every rank, each rank grows its region's faces off the band from it, rank 0
  /// gathers them and finishes (the band's detail transfer). Set-up and frames run on every rank;
  /// the photometry on rank 0, which sends it to the others. Call on every rank
  /// with the same partition.
  void DistributeOver(FaceRegions regions);

  /// Runs every stage. Throws OptionError for bad options and InputError when
  /// the patches would not fit the sample or would exceed max_texels.
  TriangleSynthesis Run(const ProgressCallback& progress = {});

  /// The stages before placement alone (set-up, frames turned to the photos,
  /// photometry), for an engine that places the sample itself (the graph-cut
  /// engine's image term, quilt/image_term.h): the result's patches hold the
  /// frames (placements unset), with the photo gains, white balance, light
  /// response and photo blur. Patches larger than the sample are not refused.
  const TriangleSynthesis& Prepare(const ProgressCallback& progress = {});

  /// Rectifies a photo that sees face `face` on the patch grid at density
  /// `level` (< 0: the photo's own). False when the photo is not among the
  /// engine's, the grid exceeds the reduced sample, or fewer than
  /// min_photo_pixels cells are seen.
  bool Rectify(std::size_t face, const sfm::TriangleView& view, RectifiedView& out, int level = -1,
               bool wide_mask = false) const;

  const MaterialSample& sample() const { return sample_; }
  const TriangleEngineOptions& options() const { return options_; }
  TriangleSynthesis& result() { return result_; }
  const TriangleSynthesis& result() const { return result_; }

 private:
  // Stages 1 to 2a; `patches_in_sample`: refuse patches larger than the sample.
  void PrepareStages(bool patches_in_sample, const ProgressCallback& progress);
  // Stage 1: frames, patch rectangles and unfoldings; refused when too large.
  void SetUpPatches(PatchGeometry geometry);
  // Stage 1b: frames turned to the photos (synth/tangent_field.h).
  void TurnFramesToPhotos();
  // The luminance structure tensor of the photos that see face `face` fully.
  Eigen::Matrix2d PhotoStructureTensor(std::size_t face) const;
  // One view of a face the photometry may observe: rectified (else nothing else is
  // set), steep, and its observation (when steep or asked for).
  struct PhotometryCandidate {
    bool rectified = false, steep = false;
    PhotometricObservation observation;
  };
  // Rectifies and observes one view; adds it to `blur` (may be null) when the
  // estimator wants a steep view of the photo and the face is one it spreads over.
  PhotometryCandidate ObserveForPhotometry(std::size_t face, const sfm::TriangleView& view,
                                           double zenith_per_cell, bool observe_if_not_steep,
                                           PhotoBlurEstimator* blur) const;
  // The faces the photometry observes (1), per face (TriangleEngineOptions::
  // photometry_faces).
  std::vector<char> PhotometryFaces() const;
  // Every fully visible view of every observed face, photo by photo; [face][rank
  // among the face's views].
  std::vector<std::vector<PhotometryCandidate>> ObservePhotoByPhoto(
      const std::vector<char>& observed_faces, double zenith_per_cell, PhotoBlurEstimator* blur,
      const ProgressCallback& progress) const;
  // Stage 2a: a gain per photo (exposure x light intensity, linear domain) and
  // the object's light response (synth/photometry.h).
  void EstimatePhotometry(const ProgressCallback& progress);
  // `zenith_per_cell` >= 0: the sample's mean under a unit zenith light (a
  // view-independent sample's, computed once); < 0: computed for the view.
  // The rotations from face `face`'s frame into the frames the renderer shades in at
  // kShadingPoints points of the face: the frame turned by the smallest rotation onto
  // the smooth normal there (mesh::SmoothNormalAt, render/model_render.h).
  static constexpr int kShadingPoints = 3;
  using ShadingTurnSet = std::array<Eigen::Quaterniond, kShadingPoints>;
  ShadingTurnSet ShadingTurns(std::size_t face) const;
  // `turns`: the face's ShadingTurns.
  PhotometricObservation Observe(std::size_t face, const RectifiedView& rect,
                                 double zenith_per_cell, const ShadingTurnSet& turns) const;
  // The sample relit under a rectified view's lighting, as luminance, over a
  // window of the view's grid size (the photo blur's comparison).
  cv::Mat SampleWindowLuminance(std::size_t face, const RectifiedView& rect) const;
  // The photometry: estimated (at rank 0 of a distributed run), sent to the other ranks.
  void EstimateOrReceivePhotometry(const ProgressCallback& progress);
  // Stage 2b: `faces` in their order, each placed and corrected (SynthesizeFace);
  // progress counts from `done_before` of `total`.
  // The faces ahead are searched on every thread (SearchFace, which reads no
  // placed face) while this thread places them in their order (core/ordered_pipeline.h).
  void PlaceFaces(const std::vector<int>& faces, std::uint32_t seed, std::size_t done_before,
                  std::size_t total, const ProgressCallback& progress);
  // How many faces' photos (each face's up to max_views) the photo cache holds at
  // once (SIZE_MAX when it holds every photo): the most faces PlaceFaces searches
  // together, so that they do not take turns decoding their photos.
  std::size_t FacesPhotosHold() const;
  // How many faces PlaceFaces searches at once: FacesPhotosHold's, at most
  // kFacesSearchedAheadPerThread a thread, with more than one thread; else 1.
  std::size_t FacesSearchedTogether() const;
  // The sets of relit buffers the searches keep (RelitScratch): one per thread
  // when faces are searched ahead, else one; and the most they can grow to.
  std::size_t RelitBufferSets() const;
  double RelitBytesAtMost() const;
  // A face's rectified views and its top_k placements by eq. 3 alone (the image
  // constraint, paper 003), which no other face's placement changes.
  struct FaceSearch {
    std::vector<RectifiedView> views;
    std::vector<std::pair<float, cv::Point>> candidates;  // ScoredPlacement, best first
  };
  FaceSearch SearchFace(std::size_t face, RelitScratch& scratch) const;
  // Places (of `found`'s candidates, the one closest to the placed neighbours)
  // and corrects a face, or places it by its neighbours when no photo sees it.
  void SynthesizeFace(std::size_t face, FaceSearch found, std::mt19937_64& rng);
  // The correction's pass after placement (PhotoCorrection::Finish) over `faces`.
  void FinishFaces(const std::vector<std::size_t>& faces, const ProgressCallback& progress);
  // Stage 2b distributed: the border faces and those next to them (placed_first_,
  // "the border faces" below) placed at rank 0 and sent to every rank, then this
  // rank's region off them placed from them and finished, gathered at rank 0, which
  // finishes the border faces; the other ranks' results are their share
  // (rank_share_only). `neighbours`: mesh::FaceNeighbours.
  void PlaceRegions(const std::vector<int>& order,
                    const std::vector<std::array<int, 3>>& neighbours,
                    const ProgressCallback& progress);
  // The border faces, in their order, placed at rank 0 and read by the others.
  void PlaceBorders(const std::vector<int>& border_faces, const ProgressCallback& progress);
  // This rank's faces off the border in the order it places them: breadth first
  // from those next to a border face at once (a front moving away from the
  // placed borders, `border_faces` in their order), or the photo-by-photo
  // `order` when the photos do not all fit.
  std::vector<int> RegionOrder(const std::vector<int>& order, const std::vector<int>& border_faces,
                               const std::vector<char>& interior,
                               const std::vector<std::array<int, 3>>& neighbours) const;
  // Throws InputError on a rank whose faces, photos, `patches` (their rectangles)
  // or regions differ from rank 0's (every rank reads its own inputs).
  void RequireSameInputsAsRankZero(const std::vector<TrianglePatch>& patches) const;
  // The patches' memory (PatchMemoryBytes) of the faces this rank holds: under the
  // default limit, against the memory the ranks on its machine share (rank 0, which
  // holds every face, may then use what the others do not need); under the user's
  // --memory-limit, against each rank's own. Every rank refuses with the same message.
  void RequirePatchMemoryOnEveryMachine(const PatchGeometry& geometry, const std::string& what);
  // Placed faces (patches, the correction's state), and their reading: each
  // face read must be `expected` and not placed yet (else `what` is broken).
  void WriteFaces(const std::vector<int>& faces, ByteWriter& out) const;
  void ReadFaces(ByteReader& in, const std::function<bool(std::size_t)>& expected,
                 const char* what);
  // A rank's placed faces and record, and their reading at rank 0.
  void WriteRegion(const std::vector<int>& faces, const RankRecord& record, ByteWriter& out) const;
  void ReadRegion(const std::vector<char>& message);
  // The placed-by counts from the patches' sources (after a distributed run).
  void CountSources();
  // The views that constrain a face, rectified.
  std::vector<RectifiedView> RectifiedViews(std::size_t face, bool wide_mask) const;

  // The synthesised neighbours' features unfolded into a face's frame, on the
  // patch texels within W_e of a shared edge.
  OverlapTexels CollectOverlapTargets(std::size_t face) const;
  // Of the candidates (eq. 3 summed over the views, top_k), the one closest to the
  // neighbours. `relit`: around the placed patch, when the correction reads it.
  void PlaceAmongCandidates(TrianglePatch& patch, const FaceSearch& found,
                            const OverlapTexels& overlap, std::vector<RelitWindow>& relit);
  // Unseen faces: the overlap constraint over every placement (OverlapPlacement).
  void PlaceByNeighbours(TrianglePatch& patch, const OverlapTexels& overlap, std::mt19937_64& rng);

  const mesh::TriangleMesh& mesh_;
  const sfm::Reconstruction& reconstruction_;
  const sfm::VisibilityResult& visibility_;
  const std::vector<MeshPhoto>& photos_;
  const MaterialSample& sample_;
  const TriangleEngineOptions& options_;
  PhotoCorrection* correction_;
  std::map<sfm::ImageId, std::size_t> photo_index_;
  std::vector<char> done_;
  std::vector<Eigen::Vector3d> vertex_normals_;      // mesh::VertexNormals, for ShadingTurns
  std::vector<std::array<int, 3>> face_neighbours_;  // mesh::FaceNeighbours, once
  /// Cells the score reads beyond the triangle (world units): W_e / 2 for a
  /// blended sample (its blending zone, so that a blend mixes two
  /// photo-corrected patches), none for a sample that is cut.
  double score_margin_ = 0.0;
  bool patches_in_sample_ = true;
  /// The faces in the order the passes over the photos visit them (FacesByPhoto).
  std::vector<std::size_t> photo_visit_order_;
  std::optional<FaceRegions> regions_;  // a distributed run (DistributeOver)
  std::vector<char> placed_first_;      // its BordersPlacedFirst
  // The placement of the faces no photo sees (their sample's spectra made once).
  std::optional<OverlapPlacement> overlap_placement_;
  // The placement search's relit buffers, one per thread searching
  // (RunAheadWorkers), lent to each face's search in turn.
  std::vector<RelitScratch> relit_scratch_;
  TriangleSynthesis result_;
};

}  // namespace texlume::synth
