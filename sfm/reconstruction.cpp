#include "sfm/reconstruction.h"

namespace texlume::sfm {

std::size_t Image::NumPoints3D() const {
  std::size_t n = 0;
  for (const Point2D& p : points2d) n += p.point3d_id.IsValid() ? 1 : 0;
  return n;
}

std::size_t Reconstruction::NumObservations() const {
  std::size_t n = 0;
  for (const auto& [id, point] : points3d) n += point.track.size();
  return n;
}

double Reconstruction::MeanTrackLength() const {
  return points3d.empty()
             ? 0.0
             : static_cast<double>(NumObservations()) / static_cast<double>(points3d.size());
}

double Reconstruction::MeanObservationsPerImage() const {
  return images.empty()
             ? 0.0
             : static_cast<double>(NumObservations()) / static_cast<double>(images.size());
}

double Reconstruction::MeanReprojectionError() const {
  double sum = 0.0;
  std::size_t n = 0;
  for (const auto& [id, point] : points3d) {
    if (point.error >= 0.0) {
      sum += point.error;
      ++n;
    }
  }
  return n == 0 ? 0.0 : sum / static_cast<double>(n);
}

std::optional<Eigen::Vector2d> Reconstruction::Project(
    const Image& image, const Eigen::Vector3d& point_in_world) const {
  return cameras.at(image.camera_id).ImageFromCam(image.cam_from_world * point_in_world);
}

}  // namespace texlume::sfm
