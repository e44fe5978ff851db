#include <chrono>
#include <cmath>
#include <map>
#include <string>

#include "core/errors.h"
#include "core/file_util.h"
#include "core/timing.h"
#include "model/baselines.h"
#include "model/model_io.h"
#include "pipeline/jobs.h"
#include "pipeline/report_pictures.h"
#include "pipeline/synth_job.h"
#include "ptm/ptm_io.h"
#include "report/report.h"
#include "sfm/colmap_io.h"
#include "sfm/lights.h"

namespace texlume::pipeline {
namespace fs = std::filesystem;
namespace {

// The demo's steps, each a method, sharing the scene's folders and the timings.
class DemoJob {
 public:
  DemoJob(const DemoJobOptions& options, std::ostream& out, std::ostream& err,
          const ProgressCallback& progress)
      : options_(options), out_(out), err_(err), progress_(progress) {
    scene_.seed = options.seed;
    scene_.material.seed = options.seed;
    scene_.shape = options.shape;
    scene_.material.kind = options.material;
    scene_.sensor = options.sensor;
    scene_.num_images = options.num_images;
    scene_.image_width = options.image_width;
    scene_.image_height = options.image_height;
    scene_.focal_px *= options.image_width / 640.0;
    scene_.write_btf = false;
    scene_.write_surface = false;
    // Held-out views at twice the photos' resolution: metrics at full
    // resolution and, reduced by 2, at the photos'.
    scene_.held_out_scale = 2;
    scene_.Check();
    scene_dir_ = options.out_dir / "scene";
    held_ = scene_dir_ / "object/held_out";
    shape_ = datasets::SceneShapeName(options.shape);
    material_ = datasets::MaterialKindName(options.material);
  }

  void Run() {
    const auto start = std::chrono::steady_clock::now();
    Timed("scene", [&] { MakeScene(); });
    Timed("inspect", [&] { Inspect(); });
    Timed("fit", [&] { FitSample(); });
    Timed("synth", [&] { Synthesise(); });
    Timed("render", [&] { RenderHeldOut(); });
    Timed("report", [&] { WriteDemoReport(); });
    seconds_["total"] = SecondsSince(start);
    WriteRecord();
    out_ << "\nReport: " << (options_.out_dir / "report.html").string()
         << " (run.json: settings, timings)\n";
  }

 private:
  template <typename Step>
  void Timed(const std::string& name, const Step& step) {
    const auto t = std::chrono::steady_clock::now();
    step();
    seconds_[name] = SecondsSince(t);
  }

  void MakeScene() {
    out_ << "1. A synthetic heritage scene: a " << material_ << " " << shape_
         << " photographed under known lights, and an RTI capture of the " << material_
         << " sample (texlume scene)\n";
    const datasets::SceneSummary scene = datasets::GenerateScene(scene_, scene_dir_, progress_);
    out_ << "   " << scene.num_files << " files in " << scene_dir_.string() << " ("
         << scene.seconds_total << " s); see MANIFEST.md there\n\n";
  }

  void Inspect() {
    sfm::InspectOptions inspect;
    inspect.model_dir = scene_dir_ / "object/sparse";
    inspect.mesh = scene_dir_ / "object/mesh.ply";
    inspect.lights = scene_dir_ / "object/lights.json";
    inspect.images_dir = scene_dir_ / "object/images";
    out_ << "2. texlume inspect --model " << inspect.model_dir.string() << " --mesh "
         << inspect.mesh->string() << " --lights " << inspect.lights->string() << " --images "
         << inspect.images_dir->string() << "\n";
    inspect_report_ = sfm::RunInspect(inspect, progress_);
    out_ << sfm::FormatInspectReport(inspect_report_) << "\n";
  }

