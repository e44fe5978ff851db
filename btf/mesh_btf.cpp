#include "btf/mesh_btf.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <opencv2/imgproc.hpp>
#include <opencv2/imgproc/detail/gcgraph.hpp>
#include <random>

#include "sfm/errors.h"
#include "synth/tangent_field.h"
#include "synth/template_match.h"
#include "synth/triangle_frame.h"

namespace texlume::btf {
namespace {

double Since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

double AngleOf(const Eigen::Matrix2d& r) { return std::atan2(r(1, 0), r(0, 0)); }

// The minimum cut of a small graph (paper 004 Fig. 8), behind an interface of
// our own: nodes, n-links, t-links, then which side each node ends on. OpenCV's
// GCGraph (BSD/Apache) does the work.
class MinCut {
 public:
  MinCut(int nodes, int links) : graph_(static_cast<unsigned>(nodes), 2u * links) {
    for (int i = 0; i < nodes; ++i) graph_.addVtx();
  }
  void Link(int a, int b, double weight) { graph_.addEdges(a, b, weight, weight); }
  /// Costs of labelling node a with A (source) and with B (sink).
  void Terminals(int a, double cost_a, double cost_b) {
    // GCGraph's t-link to the source is cut when the node ends on the sink side.
    graph_.addTermWeights(a, cost_b, cost_a);
  }
  void Solve() { graph_.maxFlow(); }
  bool IsA(int a) { return graph_.inSourceSegment(a); }

 private:
  cv::detail::GCGraph<double> graph_;
};

// Geometry maps as CV_32FC1 planes (for reductions and FFT matching).
std::vector<cv::Mat> GeometryPlanes(const BtfFactorisation& s) {
  std::vector<cv::Mat> planes(static_cast<std::size_t>(s.Components()));
  for (int i = 0; i < s.Components(); ++i) {
    cv::Mat& m = planes[static_cast<std::size_t>(i)];
    m = cv::Mat(s.height, s.width, CV_32FC1);
    for (int y = 0; y < s.height; ++y)
      for (int x = 0; x < s.width; ++x)
        m.at<float>(y, x) = s.geometry(static_cast<Eigen::Index>(y) * s.width + x, i);
  }
  return planes;
}

}  // namespace

void BtfMeshSynthesisOptions::Check() const {
  if (!(sample_texel_size > 0.0) || !std::isfinite(sample_texel_size))
    throw OptionError("sample texel size must be a positive number of world units");
  if (strip < 2 || strip > 32) throw OptionError("strip (W_e) must be in [2, 32] texels");
  if (seam_band < 1 || seam_band > strip)
    throw OptionError("seam band must be in [1, strip] texels");
  if (top_k < 1) throw OptionError("top_k must be >= 1");
  if (max_views < 1) throw OptionError("max_views must be >= 1");
  if (!(tolerance >= 0.0)) throw OptionError("tolerance must be >= 0");
  if (min_photo_pixels < 1) throw OptionError("min_photo_pixels must be >= 1");
  if (max_texels < 1) throw OptionError("max_texels must be >= 1");
  if (!(correction_noise > 0.0) || !std::isfinite(correction_noise))
    throw OptionError("correction noise must be > 0");
  if (!(correction_sigma > 0.0) || !std::isfinite(correction_sigma))
    throw OptionError("correction sigma must be > 0 photo pixels");
  if (!(field_direction_in_world.norm() > 0.0))
    throw OptionError("field direction must be nonzero");
}

void SampleGeometry(const BtfFactorisation& s, const Eigen::Vector2d& sample_px, float* out) {
  const double u = std::clamp(sample_px.x() - 0.5, 0.0, s.width - 1.0);
  const double v = std::clamp(sample_px.y() - 0.5, 0.0, s.height - 1.0);
  const int x0 = std::min(static_cast<int>(u), std::max(0, s.width - 2));
  const int y0 = std::min(static_cast<int>(v), std::max(0, s.height - 2));
  const int x1 = std::min(x0 + 1, s.width - 1), y1 = std::min(y0 + 1, s.height - 1);
  const float fx = static_cast<float>(u - x0), fy = static_cast<float>(v - y0);
  const Eigen::Index w = s.width;
  const auto r00 = s.geometry.row(y0 * w + x0), r01 = s.geometry.row(y0 * w + x1);
  const auto r10 = s.geometry.row(y1 * w + x0), r11 = s.geometry.row(y1 * w + x1);
  for (int i = 0; i < s.Components(); ++i)
    out[i] = (1 - fy) * ((1 - fx) * r00[i] + fx * r01[i]) + fy * ((1 - fx) * r10[i] + fx * r11[i]);
}

BtfSampleLookup BtfMeshSynthesis::Lookup(int face, const Eigen::Vector2d& p) const {
  auto own = [&](int f, const Eigen::Vector2d& q, double angle) {
    const synth::TrianglePatch& patch = patches[static_cast<std::size_t>(f)];
    BtfSampleLookup out;
    out.source_face = f;
    const Eigen::Vector2d in_patch((q.x() - patch.x_min) / texel_size,
                                   (patch.y_max - q.y()) / texel_size);  // texels, y down
    out.sample_px = Eigen::Vector2d(patch.sample_x, patch.sample_y) + in_patch;
    out.angle_rad = angle;
    if (static_cast<std::size_t>(f) < colour_gain.size() &&
        !colour_gain[static_cast<std::size_t>(f)].empty()) {
      // Bilinear on the factor grid (cell centres at (c + 0.5) / density texels).
      const cv::Mat& k = colour_gain[static_cast<std::size_t>(f)];
      const Eigen::Vector2d& density = gain_density[static_cast<std::size_t>(f)];
      const double u = std::clamp(in_patch.x() * density.x() - 0.5, 0.0, k.cols - 1.0);
      const double v = std::clamp(in_patch.y() * density.y() - 0.5, 0.0, k.rows - 1.0);
      const int x0 = static_cast<int>(u), y0 = static_cast<int>(v);
      const int x1 = std::min(x0 + 1, k.cols - 1), y1 = std::min(y0 + 1, k.rows - 1);
      const float fx = static_cast<float>(u - x0), fy = static_cast<float>(v - y0);
      const auto at = [&](int x, int y) {
        const cv::Vec3f& c = k.at<cv::Vec3f>(y, x);
        return Eigen::Vector3f(c[0], c[1], c[2]);
      };
      out.colour_gain = (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x1, y0)) +
                        fy * ((1 - fx) * at(x0, y1) + fx * at(x1, y1));
    }
    return out;
  };
  const synth::TrianglePatch& patch = patches[static_cast<std::size_t>(face)];
  const cv::Mat& label = labels[static_cast<std::size_t>(face)];
  const int i = static_cast<int>(std::floor((p.x() - patch.x_min) / texel_size));
  const int j = static_cast<int>(std::floor((patch.y_max - p.y()) / texel_size));
  if (label.empty() || i < 0 || j < 0 || i >= label.cols || j >= label.rows) return own(face, p, 0);
  const int l = label.at<std::uint8_t>(j, i);
  if (l == 0) return own(face, p, 0);
  const synth::Unfolding& u =
      unfoldings[static_cast<std::size_t>(face)][static_cast<std::size_t>(l - 1)];
  if (u.face < 0) return own(face, p, 0);
  return own(u.face, u.rotation * p + u.translation, AngleOf(u.rotation));
}

