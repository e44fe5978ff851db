#include <gtest/gtest.h>

#include <limits>

#include "core/errors.h"
#include "core/memory_budget.h"
#include "datasets_synthetic/shapes.h"
#include "model/baselines.h"
#include "pipeline/jobs.h"
#include "pipeline/render_job.h"
#include "pipeline/synth_job.h"
#include "tests/test_util.h"

namespace texlume::synth {
namespace {

pipeline::SynthJobOptions CompleteSynthJob() {
  pipeline::SynthJobOptions o;
  o.model_dir = "sparse";
  o.images_dir = "images";
  o.lights_file = "lights.json";
  o.mesh_file = "mesh.ply";
  o.sample_file = "sample.ptm";
  o.out_dir = "model";
  o.synthesis.sample_texel_size = 0.002;
  return o;
}

// The demo's photo count and size: refused outside the scene's ranges, naming the option.
TEST(DemoJobOptions, PhotoCountAndSizeOutsideTheirRangesNameTheirOption) {
  // The OptionError's message, or "" when Check() accepts the options.
  const auto refusal = [](const pipeline::DemoJobOptions& options) {
    try {
      options.Check();
    } catch (const OptionError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  pipeline::DemoJobOptions o;
  EXPECT_NO_THROW(o.Check());
  o.num_images = 2;
  EXPECT_NE(refusal(o).find("--images"), std::string::npos) << "2 photos: " << refusal(o);
  o = pipeline::DemoJobOptions();
  o.image_height = 8193;
  EXPECT_NE(refusal(o).find("--height"), std::string::npos) << "8193 high: " << refusal(o);
  o = pipeline::DemoJobOptions();
  o.image_width = 320;
  o.image_height = 240;
  o.num_images = 12;
  EXPECT_NO_THROW(o.Check());
  EXPECT_EQ(o.ToJson()["num_images"], 12);
}

TEST(SynthJobOptions, MissingPathsAndOutOfRangeSettingsAreRefused) {
  pipeline::SynthJobOptions o = CompleteSynthJob();
  EXPECT_NO_THROW(o.Check());
  o.sample_file.clear();
  EXPECT_THROW(o.Check(), OptionError);
  EXPECT_NO_THROW(o.CheckInputsAndLayout());  // the BTF job has no sample file
  o = CompleteSynthJob();
  o.mesh_file.clear();
  EXPECT_THROW(o.CheckInputsAndLayout(), OptionError);
  o = CompleteSynthJob();
  o.max_subdivisions = 7;
  EXPECT_THROW(o.Check(), OptionError);
  o = CompleteSynthJob();
  o.synthesis.sample_texel_size = 0.0;
  EXPECT_THROW(o.Check(), OptionError);
  o = CompleteSynthJob();
  o.atlas.gutter = 0;
  EXPECT_THROW(o.Check(), OptionError);
  EXPECT_THROW(pipeline::RunSynthJob(o), OptionError);
  // The sample horizon's settings need the horizon, and a gain in [0.25, 4] or auto.
  o = CompleteSynthJob();
  o.shadowed_synthesis = true;
  EXPECT_THROW(o.Check(), OptionError);
  o.sample_horizon_file = "horizon.exr";
  EXPECT_NO_THROW(o.Check());
  for (const double gain : {0.1, 5.0, std::numeric_limits<double>::quiet_NaN()}) {
    o.atlas_relief_gain = gain;
    EXPECT_THROW(o.Check(), OptionError) << gain;
  }
  o.atlas_relief_gain = 1.5;
  EXPECT_NO_THROW(o.Check());
  o.sample_horizon_file.clear();
  o.shadowed_synthesis = false;
  EXPECT_THROW(o.Check(), OptionError);
}

// A graph-cut fill whose dense surface the memory limit cannot hold is refused
// up front, naming the mesh and giving the estimate (quilt::QuiltingBytes).
TEST(SynthJobOptions, AGraphCutFillTheMemoryCannotHoldIsRefusedWithTheEstimate) {
  pipeline::SynthJobOptions job;
  job.mesh_file = "statue.ply";
  const mesh::TriangleMesh sphere = datasets::MakeIcosphere(3, 1.0);  // area about 12.5
  const double bytes = quilt::QuiltingBytes(sphere, 0.001, 6);
  EXPECT_GT(bytes, 1.6 * 12.0 / 1e-6 * 64);
  SetMemoryLimitBytes(static_cast<std::uint64_t>(bytes / 2));
  const std::string message =
      testing::InputErrorMessage([&] { pipeline::RequireFillMemory(job, sphere, 0.001, 6); });
  SetMemoryLimitBytes(0);
  EXPECT_NE(message.find("statue.ply"), std::string::npos) << message;
  EXPECT_NE(message.find("--fill-unseen graphcut"), std::string::npos) << message;
  EXPECT_NO_THROW(pipeline::RequireFillMemory(job, sphere, 0.01, 6));  // 100 times fewer samples
}

// Detail transfer's reach is how far past a triangle the bake reads its patch: the
// gutter ring in atlas pixels (each up to the charts' largest stretch in texels) or
// half the blend strip into a neighbour, whichever is farther.
TEST(SynthJobOptions, DetailTransferReachesAsFarAsTheBakeReads) {
  pipeline::SynthJobOptions job;
  EXPECT_LT(job.synthesis.detail_reach_texels, 0.0);  // a library caller: every cell
  job.atlas.gutter = 2, job.atlas.blend_strip = 8, job.atlas.max_chart_stretch = 1.25;
  EXPECT_DOUBLE_EQ(pipeline::SynthesisOptionsOf(job).detail_reach_texels, 4.0);
  job.atlas.gutter = 6;
  EXPECT_DOUBLE_EQ(pipeline::SynthesisOptionsOf(job).detail_reach_texels, 6.5 * 1.25);
  synth::MeshSynthesisOptions options = pipeline::SynthesisOptionsOf(job);
  options.sample_texel_size = 0.004;
  EXPECT_NO_THROW(options.Check());
  options.detail_reach_texels = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(options.Check(), OptionError);
}

TEST(RenderJobOptions, MissingPathsAndOutOfRangeSettingsAreRefused) {
  pipeline::RenderJobOptions o;
  EXPECT_THROW(o.Check(), OptionError);
  o.model_folder = "model";
  o.cameras_dir = "sparse";
  o.lights_file = "lights.json";
  o.out_dir = "render";
  EXPECT_NO_THROW(o.Check());
  o.samples_per_axis = 9;
  EXPECT_THROW(o.Check(), OptionError);
  o.samples_per_axis = 2;
  o.reduced_factor = 0;
  EXPECT_THROW(o.Check(), OptionError);
  o.reduced_factor = 1;
  o.truth_masks_dir = "masks";  // masks without images
  EXPECT_THROW(o.Check(), OptionError);
  EXPECT_THROW(pipeline::RunRenderJob(o), OptionError);
}

TEST(FitJobOptions, AnHshFitWritesRtiOfOrderTwoOrThreeWithoutExrOrRobustFit) {
  pipeline::FitJobOptions o;
  o.images_dir = "capture";
  o.lights_file = "capture/lights.lp";
  o.out_file = "sample.ptm";
  EXPECT_NO_THROW(o.Check());
  EXPECT_EQ(o.ToJson()["basis"], "ptm");
  o.basis = "hsh";
  EXPECT_THROW(o.Check(), OptionError);  // .ptm holds no HSH
  o.out_file = "sample.RTI";
  EXPECT_NO_THROW(o.Check());
  EXPECT_EQ(o.ToJson()["order"], 3);
  for (const int order : {1, 4}) {
    o.hsh_order = order;
    EXPECT_THROW(o.Check(), OptionError) << order;
  }
  o.hsh_order = 2;
  o.exr_file = "sample.exr";
  EXPECT_THROW(o.Check(), OptionError);
  o.exr_file.clear();
  o.fit.robust = true;
  EXPECT_THROW(o.Check(), OptionError);
  o.fit.robust = false;
  o.basis = "sh";
  EXPECT_THROW(o.Check(), OptionError);
}

TEST(RenderJobOptions, SettingsNameEveryChoice) {
  pipeline::RenderJobOptions o;
  o.model_folder = "model";
  o.mode = render::RenderMode::kBaked;
  o.reduced_factor = 2;
  o.truth_images_dir = "truth";
  const nlohmann::json s = o.ToJson();
  EXPECT_EQ(s["model"], "model");
  EXPECT_EQ(s["mode"], "baked");
  EXPECT_EQ(s["reduced_factor"], 2);
  EXPECT_EQ(s["truth_images"], "truth");
  EXPECT_FALSE(s.contains("truth_masks"));
  EXPECT_EQ(s["btf_as_btf"], true);
}

}  // namespace
}  // namespace texlume::synth