  void FitSample() {
    const fs::path capture = scene_dir_ / "material/capture";
    const fs::path sample = options_.out_dir / "sample.ptm";
    out_ << "3. texlume fit --images " << capture.string() << " --lights "
         << (capture / "lights.lp").string() << " --out " << sample.string() << "\n";
    const ptm::RtiCapture rti = ptm::ReadRtiCapture(capture / "lights.lp", capture);
    sample_ = ptm::FitPtmFromFiles(rti.files, rti.lights, {}, progress_).ptm;
    capture_lights_ = rti.lights;
    ptm::WritePtmFile(sample_, sample);
    ptm::WritePtmExr(sample_, options_.out_dir / "sample.exr");
  }

  void Synthesise() {
    job_.model_dir = scene_dir_ / "object/sparse";
    job_.images_dir = scene_dir_ / "object/images";
    job_.lights_file = scene_dir_ / "object/lights.json";
    job_.mesh_file = scene_dir_ / "object/mesh.ply";
    job_.sample_file = options_.out_dir / "sample.exr";
    job_.sample = &sample_;  // as fitted: sample.exr holds it for the command line
    job_.out_dir = options_.out_dir / "model";
    job_.synthesis.sample_texel_size = scene_.material.texel_size;
    job_.mm_per_world_unit = options_.mm_per_world_unit;
    out_ << "\n4. texlume synth --model " << job_.model_dir.string() << " --images "
         << job_.images_dir.string() << " --lights " << job_.lights_file.string() << " --mesh "
         << job_.mesh_file.string() << " --sample " << job_.sample_file.string()
         << " --sample-texel-size " << job_.synthesis.sample_texel_size;
    if (job_.mm_per_world_unit > 0.0) out_ << " --world-unit " << job_.mm_per_world_unit << "mm";
    out_ << " --out " << job_.out_dir.string() << "\n";
    synthesis_ = pipeline::RunSynthJob(job_, progress_);
    for (const std::string& w : synthesis_.warnings) err_ << "warning: " << w << "\n";
    out_ << "   " << synthesis_.faces << " triangles (" << synthesis_.from_photos
         << " from photos), " << synthesis_.atlases << " atlas(es), occupancy "
         << synthesis_.occupancy << ", " << synthesis_.seconds_total << " s\n";
  }

  pipeline::RenderJobSummary Render(render::RenderMode mode, const std::string& name) {
    pipeline::RenderJobOptions r;
    r.model_folder = job_.out_dir;
    r.cameras_dir = held_ / "sparse";
    r.lights_file = held_ / "lights.json";
    r.out_dir = options_.out_dir / ("render_" + name);
    r.mode = mode;
    r.truth_images_dir = held_ / "images";
    r.truth_masks_dir = held_ / "masks";
    r.reduced_factor = scene_.held_out_scale;
    out_ << "\n5. texlume render --model " << r.model_folder.string() << " --cameras "
         << r.cameras_dir.string() << " --lights " << r.lights_file.string() << " --out "
         << r.out_dir.string() << (name == "texlume" ? "" : " --baseline " + name) << " --truth "
         << r.truth_images_dir.string() << " --truth-masks " << r.truth_masks_dir.string()
         << " --reduced-factor " << r.reduced_factor << "\n";
    const pipeline::RenderJobSummary s = pipeline::RunRenderJob(r, progress_);
    out_ << "   held-out views under held-out lights, inside the masks: PSNR " << s.mean_psnr
         << " dB, SSIM " << s.mean_ssim << " at full resolution; " << s.mean_psnr_reduced << " dB, "
         << s.mean_ssim_reduced << " at the photos' resolution\n";
    return s;
  }

  void RenderHeldOut() {
    ours_ = Render(render::RenderMode::kPtm, "texlume");
    flat_ = Render(render::RenderMode::kFlat, "flat");
    baked_ = Render(render::RenderMode::kBaked, "baked");
  }

