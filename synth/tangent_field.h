#pragma once

#include <Eigen/Core>
#include <array>
#include <functional>
#include <opencv2/core.hpp>
#include <vector>

#include "mesh/triangle_frame.h"
#include "synth/triangle_parts.h"

namespace texlume::synth {

/// Structure tensor of a grid's luminance (the mean of `planes`), summed over
/// the cells whose 3 x 3 neighbourhood lies inside `mask` (> 0; empty: all):
/// sum g g^T, g the luminance gradient per texel in frame axes (x right, y up;
/// the grid's rows run down). `cells_per_texel_x/y`: the grid's density.
Eigen::Matrix2d LuminanceStructureTensor(const std::vector<cv::Mat>& planes, const cv::Mat& mask,
                                         double cells_per_texel_x, double cells_per_texel_y);

/// The dominant gradient direction of a structure tensor (radians, in [0, pi))
/// and its coherence (l1 - l2) / (l1 + l2) in [0, 1] (0: isotropic or empty).
struct Orientation {
  double angle_rad = 0.0;
  double coherence = 0.0;
};
Orientation DominantOrientation(const Eigen::Matrix2d& tensor);

/// The sample's structure tensor, summed over 9 lights (from above, and from 8
/// sides at 45 degrees of elevation) so that no light's shading favours a
/// direction: `relit(l)` gives the sample's planes under the light direction l
/// (its texel axes) at `cells_per_texel_x/y`.
Eigen::Matrix2d SampleStructureTensor(
    const std::function<std::vector<cv::Mat>(const Eigen::Vector3d&)>& relit,
    double cells_per_texel_x, double cells_per_texel_y);

/// A line field on the faces, aligned with the photos: per face the turn of the
/// tangent frame's x axis from the face's current x axis (radians), and the
/// world tangent it gives.
struct PhotoTangentField {
  std::vector<double> turn_rad;
  std::vector<Eigen::Vector3d> tangents_in_world;
  int faces_with_photos = 0;    ///< faces whose photos gave a tensor
  double mean_coherence = 0.0;  ///< of those faces' tensors
};

/// Default weight of the field's smoothness against the photos (see below).
inline constexpr double kPhotoFieldSmoothness = 1.0;

/// Orients the faces' frames so that the sample's texture, laid in them, runs
/// the way the photos show (beyond paper 003, which takes v0 -> v1; the line
/// field of paper 001 §3.1, 2-way symmetric, found as paper 002 eq. 2 finds its
/// field: a smoothness term plus a penalty toward the constraints).
/// `photo_tensors[f]`: the photos' luminance structure tensor in face f's
/// current frame (zero: no photo); `sample_tensor`: the sample's, in its own
/// texel axes (x right, y up). A face's constraint is the turn a_f that takes
/// its photos' dominant direction onto the sample's, as the doubled-angle unit
/// vector z_f = exp(2 i a_f), weighted by the photos' coherence c_f. The field
/// u_f (doubled angles, so a turn by pi is the same line) minimises
///   sum_f c_f |u_f - z_f|^2 + smoothness * sum_edges |u_f - T_fg u_g|^2,
/// T_fg carrying g's doubled angle into f's frame across the shared edge (the
/// unfolding's rotation), by a sparse Cholesky solve; turn_f = arg(u_f) / 2.
/// Faces and components with no photo follow their neighbours, or keep their
/// frame. `frames` and `unfoldings` are per face (MakePatchGeometry's).
PhotoTangentField PhotoAlignedTangents(const std::vector<mesh::TriangleFrame>& frames,
                                       const std::vector<std::array<Unfolding, 3>>& unfoldings,
                                       const std::vector<Eigen::Matrix2d>& photo_tensors,
                                       const Eigen::Matrix2d& sample_tensor,
                                       double smoothness = kPhotoFieldSmoothness);

/// What ChoosePhotoFrames decided.
struct FrameChoice {
  TangentFrame tangent_frame = TangentFrame::kFirstEdge;  ///< kPhotos or kFirstEdge
  double sample_coherence = -1.0;  ///< -1: not measured (no face seen in a photo)
  PhotoTangentField field;         ///< kPhotos: the field; else empty
};

/// Frames for kPhotos and kAuto, shared by the PTM and BTF synthesis: the
/// sample's tensor at the median of the faces' photo density levels
/// (`face_levels`, -1 for a face seen in no photo) decides, for kAuto, whether
/// the sample is anisotropic (coherence >= kAnisotropicSampleCoherence); then
/// the photos' tensors (`photo_tensor(face)`, in the face's current frame) and
/// PhotoAlignedTangents give the field, from the patches' current frames.
/// kFirstEdge: the frames stay.
FrameChoice ChoosePhotoFrames(TangentFrame requested, const std::vector<TrianglePatch>& patches,
                              const std::vector<std::array<Unfolding, 3>>& unfoldings,
                              const std::vector<int>& face_levels,
                              const std::function<Eigen::Matrix2d(int level)>& sample_tensor_at,
                              const std::function<Eigen::Matrix2d(std::size_t face)>& photo_tensor);

}  // namespace texlume::synth
