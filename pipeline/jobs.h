#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "core/progress.h"
#include "datasets_synthetic/scene.h"
#include "pipeline/quilt_job.h"
#include "pipeline/render_job.h"
#include "pipeline/synth_job.h"
#include "ptm/fit.h"
#include "ptm/ptm.h"
#include "ptm/sphere_lights.h"
#include "sfm/inspect.h"
#include "synth/planar_synthesis.h"

// The jobs the texlume program runs that are not in synth/pipeline.h: each an
// Options struct (with Check() and ToJson(), the settings written next to its
// outputs) and a function that runs it, reporting to `out` what a user reads.
// apps/ binds the command line to these Options and does nothing else.
namespace texlume::pipeline {

/// `texlume inspect`: sfm::RunInspect, its report printed and optionally written as JSON.
struct InspectJobOptions {
  sfm::InspectOptions inspect;
  std::filesystem::path json_file;  ///< empty: none
  void Check() const { inspect.Check(); }
  nlohmann::json ToJson() const;
};
/// Returns false when images named in the model are missing (the report says which).
bool RunInspectJob(const InspectJobOptions& options, std::ostream& out, std::ostream& err,
                   const ProgressCallback& progress = {});

/// `texlume fit`: a PTM fitted to an RTI capture, written as .ptm (and EXR, web),
/// with FILE.json (settings, residuals, timings).
struct FitJobOptions {
  std::filesystem::path images_dir, lights_file, out_file;
  std::filesystem::path exr_file, web_dir;  ///< empty: not written
  ptm::FitOptions fit;
  /// "ptm" (out_file: .ptm) or "hsh" (hemispherical harmonics of `hsh_order`; out_file:
  /// RTIViewer's .rti; the web format of an HSH; no EXR, no robust fit).
  std::string basis = "ptm";
  int hsh_order = 3;
  /// Not empty: the PTM is fitted to the samples the relief leaves lit and the
  /// relief's horizon map is written here (ptm/shadowed_fit.h; every image is held
  /// in memory).
  std::filesystem::path horizon_file;
  void Check() const;
  nlohmann::json ToJson() const;
};
void RunFitJob(const FitJobOptions& options, std::ostream& out, std::ostream& err,
               const ProgressCallback& progress = {});

/// `texlume btf`: a BTF capture factorised by SVD (paper 004 §III), with the error table.
struct BtfJobOptions {
  std::filesystem::path capture_dir, out_dir;
  int components = 40;  ///< paper 004: 40. >= 1
  void Check() const;
  nlohmann::json ToJson() const;
};
void RunBtfJob(const BtfJobOptions& options, std::ostream& out,
               const ProgressCallback& progress = {});

/// `texlume relight`: a PTM rendered under one light (texture frame), and its normals.
struct RelightJobOptions {
  std::filesystem::path ptm_file, out_file;
  std::filesystem::path normals_file;                ///< empty: not written
  std::filesystem::path horizon_file;                ///< empty: no self-shadowing
  Eigen::Vector3d light = Eigen::Vector3d::UnitZ();  ///< towards the light, z > 0
  ptm::EnhancementOptions enhancement;
  void Check() const;
  nlohmann::json ToJson() const;
};
void RunRelightJob(const RelightJobOptions& options, std::ostream& out);

/// `texlume lights-from-sphere`: light directions from the highlight on a glossy sphere.
struct SphereLightsJobOptions {
  std::filesystem::path images_dir, out_file;
  std::optional<ptm::SphereCircle> circle;  ///< none: detected
  ptm::HighlightOptions highlight;
  void Check() const;
  nlohmann::json ToJson() const;
};
void RunSphereLightsJob(const SphereLightsJobOptions& options, std::ostream& out,
                        std::ostream& err);

/// `texlume synth2d`: image-constrained planar PTM synthesis (paper 003 Algorithm 1).
struct Synth2dJobOptions {
  std::filesystem::path sample_file, photos_dir, lights_file, out_dir;
  synth::PlanarSynthesisOptions synthesis;
  void Check() const;
  nlohmann::json ToJson() const;
};
void RunSynth2dJob(const Synth2dJobOptions& options, std::ostream& out, std::ostream& err);

/// `texlume synth`: the main job with a PTM sample, or with a BTF sample when `btf`
/// is set (the BTF job takes the PTM job's paths, layout and shared synthesis settings).
struct SynthCommandOptions {
  pipeline::SynthJobOptions job;
  std::filesystem::path btf;  ///< a BTF capture or factorisation folder; empty: a PTM sample
  int components = 40;
  std::optional<int> seam_band;                              ///< none: min(4, strip)
  std::optional<double> correction_noise, correction_sigma;  ///< none: each sample's default
  void Check() const;
};
void RunSynthCommandJob(const SynthCommandOptions& options, std::ostream& out, std::ostream& err,
                        const ProgressCallback& progress = {});

/// `texlume synth --engine graphcut`: RunQuiltJob, and a line of what it did.
void RunQuiltCommandJob(const QuiltJobOptions& options, std::ostream& out, std::ostream& err,
                        const ProgressCallback& progress = {});

/// `texlume render`: pipeline::RunRenderJob, drawing a BTF model folder as a BTF
/// unless a baseline is asked for.
void RunRenderCommandJob(pipeline::RenderJobOptions options, bool baseline_asked, std::ostream& out,
                         std::ostream& err, const ProgressCallback& progress = {});

/// `texlume scene`: a synthetic heritage scene with ground truth.
void RunSceneJob(const datasets::SceneOptions& options, const std::filesystem::path& out_dir,
                 std::ostream& out, const ProgressCallback& progress = {});

/// `texlume demo`: the whole job on a synthetic scene, with report.html and run.json.
struct DemoJobOptions {
  std::filesystem::path out_dir = "out";
  datasets::SceneShape shape = datasets::SceneShape::kSphere;
  datasets::MaterialKind material = datasets::MaterialKind::kStone;
  std::uint32_t seed = 1;
  /// The object photos: how many, and their size in pixels (the focal length
  /// follows the width, so a smaller photo shows the same view).
  int num_images = 36;
  int image_width = 640;
  int image_height = 480;
  /// What the camera adds to the scene's photos (off: the clean scene).
  datasets::SensorOptions sensor;
  /// How long one world unit is, in millimetres (`--world-unit`, passed to synth); 0 = not
  /// stated.
  double mm_per_world_unit = 0.0;
  void Check() const;
  nlohmann::json ToJson() const;
};
void RunDemoJob(const DemoJobOptions& options, std::ostream& out, std::ostream& err,
                const ProgressCallback& progress = {});

}  // namespace texlume::pipeline