  // The photos and the held-out views (with truth and masks) the report shows.
  void AddReportViews(report::ReportInputs& rep, ReportScene& scene) const {
    const sfm::LoadedModel photos_model = sfm::ReadModel(job_.model_dir);
    const sfm::ObjectLights photo_lights = sfm::ReadObjectLightsFile(job_.lights_file);
    for (const auto& [id, image] : photos_model.reconstruction.images)
      if (const auto it = photo_lights.find(image.name); it != photo_lights.end())
        rep.photos.push_back({image.name, job_.images_dir / image.name, it->second, {}});
    const sfm::LoadedModel held_model = sfm::ReadModel(held_ / "sparse");
    const sfm::ObjectLights held_lights = sfm::ReadObjectLightsFile(held_ / "lights.json");
    for (const auto& [id, image] : held_model.reconstruction.images) {
      const auto it = held_lights.find(image.name);
      if (it == held_lights.end()) continue;
      render::PictureView view;
      view.name = image.name;
      view.camera = held_model.reconstruction.cameras.at(image.camera_id);
      view.cam_from_world = image.cam_from_world;
      view.lights = it->second;
      view.reference_image = held_ / "images" / image.name;
      view.reference_mask = held_ / "masks" / image.name;
      scene.views.push_back(std::move(view));
    }
    rep.views_heading = "Held-out views under held-out lights";
  }

  static report::ReportMetrics MetricsOf(const std::string& label,
                                         const pipeline::RenderJobSummary& s) {
    return {label, s.metrics, s.mean_psnr, s.mean_ssim, s.mean_psnr_reduced, s.mean_ssim_reduced};
  }

  // The sample, the photos, held-out views beside the truth and the baselines,
  // error maps, a light sweep, the atlases, metrics and timings.
  void WriteDemoReport() {
    out_ << "\n6. The report\n";
    const model::TexturedModel& model = *synthesis_.model;
    const model::ModelBaselines& baselines = synthesis_.baselines;
    report::ReportInputs rep;
    rep.title = "texlume demo: a " + material_ + " " + shape_;
    rep.intro =
        "A synthetic heritage scene with ground truth: the " + material_ + " " + shape_ +
        " photographed under known lights, and an RTI capture of the material sample. texlume "
        "fitted the sample PTM, synthesised the relightable model from the photos and rendered "
        "it from held-out views under held-out lights (twice the photos' resolution), beside the "
        "ground truth and two baselines: the coarse mesh flat-shaded with the mean albedo, and "
        "the photos baked into an ordinary texture.";
    rep.model = &model;
    ReportScene scene;
    scene.model = &model;
    scene.flat_albedo = baselines.flat_albedo;
    scene.baked = baselines.baked;
    scene.sample = &sample_;
    AddReportViews(rep, scene);
    std::vector<std::vector<sfm::ObjectLight>> photo_lights, held_out_lights;
    for (const report::ReportPhoto& p : rep.photos) photo_lights.push_back(p.lights);
    for (const render::PictureView& v : scene.views) held_out_lights.push_back(v.lights);
    rep.light_plots = {CaptureLightPlot(capture_lights_),
                       LightPlotOfModel("the photos' lights", photo_lights, model),
                       LightPlotOfModel("the held-out lights", held_out_lights, model)};
    DrawReportPictures(scene, rep, progress_);
    rep.metrics = {MetricsOf("texlume (PTM atlases)", ours_), MetricsOf("flat baseline", flat_),
                   MetricsOf("baked baseline", baked_)};
    rep.occupancy = synthesis_.occupancy;
    rep.facts = {
        {"triangles", std::to_string(synthesis_.faces) + " (" +
                          std::to_string(synthesis_.from_photos) + " constrained by photos)"},
        {"photos", std::to_string(synthesis_.photos_used)},
        {"atlases", std::to_string(synthesis_.atlases) + ", " + std::to_string(synthesis_.charts) +
                        " charts"}};
    rep.timings_s = {{"scene", seconds_["scene"]},
                     {"inspect", seconds_["inspect"]},
                     {"fit", seconds_["fit"]},
                     {"synth (with the model's report)", seconds_["synth"]},
                     {"render (3 models)", seconds_["render"]}};
    rep.inputs = InputFiles(job_, job_.model_dir);
    rep.inputs.emplace_back("sample", options_.out_dir / "sample.ptm");
    rep.view_folder = (options_.out_dir / "model").string();
    rep.texel_size = job_.synthesis.sample_texel_size;
    rep.mm_per_world_unit = job_.mm_per_world_unit;
    rep.links = {{"model.glb", "model/model.glb"},
                 {"model.obj", "model/model.obj"},
                 {"manifest.json", "model/manifest.json"},
                 {"the model's own report (photo views)", "model/report.html"},
                 {"run.json", "run.json"}};
    report::WriteReport(options_.out_dir, rep, progress_);
  }

