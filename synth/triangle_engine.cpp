#include "synth/triangle_engine.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>

#include "core/check.h"
#include "core/errors.h"
#include "core/image_io.h"
#include "core/memory_budget.h"
#include "core/ordered_pipeline.h"
#include "core/srgb_rows.h"
#include "core/timing.h"
#include "synth/face_order.h"
#include "synth/photo_blur.h"
#include "synth/placement_search.h"
#include "synth/tangent_field.h"
#include "synth/template_match.h"

namespace texlume::synth {
namespace {

// Faces searched ahead of their placement, per thread (PlaceFaces): enough that a
// thread rarely waits for the face to be placed next, few enough that their
// rectified views stay small.
constexpr std::size_t kFacesSearchedAheadPerThread = 4;

// The mean of a view's R, G and B planes.
cv::Mat PhotoLuminance(const RectifiedView& r) {
  return (r.planes[0] + r.planes[1] + r.planes[2]) / 3.0;
}

// One face in four, spread over the mesh whatever its face order, for the
// photo blur (PhotoBlurEstimator takes the first kFacesPerPhoto per photo).
bool SpreadForBlur(std::size_t face) { return ((face * 0x9E3779B97F4A7C15ull) >> 61) < 2; }

// The photo's sums over a view's masked cells of R, G and B, in the linear domain.
std::array<double, 3> PhotoLinearSums(const RectifiedView& r, PhotoDomain domain) {
  std::array<double, 3> sums{0.0, 0.0, 0.0};
  for (std::size_t c = 0; c < 3; ++c) {
    const cv::Mat& plane = r.planes[c];
    if (domain == PhotoDomain::kLinear) {
      sums[c] = cv::sum(plane.mul(r.mask))[0];
      continue;
    }
    for (int j = 0; j < r.mask.rows; ++j)
      for (int i = 0; i < r.mask.cols; ++i)
        if (r.mask.at<float>(j, i) > 0) sums[c] += SrgbToLinear(plane.at<float>(j, i));
  }
  return sums;
}

}  // namespace

void TakeOutWhiteBalance(const std::array<double, 3>& white_balance, PhotoDomain domain,
                         std::vector<cv::Mat>& planes) {
  for (std::size_t c = 0; c < 3; ++c) {
    const double w = white_balance[c];
    if (w == 1.0) continue;
    cv::Mat& plane = planes[c];
    if (domain == PhotoDomain::kLinear) {
      plane /= w;
      continue;
    }
    // Display to linear, divided by w (in doubles), back to display: the row
    // kernels give ToLinear's and FromLinear's values to the bit.
    std::vector<float> linear(static_cast<std::size_t>(plane.cols));
    for (int j = 0; j < plane.rows; ++j) {
      float* row = plane.ptr<float>(j);
      std::fill(linear.begin(), linear.end(), 0.0f);
      srgb::AddWeightedLinear(row, 1.0f, plane.cols, linear.data());
      for (float& v : linear) v = static_cast<float>(v / w);
      srgb::ScaledFromLinear(linear.data(), 1.0f, plane.cols, row);
    }
  }
}

void TriangleEngineOptions::Check() const {
  if (!(sample_texel_size > 0.0) || !std::isfinite(sample_texel_size))
    throw OptionError("sample texel size must be a positive number of world units");
  if (strip < 2 || strip > 32) throw OptionError("strip (W_e) must be in [2, 32] texels");
  if (top_k < 1) throw OptionError("top_k must be >= 1");
  if (search_candidates < 1) throw OptionError("search candidates must be >= 1");
  if (max_views < 1) throw OptionError("max_views must be >= 1");
  if (!(tolerance >= 0.0)) throw OptionError("tolerance must be >= 0");
  if (min_photo_pixels < 1) throw OptionError("min_photo_pixels must be >= 1");
  if (photometry_faces < kPhotometryFacesPerPhoto)
    throw OptionError("photometry_faces must be >= " + std::to_string(kPhotometryFacesPerPhoto));
  if (max_texels < 1) throw OptionError("max_texels must be >= 1");
  if (!(field_direction_in_world.norm() > 0.0))
    throw OptionError("field direction must be nonzero");
}

const char* PlacementSearchName(PlacementSearchKind kind) {
  return kind == PlacementSearchKind::kExhaustive ? "exhaustive" : "coarse-to-fine";
}

TriangleEngine::TriangleEngine(const mesh::TriangleMesh& mesh,
                               const sfm::Reconstruction& reconstruction,
                               const sfm::VisibilityResult& visibility,
                               const std::vector<MeshPhoto>& photos, const MaterialSample& sample,
                               const TriangleEngineOptions& options, PhotoCorrection* correction)
    : mesh_(mesh),
      reconstruction_(reconstruction),
      visibility_(visibility),
      photos_(photos),
      sample_(sample),
      options_(options),
      correction_(correction) {
  for (std::size_t n = 0; n < photos.size(); ++n) photo_index_[photos[n].image_id] = n;
  vertex_normals_ = mesh::VertexNormals(mesh);
  face_neighbours_ = mesh::FaceNeighbours(mesh);
}

TriangleSynthesis TriangleEngine::Run(const ProgressCallback& progress) {
  const auto start = std::chrono::steady_clock::now();
  const std::size_t num_faces = mesh_.faces.size();
  PrepareStages(true, progress);
  result_.seconds_prepare = SecondsSince(start);

  // Breadth first from the best-seen face (Algorithm 2, step 2); photo by photo
  // when the photos do not all fit in memory (synth/face_order.h).
  const std::vector<std::array<int, 3>>& neighbours = face_neighbours_;
  const std::vector<int> order =
      PhotosHeldTogether(photos_)
          ? mesh::BreadthFirstFaceOrder(mesh_, neighbours, BestSeenFace(visibility_))
          : PhotoByPhotoBreadthFirstOrder(neighbours, KeyPhotoOfFaces(visibility_, photos_),
                                          BestSeenFace(visibility_));
  done_.assign(num_faces, 0);
  if (!regions_) {
    PlaceFaces(order, options_.seed, 0, num_faces, progress);
    std::vector<std::size_t> every_face(num_faces);
    std::iota(every_face.begin(), every_face.end(), std::size_t{0});
    FinishFaces(every_face, progress);
  } else {
    PlaceRegions(order, neighbours,
                 progress);  // rank 0 finishes; the others' result is their share
  }
  result_.seconds_synthesis = SecondsSince(start);
  return std::move(result_);
}

void TriangleEngine::FinishFaces(const std::vector<std::size_t>& faces,
                                 const ProgressCallback& progress) {
  const auto start = std::chrono::steady_clock::now();
  relit_scratch_.clear();  // the placements are done: their memory goes to the finish
  if (correction_) correction_->Finish(*this, faces, progress);
  result_.seconds_finish += SecondsSince(start);
}

void TriangleEngine::PlaceFaces(const std::vector<int>& faces, std::uint32_t seed,
                                std::size_t done_before, std::size_t total,
                                const ProgressCallback& progress) {
  std::mt19937_64 rng(seed);
  std::size_t processed = done_before;
  const std::size_t workers = RunAheadWorkers();
  const std::size_t window = FacesSearchedTogether();
  const bool search_ahead = window > 1;
  relit_scratch_.resize(std::max(relit_scratch_.size(), workers));
  std::vector<FaceSearch> found(window);  // slot n % window: face faces[n]'s search
  const auto search = [&](std::size_t n, std::size_t worker) {
    found[n % window] = SearchFace(static_cast<std::size_t>(faces[n]), relit_scratch_[worker]);
  };
  const auto place = [&](std::size_t n) {
    const auto face = static_cast<std::size_t>(faces[n]);
    SynthesizeFace(face, std::move(found[n % window]), rng);
    done_[face] = 1;
    ++processed;
    if (progress && (processed % 64 == 0 || processed == total))
      progress("synthesis", processed, total);
  };
  if (search_ahead) {
    RunAhead(faces.size(), window, search, place);
  } else {  // each face's views scored on every thread instead (PlacementSearch)
    for (std::size_t n = 0; n < faces.size(); ++n) {
      search(n, 0);
      place(n);
    }
  }
}

std::size_t TriangleEngine::FacesSearchedTogether() const {
  // As many faces in flight as the photo cache holds the photos of (a face's
  // search takes its turn decoding them otherwise).
  const std::size_t workers = RunAheadWorkers();
  const std::size_t ahead = std::min(kFacesSearchedAheadPerThread * workers, FacesPhotosHold());
  return workers > 1 && ahead >= 2 ? ahead : 1;
}

std::size_t TriangleEngine::RelitBufferSets() const {
  // One set per thread searching faces ahead, else the one the face being placed
  // lends its search.
  return FacesSearchedTogether() > 1 ? RunAheadWorkers() : 1;
}

double TriangleEngine::RelitBytesAtMost() const {
  return static_cast<double>(RelitBufferSets()) *
         RelitScratch::BytesAtMost(options_.max_views, cv::Size(sample_.Width(), sample_.Height()));
}

std::size_t TriangleEngine::FacesPhotosHold() const {
  std::size_t faces = std::numeric_limits<std::size_t>::max();
  if (PhotosHeldTogether(photos_)) return faces;
  // Each face in flight holds up to max_views photos while it is rectified.
  const PhotoCache* checked = nullptr;
  for (const MeshPhoto& photo : photos_) {
    const PhotoCache* cache = photo.pixels.cache().get();
    if (!cache || cache == checked || cache->NumPhotos() == 0) continue;
    checked = cache;
    const double mean_photo_bytes =
        static_cast<double>(cache->TotalBytes()) / static_cast<double>(cache->NumPhotos());
    faces = std::min(faces, static_cast<std::size_t>(static_cast<double>(cache->budget_bytes()) /
                                                     (options_.max_views * mean_photo_bytes)));
  }
  return faces;
}

const TriangleSynthesis& TriangleEngine::Prepare(const ProgressCallback& progress) {
  const auto start = std::chrono::steady_clock::now();
  PrepareStages(false, progress);
  result_.seconds_synthesis = SecondsSince(start);
  return result_;
}

void TriangleEngine::PrepareStages(bool patches_in_sample, const ProgressCallback& progress) {
  options_.Check();
  TEXLUME_CHECK(visibility_.triangles.size() == mesh_.faces.size(),
                "visibility is computed for the engine's mesh");
  const double t = options_.sample_texel_size;
  result_.texel_size = t;
  patches_in_sample_ = patches_in_sample;
  score_margin_ = sample_.Blendable() ? 0.5 * options_.strip * t : 0.0;
  photo_visit_order_ =
      FacesByPhoto(KeyPhotoOfFaces(visibility_, photos_), PhotosHeldTogether(photos_));
  SetUpPatches(MakePatchGeometry(mesh_, t, options_.strip, options_.tangent_frame,
                                 options_.field_direction_in_world));
  TurnFramesToPhotos();
  EstimateOrReceivePhotometry(progress);
}

void TriangleEngine::SetUpPatches(PatchGeometry geometry) {
  const double t = options_.sample_texel_size;
  if (geometry.total_texels > options_.max_texels) {
    const std::int64_t mib =
        geometry.total_texels * 4 * static_cast<std::int64_t>(sample_.NumFeatures()) >> 20;
    throw InputError("mesh", "at a texel size of " + std::to_string(t) + " world units the " +
                                 std::to_string(mesh_.faces.size()) + " patches need " +
                                 std::to_string(geometry.total_texels) + " texels (about " +
                                 std::to_string(mib) +
                                 " MiB of features), more than the limit of " +
                                 std::to_string(options_.max_texels) +
                                 "; use a larger texel size or a finer mesh");
  }
  // The patches' feature planes, the atlases baked from them and the bake's own
  // buffers, and the relit buffers each searching thread keeps (docs/robustness.md
  // "Memory").
  const std::size_t threads = RelitBufferSets();
  const std::string what =
      "the patches and atlases of " + std::to_string(geometry.total_texels) +
      " texels at a texel size of " + std::to_string(t) +
      " world units (a larger --sample-texel-size needs fewer), and the relit sample buffers " +
      (threads > 1 ? "of " + std::to_string(threads) + " threads searching faces (OMP_NUM_THREADS)"
                   : std::string("of the search"));
  if (regions_) {
    RequireSameInputsAsRankZero(geometry.patches);  // before anything a rank reads from rank 0
    RequirePatchMemoryOnEveryMachine(geometry, what);
  } else {
    result_.patch_memory_bytes =
        PatchMemoryBytes(geometry, sample_.NumFeatures()) + RelitBytesAtMost();
    RequireMemory(result_.patch_memory_bytes, what, "mesh");
  }
  if (patches_in_sample_ &&
      (geometry.widest > sample_.Width() || geometry.tallest > sample_.Height())) {
    throw InputError(
        "mesh", "the largest triangle needs a patch of " + std::to_string(geometry.widest) + " x " +
                    std::to_string(geometry.tallest) + " texels (strip included) but the " +
                    sample_.Name() + " sample is " + std::to_string(sample_.Width()) + " x " +
                    std::to_string(sample_.Height()) +
                    "; subdivide the mesh (texlume synth --max-subdivisions) or "
                    "capture a larger sample");
  }
  result_.patches = std::move(geometry.patches);
  result_.unfoldings = std::move(geometry.unfoldings);
}

bool TriangleEngine::Rectify(std::size_t face, const sfm::TriangleView& view, RectifiedView& out,
                             int level, bool wide_mask) const {
  const auto it = photo_index_.find(view.image_id);
  if (it == photo_index_.end()) return false;
  const double t = options_.sample_texel_size;
  const MeshPhoto& photo = photos_[it->second];
  const sfm::Image& image = reconstruction_.images.at(view.image_id);
  const sfm::Camera& camera = reconstruction_.cameras.at(image.camera_id);
  const TrianglePatch& patch = result_.patches[face];
  const int own_level = PhotoDensityLevel(patch, view, t);
  if (level < 0) level = own_level;
  const ReducedPlanes& r = sample_.Reduced(level);
  const int tw = std::max(1, static_cast<int>(std::lround(patch.width * r.rx)));
  const int th = std::max(1, static_cast<int>(std::lround(patch.height * r.ry)));
  if (tw > r.planes[0].cols || th > r.planes[0].rows) return false;
  cv::Mat map_x, map_y;
  out.count =
      RectificationMaps(patch, t, r.rx, r.ry, cv::Size(tw, th), camera, image.cam_from_world,
                        photo.pixels.size(), score_margin_, map_x, map_y, out.mask);
  if (out.count < options_.min_photo_pixels) return false;
  if (wide_mask && correction_ && correction_->WideMaskMargin() >= 0.0) {
    cv::Mat wide_x, wide_y;
    RectificationMaps(patch, t, r.rx, r.ry, cv::Size(tw, th), camera, image.cam_from_world,
                      photo.pixels.size(), correction_->WideMaskMargin(), wide_x, wide_y,
                      out.wide_mask);
  }
  cv::Mat rectified;
  RemapPhotoRegion(photo.pixels, map_x, map_y, rectified);
  cv::split(rectified, out.planes);
  if (sample_.Domain() == PhotoDomain::kLinear)
    for (cv::Mat& plane : out.planes)
      for (int j = 0; j < th; ++j)
        for (int i = 0; i < tw; ++i) plane.at<float>(j, i) = SrgbToLinear(plane.at<float>(j, i));
  if (!result_.white_balance.empty())
    TakeOutWhiteBalance(result_.white_balance[it->second], sample_.Domain(), out.planes);
  out.lighting =
      LightingInFrame(patch.frame, image.ProjectionCenter(), photo.lights, result_.light_response);
  out.steep = !sample_.ViewDependent() || out.lighting.view_in_frame.z() > 0.5;
  for (const auto& [l, intensity] : out.lighting.lights) out.steep = out.steep && l.z() > 0.5;
  out.photo = it->second;
  out.view = view;
  out.level = level;
  if (!result_.photo_blur.empty())
    out.blur_cells = BlurOnGrid(result_.photo_blur[it->second], own_level, level);
  return true;
}

std::vector<RectifiedView> TriangleEngine::RectifiedViews(std::size_t face, bool wide_mask) const {
  std::vector<RectifiedView> views;
  for (const sfm::TriangleView& view :
       ConstrainingViews(visibility_.triangles[face], options_.all_views, options_.max_views)) {
    RectifiedView r;
    if (Rectify(face, view, r, -1, wide_mask)) views.push_back(std::move(r));
  }
  return views;
}

void TriangleEngine::TurnFramesToPhotos() {
  // Beyond the paper (synth/tangent_field.h): the sample's structure tensor at
  // the photos' median density against each face's photos' tensor in its
  // first-edge frame; kAuto turns only for an anisotropic sample. The sample
  // is relit seen from above.
  result_.tangent_frame = options_.tangent_frame;
  if (options_.tangent_frame != TangentFrame::kPhotos &&
      options_.tangent_frame != TangentFrame::kAuto)
    return;
  const double t = options_.sample_texel_size;
  const std::size_t num_faces = mesh_.faces.size();
  std::vector<int> face_levels(num_faces, -1);
  for (std::size_t f = 0; f < num_faces; ++f) {
    const std::vector<sfm::TriangleView> views =
        ConstrainingViews(visibility_.triangles[f], options_.all_views, options_.max_views);
    if (!views.empty()) face_levels[f] = PhotoDensityLevel(result_.patches[f], views[0], t);
  }
  const auto sample_tensor_at = [&](int level) {
    const ReducedPlanes& red = sample_.Reduced(level);
    return SampleStructureTensor(
        [&](const Eigen::Vector3d& l) {
          return sample_.Relight(red, FaceLighting{Eigen::Vector3d::UnitZ(), {{l, 1.0}}, {}}, 1.0);
        },
        red.rx, red.ry);
  };
  // Every seen face's tensor, at the first ask, in the photos' visit order.
  std::vector<Eigen::Matrix2d> photo_tensors;
  const auto photo_tensor = [&](std::size_t face) {
    if (photo_tensors.empty()) {
      photo_tensors.assign(num_faces, Eigen::Matrix2d::Zero());
      for (const std::size_t f : photo_visit_order_)
        if (face_levels[f] >= 0) photo_tensors[f] = PhotoStructureTensor(f);
    }
    return photo_tensors[face];
  };
  const FrameChoice choice =
      ChoosePhotoFrames(options_.tangent_frame, result_.patches, result_.unfoldings, face_levels,
                        sample_tensor_at, photo_tensor);
  result_.tangent_frame = choice.tangent_frame;
  result_.sample_coherence = choice.sample_coherence;
  if (choice.tangent_frame == TangentFrame::kPhotos)
    SetUpPatches(MakePatchGeometry(mesh_, t, options_.strip, choice.field.tangents_in_world));
}

Eigen::Matrix2d TriangleEngine::PhotoStructureTensor(std::size_t face) const {
  Eigen::Matrix2d tensor = Eigen::Matrix2d::Zero();
  for (const RectifiedView& rect : RectifiedViews(face, false)) {
    const ReducedPlanes& r = sample_.Reduced(rect.level);
    tensor += LuminanceStructureTensor(rect.planes, rect.mask, r.rx, r.ry);
  }
  return tensor;
}

TriangleEngine::PhotometryCandidate TriangleEngine::ObserveForPhotometry(
    std::size_t face, const sfm::TriangleView& view, double zenith_per_cell,
    bool observe_if_not_steep, PhotoBlurEstimator* blur) const {
  PhotometryCandidate c;
  RectifiedView rect;
  if (!Rectify(face, view, rect)) return c;
  c.rectified = true;
  c.steep = rect.steep;
  if (blur && rect.steep && blur->Wants(rect.photo) && SpreadForBlur(face))
    blur->Add(rect.photo, PhotoLuminance(rect), SampleWindowLuminance(face, rect), rect.mask);
  if (rect.steep || observe_if_not_steep)
    c.observation = Observe(face, rect, zenith_per_cell, ShadingTurns(face));
  return c;
}

std::vector<char> TriangleEngine::PhotometryFaces() const {
  // Within the limit every face is observed: no per-face photo lists needed.
  if (mesh_.faces.size() <= static_cast<std::size_t>(options_.photometry_faces))
    return std::vector<char>(mesh_.faces.size(), 1);
  std::vector<std::vector<std::uint32_t>> photos_of_face(mesh_.faces.size());
  for (std::size_t f = 0; f < mesh_.faces.size(); ++f)
    for (const sfm::TriangleView& view : visibility_.triangles[f].views) {
      const auto it = photo_index_.find(view.image_id);
      if (view.fully_visible && it != photo_index_.end())
        photos_of_face[f].push_back(static_cast<std::uint32_t>(it->second));
    }
  return synth::PhotometryFaces(photos_of_face, photos_.size(),
                                static_cast<std::size_t>(options_.photometry_faces),
                                TriangleEngineOptions::kPhotometryFacesPerPhoto);
}

std::vector<std::vector<TriangleEngine::PhotometryCandidate>> TriangleEngine::ObservePhotoByPhoto(
    const std::vector<char>& observed_faces, double zenith_per_cell, PhotoBlurEstimator* blur,
    const ProgressCallback& progress) const {
  // Each photo's fully visible faces, as (face, rank among the face's views).
  std::vector<std::vector<std::pair<std::size_t, std::size_t>>> faces_of_photo(photos_.size());
  std::vector<std::vector<PhotometryCandidate>> candidates(mesh_.faces.size());
  for (std::size_t f = 0; f < mesh_.faces.size(); ++f) {
    if (!observed_faces[f]) continue;
    const std::vector<sfm::TriangleView>& views = visibility_.triangles[f].views;
    candidates[f].resize(views.size());
    for (std::size_t rank = 0; rank < views.size(); ++rank) {
      const auto it = photo_index_.find(views[rank].image_id);
      if (views[rank].fully_visible && it != photo_index_.end())
        faces_of_photo[it->second].emplace_back(f, rank);
    }
  }
  for (std::size_t p = 0; p < photos_.size(); ++p) {
    if (progress) progress("photometry", p, photos_.size());
    for (const auto& [f, rank] : faces_of_photo[p])
      candidates[f][rank] = ObserveForPhotometry(f, visibility_.triangles[f].views[rank],
                                                 zenith_per_cell, options_.light_response, blur);
  }
  return candidates;
}

void TriangleEngine::EstimatePhotometry(const ProgressCallback& progress) {
  // Every observed face (PhotometryFaces: all up to photometry_faces) fully
  // visible in a photo (up to 8 steep views, whose lighting the
  // gains trust, and 8 others): the photo's linear sum over the face, and the
  // sample's mean relit under each light alone and at the zenith (synth/photometry.h).
  // When the photos do not all fit in memory, every view is observed first photo by
  // photo (each photo decoded once), then chosen face by face as below.
  std::vector<PhotometricObservation> observations;
  const std::size_t num_faces = mesh_.faces.size();
  std::optional<PhotoBlurEstimator> blur;
  if (options_.photo_blur) blur.emplace(photos_.size());
  // A view-independent sample's mean under a unit zenith light, once.
  const double zenith_per_cell =
      sample_.ViewDependent()
          ? -1.0
          : sample_.RelitLinearSum(
                FaceLighting{Eigen::Vector3d::UnitZ(), {{Eigen::Vector3d::UnitZ(), 1.0}}, {}}, 1);
  PhotoBlurEstimator* blur_estimator = blur ? &*blur : nullptr;
  const std::vector<char> observed_faces = PhotometryFaces();
  std::vector<std::vector<PhotometryCandidate>> observed;
  if (!PhotosHeldTogether(photos_))
    observed = ObservePhotoByPhoto(observed_faces, zenith_per_cell, blur_estimator, progress);
  for (std::size_t f = 0; f < num_faces; ++f) {
    if (progress && observed.empty() && f % 256 == 0) progress("photometry", f, num_faces);
    if (!observed_faces[f]) continue;
    const std::vector<sfm::TriangleView>& views = visibility_.triangles[f].views;
    int steep = 0, other = 0;
    for (std::size_t rank = 0; rank < views.size(); ++rank) {
      if (!views[rank].fully_visible || steep >= 8) continue;
      PhotometryCandidate computed;
      const PhotometryCandidate& c =
          observed.empty() ? (computed = ObserveForPhotometry(f, views[rank], zenith_per_cell,
                                                              other < 8 && options_.light_response,
                                                              blur_estimator))
                           : observed[f][rank];
      if (!c.rectified) continue;
      if (!c.steep && (other >= 8 || !options_.light_response)) continue;
      const PhotometricObservation& o = c.observation;
      // A steep view counts towards the 8 only when it is lit enough for the
      // gains (GainsUnder's test under the identity).
      const bool lit = o.Predicted({}) > 0.02 * 3 * o.cells && o.photo_linear > 1e-6;
      const bool counts_as_steep = c.steep && lit;
      if (c.steep && !lit && !options_.light_response) continue;
      if (counts_as_steep)
        ++steep;
      else
        ++other;
      observations.push_back(o);
    }
  }
  if (progress) progress("photometry", num_faces, num_faces);
  // A sample that holds the view's effect itself (a BTF) takes no Oren-Nayar term.
  const Photometry photometry =
      SolvePhotometry(std::move(observations), num_faces, photos_.size(), options_.light_response,
                      options_.white_balance, options_.view_term && !sample_.ViewDependent());
  result_.photo_gains = photometry.photo_gains;
  if (blur) {
    std::vector<std::uint32_t> camera_of_photo;
    for (const MeshPhoto& photo : photos_)
      camera_of_photo.push_back(reconstruction_.images.at(photo.image_id).camera_id.value);
    result_.photo_blur = blur->SolvePerCamera(camera_of_photo);
  }
  result_.light_response = photometry.response;
  if (options_.white_balance) result_.white_balance = photometry.white_balance;
}

cv::Mat TriangleEngine::SampleWindowLuminance(std::size_t face, const RectifiedView& rect) const {
  const ReducedPlanes& reduced = sample_.Reduced(rect.level);
  const cv::Size size = rect.mask.size();
  // A window at a place fixed by the face and the photo (any place will do: the
  // estimate compares band energies, not values).
  const std::uint64_t hash = (face + 1) * 0x9E3779B97F4A7C15ull ^ (rect.photo + 1) * 0xC2B2AE3Dull;
  const int x =
      static_cast<int>(hash % static_cast<std::uint64_t>(reduced.planes[0].cols - size.width + 1));
  const int y = static_cast<int>(
      (hash >> 32) % static_cast<std::uint64_t>(reduced.planes[0].rows - size.height + 1));
  const std::vector<cv::Mat> relit =
      sample_.Relight(reduced.Window(cv::Rect(cv::Point(x, y), size)), rect.lighting, 1.0);
  return (relit[0] + relit[1] + relit[2]) / 3.0;
}

PhotometricObservation TriangleEngine::Observe(std::size_t face, const RectifiedView& rect,
                                               double zenith_per_cell,
                                               const ShadingTurnSet& turns) const {
  PhotometricObservation o;
  o.face = face;
  o.photo = rect.photo;
  o.cells = rect.count;
  o.steep = rect.steep;
  o.photo_channels = PhotoLinearSums(rect, sample_.Domain());
  o.photo_linear = o.photo_channels[0] + o.photo_channels[1] + o.photo_channels[2];
  const auto relit_under = [&](const Eigen::Vector3d& view, const Eigen::Vector3d& l,
                               double intensity) {
    return sample_.RelitLinearSum(FaceLighting{view, {{l, intensity}}, {}}, rect.count);
  };
  // Each light as the renderer shades it: per pixel, in the frame turned onto the smooth
  // normal, so that near the terminator part of a face is lit and part is not. Each of
  // the shading points stands for an equal share of the face's cells.
  for (const Eigen::Quaterniond& turn : turns) {
    const Eigen::Vector3d view = turn * rect.lighting.view_in_frame;
    for (const auto& [light, intensity] : rect.lighting.lights) {
      const Eigen::Vector3d l = turn * light;
      if (l.z() > 0.0)
        o.lights.push_back({std::asin(std::min(1.0, l.z())) * 180.0 / std::numbers::pi,
                            relit_under(view, l, intensity) / kShadingPoints,
                            ptm::OrenNayarTerm(l, view)});
    }
  }
  o.zenith_linear = zenith_per_cell >= 0.0
                        ? zenith_per_cell * rect.count
                        : relit_under(rect.lighting.view_in_frame, Eigen::Vector3d::UnitZ(), 1.0);
  return o;
}

TriangleEngine::ShadingTurnSet TriangleEngine::ShadingTurns(std::size_t face) const {
  // Points at barycentric (2/3, 1/6, 1/6) and its permutations.
  const mesh::TriangleFrame& frame = result_.patches[face].frame;
  ShadingTurnSet turns;
  for (int i = 0; i < kShadingPoints; ++i) {
    Eigen::Vector3d barycentric = Eigen::Vector3d::Constant(1.0 / 6.0);
    barycentric[i] = 2.0 / 3.0;
    const Eigen::Vector3d normal_in_frame =
        frame.DirectionInFrame(mesh::SmoothNormalAt(mesh_, vertex_normals_, face, barycentric));
    turns[static_cast<std::size_t>(i)] =
        normal_in_frame.norm() > 1e-12
            ? Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), normal_in_frame)
                  .conjugate()
            : Eigen::Quaterniond::Identity();
  }
  return turns;
}

