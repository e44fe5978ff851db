#include "synth/triangle_parts.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <string>

#include "core/check.h"
#include "core/errors.h"
#include "core/srgb.h"
#include "ptm/coefficient_space.h"

namespace texlume::synth {

using LightList = std::vector<std::pair<Eigen::Vector3d, double>>;  // (tangent-frame dir, I)

Eigen::Vector3f RelightMixture(const float* coefficients, const float* colour,
                               ptm::PtmFormat format, const LightList& lights, double gain,
                               const ptm::LightResponse& response, const Eigen::Vector3d& view) {
  return RelightEffective(coefficients, colour, format,
                          ptm::EffectiveLights(lights, response, view), gain);
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

namespace {

// SignedDistanceToTriangle(c, p) <= margin, with no distance taken inside the
// triangle when the margin is not negative.
bool WithinMargin(const std::array<Eigen::Vector2d, 3>& c, const Eigen::Vector2d& p,
                  double margin) {
  return margin >= 0.0 ? mesh::WithinReachOfTriangle(c, p, margin)
                       : mesh::SignedDistanceToTriangle(c, p) <= margin;
}

}  // namespace

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
      if (px && px->x() >= 0.5 && px->y() >= 0.5 && px->x() <= image_size.width - 0.5 &&
          px->y() <= image_size.height - 0.5 &&
          WithinMargin(patch.corners_in_frame, p, mask_margin)) {
        mask.at<float>(j, i) = 1.0f;
        ++count;
      }
    }
  }
  return count;
}

void RemapPhotoRegion(const PhotoPixels& pixels, cv::Mat& map_x, cv::Mat& map_y, cv::Mat& out) {
  double x_lo, x_hi, y_lo, y_hi;
  cv::minMaxLoc(map_x, &x_lo, &x_hi);
  cv::minMaxLoc(map_y, &y_lo, &y_hi);
  const cv::Size size = pixels.size();
  const int x0 = std::clamp(static_cast<int>(std::floor(x_lo)) - 2, 0, size.width - 1);
  const int y0 = std::clamp(static_cast<int>(std::floor(y_lo)) - 2, 0, size.height - 1);
  const int x1 = std::clamp(static_cast<int>(std::floor(x_hi)) + 4, x0 + 1, size.width);
  const int y1 = std::clamp(static_cast<int>(std::floor(y_hi)) + 4, y0 + 1, size.height);
  const cv::Mat region = pixels.Display(cv::Rect(x0, y0, x1 - x0, y1 - y0));
  // Whole-pixel shifts keep the maps' sub-pixel parts exact.
  map_x -= x0;
  map_y -= y0;
  cv::remap(region, out, map_x, map_y, cv::INTER_CUBIC, cv::BORDER_REPLICATE);
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
                                    std::size_t num_faces, std::size_t num_photos,
                                    std::vector<double>* face_albedo) {
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
  if (face_albedo) {
    face_albedo->assign(num_faces, 0.0);
    for (const GainObservation& r : ratios) (*face_albedo)[r.face] = std::exp(log_albedo[r.face]);
  }
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

void AddImageScore(const cv::Mat& ssd, double count, double rx, double ry, cv::Mat& total) {
  const float cells = static_cast<float>(count);
  for (int sy = 0; sy < total.rows; ++sy) {
    const int py = std::min(static_cast<int>(std::lround(sy * ry)), ssd.rows - 1);
    for (int sx = 0; sx < total.cols; ++sx) {
      const int px = std::min(static_cast<int>(std::lround(sx * rx)), ssd.cols - 1);
      total.at<float>(sy, sx) += std::sqrt(ssd.at<float>(py, px) / (3.0f * cells));
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

std::size_t ClosestToNeighbours(const std::vector<std::pair<float, cv::Point>>& candidates,
                                const std::function<double(int, int)>& overlap_error,
                                double* error) {
  double best = std::numeric_limits<double>::infinity();
  std::size_t chosen = 0;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const double e = overlap_error(candidates[i].second.x, candidates[i].second.y);
    if (e < best) best = e, chosen = i;
  }
  if (error) *error = best;
  return chosen;
}

void KeepClosestToNeighbours(const std::vector<std::pair<float, cv::Point>>& candidates,
                             const std::function<double(int, int)>& overlap_error,
                             TrianglePatch& patch) {
  if (candidates.empty()) return;
  double error = 0;
  const auto& [score, at] = candidates[ClosestToNeighbours(candidates, overlap_error, &error)];
  if (!(error < std::numeric_limits<double>::infinity())) return;
  patch.sample_x = at.x;
  patch.sample_y = at.y;
  patch.image_score = score;
  patch.overlap_error = error;
}

namespace {

// A triangle's own area in texels of side `t` (its corners in its patch frame).
double TriangleTexels(const TrianglePatch& patch, double t) {
  const Eigen::Vector2d e1 = patch.corners_in_frame[1] - patch.corners_in_frame[0];
  const Eigen::Vector2d e2 = patch.corners_in_frame[2] - patch.corners_in_frame[0];
  return 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x()) / (t * t);
}

double PatchMemoryBytes(double patch_texels, double surface_texels, int feature_planes) {
  const double like_triangles = std::min(patch_texels, 4.0 * surface_texels);
  return feature_planes * (20.0 * like_triangles + 3.0 * (patch_texels - like_triangles));
}

}  // namespace

double PatchMemoryBytes(const PatchGeometry& geometry, int feature_planes) {
  return PatchMemoryBytes(static_cast<double>(geometry.total_texels), geometry.surface_texels,
                          feature_planes);
}

double PatchMemoryBytes(const PatchGeometry& geometry, int feature_planes,
                        const std::vector<char>& held) {
  TEXLUME_CHECK(held.size() == geometry.patches.size() && geometry.texel_size > 0.0,
                "a flag per patch of a geometry MakePatchGeometry made");
  double patch_texels = 0.0, surface_texels = 0.0;
  for (std::size_t f = 0; f < geometry.patches.size(); ++f) {
    if (!held[f]) continue;
    const TrianglePatch& p = geometry.patches[f];
    patch_texels += static_cast<double>(p.width) * p.height;
    surface_texels += TriangleTexels(p, geometry.texel_size);
  }
  return PatchMemoryBytes(patch_texels, surface_texels, feature_planes);
}

PatchGeometry MakePatchGeometry(const mesh::TriangleMesh& mesh, double t, int strip,
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

PatchGeometry MakePatchGeometry(const mesh::TriangleMesh& mesh, double t, int strip,
                                const std::vector<Eigen::Vector3d>& tangents_in_world) {
  const std::size_t num_faces = mesh.faces.size();
  PatchGeometry result;
  result.texel_size = t;
  std::int64_t& total_texels = result.total_texels;
  int& widest = result.widest;
  int& tallest = result.tallest;
  result.patches.resize(num_faces);
  for (std::size_t f = 0; f < num_faces; ++f) {
    TrianglePatch& patch = result.patches[f];
    patch.frame = mesh::MakeTriangleFrame(mesh, f, tangents_in_world[f]);
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
    result.surface_texels += TriangleTexels(patch, t);
  }
  // Unfoldings across every shared edge.
  const std::vector<std::array<int, 3>> neighbours = mesh::FaceNeighbours(mesh);
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

}  // namespace texlume::synth