  void WriteRecord() const {
    nlohmann::json run;
    run["command"] = "demo";
    run["settings"] = options_.ToJson();
    run["settings"].update(
        {{"num_images", scene_.num_images}, {"held_out_scale", scene_.held_out_scale}});
    run["timings_s"] = seconds_;
    run["inspect"] = nlohmann::json::parse(sfm::InspectReportToJson(inspect_report_));
    auto metrics = [](const pipeline::RenderJobSummary& s) {
      return nlohmann::json{{"psnr_db", s.mean_psnr},
                            {"ssim", s.mean_ssim},
                            {"psnr_db_photo_resolution", s.mean_psnr_reduced},
                            {"ssim_photo_resolution", s.mean_ssim_reduced}};
    };
    run["metrics"] = {{"texlume", metrics(ours_)},
                      {"flat", metrics(flat_)},
                      {"baked", metrics(baked_)},
                      {"held_out_scale", scene_.held_out_scale}};
    WriteFileAtomically(
        options_.out_dir / "run.json", [&](std::ostream& o) { o << run.dump(2) << "\n"; }, false);
  }

  const DemoJobOptions& options_;
  std::ostream& out_;
  std::ostream& err_;
  const ProgressCallback& progress_;
  datasets::SceneOptions scene_;
  fs::path scene_dir_, held_;
  std::string shape_, material_;
  sfm::InspectReport inspect_report_;
  ptm::Ptm sample_;
  std::vector<Eigen::Vector3d> capture_lights_;  ///< the sample capture's (.lp)
  pipeline::SynthJobOptions job_;
  pipeline::SynthJobSummary synthesis_;
  pipeline::RenderJobSummary ours_, flat_, baked_;
  std::map<std::string, double> seconds_;
};

}  // namespace

void DemoJobOptions::Check() const {
  if (out_dir.empty()) throw OptionError("give the demo's output folder");
  if (num_images < 3 || num_images > 500)
    throw OptionError("--images must be in [3, 500], got " + std::to_string(num_images));
  if (image_width < 64 || image_width > 8192 || image_height < 64 || image_height > 8192)
    throw OptionError("--width and --height must be in [64, 8192] pixels, got " +
                      std::to_string(image_width) + " x " + std::to_string(image_height));
  sensor.Check();
  CheckWorldUnit(mm_per_world_unit);
}

nlohmann::json DemoJobOptions::ToJson() const {
  return {{"shape", std::string(datasets::SceneShapeName(shape))},
          {"material", std::string(datasets::MaterialKindName(material))},
          {"seed", seed},
          {"num_images", num_images},
          {"image_width", image_width},
          {"image_height", image_height},
          {"sensor", sensor.ToJson()},
          {"world_unit_mm", WorldUnitJson(mm_per_world_unit)}};
}

void RunDemoJob(const DemoJobOptions& options, std::ostream& out, std::ostream& err,
                const ProgressCallback& progress) {
  options.Check();
  DemoJob(options, out, err, progress).Run();
}

}  // namespace texlume::pipeline
