#include "quilt/image_term.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "core/image_io.h"
#include "synth/template_match.h"
#include "synth/triangle_parts.h"

namespace texlume::quilt {
namespace {

// A Gaussian as wide as a photo pixel's footprint sampled bilinearly, in
// photo pixels: a box of one pixel (sigma 1/sqrt 12) and the interpolation's
// tent (the same again).
constexpr double kPixelFootprintSigma = 0.41;

// A photo's display RGB over the region its bilinear lookups reach, and the
// lookups: at a COLMAP pixel position (top-left corner convention) of the whole
// photo, false outside it.
class PhotoRegion {
 public:
  // The region around `positions` (COLMAP pixels) of the photo.
  PhotoRegion(const PhotoPixels& pixels, const std::vector<Eigen::Vector2d>& positions)
      : size_(pixels.size()) {
    if (positions.empty()) return;
    Eigen::Vector2d lo = positions[0], hi = positions[0];
    for (const Eigen::Vector2d& p : positions) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    origin_ = cv::Point(std::clamp(static_cast<int>(std::floor(lo.x())) - 2, 0, size_.width),
                        std::clamp(static_cast<int>(std::floor(lo.y())) - 2, 0, size_.height));
    const cv::Point end(std::clamp(static_cast<int>(std::floor(hi.x())) + 3, 0, size_.width),
                        std::clamp(static_cast<int>(std::floor(hi.y())) + 3, 0, size_.height));
    if (end.x > origin_.x && end.y > origin_.y) display_ = pixels.Display(cv::Rect(origin_, end));
  }

  // The bilinear value at `px`, as read from the whole photo.
  bool At(const Eigen::Vector2d& px, float rgb[3]) const {
    const double x = px.x() - 0.5, y = px.y() - 0.5;
    if (!(x >= 0 && y >= 0 && x <= size_.width - 1 && y <= size_.height - 1)) return false;
    const int x0 = std::min(static_cast<int>(x), size_.width - 2);
    const int y0 = std::min(static_cast<int>(y), size_.height - 2);
    const float fx = static_cast<float>(x - x0), fy = static_cast<float>(y - y0);
    const cv::Vec3f* r0 = display_.ptr<cv::Vec3f>(y0 - origin_.y) - origin_.x;
    const cv::Vec3f* r1 = display_.ptr<cv::Vec3f>(y0 + 1 - origin_.y) - origin_.x;
    for (int c = 0; c < 3; ++c)
      rgb[c] = (1 - fy) * ((1 - fx) * r0[x0][c] + fx * r0[x0 + 1][c]) +
               fy * ((1 - fx) * r1[x0][c] + fx * r1[x0 + 1][c]);
    return true;
  }