OverlapTexels TriangleEngine::CollectOverlapTargets(std::size_t f) const {
  const TrianglePatch& patch = result_.patches[f];
  const double t = options_.sample_texel_size;
  const int w = patch.width, h = patch.height;
  OverlapTexels overlap;
  overlap.patch = cv::Size(w, h);
  std::vector<float> value(static_cast<std::size_t>(sample_.NumFeatures()));
  for (int j = 0; j < h; ++j) {
    for (int i = 0; i < w; ++i) {
      const Eigen::Vector2d p(patch.x_min + (i + 0.5) * t, patch.y_max - (j + 0.5) * t);
      for (std::size_t k = 0; k < 3; ++k) {
        const Unfolding& u = result_.unfoldings[f][k];
        if (u.face < 0 || !done_[static_cast<std::size_t>(u.face)]) continue;
        const double d = mesh::DistanceToSegment(patch.corners_in_frame[k],
                                                 patch.corners_in_frame[(k + 1) % 3], p);
        if (d > options_.strip * t) continue;
        const TrianglePatch& other = result_.patches[static_cast<std::size_t>(u.face)];
        if (!sample_.PatchFeatures(other, t, u.rotation * p + u.translation, value.data()))
          continue;
        sample_.TurnFeatures(u, value.data());
        overlap.texels.push_back(j * w + i);
        overlap.targets.insert(overlap.targets.end(), value.begin(), value.end());
        break;
      }
    }
  }
  return overlap;
}

