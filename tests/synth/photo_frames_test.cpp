// Frames turned to the photos on a photographed brick column (synth/tangent_field.h,
// synth/mesh_synthesis.h): a whole scene and two syntheses, so an e2e test.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "datasets_synthetic/scene.h"
#include "pipeline/synth_job.h"
#include "synth/mesh_synthesis.h"
#include "synth/tangent_field.h"
#include "tests/test_util.h"

namespace texlume::synth {
namespace {

constexpr double kPi = std::numbers::pi;

// Angle between two lines (radians, in [0, pi/2]).
double LineAngle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(std::abs(a.normalized().dot(b.normalized())), 0.0, 1.0));
}

// A brick column photographed: quilted with first-edge frames, half its side
// faces lay the bricks along a diagonal; turned to the photos, the bricks run
// around the column as they do in the photos, and the quilted patches agree
// with the photos better (paper 003 eq. 3, summed over the constraint views).
TEST(PhotoFrames, BricksOnAColumnRunAroundItAndMatchThePhotosBetter) {
  testing::TempDir tmp;
  datasets::SceneOptions o = datasets::SmallObjectSceneOptions(datasets::SceneShape::kCylinder,
                                                               datasets::MaterialKind::kBrick);
  o.num_held_out_views = 0;
  datasets::GenerateScene(o, tmp.path() / "scene");
  const ptm::Ptm sample = datasets::FitSceneSample(tmp.path() / "scene");
  pipeline::SynthJobOptions job;
  const std::filesystem::path object = tmp.path() / "scene/object";
  job.model_dir = object / "sparse";
  job.images_dir = object / "images";
  job.lights_file = object / "lights.json";
  job.mesh_file = object / "mesh.ply";
  job.synthesis.sample_texel_size = 0.004;
  job.synthesis.correction_iterations = 0;  // the quilting alone
  job.synthesis.detail_transfer = false;
  pipeline::SynthInputs inputs = pipeline::LoadSynthInputs(job);
  pipeline::PrepareSynthMesh(inputs, job, std::min(sample.width, sample.height), 0.004,
                             job.synthesis.strip);
  auto synthesise = [&](TangentFrame frame) {
    job.synthesis.tangent_frame = frame;
    return SynthesizeMeshPtm(inputs.mesh, inputs.reconstruction, inputs.visibility, inputs.photos,
                             sample, job.synthesis);
  };
  const MeshSynthesis first_edge = synthesise(TangentFrame::kFirstEdge);
  const MeshSynthesis turned = synthesise(TangentFrame::kAuto);
  EXPECT_EQ(first_edge.sample_coherence, -1.0);
  EXPECT_GT(turned.sample_coherence, kAnisotropicSampleCoherence);
  ASSERT_EQ(turned.tangent_frame, TangentFrame::kPhotos);
  // Side faces seen in the photos: the texture's x axis against the way around.
  int side = 0, aligned = 0, aligned_first_edge = 0;
  double score_first_edge = 0.0, score_turned = 0.0;
  for (std::size_t f = 0; f < turned.patches.size(); ++f) {
    const TrianglePatch& p = turned.patches[f];
    if (std::abs(p.frame.z_axis.z()) > 0.3 || p.source != PatchSource::kPhotos ||
        first_edge.patches[f].source != PatchSource::kPhotos)
      continue;
    ++side;
    const Eigen::Vector3d around = Eigen::Vector3d::UnitZ().cross(p.frame.origin_in_world);
    aligned += LineAngle(p.frame.x_axis, around) < 15.0 * kPi / 180.0;
    aligned_first_edge +=
        LineAngle(first_edge.patches[f].frame.x_axis, around) < 15.0 * kPi / 180.0;
    score_turned += p.image_score / p.views_used;
    score_first_edge += first_edge.patches[f].image_score / first_edge.patches[f].views_used;
  }
  std::printf(
      "side faces %d: x axis within 15 degrees of the way around %d (first edge %d); mean image "
      "score %.4f (first edge %.4f); sample coherence %.3f\n",
      side, aligned, aligned_first_edge, score_turned / side, score_first_edge / side,
      turned.sample_coherence);
  ASSERT_GT(side, 100);
  EXPECT_GT(aligned, 0.9 * side);
  EXPECT_LT(aligned_first_edge, 0.75 * side);
  EXPECT_LT(score_turned, 0.95 * score_first_edge);
}

}  // namespace
}  // namespace texlume::synth