 private:
  cv::Size size_;
  cv::Point origin_;
  cv::Mat display_;
};

// A direction of the work frame turned by -rad about its normal.
Eigen::Vector3d TurnedBack(const Eigen::Vector3d& d, double rad) {
  const double c = std::cos(rad), s = std::sin(rad);
  return {c * d.x() + s * d.y(), -s * d.x() + c * d.y(), d.z()};
}

}  // namespace

PhotoImageTerm::PhotoImageTerm(const DenseSurface& surface, const atlas::AtlasLayout& layout,
                               const synth::MaterialSample& sample, const PhotoEvidence& photos,
                               const ImageTermOptions& options)
    : surface_(surface), layout_(layout), sample_(sample), photos_(photos), options_(options) {
  for (std::size_t n = 0; n < photos.photos.size(); ++n)
    photo_index_[photos.photos[n].image_id] = n;
}

PatchImageTerm::Score PhotoImageTerm::Placements(int seed,
                                                 const std::vector<WorkImageSample>& samples,
                                                 cv::Size work_size, int rotation,
                                                 const RotatedSample& rotated) {
  Score score;
  const int face = surface_.samples()[static_cast<std::size_t>(seed)].face;
  if (relit_face_ != face) relit_.clear(), relit_face_ = face;  // a retry keeps them
  const std::vector<View> views = ViewsOf(face);
  for (const View& view : views) {
    std::vector<cv::Mat> photo;
    cv::Mat mask;
    const int count = PhotoPlanes(view, samples, work_size, photo, mask);
    const double r2 = view.px_per_texel * view.px_per_texel;
    if (count * std::min(r2, 1.0) < options_.min_photo_pixels) continue;
    const std::vector<cv::Mat>& relit = RelitCopy(face, view, rotation, rotated);
    const Relit& cached = relit_.at(view.photo);
    if (score.rms.empty()) {
      const int side = rotated.side();
      score.rms = cv::Mat::zeros(side - work_size.height + 1, side - work_size.width + 1, CV_32FC1);
      score.stride = std::max(1, static_cast<int>(std::floor(1.0 / view.px_per_texel)));
    }
    // Eq. 3 of paper 003 for this photo (RMS over its pixels and R, G, B).
    synth::AddImageScore(synth::MaskedSsd(relit, cached.energy, photo, mask), count, 1.0, 1.0,
                         score.rms);
  }
  return score;
}

std::vector<PhotoImageTerm::View> PhotoImageTerm::ViewsOf(int face) const {
  std::vector<View> views;
  const atlas::FacePlacement& placement = layout_.faces[static_cast<std::size_t>(face)];
  const auto& c = placement.corners_px;  // atlas pixels are texels
  const double texels2 =
      0.5 * std::abs((c[1] - c[0]).x() * (c[2] - c[0]).y() - (c[1] - c[0]).y() * (c[2] - c[0]).x());
  for (const sfm::TriangleView& view :
       synth::ConstrainingViews(photos_.visibility.triangles[static_cast<std::size_t>(face)],
                                options_.all_views, options_.max_views)) {
    const auto it = photo_index_.find(view.image_id);
    if (it == photo_index_.end()) continue;
    views.push_back(
        {it->second, std::sqrt(std::max(view.projected_area_px, 1e-6f) / std::max(texels2, 1e-9))});
  }
  return views;
}

bool PhotoImageTerm::SeesFully(std::size_t photo, int face) const {
  const sfm::ImageId id = photos_.photos[photo].image_id;
  for (const sfm::TriangleView& v :
       photos_.visibility.triangles[static_cast<std::size_t>(face)].views)
    if (v.image_id == id) return v.fully_visible;
  return false;
}

int PhotoImageTerm::PhotoPlanes(const View& view, const std::vector<WorkImageSample>& samples,
                                cv::Size work_size, std::vector<cv::Mat>& planes,
                                cv::Mat& mask) const {
  const synth::MeshPhoto& photo = photos_.photos[view.photo];
  const sfm::Image& image = photos_.reconstruction.images.at(photo.image_id);
  planes.assign(3, cv::Mat());
  for (cv::Mat& plane : planes) plane = cv::Mat::zeros(work_size, CV_32FC1);
  mask = cv::Mat::zeros(work_size, CV_32FC1);
  // The work cells the photo may constrain, and where it sees them.
  std::vector<const WorkImageSample*> cells;
  std::vector<Eigen::Vector2d> positions;
  cv::Mat taken = cv::Mat::zeros(work_size, CV_8UC1);
  std::map<int, bool> seen;  // per face met
  for (const WorkImageSample& w : samples) {
    const int face = surface_.samples()[static_cast<std::size_t>(w.sample)].face;
    auto it = seen.find(face);
    if (it == seen.end()) it = seen.emplace(face, SeesFully(view.photo, face)).first;
    if (w.synthesised || !it->second || taken.at<std::uint8_t>(w.y, w.x)) continue;
    const auto px = photos_.reconstruction.Project(image, surface_.PointInWorld(w.sample));
    const double x = px ? px->x() - 0.5 : -1.0, y = px ? px->y() - 0.5 : -1.0;
    const cv::Size size = photo.pixels.size();
    if (!(x >= 0 && y >= 0 && x <= size.width - 1 && y <= size.height - 1)) continue;
    taken.at<std::uint8_t>(w.y, w.x) = 1;
    cells.push_back(&w);
    positions.push_back(*px);
  }
  const PhotoRegion region(photo.pixels, positions);
  int count = 0;
  for (std::size_t k = 0; k < cells.size(); ++k) {
    const WorkImageSample& w = *cells[k];
    float rgb[3];
    if (!region.At(positions[k], rgb)) continue;
    for (int c = 0; c < 3; ++c) {
      const float v = rgb[c];
      planes[static_cast<std::size_t>(c)].at<float>(w.y, w.x) =
          sample_.Domain() == synth::PhotoDomain::kLinear ? SrgbToLinear(v) : v;
    }
    mask.at<float>(w.y, w.x) = 1.0f;
    ++count;
  }
  if (!photos_.photometry.white_balance.empty())
    synth::TakeOutWhiteBalance(photos_.photometry.white_balance[view.photo], sample_.Domain(),
                               planes);
  return count;
}

synth::FaceLighting PhotoImageTerm::LightingOf(int face, const View& view, double copy_rad) const {
  const AtlasAxes axes = AtlasAxesOf(surface_, layout_, face);
  mesh::TriangleFrame work{surface_.FrameOf(face).origin_in_world, axes.x, axes.y, axes.normal};
  const synth::MeshPhoto& photo = photos_.photos[view.photo];
  synth::FaceLighting lighting = synth::LightingInFrame(
      work, photos_.reconstruction.images.at(photo.image_id).ProjectionCenter(), photo.lights,
      photos_.photometry.light_response);
  lighting.view_in_frame = TurnedBack(lighting.view_in_frame, copy_rad);
  for (auto& [l, intensity] : lighting.lights) l = TurnedBack(l, copy_rad);
  return lighting;
}

const std::vector<cv::Mat>& PhotoImageTerm::RelitCopy(int face, const View& view, int rotation,
                                                      const RotatedSample& rotated) {
  Relit& relit = relit_[view.photo];
  if (relit.rotation == rotation) return relit.planes;
  const double gain =
      photos_.photometry.photo_gains.empty() ? 1.0 : photos_.photometry.photo_gains[view.photo];
  relit.planes = rotated.TurnPlanes(
      rotation, sample_.Relight(sample_.Reduced(0),
                                LightingOf(face, view, RotatedSample::AngleOf(rotation)), gain));
  // The photo's resolution and blur (photo pixels) in texels.
  const double blur_px =
      photos_.photometry.photo_blur.empty() ? 0.0 : photos_.photometry.photo_blur[view.photo];
  const double footprint_px = view.px_per_texel < 1.0 ? kPixelFootprintSigma : 0.0;
  const double sigma =
      std::min(std::hypot(footprint_px, blur_px) / view.px_per_texel, rotated.side() / 4.0);
  if (sigma > 0.3)
    for (cv::Mat& plane : relit.planes) cv::GaussianBlur(plane, plane, cv::Size(), sigma);
  relit.energy = synth::PlaneEnergy(relit.planes);
  relit.rotation = rotation;
  return relit.planes;
}

}  // namespace texlume::quilt