TriangleEngine::FaceSearch TriangleEngine::SearchFace(std::size_t f, RelitScratch& scratch) const {
  // Eq. 3 of paper 003 per photo (RMS at the photo's density), summed over the
  // photos, at the placements of the patch in the sample the search visits.
  FaceSearch found;
  found.views = RectifiedViews(f, correction_ && correction_->WideMaskMargin() >= 0.0);
  if (found.views.empty()) return found;
  const TrianglePatch& patch = result_.patches[f];
  const PlacementSearch search(sample_, found.views, result_.photo_gains,
                               cv::Size(patch.width, patch.height), &scratch);
  found.candidates = options_.search == PlacementSearchKind::kExhaustive
                         ? search.Exhaustive(options_.top_k)
                         : search.CoarseToFine(options_.top_k, options_.search_candidates);
  return found;
}

void TriangleEngine::PlaceAmongCandidates(TrianglePatch& patch, const FaceSearch& found,
                                          const OverlapTexels& overlap,
                                          std::vector<RelitWindow>& relit) {
  // Of the top_k, the one closest to the synthesised neighbours (Algorithm 2): the
  // mean squared difference over the overlap.
  const auto overlap_error = [&](int sx, int sy) {
    if (overlap.texels.empty()) return 0.0;
    return overlap.SumOfSquares(sample_.FeaturePlanes(), cv::Point(sx, sy)) /
           static_cast<double>(overlap.texels.size());
  };
  KeepClosestToNeighbours(found.candidates, overlap_error, patch);
  const std::vector<RectifiedView>& views = found.views;
  if (!correction_ || correction_->RelitMarginCells(views.front()) < 0) return;
  std::vector<int> margins;
  for (const RectifiedView& r : views) margins.push_back(correction_->RelitMarginCells(r));
  const PlacementSearch search(sample_, views, result_.photo_gains,
                               cv::Size(patch.width, patch.height));
  relit = search.RelitAround(cv::Point(patch.sample_x, patch.sample_y), margins);
}

