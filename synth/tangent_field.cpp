#include "synth/tangent_field.h"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>

namespace texlume::synth {

Eigen::Matrix2d LuminanceStructureTensor(const std::vector<cv::Mat>& planes, const cv::Mat& mask,
                                         double cells_per_texel_x, double cells_per_texel_y) {
  Eigen::Matrix2d tensor = Eigen::Matrix2d::Zero();
  if (planes.empty() || planes[0].rows < 3 || planes[0].cols < 3) return tensor;
  cv::Mat luminance = cv::Mat::zeros(planes[0].size(), CV_32FC1);
  for (const cv::Mat& p : planes) luminance += p;
  luminance /= static_cast<double>(planes.size());
  cv::Mat d_col, d_row;  // per cell; Sobel's 3 x 3 weights sum to 8 per side
  cv::Sobel(luminance, d_col, CV_32F, 1, 0, 3, 1.0 / 8.0);
  cv::Sobel(luminance, d_row, CV_32F, 0, 1, 3, 1.0 / 8.0);
  cv::Mat inside;
  if (!mask.empty()) {
    cv::Mat m = mask > 0;
    cv::erode(m, inside, cv::Mat::ones(3, 3, CV_8UC1), cv::Point(-1, -1), 1, cv::BORDER_CONSTANT,
              cv::Scalar(0));
  }
  for (int j = 1; j + 1 < luminance.rows; ++j)
    for (int i = 1; i + 1 < luminance.cols; ++i) {
      if (!inside.empty() && !inside.at<std::uint8_t>(j, i)) continue;
      // Per texel, frame axes: y up, rows down.
      const Eigen::Vector2d g(d_col.at<float>(j, i) * cells_per_texel_x,
                              -d_row.at<float>(j, i) * cells_per_texel_y);
      tensor += g * g.transpose();
    }
  return tensor;
}

Orientation DominantOrientation(const Eigen::Matrix2d& tensor) {
  Orientation o;
  const double a = tensor(0, 0) - tensor(1, 1), b = 2.0 * tensor(0, 1);
  const double trace = tensor(0, 0) + tensor(1, 1);
  if (!(trace > 0.0) || !std::isfinite(trace)) return o;
  // The doubled-angle vector (a, b) has length l1 - l2 and angle 2 theta.
  o.coherence = std::clamp(std::hypot(a, b) / trace, 0.0, 1.0);
  double angle = 0.5 * std::atan2(b, a);
  if (angle < 0.0) angle += std::numbers::pi;
  o.angle_rad = angle;
  return o;
}

Eigen::Matrix2d SampleStructureTensor(
    const std::function<std::vector<cv::Mat>(const Eigen::Vector3d&)>& relit,
    double cells_per_texel_x, double cells_per_texel_y) {
  Eigen::Matrix2d tensor = Eigen::Matrix2d::Zero();
  for (int k = -1; k < 8; ++k) {
    const double azimuth = k * std::numbers::pi / 4.0,
                 elevation = k < 0 ? std::numbers::pi / 2.0 : std::numbers::pi / 4.0;
    const Eigen::Vector3d light(std::cos(elevation) * std::cos(azimuth),
                                std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
    tensor +=
        LuminanceStructureTensor(relit(light), cv::Mat(), cells_per_texel_x, cells_per_texel_y);
  }
  return tensor;
}

PhotoTangentField PhotoAlignedTangents(const std::vector<mesh::TriangleFrame>& frames,
                                       const std::vector<std::array<Unfolding, 3>>& unfoldings,
                                       const std::vector<Eigen::Matrix2d>& photo_tensors,
                                       const Eigen::Matrix2d& sample_tensor, double smoothness) {
  const std::size_t num_faces = frames.size();
  PhotoTangentField field;
  field.turn_rad.assign(num_faces, 0.0);
  field.tangents_in_world.resize(num_faces);
  for (std::size_t f = 0; f < num_faces; ++f) field.tangents_in_world[f] = frames[f].x_axis;
  if (num_faces == 0) return field;
  const double sample_angle = DominantOrientation(sample_tensor).angle_rad;
  // Unknowns: per face the doubled-angle vector (u_x, u_y) = |u| (cos 2a, sin 2a).
  const Eigen::Index n = static_cast<Eigen::Index>(2 * num_faces);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(num_faces * 16);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
  // Faces seen in no photo are held toward their own frame, so weakly that
  // any neighbour with photos outweighs it (the system stays positive definite).
  constexpr double kNoPhotoWeight = 1e-6;
  double coherence_sum = 0.0;
  for (std::size_t f = 0; f < num_faces; ++f) {
    const Orientation photos = DominantOrientation(photo_tensors[f]);
    double weight = kNoPhotoWeight, turn = 0.0;
    if (photos.coherence > 0.0) {
      // Turning the frame by a moves a direction at angle phi to phi - a: the
      // photos' dominant direction lands on the sample's for a = phi - phi_s.
      turn = photos.angle_rad - sample_angle;
      weight = std::max(photos.coherence, kNoPhotoWeight);
      ++field.faces_with_photos;
      coherence_sum += photos.coherence;
    }
    const Eigen::Index i = static_cast<Eigen::Index>(2 * f);
    entries.emplace_back(i, i, weight);
    entries.emplace_back(i + 1, i + 1, weight);
    rhs[i] = weight * std::cos(2.0 * turn);
    rhs[i + 1] = weight * std::sin(2.0 * turn);
  }
  if (field.faces_with_photos > 0) field.mean_coherence = coherence_sum / field.faces_with_photos;
  // Smoothness: |u_f - T u_g|^2 once per shared edge, T the rotation by -2 beta
  // (a direction at theta in f's frame is at theta + beta in g's).
  for (std::size_t f = 0; f < num_faces; ++f)
    for (const Unfolding& u : unfoldings[f]) {
      if (u.face < 0 || static_cast<std::size_t>(u.face) <= f) continue;
      const double beta = std::atan2(u.rotation(1, 0), u.rotation(0, 0));
      const double c = std::cos(-2.0 * beta), s = std::sin(-2.0 * beta);
      const Eigen::Index i = static_cast<Eigen::Index>(2 * f);
      const Eigen::Index j = static_cast<Eigen::Index>(2 * u.face);
      const Eigen::Matrix2d t_fg = (Eigen::Matrix2d() << c, -s, s, c).finished();
      for (int r = 0; r < 2; ++r) {
        entries.emplace_back(i + r, i + r, smoothness);
        entries.emplace_back(j + r, j + r, smoothness);
        for (int k = 0; k < 2; ++k) {
          entries.emplace_back(i + r, j + k, -smoothness * t_fg(r, k));
          entries.emplace_back(j + k, i + r, -smoothness * t_fg(r, k));
        }
      }
    }
  Eigen::SparseMatrix<double> a(n, n);
  a.setFromTriplets(entries.begin(), entries.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(a);
  if (solver.info() != Eigen::Success) return field;
  const Eigen::VectorXd u = solver.solve(rhs);
  if (solver.info() != Eigen::Success) return field;
  for (std::size_t f = 0; f < num_faces; ++f) {
    const double ux = u[static_cast<Eigen::Index>(2 * f)],
                 uy = u[static_cast<Eigen::Index>(2 * f + 1)];
    if (!(std::hypot(ux, uy) > 1e-12)) continue;  // no direction: keep the frame
    const double turn = 0.5 * std::atan2(uy, ux);
    field.turn_rad[f] = turn;
    field.tangents_in_world[f] =
        std::cos(turn) * frames[f].x_axis + std::sin(turn) * frames[f].y_axis;
  }
  return field;
}

FrameChoice ChoosePhotoFrames(
    TangentFrame requested, const std::vector<TrianglePatch>& patches,
    const std::vector<std::array<Unfolding, 3>>& unfoldings, const std::vector<int>& face_levels,
    const std::function<Eigen::Matrix2d(int level)>& sample_tensor_at,
    const std::function<Eigen::Matrix2d(std::size_t face)>& photo_tensor) {
  FrameChoice choice;
  if (requested != TangentFrame::kPhotos && requested != TangentFrame::kAuto) return choice;
  std::vector<int> levels;
  for (const int level : face_levels)
    if (level >= 0) levels.push_back(level);
  if (levels.empty()) return choice;
  const auto middle = levels.begin() + static_cast<std::ptrdiff_t>(levels.size() / 2);
  std::nth_element(levels.begin(), middle, levels.end());
  const Eigen::Matrix2d sample_tensor = sample_tensor_at(*middle);
  choice.sample_coherence = DominantOrientation(sample_tensor).coherence;
  if (requested == TangentFrame::kAuto && choice.sample_coherence < kAnisotropicSampleCoherence)
    return choice;
  std::vector<Eigen::Matrix2d> photo_tensors(patches.size(), Eigen::Matrix2d::Zero());
  std::vector<mesh::TriangleFrame> frames(patches.size());
  for (std::size_t f = 0; f < patches.size(); ++f) {
    frames[f] = patches[f].frame;
    if (face_levels[f] >= 0) photo_tensors[f] = photo_tensor(f);
  }
  choice.field = PhotoAlignedTangents(frames, unfoldings, photo_tensors, sample_tensor);
  choice.tangent_frame = TangentFrame::kPhotos;
  return choice;
}

}  // namespace texlume::synth