BtfMeshSynthesis SynthesizeMeshBtf(const sfm::TriangleMesh& mesh,
                                   const sfm::Reconstruction& reconstruction,
                                   const sfm::VisibilityResult& visibility,
                                   const std::vector<synth::MeshPhoto>& photos,
                                   const BtfFactorisation& sample,
                                   const BtfMeshSynthesisOptions& options,
                                   const ProgressCallback& progress) {
  options.Check();
  const auto start = std::chrono::steady_clock::now();
  const std::size_t num_faces = mesh.faces.size();
  if (visibility.triangles.size() != num_faces)
    throw InputError("visibility", "does not match the mesh's face count");
  const double t = options.sample_texel_size;
  const int n = sample.Components();
  BtfMeshSynthesis result;
  result.texel_size = t;
  result.sample_width = sample.width;
  result.sample_height = sample.height;

  // 1. Frames, patch rectangles, unfoldings (Algorithm 2's set-up).
  auto take_geometry = [&](synth::PatchGeometry geometry) {
    if (geometry.total_texels > options.max_texels) {
      throw InputError("mesh", "at a texel size of " + std::to_string(t) + " world units the " +
                                   std::to_string(num_faces) + " patches need " +
                                   std::to_string(geometry.total_texels) +
                                   " texels, more than the limit of " +
                                   std::to_string(options.max_texels));
    }
    if (geometry.widest > sample.width || geometry.tallest > sample.height) {
      throw InputError("mesh",
                       "the largest triangle needs a patch of " + std::to_string(geometry.widest) +
                           " x " + std::to_string(geometry.tallest) +
                           " texels (strip included) but the BTF sample is " +
                           std::to_string(sample.width) + " x " + std::to_string(sample.height) +
                           "; subdivide the mesh or capture a larger sample");
    }
    result.patches = std::move(geometry.patches);
    result.unfoldings = std::move(geometry.unfoldings);
  };
  take_geometry(synth::MakePatchGeometry(mesh, t, options.strip, options.tangent_frame,
                                         options.field_direction_in_world));
  const std::vector<cv::Mat> planes = GeometryPlanes(sample);
  const cv::Mat planes_energy = synth::PlaneEnergy(planes);
  const Eigen::VectorXf mean_g = sample.geometry.colwise().mean().transpose();

  // Geometry maps reduced to a photo density r = 2^(-level/4) photo pixels per
  // texel. The BTF is linear in g, so reducing g equals reducing the relit image.
  std::map<int, synth::ReducedPlanes> reduced;
  auto reduced_at = [&](int level) -> const synth::ReducedPlanes& {
    auto it = reduced.find(level);
    if (it != reduced.end()) return it->second;
    return reduced.emplace(level, synth::ReduceToDensityLevel(planes, level)).first->second;
  };

  // A triangle in one photo: the photo rectified into the triangle frame at the
  // photo's density (linear RGB), the mask, and A = sum_lights I p(v, l)
  // (n x 3): the relit sample is then sum_i g_i A_i.
  std::map<sfm::ImageId, std::size_t> photo_index;
  for (std::size_t k = 0; k < photos.size(); ++k) photo_index[photos[k].image_id] = k;
  struct Rectified {
    std::size_t photo = 0;
    int level = 0;
    std::vector<cv::Mat> linear;  // RGB
    cv::Mat mask;                 // CV_32FC1
    cv::Mat wide_mask;            // the same over the seam band too (photo correction)
    int count = 0;
    Eigen::MatrixX3f appearance;  // n x 3
    bool steep = true;            // every light and the view above 60 degrees
  };
  // `seam_band_mask`: also the mask over the seam band (the photo correction's).
  auto rectify = [&](std::size_t f, const sfm::TriangleView& view, Rectified& out,
                     bool seam_band_mask) -> bool {
    const auto it = photo_index.find(view.image_id);
    if (it == photo_index.end()) return false;
    const synth::MeshPhoto& photo = photos[it->second];
    const sfm::Image& image = reconstruction.images.at(view.image_id);
    const sfm::Camera& camera = reconstruction.cameras.at(image.camera_id);
    const synth::TrianglePatch& patch = result.patches[f];
    const int level = synth::PhotoDensityLevel(patch, view, t);
    const synth::ReducedPlanes& r = reduced_at(level);
    const int tw = std::max(1, static_cast<int>(std::lround(patch.width * r.rx)));
    const int th = std::max(1, static_cast<int>(std::lround(patch.height * r.ry)));
    if (tw > r.planes[0].cols || th > r.planes[0].rows) return false;
    cv::Mat map_x, map_y;
    out.count = synth::RectificationMaps(patch, t, r.rx, r.ry, cv::Size(tw, th), camera,
                                         image.cam_from_world, photo.image.size(), 0.0, map_x,
                                         map_y, out.mask);
    if (out.count < options.min_photo_pixels) return false;
    if (seam_band_mask) {
      cv::Mat wide_x, wide_y;
      synth::RectificationMaps(patch, t, r.rx, r.ry, cv::Size(tw, th), camera, image.cam_from_world,
                               photo.image.size(), (options.seam_band + 1) * t, wide_x, wide_y,
                               out.wide_mask);
    }
    cv::Mat rectified;
    cv::remap(photo.image, rectified, map_x, map_y, cv::INTER_CUBIC, cv::BORDER_REPLICATE);
    std::vector<cv::Mat> display;
    cv::split(rectified, display);
    out.linear.assign(3, cv::Mat());
    for (int ch = 0; ch < 3; ++ch) {
      cv::Mat& m = out.linear[static_cast<std::size_t>(ch)];
      m = cv::Mat(th, tw, CV_32FC1);
      for (int j = 0; j < th; ++j)
        for (int i = 0; i < tw; ++i)
          m.at<float>(j, i) =
              synth::SrgbToLinear(display[static_cast<std::size_t>(ch)].at<float>(j, i));
    }
    const Eigen::Vector3d v = patch.frame.DirectionInFrame(
        (image.ProjectionCenter() - patch.frame.origin_in_world).normalized());
    out.steep = v.z() > 0.5;
    out.appearance = Eigen::MatrixX3f::Zero(n, 3);
    for (const sfm::ObjectLight& light : photo.lights) {
      const Eigen::Vector3d l =
          patch.frame.DirectionInFrame(light.DirectionFrom(patch.frame.origin_in_world));
      out.steep = out.steep && l.z() > 0.5;
      if (l.z() <= 0.0 || v.z() <= 0.0) continue;
      out.appearance += static_cast<float>(light.intensity) * InterpolateAppearance(sample, v, l);
    }
    out.photo = it->second;
    out.level = level;
    return true;
  };
  auto relit = [&](const synth::ReducedPlanes& r, const Eigen::MatrixX3f& a, double gain) {
    std::vector<cv::Mat> out(3);
    for (int ch = 0; ch < 3; ++ch) {
      cv::Mat& m = out[static_cast<std::size_t>(ch)];
      m = cv::Mat::zeros(r.planes[0].size(), CV_32FC1);
      for (int i = 0; i < n; ++i)
        cv::scaleAdd(r.planes[static_cast<std::size_t>(i)], static_cast<double>(a(i, ch)) * gain, m,
                     m);
    }
    return out;
  };

  // 1b. Frames turned to the photos (kPhotos, or kAuto for an anisotropic
  // sample), as in the PTM synthesis (synth/tangent_field.h); the sample is
  // relit seen from above.
  result.tangent_frame = options.tangent_frame;
  if (options.tangent_frame == synth::TangentFrame::kPhotos ||
      options.tangent_frame == synth::TangentFrame::kAuto) {
    std::vector<int> face_levels(num_faces, -1);
    for (std::size_t f = 0; f < num_faces; ++f) {
      const std::vector<sfm::TriangleView> views =
          synth::ConstrainingViews(visibility.triangles[f], true, options.max_views);
      if (!views.empty()) face_levels[f] = synth::PhotoDensityLevel(result.patches[f], views[0], t);
    }
    const synth::FrameChoice choice = synth::ChoosePhotoFrames(
        options.tangent_frame, result.patches, result.unfoldings, face_levels,
        [&](int level) {
          const synth::ReducedPlanes& red = reduced_at(level);
          return synth::SampleStructureTensor(
              [&](const Eigen::Vector3d& l) {
                return relit(red, InterpolateAppearance(sample, Eigen::Vector3d::UnitZ(), l), 1.0);
              },
              red.rx, red.ry);
        },
        [&](std::size_t f) {
          Eigen::Matrix2d tensor = Eigen::Matrix2d::Zero();
          for (const sfm::TriangleView& view :
               synth::ConstrainingViews(visibility.triangles[f], true, options.max_views)) {
            Rectified rect;
            if (!rectify(f, view, rect, false)) continue;
            const synth::ReducedPlanes& r = reduced_at(rect.level);
            tensor += synth::LuminanceStructureTensor(rect.linear, rect.mask, r.rx, r.ry);
          }
          return tensor;
        });
    result.tangent_frame = choice.tangent_frame;
    result.sample_coherence = choice.sample_coherence;
    if (choice.tangent_frame == synth::TangentFrame::kPhotos)
      take_geometry(
          synth::MakePatchGeometry(mesh, t, options.strip, choice.field.tangents_in_world));
  }

  // 2a. Gain per photo, as in the PTM synthesis: photo mean over the sample's
  // mean relit under the triangle's view and lights, m = a_T g_n, solved for
  // log g_n by alternating least squares with the mean log a_T at 0.
  std::vector<synth::GainObservation> ratios;
  for (std::size_t f = 0; f < num_faces; ++f) {
    int used = 0;
    for (const sfm::TriangleView& view : visibility.triangles[f].views) {
      if (!view.fully_visible || used >= 8) continue;
      Rectified rect;
      if (!rectify(f, view, rect, false) || !rect.steep) continue;
      double photo_linear = 0.0;
      for (int ch = 0; ch < 3; ++ch)
        photo_linear += cv::sum(rect.linear[static_cast<std::size_t>(ch)].mul(rect.mask))[0];
      const double model_linear = (mean_g.transpose() * rect.appearance).sum() * rect.count;
      if (!(model_linear > 0.02 * 3 * rect.count) || !(photo_linear > 1e-6)) continue;
      ratios.push_back({f, rect.photo, std::log(photo_linear / model_linear), model_linear});
      ++used;
    }
  }
  result.photo_gains = synth::SolvePhotoGains(ratios, num_faces, photos.size());

  // Photo-consistency factors (per face in 2b, after its placement): k per channel
  // on a grid at the first (best) photo's density over the whole patch:
  // k = (sum_r m_r p_r + lambda mu) / (sum_r m_r^2 + lambda mu), smoothed by a
  // Gaussian normalised over the observed cells (which carries k into the strip
  // the graph cuts may show), 1 where nothing is observed nearby.
  result.colour_gain.resize(num_faces);
  result.gain_density.assign(num_faces, Eigen::Vector2d::Ones());
  double residual_quilted = 0.0, residual_corrected = 0.0, residual_count = 0.0;
  auto correct = [&](std::size_t f, const std::vector<Rectified>& scored,
                     const std::vector<std::vector<cv::Mat>>& models) {
    const synth::TrianglePatch& patch = result.patches[f];
    const cv::Size grid = scored[0].mask.size();
    std::array<cv::Mat, 3> num, den;
    for (int ch = 0; ch < 3; ++ch) {
      num[static_cast<std::size_t>(ch)] = cv::Mat::zeros(grid, CV_32FC1);
      den[static_cast<std::size_t>(ch)] = cv::Mat::zeros(grid, CV_32FC1);
    }
    cv::Mat observed = cv::Mat::zeros(grid, CV_32FC1);
    struct OnGrid {
      std::array<cv::Mat, 3> model, photo;
      cv::Mat inside;  // the triangle's cells (for the residuals)
    };
    std::vector<OnGrid> on_grid(scored.size());
    for (std::size_t r = 0; r < scored.size(); ++r) {
      const synth::ReducedPlanes& red = reduced_at(scored[r].level);
      const cv::Size size = scored[r].mask.size();
      OnGrid& g = on_grid[r];
      // The chosen patch relit under photo r: its cell i is at reduced-sample
      // position sample_x rx + i (pixel centres at integers).
      const cv::Point2f centre(
          static_cast<float>(patch.sample_x * red.rx + (size.width - 1) * 0.5),
          static_cast<float>(patch.sample_y * red.ry + (size.height - 1) * 0.5));
      cv::Mat wide = scored[r].wide_mask;
      g.inside = scored[r].mask;
      for (std::size_t ch = 0; ch < 3; ++ch) {
        cv::getRectSubPix(models[r][ch], size, centre, g.model[ch]);
        g.photo[ch] = scored[r].linear[ch];
      }
      if (size != grid) {
        for (std::size_t ch = 0; ch < 3; ++ch) {
          cv::resize(g.model[ch], g.model[ch], grid, 0, 0, cv::INTER_AREA);
          cv::resize(g.photo[ch], g.photo[ch], grid, 0, 0, cv::INTER_AREA);
        }
        cv::resize(wide, wide, grid, 0, 0, cv::INTER_AREA);
        cv::resize(g.inside, g.inside, grid, 0, 0, cv::INTER_AREA);
      }
      for (std::size_t ch = 0; ch < 3; ++ch) {
        num[ch] += g.model[ch].mul(g.photo[ch]).mul(wide);
        den[ch] += g.model[ch].mul(g.model[ch]).mul(wide);
      }
      observed += wide;
    }
    const double observed_sum = cv::sum(observed)[0];
    if (!(observed_sum > 0.0)) return;
    const double sigma = options.correction_sigma;
    cv::Mat weight, wide_weight;
    cv::GaussianBlur(observed, weight, cv::Size(), sigma);
    cv::GaussianBlur(observed, wide_weight, cv::Size(), 4.0 * sigma);
    std::vector<cv::Mat> k(3);
    for (std::size_t ch = 0; ch < 3; ++ch) {
      const double mu = cv::sum(den[ch])[0] / observed_sum;  // mean m^2 per observation
      const double prior = options.correction_noise * std::max(mu, 1e-12);
      cv::Mat raw;
      cv::divide(num[ch] + prior * observed, den[ch] + prior * observed + 1e-30, raw);
      // raw * observed is 0 where nothing is observed: normalised smoothing.
      const cv::Mat weighted = raw.mul(observed);
      cv::Mat smooth, wide;
      cv::GaussianBlur(weighted, smooth, cv::Size(), sigma);
      cv::GaussianBlur(weighted, wide, cv::Size(), 4.0 * sigma);
      k[ch] = cv::Mat(grid, CV_32FC1);
      for (int j = 0; j < grid.height; ++j)
        for (int i = 0; i < grid.width; ++i) {
          float v = 1.0f;
          if (weight.at<float>(j, i) > 0.05f)
            v = smooth.at<float>(j, i) / weight.at<float>(j, i);
          else if (wide_weight.at<float>(j, i) > 0.01f)
            v = wide.at<float>(j, i) / wide_weight.at<float>(j, i);
          k[ch].at<float>(j, i) = std::clamp(v, 0.2f, 5.0f);
        }
    }
    for (const OnGrid& g : on_grid)
      for (std::size_t ch = 0; ch < 3; ++ch) {
        const cv::Mat before = g.model[ch] - g.photo[ch];
        const cv::Mat after = g.model[ch].mul(k[ch]) - g.photo[ch];
        residual_quilted += cv::sum(before.mul(before).mul(g.inside))[0];
        residual_corrected += cv::sum(after.mul(after).mul(g.inside))[0];
        residual_count += cv::sum(g.inside)[0];
      }
    cv::merge(k, result.colour_gain[f]);
    const synth::ReducedPlanes& grid_level = reduced_at(scored[0].level);
    result.gain_density[f] = Eigen::Vector2d(grid_level.rx, grid_level.ry);
  };

  // 2b. Breadth-first synthesis from the best-seen triangle.
  const int seed_face = synth::BestSeenFace(visibility);
  const std::vector<int> order =
      sfm::BreadthFirstFaceOrder(mesh, sfm::FaceNeighbours(mesh), seed_face);
  std::vector<char> done(num_faces, 0);
  std::mt19937_64 rng(options.seed);
  std::vector<float> value(static_cast<std::size_t>(n));
  std::size_t processed = 0;
  for (const int face : order) {
    const std::size_t f = static_cast<std::size_t>(face);
    synth::TrianglePatch& patch = result.patches[f];
    const int w = patch.width, h = patch.height;
    // Overlap targets: synthesised neighbours' geometry maps, unfolded into this
    // frame, on the texels within W_e of the shared edge.
    std::vector<int> target_texels;
    std::vector<float> targets;  // n per target texel
    for (int j = 0; j < h; ++j) {
      for (int i = 0; i < w; ++i) {
        const Eigen::Vector2d p(patch.x_min + (i + 0.5) * t, patch.y_max - (j + 0.5) * t);
        for (int k = 0; k < 3; ++k) {
          const synth::Unfolding& u = result.unfoldings[f][static_cast<std::size_t>(k)];
          if (u.face < 0 || !done[static_cast<std::size_t>(u.face)]) continue;
          const double d = synth::DistanceToSegment(
              patch.corners_in_frame[static_cast<std::size_t>(k)],
              patch.corners_in_frame[static_cast<std::size_t>((k + 1) % 3)], p);
          if (d > options.strip * t) continue;
          const synth::TrianglePatch& other = result.patches[static_cast<std::size_t>(u.face)];
          const Eigen::Vector2d q = u.rotation * p + u.translation;
          const double sx = other.sample_x + (q.x() - other.x_min) / t;
          const double sy = other.sample_y + (other.y_max - q.y()) / t;
          if (sx < other.sample_x || sy < other.sample_y || sx > other.sample_x + other.width ||
              sy > other.sample_y + other.height)
            continue;
          SampleGeometry(sample, Eigen::Vector2d(sx, sy), value.data());
          target_texels.push_back(j * w + i);
          targets.insert(targets.end(), value.begin(), value.end());
          break;
        }
      }
    }
    auto overlap_error = [&](int sx, int sy) {
      if (target_texels.empty()) return 0.0;
      double e = 0.0;
      for (std::size_t m = 0; m < target_texels.size(); ++m) {
        const int i = target_texels[m] % w, j = target_texels[m] / w;
        const auto row =
            sample.geometry.row(static_cast<Eigen::Index>(sy + j) * sample.width + sx + i);
        for (int c = 0; c < n; ++c) {
          const double d = row[c] - targets[m * static_cast<std::size_t>(n) + c];
          e += d * d;
        }
      }
      return e / static_cast<double>(target_texels.size());
    };

    std::vector<Rectified> rects;
    for (const sfm::TriangleView& view :
         synth::ConstrainingViews(visibility.triangles[f], true, options.max_views)) {
      Rectified r;
      if (rectify(f, view, r, options.photo_correction)) rects.push_back(std::move(r));
    }
    const int max_sx = sample.width - w, max_sy = sample.height - h;
    if (!rects.empty()) {
      // Eq. 3 of paper 003 per photo (RMS, linear RGB), summed over the photos.
      cv::Mat total = cv::Mat::zeros(max_sy + 1, max_sx + 1, CV_32FC1);
      std::vector<std::vector<cv::Mat>> models;  // per photo: the relit sample at its density
      for (const Rectified& r : rects) {
        const synth::ReducedPlanes& red = reduced_at(r.level);
        const std::vector<cv::Mat>& model =
            models.emplace_back(relit(red, r.appearance, result.photo_gains[r.photo]));
        synth::AddImageScore(synth::MaskedSsd(model, synth::PlaneEnergy(model), r.linear, r.mask),
                             r.count, red.rx, red.ry, total);
      }
      synth::KeepClosestToNeighbours(
          synth::BestPlacements(
              total, std::max(1, static_cast<int>(std::floor(1.0 / reduced_at(rects[0].level).rx))),
              options.top_k),
          overlap_error, patch);
      patch.source = synth::PatchSource::kPhotos;
      patch.views_used = static_cast<int>(rects.size());
      ++result.num_from_photos;
      if (options.photo_correction) correct(f, rects, models);
    } else if (!target_texels.empty()) {
      std::vector<cv::Mat> target_planes(static_cast<std::size_t>(n));
      for (cv::Mat& m : target_planes) m = cv::Mat::zeros(h, w, CV_32FC1);
      cv::Mat mask = cv::Mat::zeros(h, w, CV_32FC1);
      for (std::size_t m = 0; m < target_texels.size(); ++m) {
        const int i = target_texels[m] % w, j = target_texels[m] / w;
        mask.at<float>(j, i) = 1.0f;
        for (int c = 0; c < n; ++c)
          target_planes[static_cast<std::size_t>(c)].at<float>(j, i) =
              targets[m * static_cast<std::size_t>(n) + c];
      }
      const cv::Mat errors = synth::MaskedSsd(planes, planes_energy, target_planes, mask);
      const cv::Point p = synth::PickWithinTolerance(errors, options.tolerance, rng);
      patch.sample_x = p.x;
      patch.sample_y = p.y;
      patch.overlap_error = errors.at<float>(p.y, p.x) / static_cast<double>(target_texels.size());
      patch.source = synth::PatchSource::kNeighbours;
      ++result.num_from_neighbours;
    } else {
      patch.sample_x = std::uniform_int_distribution<int>(0, max_sx)(rng);
      patch.sample_y = std::uniform_int_distribution<int>(0, max_sy)(rng);
      patch.source = synth::PatchSource::kRandom;
      ++result.num_random;
    }
    done[f] = 1;
    ++processed;
    if (progress && (processed % 64 == 0 || processed == num_faces))
      progress("btf synthesis", processed, num_faces);
  }
  if (residual_count > 0) {
    result.photo_rms_quilted = std::sqrt(residual_quilted / residual_count);
    result.photo_rms_corrected = std::sqrt(residual_corrected / residual_count);
  }
  result.seconds_synthesis = Since(start);

  // 3. Graph-cut seams across every shared edge (paper 004 §V, Fig. 8).
  const auto seams_start = std::chrono::steady_clock::now();
  result.labels.resize(num_faces);
  for (std::size_t f = 0; f < num_faces; ++f)
    result.labels[f] = cv::Mat::zeros(result.patches[f].height, result.patches[f].width, CV_8UC1);
  const double band = options.seam_band * t;
  double cut_cost = 0.0, edge_cost = 0.0;
  std::size_t edge_links = 0;
  std::vector<float> a_value(static_cast<std::size_t>(n)), b_value(static_cast<std::size_t>(n));
  // The distance between the two patches' geometry-map vectors at a point of
  // face f's frame (the |f_A(p) - f_B(p)| of E_smooth).
  auto difference = [&](std::size_t f, const synth::Unfolding& u, const Eigen::Vector2d& p) {
    const synth::TrianglePatch& own = result.patches[f];
    SampleGeometry(sample,
                   Eigen::Vector2d(own.sample_x + (p.x() - own.x_min) / t,
                                   own.sample_y + (own.y_max - p.y()) / t),
                   a_value.data());
    const synth::TrianglePatch& other = result.patches[static_cast<std::size_t>(u.face)];
    const Eigen::Vector2d q = u.rotation * p + u.translation;
    SampleGeometry(sample,
                   Eigen::Vector2d(other.sample_x + (q.x() - other.x_min) / t,
                                   other.sample_y + (other.y_max - q.y()) / t),
                   b_value.data());
    double d = 0.0;
    for (int c = 0; c < n; ++c) d += (a_value[c] - b_value[c]) * (a_value[c] - b_value[c]);
    return std::sqrt(d);
  };
  auto nearest_edge = [](const std::array<Eigen::Vector2d, 3>& c, const Eigen::Vector2d& p) {
    int best = 0;
    double best_d = std::numeric_limits<double>::max();
    for (int k = 0; k < 3; ++k) {
      const double d = synth::DistanceToSegment(c[static_cast<std::size_t>(k)],
                                                c[static_cast<std::size_t>((k + 1) % 3)], p);
      if (d < best_d) best_d = d, best = k;
    }
    return best;
  };
  std::size_t edges_done = 0;
  for (std::size_t f = 0; f < num_faces; ++f) {
    const synth::TrianglePatch& patch = result.patches[f];
    for (int k = 0; k < 3; ++k) {
      const synth::Unfolding& u = result.unfoldings[f][static_cast<std::size_t>(k)];
      if (u.face < 0 || static_cast<std::size_t>(u.face) < f) continue;  // each edge once
      const std::size_t h = static_cast<std::size_t>(u.face);
      const synth::TrianglePatch& other = result.patches[h];
      int kh = -1;  // the shared edge's index in the neighbour
      for (int m = 0; m < 3; ++m)
        if (result.unfoldings[h][static_cast<std::size_t>(m)].face == static_cast<int>(f)) kh = m;
      if (kh < 0) continue;
      const Eigen::Vector2d a = patch.corners_in_frame[static_cast<std::size_t>(k)];
      const Eigen::Vector2d b = patch.corners_in_frame[static_cast<std::size_t>((k + 1) % 3)];
      // Side of the edge a point is on: +1 towards f's third corner.
      const Eigen::Vector2d third = patch.corners_in_frame[static_cast<std::size_t>((k + 2) % 3)];
      auto cross = [&](const Eigen::Vector2d& p) {
        return (b - a).x() * (p - a).y() - (b - a).y() * (p - a).x();
      };
      const double own_sign = cross(third) >= 0 ? 1.0 : -1.0;
      // Nodes: f's patch texels within the band whose nearest edge (of their own
      // triangle) is this one, on f's side or the neighbour's.
      const int w = patch.width, hgt = patch.height;
      std::vector<int> node(static_cast<std::size_t>(w * hgt), -1);
      std::vector<signed char> side(static_cast<std::size_t>(w * hgt), 0);  // +1 f, -1 h
      std::vector<std::pair<int, int>> cells;
      auto centre = [&](int i, int j) {
        return Eigen::Vector2d(patch.x_min + (i + 0.5) * t, patch.y_max - (j + 0.5) * t);
      };
      for (int j = 0; j < hgt; ++j) {
        for (int i = 0; i < w; ++i) {
          const Eigen::Vector2d p = centre(i, j);
          const bool on_f = cross(p) * own_sign >= 0;
          side[static_cast<std::size_t>(j * w + i)] = on_f ? 1 : -1;
          if (synth::DistanceToSegment(a, b, p) > band) continue;
          const Eigen::Vector2d q = u.rotation * p + u.translation;
          if (on_f ? nearest_edge(patch.corners_in_frame, p) != k
                   : nearest_edge(other.corners_in_frame, q) != kh)
            continue;
          const double sx = (q.x() - other.x_min) / t, sy = (other.y_max - q.y()) / t;
          if (sx < 0 || sy < 0 || sx > other.width || sy > other.height) continue;
          node[static_cast<std::size_t>(j * w + i)] = static_cast<int>(cells.size());
          cells.emplace_back(i, j);
        }
      }
      if (cells.empty()) continue;
      std::vector<double> diff(cells.size());
      for (std::size_t c = 0; c < cells.size(); ++c)
        diff[c] = difference(f, u, centre(cells[c].first, cells[c].second));
      MinCut cut(static_cast<int>(cells.size()), static_cast<int>(2 * cells.size()));
      constexpr double kHard = 1e9;
      constexpr int di[4] = {1, -1, 0, 0}, dj[4] = {0, 0, 1, -1};
      for (std::size_t c = 0; c < cells.size(); ++c) {
        const auto [i, j] = cells[c];
        const int s = side[static_cast<std::size_t>(j * w + i)];
        bool hard = false;
        for (int m = 0; m < 4; ++m) {
          const int ii = i + di[m], jj = j + dj[m];
          const bool inside = ii >= 0 && jj >= 0 && ii < w && jj < hgt;
          const int other_node = inside ? node[static_cast<std::size_t>(jj * w + ii)] : -1;
          if (other_node < 0) {
            // Next to a texel outside the band on this side: it keeps its own patch.
            if (!inside || side[static_cast<std::size_t>(jj * w + ii)] == s) hard = true;
          } else if (m % 2 == 0) {  // each pair once (right and down)
            // E_smooth's V(p, q), plus a little per link so seams stay short.
            cut.Link(static_cast<int>(c), other_node,
                     diff[c] + diff[static_cast<std::size_t>(other_node)] + 1e-6);
          }
          if (other_node >= 0 && m % 2 == 0 && side[static_cast<std::size_t>(jj * w + ii)] != s) {
            edge_cost += diff[c] + diff[static_cast<std::size_t>(other_node)];
            ++edge_links;
          }
        }
        // Hard: next to the band's outside. Otherwise a vanishing preference for
        // its own side, so texels the cut leaves free keep their own patch.
        const double keep = hard ? kHard : 1e-9;
        cut.Terminals(static_cast<int>(c), s > 0 ? 0.0 : keep, s > 0 ? keep : 0.0);
      }
      cut.Solve();
      std::vector<char> is_a(cells.size());
      for (std::size_t c = 0; c < cells.size(); ++c) is_a[c] = cut.IsA(static_cast<int>(c));
      for (std::size_t c = 0; c < cells.size(); ++c) {
        const auto [i, j] = cells[c];
        if (!is_a[c]) result.labels[f].at<std::uint8_t>(j, i) = static_cast<std::uint8_t>(1 + k);
        for (int m = 0; m < 4; m += 2) {
          const int ii = i + di[m], jj = j + dj[m];
          if (ii >= w || jj >= hgt) continue;
          const int o = node[static_cast<std::size_t>(jj * w + ii)];
          if (o >= 0 && is_a[c] != is_a[static_cast<std::size_t>(o)]) {
            cut_cost += diff[c] + diff[static_cast<std::size_t>(o)];
            ++result.seam_links;
          }
        }
      }
      // The neighbour's texels near the edge take the cut's label at the nearest
      // cell of this grid: where it chose A, they show this face's patch.
      cv::Mat& nb_labels = result.labels[h];
      const Eigen::Matrix2d back = u.rotation.transpose();
      for (int j = 0; j < other.height; ++j) {
        for (int i = 0; i < other.width; ++i) {
          const Eigen::Vector2d q(other.x_min + (i + 0.5) * t, other.y_max - (j + 0.5) * t);
          const Eigen::Vector2d p = back * (q - u.translation);
          if (synth::DistanceToSegment(a, b, p) > band + t) continue;
          const int ci = static_cast<int>(std::floor((p.x() - patch.x_min) / t));
          const int cj = static_cast<int>(std::floor((patch.y_max - p.y()) / t));
          if (ci < 0 || cj < 0 || ci >= w || cj >= hgt) continue;
          const int c = node[static_cast<std::size_t>(cj * w + ci)];
          if (c >= 0 && is_a[static_cast<std::size_t>(c)] &&
              side[static_cast<std::size_t>(cj * w + ci)] < 0)
            nb_labels.at<std::uint8_t>(j, i) = static_cast<std::uint8_t>(1 + kh);
        }
      }
      ++result.seam_edges;
    }
    ++edges_done;
    if (progress && (edges_done % 256 == 0 || edges_done == num_faces))
      progress("graph-cut seams", edges_done, num_faces);
  }
  result.seam_cost = cut_cost;
  result.edge_cost = edge_cost;
  result.seam_cost_per_link =
      result.seam_links ? cut_cost / static_cast<double>(result.seam_links) : 0.0;
  result.edge_cost_per_link = edge_links ? edge_cost / static_cast<double>(edge_links) : 0.0;
  result.seconds_seams = Since(seams_start);
  return result;
}

}  // namespace texlume::btf