void TriangleEngine::PlaceByNeighbours(TrianglePatch& patch, const OverlapTexels& overlap,
                                       std::mt19937_64& rng) {
  if (!overlap_placement_) overlap_placement_.emplace(sample_.FeaturePlanes());
  const OverlapPlacement::Placement p = overlap_placement_->Pick(overlap, options_.tolerance, rng);
  patch.sample_x = p.texel.x;
  patch.sample_y = p.texel.y;
  patch.overlap_error = p.error / static_cast<double>(overlap.texels.size());
}

void TriangleEngine::SynthesizeFace(std::size_t f, FaceSearch found, std::mt19937_64& rng) {
  TrianglePatch& patch = result_.patches[f];
  const OverlapTexels overlap = CollectOverlapTargets(f);
  if (!found.views.empty()) {
    std::vector<RelitWindow> relit;  // per view: the sample relit around the placed patch
    PlaceAmongCandidates(patch, found, overlap, relit);
    patch.source = PatchSource::kPhotos;
    patch.views_used = static_cast<int>(found.views.size());
    ++result_.num_from_photos;
    if (correction_) correction_->Correct(*this, f, found.views, relit);
  } else if (!overlap.texels.empty()) {
    PlaceByNeighbours(patch, overlap, rng);
    patch.source = PatchSource::kNeighbours;
    ++result_.num_from_neighbours;
  } else {
    patch.sample_x = std::uniform_int_distribution<int>(0, sample_.Width() - patch.width)(rng);
    patch.sample_y = std::uniform_int_distribution<int>(0, sample_.Height() - patch.height)(rng);
    patch.source = PatchSource::kRandom;
    ++result_.num_random;
  }
}

}  // namespace texlume::synth
