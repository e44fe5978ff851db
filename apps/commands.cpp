#include "apps/commands.h"

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "apps/cli.h"
#include "apps/progress_bar.h"
#include "apps/view_command.h"
#include "pipeline/jobs.h"

namespace texlume::apps {

std::map<std::string, datasets::SceneShape> ShapeWords() {
  return {{"sphere", datasets::SceneShape::kSphere},
          {"cylinder", datasets::SceneShape::kCylinder},
          {"plane", datasets::SceneShape::kPlane},
          {"torus", datasets::SceneShape::kTorus}};
}

std::map<std::string, datasets::MaterialKind> MaterialWords() {
  return {{"stone", datasets::MaterialKind::kStone},
          {"brick", datasets::MaterialKind::kBrick},
          {"grooves", datasets::MaterialKind::kGrooves}};
}

CLI::Validator OneOf(const std::vector<std::string>& words, const std::string& message) {
  return CLI::Validator(
      [words, message](std::string& value) {
        return std::find(words.begin(), words.end(), value) == words.end() ? message
                                                                           : std::string();
      },
      CLI::detail::join(words, "|"));
}

namespace {

int Succeeded(bool ok) { return ok ? kExitOk : kExitInputError; }

}  // namespace

void AddInspectCommand(CLI::App& app, CommandRunners& run) {
  auto* sub = app.add_subcommand(
      "inspect",
      "Summarise a COLMAP model (.bin or .txt), check a mesh, lights and image files, and report "
      "which triangles the photos see fully.");
  auto o = std::make_shared<pipeline::InspectJobOptions>();
  auto mesh = std::make_shared<std::string>(), images = std::make_shared<std::string>(),
       lights = std::make_shared<std::string>();
  sub->add_option("--model", o->inspect.model_dir, "COLMAP model folder")->required();
  sub->add_option("--mesh", *mesh, "coarse mesh in the model's frame (PLY, OBJ, OFF, STL)");
  sub->add_option("--images", *images, "folder the model's image names are relative to");
  sub->add_option("--lights", *lights, "object-lights JSON or an .lp file");
  sub->add_option("--json", o->json_file, "also write the report as JSON");
  sub->add_option("--max-buffer-size", o->inspect.visibility.max_buffer_dimension,
                  "largest z-buffer side in pixels (0: full resolution)");
  run[sub] = [o, mesh, images, lights](std::ostream& out, std::ostream& err) {
    if (!mesh->empty()) o->inspect.mesh = *mesh;
    if (!images->empty()) o->inspect.images_dir = *images;
    if (!lights->empty()) o->inspect.lights = *lights;
    ProgressBar bar;
    return Succeeded(pipeline::RunInspectJob(*o, out, err, bar.Callback()));
  };
}

void AddFitCommand(CLI::App& app, CommandRunners& run) {
  auto* sub = app.add_subcommand(
      "fit", "Fit a PTM to an RTI capture (writes FILE.json with settings and timings).");
  auto o = std::make_shared<pipeline::FitJobOptions>();
  sub->add_option("--images", o->images_dir, "the capture's photos")->required();
  sub->add_option("--lights", o->lights_file, "the capture's .lp file")->required();
  sub->add_option("--out", o->out_file, "the .ptm (or, with --basis hsh, .rti) file to write")
      ->required();
  sub->add_option("--format", o->fit.format, "PTM format")
      ->transform(Choice(std::map<std::string, ptm::PtmFormat>(
          {{"lrgb", ptm::PtmFormat::kLrgb}, {"rgb", ptm::PtmFormat::kRgb}})))
      ->default_str("lrgb");
  sub->add_flag("--robust", o->fit.robust, "Ceres fit ignoring shadows and highlights");
  sub->add_option("--basis", o->basis, "ptm, or hsh (hemispherical harmonics; --out FILE.rti)")
      ->check(CLI::IsMember({"ptm", "hsh"}))
      ->capture_default_str();
  sub->add_option("--order", o->hsh_order, "HSH order: 2 (4 terms) or 3 (9 terms)")
      ->capture_default_str();
  sub->add_option("--exr", o->exr_file, "also write the lossless EXR");
  sub->add_option("--web", o->web_dir, "also write the relight/OpenLIME web format");
  sub->add_option("--band-rows", o->fit.band_rows, "rows decoded and fitted at a time")
      ->capture_default_str();
  sub->add_option("--horizon", o->horizon_file,
                  "also fit the relief's self-shadowing: the PTM of the lit samples, and "
                  "the horizon map written to FILE.exr (every image in memory)");
  run[sub] = [o](std::ostream& out, std::ostream& err) {
    ProgressBar bar;
    pipeline::RunFitJob(*o, out, err, bar.Callback());
    return kExitOk;
  };
}

void AddBtfCommand(CLI::App& app, CommandRunners& run) {
  auto* sub = app.add_subcommand(
      "btf",
      "SVD-factorise a BTF capture (btf.json + one image per view and light) into N geometry "
      "maps and appearance functions; prints the error table.");
  auto o = std::make_shared<pipeline::BtfJobOptions>();
  sub->add_option("--capture", o->capture_dir, "capture folder (btf.json)")->required();
  sub->add_option("--out", o->out_dir, "the factorisation folder to write")->required();
  sub->add_option("--components", o->components, "components kept (paper 004: 40)")
      ->capture_default_str();
  run[sub] = [o](std::ostream& out, std::ostream&) {
    ProgressBar bar;
    pipeline::RunBtfJob(*o, out, bar.Callback());
    return kExitOk;
  };
}

void AddRelightCommand(CLI::App& app, CommandRunners& run) {
  auto* sub = app.add_subcommand(
      "relight", "Render a PTM under a light (texture frame: x right, y up, z out).");
  auto o = std::make_shared<pipeline::RelightJobOptions>();
  auto light = std::make_shared<std::vector<double>>();
  sub->add_option("--ptm", o->ptm_file, "the PTM (.ptm or .exr)")->required();
  sub->add_option("--light", *light, "light direction lx,ly,lz")
      ->required()
      ->delimiter(',')
      ->expected(3);
  sub->add_option("--out", o->out_file, "the image to write (.png, .jpg, .tif)")->required();
  sub->add_option("--normals", o->normals_file, "also write the normal map");
  sub->add_option("--horizon", o->horizon_file,
                  "the PTM's horizon map (texlume fit --horizon): the relief's own shadows");
  sub->add_option("--gain", o->enhancement.diffuse_gain, "diffuse gain (1: off)")
      ->capture_default_str();
  sub->add_option("--specular", o->enhancement.specular, "specular enhancement (0: off)")
      ->capture_default_str();
  run[sub] = [o, light](std::ostream& out, std::ostream&) {
    o->light = Eigen::Vector3d((*light)[0], (*light)[1], (*light)[2]);
    pipeline::RunRelightJob(*o, out);
    return kExitOk;
  };
}

void AddLightsFromSphereCommand(CLI::App& app, CommandRunners& run) {
  auto* sub =
      app.add_subcommand("lights-from-sphere",
                         "Light directions from the highlight on a glossy sphere in every photo.");
  auto o = std::make_shared<pipeline::SphereLightsJobOptions>();
  auto circle = std::make_shared<std::vector<double>>();
  sub->add_option("--images", o->images_dir, "the photos")->required();
  sub->add_option("--out", o->out_file, "the .lp file to write")->required();
  sub->add_option("--circle", *circle, "the sphere cx,cy,r in pixels (default: detected)")
      ->delimiter(',')
      ->expected(3);
  sub->add_option("--threshold", o->highlight.threshold_fraction,
                  "highlight pixels: at least this fraction of the brightest")
      ->capture_default_str();
  run[sub] = [o, circle](std::ostream& out, std::ostream& err) {
    if (!circle->empty()) o->circle = ptm::SphereCircle{(*circle)[0], (*circle)[1], (*circle)[2]};
    pipeline::RunSphereLightsJob(*o, out, err);
    return kExitOk;
  };
}

void AddSynth2dCommand(CLI::App& app, CommandRunners& run) {
  auto* sub = app.add_subcommand("synth2d",
                                 "Image-constrained planar PTM synthesis (paper 003 Algorithm 1).");
  auto o = std::make_shared<pipeline::Synth2dJobOptions>();
  synth::PlanarSynthesisOptions& s = o->synthesis;
  sub->add_option("--sample", o->sample_file, "the sample PTM")->required();
  sub->add_option("--photos", o->photos_dir, "the photos of the surface");
  sub->add_option("--lights", o->lights_file, "the photos' .lp file");
  sub->add_option("--out", o->out_dir, "the folder to write")->required();
  sub->add_option("--scale", s.scale, "output texels per photo pixel (0: from the photos)")
      ->capture_default_str();
  sub->add_option("--width", s.width, "output width in texels (0: from the photos)")
      ->capture_default_str();
  sub->add_option("--height", s.height, "output height in texels (0: from the photos)")
      ->capture_default_str();
  sub->add_option("--block", s.block_size, "block side in texels")->capture_default_str();
  sub->add_option("--overlap", s.overlap, "overlap in texels")->capture_default_str();
  sub->add_option("--top-k", s.top_k, "candidates kept by the image score")->capture_default_str();
  sub->add_option("--seed", s.seed, "random seed")->capture_default_str();
  sub->add_option("--correction-iterations", s.correction_iterations,
                  "photo-consistency rounds (0: off)")
      ->capture_default_str();
  auto seam = std::make_shared<bool>(false), unconstrained = std::make_shared<bool>(false);
  sub->add_flag("--seam", *seam, "cut seams instead of blending");
  sub->add_flag("--unconstrained", *unconstrained, "ignore the photos (needs --width --height)");
  run[sub] = [o, seam, unconstrained](std::ostream& out, std::ostream& err) {
    o->synthesis.stitch = *seam ? synth::Stitch::kSeamCut : synth::Stitch::kBlend;
    o->synthesis.use_photos = !*unconstrained;
    pipeline::RunSynth2dJob(*o, out, err);
    return kExitOk;
  };
}

void AddViewCommand(CLI::App& app, CommandRunners& run) {
  auto* sub = app.add_subcommand(
      "view",
      "Serve the model's relighting preview in the browser (http://127.0.0.1:8080/; --port 0 "
      "picks a free port).");
  auto o = std::make_shared<ViewOptions>();
  sub->add_option("model", o->model_dir, "a model folder written by texlume synth")->required();
  sub->add_option("--port", o->port, "TCP port")
      ->check(CLI::Range(0, 65535))
      ->capture_default_str();
  sub->add_option("--host", o->host, "address to listen on")->capture_default_str();
  run[sub] = [o](std::ostream& out, std::ostream& err) {
    ServeViewer(*o, out, err);
    return kExitOk;
  };
}

void AddDemoCommand(CLI::App& app, CommandRunners& run) {
  auto* sub = app.add_subcommand(
      "demo",
      "The whole job on a synthetic scene: scene, inspect, fit, synth, render held-out views and "
      "the two baselines; writes DIR/report.html.");
  auto o = std::make_shared<pipeline::DemoJobOptions>();
  sub->add_option("--out", o->out_dir, "the folder to write")->capture_default_str();
  sub->add_option("--kind", o->shape, "the object's shape")
      ->transform(Choice(ShapeWords()))
      ->default_str("sphere");
  sub->add_option("--material", o->material, "the object's material")
      ->transform(Choice(MaterialWords()))
      ->default_str("stone");
  sub->add_option("--seed", o->seed, "random seed")->capture_default_str();
  sub->add_option("--images", o->num_images, "object photos (a smaller demo: fewer)")
      ->capture_default_str();
  sub->add_option("--width", o->image_width, "photo width in pixels")->capture_default_str();
  sub->add_option("--height", o->image_height, "photo height in pixels")->capture_default_str();
  BindSensor(sub, o->sensor);
  auto world_unit = std::make_shared<std::string>();
  BindWorldUnit(sub, *world_unit);
  run[sub] = [o, world_unit](std::ostream& out, std::ostream& err) {
    o->mm_per_world_unit = WorldUnitMm(*world_unit);
    ProgressBar bar;
    pipeline::RunDemoJob(*o, out, err, bar.Callback());
    return kExitOk;
  };
}

}  // namespace texlume::apps
