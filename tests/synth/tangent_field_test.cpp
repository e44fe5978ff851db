// Frames turned to the photos (synth/tangent_field.h): structure tensors of
// known stripes, and line fields on a plane and a cylinder with known answers
// (photo_frames_test.cpp: the frames on a photographed brick column).
#include "synth/tangent_field.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "datasets_synthetic/shapes.h"
#include "synth/mesh_synthesis.h"

namespace texlume::synth {
namespace {

constexpr double kPi = std::numbers::pi;

// Angle between two lines (radians, in [0, pi/2]).
double LineAngle(double a, double b) {
  const double d = std::fmod(std::abs(a - b), kPi);
  return std::min(d, kPi - d);
}
double LineAngle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(std::abs(a.normalized().dot(b.normalized())), 0.0, 1.0));
}

// Stripes varying along direction `angle` of the frame (x right, y up) on a grid
// of `rx` x `ry` cells per texel, rows down: cell (i, j) is at frame point
// ((i + 0.5) / rx, -(j + 0.5) / ry).
cv::Mat Stripes(cv::Size size, double angle, double period_texels, double rx, double ry) {
  cv::Mat m(size, CV_32FC1);
  for (int j = 0; j < size.height; ++j)
    for (int i = 0; i < size.width; ++i) {
      const double x = (i + 0.5) / rx, y = -(j + 0.5) / ry;
      m.at<float>(j, i) = static_cast<float>(
          0.5 +
          0.4 * std::sin(2 * kPi * (x * std::cos(angle) + y * std::sin(angle)) / period_texels));
    }
  return m;
}

TEST(LuminanceStructureTensor, FindsTheDirectionStripesVaryIn) {
  for (const double angle : {0.0, 0.4, 1.2, 2.0, 2.9}) {
    for (const auto& [rx, ry] : {std::pair{1.0, 1.0}, std::pair{0.5, 0.7}}) {
      const cv::Mat l = Stripes(cv::Size(48, 40), angle, 16.0, rx, ry);
      const Orientation o =
          DominantOrientation(LuminanceStructureTensor({l, l, l}, cv::Mat(), rx, ry));
      EXPECT_LT(LineAngle(o.angle_rad, angle), 2.0 * kPi / 180.0) << angle << " " << rx;
      EXPECT_GT(o.coherence, 0.9);
      EXPECT_GE(o.angle_rad, 0.0);
      EXPECT_LT(o.angle_rad, kPi);
    }
  }
}

TEST(LuminanceStructureTensor, IgnoresCellsOutsideTheMaskAndNoiseIsIsotropic) {
  // Vertical stripes inside the mask, horizontal ones outside it.
  const cv::Size size(60, 60);
  cv::Mat l = Stripes(size, 0.0, 8.0, 1.0, 1.0);
  const cv::Mat outside = Stripes(size, kPi / 2, 8.0, 1.0, 1.0);
  cv::Mat mask = cv::Mat::zeros(size, CV_32FC1);
  mask(cv::Rect(10, 10, 30, 30)).setTo(1.0f);
  outside.copyTo(l, mask == 0);
  const Orientation inside = DominantOrientation(LuminanceStructureTensor({l}, mask, 1.0, 1.0));
  EXPECT_LT(LineAngle(inside.angle_rad, 0.0), 2.0 * kPi / 180.0);
  EXPECT_GT(inside.coherence, 0.9);
  // Smoothed white noise has no direction.
  cv::Mat noise(256, 256, CV_32FC1);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::NORMAL, 0.5, 0.2);
  EXPECT_LT(DominantOrientation(LuminanceStructureTensor({noise}, cv::Mat(), 1.0, 1.0)).coherence,
            0.1);
  EXPECT_EQ(DominantOrientation(Eigen::Matrix2d::Zero()).coherence, 0.0);
}

// The photos' tensor of face f when the sample's texture (dominant gradient at
// `sample_angle` in its texel axes) is laid on the surface with its x axis along
// `x_in_world`: the gradient in the world, taken into the face's frame, plus
// some isotropic texture (coherence about 0.6) and a little angular noise.
Eigen::Matrix2d PhotoTensor(const mesh::TriangleFrame& frame, const Eigen::Vector3d& x_in_world,
                            double sample_angle, std::mt19937& rng) {
  const Eigen::Vector3d x = (x_in_world - frame.z_axis * frame.z_axis.dot(x_in_world)).normalized();
  const Eigen::Vector3d y = frame.z_axis.cross(x);
  std::normal_distribution<double> noise(0.0, 5.0 * kPi / 180.0);
  const double angle = sample_angle + noise(rng);
  const Eigen::Vector3d g_world = std::cos(angle) * x + std::sin(angle) * y;
  const Eigen::Vector2d g(frame.x_axis.dot(g_world), frame.y_axis.dot(g_world));
  return g.normalized() * g.normalized().transpose() + 0.25 * Eigen::Matrix2d::Identity();
}

