#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "apps/cli.h"
#include "apps/commands.h"
#include "apps/progress_bar.h"
#include "core/errors.h"
#include "core/memory_budget.h"
#include "core/units.h"
#include "pipeline/jobs.h"

namespace texlume::apps {
namespace {

// What the synth command reads besides the Options it binds directly.
struct SynthWords {
  std::string tangent_frame, prior_shrink, relief_gain, world_unit, photo_cache,
      engine = "triangle", orientation = "field", fill_unseen = "overlap";
  std::vector<double> tangent_field;
  bool best_view_only = false, no_additive = false, no_channel = false, no_detail = false,
       no_report = false, no_light_response = false, no_view_term = false, no_white_balance = false,
       no_photo_blur = false;
};

// "auto", or a number in [low, high]: the word's check.
CLI::Validator AutoOrNumberIn(double low, double high) {
  char range[64];
  std::snprintf(range, sizeof range, "[%g, %g]", low, high);
  const std::string message = std::string("give auto or a number in ") + range;
  return CLI::Validator(
      [=](std::string& v) -> std::string {
        if (v == "auto") return "";
        try {
          std::size_t used = 0;
          const double x = std::stod(v, &used);
          if (used == v.size() && x >= low && x <= high) return "";
        } catch (const std::exception&) {
        }
        return message;
      },
      "auto|X");
}

void BindSynthInputs(CLI::App* sub, pipeline::SynthCommandOptions& o, SynthWords& w) {
  pipeline::SynthJobOptions& j = o.job;
  sub->add_option(
      "--model", j.model_dir,
      "COLMAP model folder (required by --engine triangle; graphcut: photos to follow)");
  sub->add_option("--images", j.images_dir, "the object photos (with --model)");
  sub->add_option("--lights", j.lights_file, "object-lights JSON (docs/lights.md; with --model)");
  sub->add_option("--mesh", j.mesh_file, "coarse mesh in the model's frame")->required();
  sub->add_option("--out", j.out_dir, "the model folder to write")->required();
  auto* sample =
      sub->add_option("--sample", j.sample_file,
                      "sample: a PTM (.ptm, .exr) or a colour photo (.png, .jpg, .tif, RGB .exr); "
                      "graphcut also a BTF capture or factorisation folder");
  sub->add_option("--sample-horizon", j.sample_horizon_file,
                  "the PTM sample's horizon map (texlume fit --horizon): the model casts the "
                  "relief's own shadows")
      ->needs(sample);
  sub->add_option("--atlas-relief-gain", w.relief_gain,
                  "with --sample-horizon: the atlases' relief heights times this (their shadows), "
                  "or auto: as much shadow under low lights as the sample's")
      ->check(AutoOrNumberIn(0.25, 4.0))
      ->default_str("auto")
      ->needs("--sample-horizon");
  sub->add_flag("--shadowed-synthesis", j.shadowed_synthesis,
                "with --sample-horizon: placement, gains and the photo-consistency pass also "
                "relight the sample with its shadows (slower; docs/synth.md)")
      ->needs("--sample-horizon");
  sub->add_option("--btf", o.btf, "BTF capture or factorisation folder (instead of --sample)")
      ->excludes(sample);
  sub->add_option("--components", o.components, "BTF components kept when factorising a capture")
      ->capture_default_str();
  sub->add_option("--sample-texel-size", j.synthesis.sample_texel_size,
                  "world units per sample texel (required with --sample but a BTF folder; BTF: the "
                  "capture's)");
  BindWorldUnit(sub, w.world_unit);
  sub->add_option("--seam-band", o.seam_band,
                  "BTF graph-cut band half-width in texels [min(4, "
                  "strip)]");
  sub->add_option("--max-subdivisions", j.max_subdivisions,
                  "1-to-4 splits allowed so that every patch fits the sample")
      ->capture_default_str();
  sub->add_option("--max-buffer-size", j.visibility.max_buffer_dimension,
                  "largest z-buffer side in pixels (0: full resolution)")
      ->capture_default_str();
  sub->add_option("--photo-cache", w.photo_cache,
                  "decoded photos held at once, e.g. 4G (default: half of --memory-limit; the "
                  "photos are decoded on demand)");
  sub->add_option("--compare-regions", j.compare_regions,
                  "one process: also measure the edge mismatch on region borders, next to them and "
                  "elsewhere for the N regions mpirun -np N would place apart, for each N of a "
                  "list such as 2,4 (manifest region_comparison)")
      ->delimiter(',');
}

void BindEngine(CLI::App* sub, synth::MeshSynthesisOptions& s, SynthWords& w) {
  sub->add_option("--strip", s.strip, "W_e: texels of strip around each triangle [2, 32]")
      ->capture_default_str();
  sub->add_option("--top-k", s.top_k, "candidates kept by the image score")->capture_default_str();
  sub->add_option("--search", s.search,
                  "how the image score searches the sample: coarse-to-fine or exhaustive")
      ->transform(Choice(std::map<std::string, synth::PlacementSearchKind>{
          {"coarse-to-fine", synth::PlacementSearchKind::kCoarseToFine},
          {"exhaustive", synth::PlacementSearchKind::kExhaustive}}))
      ->default_str("coarse-to-fine");
  sub->add_option("--search-candidates", s.search_candidates,
                  "coarse-to-fine: placements kept at each coarser density (at least --top-k)")
      ->capture_default_str();
  sub->add_option("--photometry-faces", s.photometry_faces,
                  "most faces the photo gains and light response observe (more: evenly spread "
                  "among them)")
      ->capture_default_str();
  sub->add_flag("--best-view-only", w.best_view_only, "constrain by the best view alone");
  sub->add_option("--max-views", s.max_views, "most photos constraining a triangle")
      ->capture_default_str();
  sub->add_option("--seed", s.seed, "random seed")->capture_default_str();
  auto* frame =
      sub->add_option("--tangent-frame", w.tangent_frame,
                      "each face's frame: auto, photos or first-edge")
          ->check(OneOf({"auto", "photos", "first-edge"}, "give first-edge, photos or auto"))
          ->default_str("auto");
  sub->add_option("--tangent-field", w.tangent_field,
                  "a world direction x,y,z laid on every face (instead of --tangent-frame)")
      ->delimiter(',')
      ->expected(3)
      ->excludes(frame);
}

// Graph-cut surface quilting (paper 004 §III, docs/quilting.md).
void BindQuilting(CLI::App* sub, pipeline::QuiltJobOptions& q, SynthWords& w) {
  sub->add_option("--engine", w.engine,
                  "triangle (paper 003, from the photos) or graphcut (paper 004; photos optional)")
      ->check(OneOf({"triangle", "graphcut"}, "give triangle or graphcut"))
      ->capture_default_str();
  sub->add_option("--fill-unseen", w.fill_unseen,
                  "triangle: the faces no photo sees placed by their overlap with their "
                  "neighbours (overlap) or quilted by the graph-cut engine from the faces the "
                  "photos placed (graphcut; --work-patch and --seam-threshold apply)")
      ->check(OneOf({"overlap", "graphcut"}, "give overlap or graphcut"))
      ->capture_default_str();
  sub->add_option("--work-patch", q.quilt.work_patch_levels,
                  "graphcut: r_w, breadth-first levels of the work patch")
      ->capture_default_str();
  sub->add_option("--seam-threshold", q.quilt.seam_threshold,
                  "graphcut: T_c, the largest mean seam cost per cut link, as a share of a cut "
                  "between unrelated texels")
      ->capture_default_str();
  sub->add_option("--orientation", w.orientation,
                  "graphcut: the sample's x axis along the field (--field, or --tangent-field "
                  "laid on every face, default 0,0,1) or turned at random per patch")
      ->check(OneOf({"field", "random"}, "give field or random"))
      ->capture_default_str();
  sub->add_option("--field", q.field_file,
                  "graphcut: key vectors orienting the sample (docs/quilting.md, \"The field "
                  "file\")");
}

void BindCorrection(CLI::App* sub, pipeline::SynthCommandOptions& o, SynthWords& w) {
  synth::MeshSynthesisOptions& s = o.job.synthesis;
  sub->add_option("--correction-iterations", s.correction_iterations,
                  "photo-consistency rounds [0, 5] (0: off, also for a BTF)")
      ->capture_default_str();
  sub->add_option("--correction-noise", o.correction_noise,
                  "photo noise of the pass (PTM 0.1, BTF 0.05)");
  sub->add_option("--correction-sigma", o.correction_sigma,
                  "smoothing of the per-channel factors, photo pixels (PTM 2, BTF 0.35)");
  sub->add_option("--correction-prior-shrink", w.prior_shrink,
                  "auto, or the share in [0, 1] of the way to the sample's mean")
      ->check(AutoOrNumberIn(0.0, 1.0))
      ->default_str("auto");
  sub->add_flag("--no-additive-correction", w.no_additive, "no change of the luminance");
  sub->add_flag("--no-channel-correction", w.no_channel, "no per-channel factors");
  sub->add_flag("--no-detail-transfer", w.no_detail, "keep the quilted patch's own detail");
  sub->add_flag("--no-light-response", w.no_light_response,
                "no light response from the photos (elevation factors, ambient)");
  sub->add_flag(
      "--no-view-term", w.no_view_term,
      "a light response without Oren and Nayar's view term (elevation factors and ambient "
      "alone)");
  sub->add_flag("--no-white-balance", w.no_white_balance,
                "keep each photo's white balance as taken");
  sub->add_flag("--no-photo-blur", w.no_photo_blur,
                "compare the photos with the sharp model (no blur estimated from the photos)");
}

void BindAtlas(CLI::App* sub, atlas::AtlasOptions& a, SynthWords& w) {
  sub->add_option("--atlas", a.mode, "charts or per-triangle")
      ->transform(Choice(std::map<std::string, atlas::AtlasMode>{
          {"charts", atlas::AtlasMode::kCharts}, {"per-triangle", atlas::AtlasMode::kPerTriangle}}))
      ->default_str("charts");
  sub->add_option("--atlas-size", a.atlas_size, "atlas side in texels")->capture_default_str();
  sub->add_option("--gutter", a.gutter, "texels around every chart")->capture_default_str();
  sub->add_option("--chart-angle", a.max_chart_normal_angle_deg,
                  "largest normal angle within a chart, degrees")
      ->capture_default_str();
  sub->add_option("--chart-size", a.max_chart_size, "largest chart side in texels (0: any)")
      ->capture_default_str();
  sub->add_option("--chart-flattening", a.flattening, "auto, strips, rigid or conformal")
      ->transform(Choice(std::map<std::string, atlas::ChartFlattening>{
          {"auto", atlas::ChartFlattening::kAuto},
          {"strips", atlas::ChartFlattening::kStrips},
          {"rigid", atlas::ChartFlattening::kRigid},
          {"conformal", atlas::ChartFlattening::kConformal}}))
      ->default_str("auto");
  sub->add_option("--chart-stretch", a.max_chart_stretch, "texel stretch bound of a chart")
      ->capture_default_str();
  sub->add_flag("--no-report", w.no_report, "do not write report.html");
}

// The frames --tangent-frame and --tangent-field ask for (`auto`: `otherwise`).
synth::TangentFrame TangentFrameOf(const SynthWords& w, synth::TangentFrame otherwise) {
  if (!w.tangent_field.empty()) return synth::TangentFrame::kSmoothField;
  if (w.tangent_frame == "first-edge") return synth::TangentFrame::kFirstEdge;
  if (w.tangent_frame == "photos") return synth::TangentFrame::kPhotos;
  return otherwise;
}

// `--engine graphcut` with --model, --images and --lights: the photos to
// follow and the settings that calibrate them and score placements; those
// settings are refused without photos.
void TakePhotos(const CLI::App* sub, const SynthWords& w, const pipeline::SynthCommandOptions& o,
                pipeline::QuiltJobOptions& q) {
  const pipeline::SynthJobOptions& j = o.job;
  q.model_dir = j.model_dir;
  q.images_dir = j.images_dir;
  q.lights_file = j.lights_file;
  if (!q.Photos() || j.images_dir.empty() || j.lights_file.empty()) {
    for (const char* name : {"--model", "--images", "--lights"})
      if (sub->count(name) > 0)
        throw UsageError("--engine graphcut follows photos with --model, --images and --lights");
    for (const char* name :
         {"--top-k", "--best-view-only", "--max-views", "--tangent-frame", "--max-buffer-size",
          "--no-light-response", "--no-view-term", "--no-white-balance", "--no-photo-blur"})
      if (sub->count(name) > 0)
        throw UsageError(std::string(name) +
                         " is for --engine graphcut with photos (--model, --images, --lights)");
    return;
  }
  q.visibility = j.visibility;
  synth::TriangleEngineOptions& e = q.photo_engine;
  e.top_k = j.synthesis.top_k;
  e.all_views = !w.best_view_only;
  e.max_views = j.synthesis.max_views;
  e.light_response = !w.no_light_response;
  e.view_term = !w.no_view_term;
  e.white_balance = !w.no_white_balance;
  e.photo_blur = !w.no_photo_blur;
  e.seed = j.synthesis.seed;
  e.tangent_frame = TangentFrameOf(w, e.tangent_frame);
}

// `--engine graphcut`: the quilting job's Options from the command's. What it
// does not take yet is refused, not ignored.
pipeline::QuiltJobOptions QuiltJobFrom(const CLI::App* sub, const SynthWords& w,
                                       const pipeline::SynthCommandOptions& o,
                                       pipeline::QuiltJobOptions q) {
  for (const char* name :
       {"--fill-unseen", "--seam-band", "--strip", "--max-subdivisions", "--correction-iterations",
        "--correction-noise", "--correction-sigma", "--correction-prior-shrink",
        "--no-additive-correction", "--no-channel-correction", "--no-detail-transfer", "--search",
        "--search-candidates", "--photometry-faces", "--compare-regions", "--sample-horizon",
        "--shadowed-synthesis", "--atlas-relief-gain"})
    if (sub->count(name) > 0)
      throw UsageError(std::string(name) + " is not taken by --engine graphcut (docs/quilting.md)");
  TakePhotos(sub, w, o, q);
  q.mesh_file = o.job.mesh_file;
  q.sample_file = o.btf.empty() ? o.job.sample_file : o.btf;
  if (q.sample_file.empty()) throw UsageError("--sample or --btf is required");
  if (sub->count("--photo-cache") > 0) throw UsageError("--photo-cache is for --engine triangle");
  if (!o.btf.empty() && !q.BtfSample())
    throw InputError(o.btf.string(), "is not a folder (a BTF capture or factorisation)");
  q.btf_components = o.components;
  if (sub->count("--components") > 0 && !q.BtfSample())
    throw UsageError("--components is for a BTF sample (a capture folder)");
  if (sub->count("--sample-texel-size") == 0 && !q.BtfSample())
    throw UsageError(
        "--sample-texel-size: give the sample's texel size in world units of the mesh");
  q.out_dir = o.job.out_dir;
  q.write_report = !w.no_report;
  q.mm_per_world_unit = WorldUnitMm(w.world_unit);
  q.sample_texel_size = o.job.synthesis.sample_texel_size;
  q.quilt.seed = o.job.synthesis.seed;
  q.quilt.random_orientation = w.orientation == "random";
  if (!w.tangent_field.empty())
    q.field_direction_in_world =
        Eigen::Vector3d(w.tangent_field[0], w.tangent_field[1], w.tangent_field[2]);
  const atlas::ChartFlattening flattening = q.atlas.flattening;
  q.atlas = o.job.atlas;
  if (sub->count("--chart-flattening") == 0) q.atlas.flattening = flattening;
  return q;
}

// The graph-cut settings of `--fill-unseen graphcut`; refused without it.
void ResolveFillUnseen(const CLI::App* sub, const SynthWords& w, const quilt::QuiltOptions& quilt,
                       pipeline::SynthJobOptions& job) {
  const bool graphcut = w.fill_unseen == "graphcut";
  for (const char* name : {"--orientation", "--field"})
    if (sub->count(name) > 0) throw UsageError(std::string(name) + " is for --engine graphcut");
  for (const char* name : {"--work-patch", "--seam-threshold"})
    if (sub->count(name) > 0 && !graphcut)
      throw UsageError(std::string(name) + " is for --engine graphcut or --fill-unseen graphcut");
  job.fill_unseen = graphcut ? pipeline::FillUnseen::kGraphcut : pipeline::FillUnseen::kOverlap;
  job.fill_quilt.work_patch_levels = quilt.work_patch_levels;
  job.fill_quilt.seam_threshold = quilt.seam_threshold;
}

// The words and flags into the job's Options.
void Resolve(const CLI::App* sub, const SynthWords& w, const quilt::QuiltOptions& quilt,
             pipeline::SynthCommandOptions& o) {
  for (const char* name : {"--model", "--images", "--lights"})
    if (sub->count(name) == 0) throw UsageError(std::string(name) + " is required");
  ResolveFillUnseen(sub, w, quilt, o.job);
  synth::MeshSynthesisOptions& s = o.job.synthesis;
  if (o.btf.empty() && sub->count("--sample-texel-size") == 0)
    throw UsageError(
        "--sample-texel-size: give the sample's texel size in world units of the model");
  s.all_views = !w.best_view_only;
  s.additive_correction = !w.no_additive;
  s.channel_correction = !w.no_channel;
  s.detail_transfer = !w.no_detail;
  s.light_response = !w.no_light_response;
  s.view_term = !w.no_view_term;
  s.white_balance = !w.no_white_balance;
  s.photo_blur = !w.no_photo_blur;
  if (!w.prior_shrink.empty() && w.prior_shrink != "auto")
    s.correction_prior_shrink = std::stod(w.prior_shrink);
  if (!w.relief_gain.empty() && w.relief_gain != "auto")
    o.job.atlas_relief_gain = std::stod(w.relief_gain);
  s.tangent_frame = TangentFrameOf(w, s.tangent_frame);
  if (!w.tangent_field.empty()) {
    s.field_direction_in_world =
        Eigen::Vector3d(w.tangent_field[0], w.tangent_field[1], w.tangent_field[2]);
  }
  o.job.atlas.blend_strip = s.strip;
  o.job.write_report = !w.no_report;
  o.job.mm_per_world_unit = WorldUnitMm(w.world_unit);
  if (!w.photo_cache.empty()) o.job.photo_cache_bytes = ParseMemorySize(w.photo_cache);
}

}  // namespace

void AddSynthCommand(CLI::App& app, CommandRunners& run) {
  auto* sub = app.add_subcommand(
      "synth",
      "The relightable model: per-triangle image-constrained synthesis on the mesh (paper 003 "
      "Algorithm 2) from a PTM (--sample) or BTF (--btf) sample, packed into atlases, exported, "
      "with report.html (docs/synth.md).");
  auto o = std::make_shared<pipeline::SynthCommandOptions>();
  auto w = std::make_shared<SynthWords>();
  BindSynthInputs(sub, *o, *w);
  BindEngine(sub, o->job.synthesis, *w);
  BindCorrection(sub, *o, *w);
  BindAtlas(sub, o->job.atlas, *w);
  auto q = std::make_shared<pipeline::QuiltJobOptions>();
  BindQuilting(sub, *q, *w);
  run[sub] = [sub, o, w, q](std::ostream& out, std::ostream& err) {
    synth::RankCommunicator* ranks = Ranks();
    if (w->engine == "graphcut") {
      if (ranks && ranks->Size() > 1)
        throw UsageError("--engine graphcut runs in one process; start it without mpirun");
      ProgressBar bar;
      pipeline::RunQuiltCommandJob(QuiltJobFrom(sub, *w, *o, *q), out, err, bar.Callback());
      return 0;
    }
    Resolve(sub, *w, q->quilt, *o);
    o->job.ranks = ranks;
    if (ranks && ranks->Rank() != 0) {  // rank 0 shows the progress and writes the model
      std::ostream quiet(nullptr);
      pipeline::RunSynthCommandJob(*o, quiet, err, {});
      return 0;
    }
    ProgressBar bar;
    pipeline::RunSynthCommandJob(*o, out, err, bar.Callback());
    return 0;
  };
}

void AddRenderCommand(CLI::App& app, CommandRunners& run) {
  auto* sub = app.add_subcommand(
      "render", "Render a model folder for every image of a COLMAP model under its light(s).");
  auto o = std::make_shared<pipeline::RenderJobOptions>();
  sub->add_option("--model", o->model_folder, "model folder written by texlume synth")->required();
  sub->add_option("--cameras", o->cameras_dir, "COLMAP model of the views")->required();
  sub->add_option("--lights", o->lights_file, "object-lights JSON of those views")->required();
  sub->add_option("--out", o->out_dir, "the folder to write")->required();
  auto* baseline = sub->add_option("--baseline", o->mode, "flat, baked or ptm (a BTF's preview)")
                       ->transform(Choice(std::map<std::string, render::RenderMode>{
                           {"flat", render::RenderMode::kFlat},
                           {"baked", render::RenderMode::kBaked},
                           {"ptm", render::RenderMode::kPtm}}));
  sub->add_option("--samples", o->samples_per_axis, "samples per pixel along each axis [1, 8]")
      ->capture_default_str();
  sub->add_option("--truth", o->truth_images_dir, "ground-truth images: PSNR and SSIM");
  sub->add_option("--truth-masks", o->truth_masks_dir, "their masks");
  sub->add_option("--reduced-factor", o->reduced_factor,
                  "also compare after reducing both by this factor")
      ->capture_default_str();
  run[sub] = [o, baseline](std::ostream& out, std::ostream& err) {
    ProgressBar bar;
    pipeline::RunRenderCommandJob(*o, baseline->count() > 0, out, err, bar.Callback());
    return 0;
  };
}

void BindWorldUnit(CLI::App* sub, std::string& text) {
  sub->add_option("--world-unit", text,
                  "how long one world unit is (1m, 10cm, 25.4mm, 1in): the reports give "
                  "millimetres");
}

double WorldUnitMm(const std::string& text) {
  return text.empty() ? 0.0 : ParseLengthMm(text, "--world-unit");
}

void BindSensor(CLI::App* sub, datasets::SensorOptions& s) {
  sub->add_option("--shot-noise", s.shot_noise,
                  "photos' shot noise: variance per unit linear signal (0: off)")
      ->capture_default_str();
  sub->add_option("--read-noise", s.read_noise,
                  "photos' read noise: standard deviation, linear (0: off)")
      ->capture_default_str();
  sub->add_option("--vignetting", s.vignetting, "photos' brightness lost at the corners (0: off)")
      ->capture_default_str();
  sub->add_option("--white-balance-spread", s.white_balance_spread,
                  "photos' per-channel gain drawn in [1 - s, 1 + s] (0: off)")
      ->capture_default_str();
  sub->add_option("--jpeg-quality", s.jpeg_quality,
                  "photos stored as a JPEG of this quality would be (0: lossless)")
      ->capture_default_str();
}

namespace {

void BindSceneCapture(CLI::App* sub, datasets::SceneOptions& s) {
  sub->add_option("--capture-size", s.capture_size, "RTI capture side in texels")
      ->capture_default_str();
  sub->add_option("--capture-lights", s.num_capture_lights, "RTI capture lights")
      ->capture_default_str();
  sub->add_option("--held-out-lights", s.num_held_out_capture_lights,
                  "held-out lights of the capture")
      ->capture_default_str();
  sub->add_option("--held-out-views", s.num_held_out_views, "held-out views of the object")
      ->capture_default_str();
  sub->add_option("--held-out-scale", s.held_out_scale, "held-out views' resolution factor")
      ->capture_default_str();
  sub->add_option("--texel-size", s.material.texel_size, "world units per material texel")
      ->capture_default_str();
  sub->add_option("--relief", s.material.relief_height, "relief height, world units")
      ->capture_default_str();
  sub->add_option("--specular", s.material.specular, "specular strength")->capture_default_str();
  sub->add_option("--shininess", s.material.shininess,
                  "specular exponent: the lobe's roughness (lower is rougher)")
      ->capture_default_str();
  sub->add_option("--sheen", s.material.sheen, "sheen strength at grazing angles")
      ->capture_default_str();
  sub->add_option("--interreflection-rays", s.shading.interreflection_rays,
                  "rays per sample for one bounce of interreflection (0: off)")
      ->capture_default_str();
  sub->add_option("--light-error", s.light_error_deg,
                  "RMS error of the recorded photo lights, degrees (0: exact)")
      ->capture_default_str();
  sub->add_option("--samples", s.shading.samples_per_axis, "samples per pixel along each axis")
      ->capture_default_str();
  sub->add_option("--mesh-resolution", s.mesh_resolution, "coarse mesh resolution [0, 7]")
      ->capture_default_str();
  sub->add_option("--mesh-faces", s.mesh_faces,
                  "a coarse mesh of about this many faces instead (0: --mesh-resolution; a "
                  "monument: 1000000)")
      ->capture_default_str();
  sub->add_option("--btf-size", s.btf_size, "BTF capture side in texels")->capture_default_str();
  sub->add_option("--btf-views", s.btf_view_count, "BTF capture views")->capture_default_str();
  sub->add_option("--btf-lights", s.btf_light_count, "BTF capture lights")->capture_default_str();
}

// The options UseRealisticCapture sets: under --clean, each one not given on the
// command line takes its clean-scene value.
void ApplyClean(const CLI::App& sub, datasets::SceneOptions& s) {
  const datasets::SceneOptions clean;
  const auto unless_given = [&](const char* name, auto& value, const auto& clean_value) {
    if (sub.count(name) == 0) value = clean_value;
  };
  unless_given("--shot-noise", s.sensor.shot_noise, clean.sensor.shot_noise);
  unless_given("--read-noise", s.sensor.read_noise, clean.sensor.read_noise);
  unless_given("--vignetting", s.sensor.vignetting, clean.sensor.vignetting);
  unless_given("--white-balance-spread", s.sensor.white_balance_spread,
               clean.sensor.white_balance_spread);
  unless_given("--jpeg-quality", s.sensor.jpeg_quality, clean.sensor.jpeg_quality);
  unless_given("--specular", s.material.specular, clean.material.specular);
  unless_given("--shininess", s.material.shininess, clean.material.shininess);
  unless_given("--sheen", s.material.sheen, clean.material.sheen);
  unless_given("--interreflection-rays", s.shading.interreflection_rays,
               clean.shading.interreflection_rays);
  unless_given("--light-error", s.light_error_deg, clean.light_error_deg);
}

}  // namespace

void AddSceneCommand(CLI::App& app, CommandRunners& run) {
  auto* sub = app.add_subcommand(
      "scene", "Write a synthetic heritage scene with ground truth (docs/synthetic_scenes.md).");
  auto s = std::make_shared<datasets::SceneOptions>();
  datasets::UseRealisticCapture(*s);
  auto out_dir = std::make_shared<std::filesystem::path>();
  auto clean = std::make_shared<bool>(false);
  auto material_seed = std::make_shared<std::uint32_t>(0);
  auto elevations = std::make_shared<std::vector<double>>();
  auto flags = std::make_shared<std::pair<bool, bool>>(false, false);  // no BTF, fixed exposure
  sub->add_option("--out", *out_dir, "the folder to write")->required();
  sub->add_option("--kind", s->shape, "sphere, cylinder, plane or torus")
      ->transform(Choice(ShapeWords()))
      ->default_str("sphere");
  sub->add_option("--material", s->material.kind, "stone, brick or grooves")
      ->transform(Choice(MaterialWords()))
      ->default_str("stone");
  sub->add_option("--seed", s->seed, "random seed (scene and material)")->capture_default_str();
  sub->add_option("--material-seed", *material_seed,
                  "another instance of the material: its own seed (0: --seed)")
      ->capture_default_str();
  sub->add_option("--held-out-elevation", *elevations,
                  "held-out lights between these elevations, degrees: MIN,MAX (default 25,65)")
      ->delimiter(',')
      ->expected(2);
  sub->add_flag("--clean", *clean,
                "today's clean scene: no sensor effects, matte, no interreflection, exact lights "
                "(options given still apply)");
  sub->add_option("--images", s->num_images, "object photos")->capture_default_str();
  sub->add_option("--camera-model", s->camera_model, "pinhole or opencv")
      ->transform(Choice(std::map<std::string, sfm::CameraModelId>{
          {"pinhole", sfm::CameraModelId::kPinhole}, {"opencv", sfm::CameraModelId::kOpenCV}}))
      ->default_str("pinhole");
  sub->add_option("--width", s->image_width, "photo width in pixels")->capture_default_str();
  sub->add_option("--height", s->image_height, "photo height in pixels")->capture_default_str();
  sub->add_option("--camera-rings", s->camera_rings,
                  "rings the photos lie on (1: one waving ring; more: a monument's capture)")
      ->capture_default_str();
  sub->add_option("--camera-distance", s->camera_distance,
                  "cameras' distance from the object's centre, world units")
      ->capture_default_str();
  sub->add_option("--photo-light-spread", s->photo_light_azimuth_spread_deg,
                  "azimuths of the photos' lights: within this many degrees centred on their "
                  "camera's (72: its side of the object; 360: from anywhere)")
      ->capture_default_str();
  sub->add_option("--focal", s->focal_px,
                  "focal length in pixels of a 640-pixel-wide photo (scaled with --width)")
      ->capture_default_str();
  BindSceneCapture(sub, *s);
  BindSensor(sub, s->sensor);
  sub->add_flag("--no-btf", flags->first, "no BTF capture");
  sub->add_flag("--fixed-exposure", flags->second, "every photo at one exposure");
  run[sub] = [sub, s, out_dir, flags, clean, material_seed, elevations](std::ostream& out,
                                                                        std::ostream&) {
    if (*clean) ApplyClean(*sub, *s);
    if (!elevations->empty()) {
      s->held_out_min_elevation_deg = (*elevations)[0];
      s->held_out_max_elevation_deg = (*elevations)[1];
    }
    s->material.seed = *material_seed != 0 ? *material_seed : s->seed;
    s->focal_px *= s->image_width / 640.0;
    s->write_btf = !flags->first;
    s->vary_exposure = !flags->second;
    ProgressBar bar;
    pipeline::RunSceneJob(*s, *out_dir, out, bar.Callback());
    return 0;
  };
}

}  // namespace texlume::apps