// A mesh's first-edge patch geometry (texels of 0.01, strip 4).
PatchGeometry FirstEdgeGeometry(const mesh::TriangleMesh& mesh) {
  return MakePatchGeometry(mesh, 0.01, 4, TangentFrame::kFirstEdge, Eigen::Vector3d::UnitZ());
}
std::vector<mesh::TriangleFrame> FramesOf(const PatchGeometry& geometry) {
  std::vector<mesh::TriangleFrame> frames;
  for (const TrianglePatch& p : geometry.patches) frames.push_back(p.frame);
  return frames;
}

Eigen::Matrix2d SampleTensor(double angle) {
  const Eigen::Vector2d g(std::cos(angle), std::sin(angle));
  return g * g.transpose() + 0.3 * Eigen::Matrix2d::Identity();
}

TEST(PhotoAlignedTangents, ALineFieldOnAPlaneFollowsThePhotosWhereverTheyAre) {
  const PatchGeometry geometry = FirstEdgeGeometry(datasets::MakeGridPlane(12, 1.2));
  const std::vector<mesh::TriangleFrame> frames = FramesOf(geometry);
  const Eigen::Vector3d truth(std::cos(0.5), std::sin(0.5), 0.0);  // the texture's x axis
  const double sample_angle = kPi / 2;  // horizontal stripes: gradients along y
  std::mt19937 rng(3);
  std::vector<Eigen::Matrix2d> tensors(frames.size(), Eigen::Matrix2d::Zero());
  // Photos see a third of the faces only.
  for (std::size_t f = 0; f < frames.size(); f += 3)
    tensors[f] = PhotoTensor(frames[f], truth, sample_angle, rng);
  const PhotoTangentField field =
      PhotoAlignedTangents(frames, geometry.unfoldings, tensors, SampleTensor(sample_angle));
  EXPECT_EQ(field.faces_with_photos, static_cast<int>((frames.size() + 2) / 3));
  EXPECT_GT(field.mean_coherence, 0.5);
  EXPECT_LT(field.mean_coherence, 0.8);
  // Photo noise of 5 degrees per face: the field averages it out.
  double worst = 0.0, mean = 0.0;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    worst = std::max(worst, LineAngle(field.tangents_in_world[f], truth));
    mean += LineAngle(field.tangents_in_world[f], truth) / static_cast<double>(frames.size());
    // The turn takes the face's own x axis onto the tangent.
    const Eigen::Vector3d turned = std::cos(field.turn_rad[f]) * frames[f].x_axis +
                                   std::sin(field.turn_rad[f]) * frames[f].y_axis;
    EXPECT_LT((turned - field.tangents_in_world[f]).norm(), 1e-9);
  }
  std::printf("plane: field within %.2f degrees of the truth (mean), %.2f (worst)\n",
              mean * 180.0 / kPi, worst * 180.0 / kPi);
  EXPECT_LT(mean, 2.0 * kPi / 180.0);
  EXPECT_LT(worst, 8.0 * kPi / 180.0);
}

TEST(PhotoAlignedTangents, ACylindersFieldRunsAroundItAcrossCurvedEdges) {
  const PatchGeometry geometry = FirstEdgeGeometry(datasets::MakeCylinder(24, 8, 0.6, 1.6));
  const std::vector<mesh::TriangleFrame> frames = FramesOf(geometry);
  std::mt19937 rng(5);
  // The way around: horizontal in the face's plane.
  auto around = [&](std::size_t f) {
    return Eigen::Vector3d::UnitZ().cross(frames[f].z_axis).normalized();
  };
  const double sample_angle = 0.3;
  std::vector<Eigen::Matrix2d> tensors(frames.size(), Eigen::Matrix2d::Zero());
  const std::size_t side_faces = 2 * 24 * 8;  // the caps follow (MakeCylinder's order)
  for (std::size_t f = 0; f < side_faces; f += 2)
    tensors[f] = PhotoTensor(frames[f], around(f), sample_angle, rng);
  const PhotoTangentField field =
      PhotoAlignedTangents(frames, geometry.unfoldings, tensors, SampleTensor(sample_angle));
  double worst = 0.0, mean = 0.0;
  for (std::size_t f = 0; f < side_faces; ++f) {
    worst = std::max(worst, LineAngle(field.tangents_in_world[f], around(f)));
    mean += LineAngle(field.tangents_in_world[f], around(f)) / static_cast<double>(side_faces);
  }
  std::printf("side faces: field within %.2f degrees of the way around (mean), %.2f (worst)\n",
              mean * 180.0 / kPi, worst * 180.0 / kPi);
  EXPECT_LT(mean, 2.0 * kPi / 180.0);
  EXPECT_LT(worst, 8.0 * kPi / 180.0);
  // First-edge frames are far from it on half the side faces (the diagonals).
  double first_edge_worst = 0.0;
  for (std::size_t f = 0; f < side_faces; ++f)
    first_edge_worst = std::max(first_edge_worst, LineAngle(frames[f].x_axis, around(f)));
  EXPECT_GT(first_edge_worst, 30.0 * kPi / 180.0);
}

TEST(ChoosePhotoFrames, AutoTurnsFramesOnlyForAnAnisotropicSample) {
  const PatchGeometry geometry = FirstEdgeGeometry(datasets::MakeGridPlane(4, 1.0));
  const std::vector<mesh::TriangleFrame> frames = FramesOf(geometry);
  std::vector<int> levels(frames.size(), 3);
  levels[0] = -1;  // seen in no photo
  int sample_level = -1;
  std::vector<std::size_t> asked;
  auto choose = [&](TangentFrame requested, const Eigen::Matrix2d& sample) {
    asked.clear();
    return ChoosePhotoFrames(
        requested, geometry.patches, geometry.unfoldings, levels,
        [&](int level) {
          sample_level = level;
          return sample;
        },
        [&](std::size_t f) {
          asked.push_back(f);
          const Eigen::Vector2d g(frames[f].x_axis.y(), frames[f].y_axis.y());  // world y
          return Eigen::Matrix2d(g * g.transpose());
        });
  };
  const FrameChoice isotropic = choose(TangentFrame::kAuto, Eigen::Matrix2d::Identity());
  EXPECT_EQ(isotropic.tangent_frame, TangentFrame::kFirstEdge);
  EXPECT_NEAR(isotropic.sample_coherence, 0.0, 1e-12);
  EXPECT_EQ(sample_level, 3);
  EXPECT_TRUE(asked.empty());
  const FrameChoice striped = choose(TangentFrame::kAuto, SampleTensor(kPi / 2));
  EXPECT_EQ(striped.tangent_frame, TangentFrame::kPhotos);
  EXPECT_GT(striped.sample_coherence, kAnisotropicSampleCoherence);
  EXPECT_EQ(asked.size(), frames.size() - 1);  // not the unseen face
  // The sample's gradients run along its y axis, the photos' along world y:
  // the texture's x axis is world x.
  for (const Eigen::Vector3d& t : striped.field.tangents_in_world)
    EXPECT_LT(LineAngle(t, Eigen::Vector3d::UnitX()), 1e-6);
  // kPhotos turns the frames whatever the sample; kFirstEdge never asks.
  EXPECT_EQ(choose(TangentFrame::kPhotos, Eigen::Matrix2d::Identity()).tangent_frame,
            TangentFrame::kPhotos);
  const FrameChoice first = choose(TangentFrame::kFirstEdge, SampleTensor(0.0));
  EXPECT_EQ(first.tangent_frame, TangentFrame::kFirstEdge);
  EXPECT_EQ(first.sample_coherence, -1.0);
  EXPECT_TRUE(asked.empty());
}

TEST(PatchMemoryBytes, SmallTrianglesStripsCostLessThanTheirTexels) {
  // A 2 x 2 plane (4e4 texels of 0.01): 2 x 2 triangles (large: patches about
  // 1.5 times the surface) and 2 x 50^2 (small: mostly strip).
  for (const int segments : {1, 50}) {
    const PatchGeometry g = FirstEdgeGeometry(datasets::MakeGridPlane(segments, 2.0));
    EXPECT_NEAR(g.surface_texels, 4e4, 1e-6);
    const double patch = static_cast<double>(g.total_texels);
    const double expected =
        patch <= 4 * g.surface_texels
            ? 6 * 20.0 * patch
            : 6 * (20.0 * 4 * g.surface_texels + 3.0 * (patch - 4 * g.surface_texels));
    EXPECT_DOUBLE_EQ(PatchMemoryBytes(g, 6), expected);
    if (segments == 1) {
      EXPECT_LT(patch, 4 * g.surface_texels);
    } else {
      EXPECT_GT(patch, 8 * g.surface_texels);  // strips: 16 x 16 texels at least per 4-texel face
      EXPECT_LT(PatchMemoryBytes(g, 6), 0.5 * 6 * 20.0 * patch);
    }
  }
}

TEST(PatchMemoryBytes, OfHeldFacesCountsOnlyThem) {
  // A rank's share (its region and the borders): every face is the whole; the
  // first half of 2 x 50^2 equal triangles is half of it; none is nothing.
  const PatchGeometry g = FirstEdgeGeometry(datasets::MakeGridPlane(50, 2.0));
  const std::size_t faces = g.patches.size();
  EXPECT_NEAR(PatchMemoryBytes(g, 6, std::vector<char>(faces, 1)), PatchMemoryBytes(g, 6),
              1e-9 * PatchMemoryBytes(g, 6));
  std::vector<char> half(faces, 0);
  std::fill(half.begin(), half.begin() + static_cast<std::ptrdiff_t>(faces / 2), 1);
  EXPECT_NEAR(PatchMemoryBytes(g, 6, half), 0.5 * PatchMemoryBytes(g, 6),
              0.02 * PatchMemoryBytes(g, 6));
  EXPECT_EQ(PatchMemoryBytes(g, 6, std::vector<char>(faces, 0)), 0.0);
}

}  // namespace
}  // namespace texlume::synth
