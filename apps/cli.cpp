#include "apps/cli.h"

#include <charconv>
#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>

#include "apps/progress_bar.h"
#include "datasets_synthetic/object_scene.h"
#include "datasets_synthetic/scene.h"
#include "sfm/file_util.h"
#include "sfm/inspect.h"

namespace texlume::apps {

Arguments::Arguments(const std::vector<std::string>& args, const std::set<std::string>& with_value,
                     const std::set<std::string>& flags) {
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a.rfind("--", 0) != 0) throw UsageError("unexpected argument '" + a + "'");
    std::string name = a.substr(2);
    std::optional<std::string> inline_value;
    if (const auto eq = name.find('='); eq != std::string::npos) {
      inline_value = name.substr(eq + 1);
      name = name.substr(0, eq);
    }
    if (flags.count(name)) {
      if (inline_value) throw UsageError("--" + name + " takes no value");
      values_[name] = "";
    } else if (with_value.count(name)) {
      if (inline_value) {
        values_[name] = *inline_value;
      } else {
        if (i + 1 >= args.size()) throw UsageError("--" + name + " needs a value");
        values_[name] = args[++i];
      }
    } else {
      throw UsageError("unknown option --" + name);
    }
  }
}

std::optional<std::string> Arguments::Get(const std::string& name) const {
  const auto it = values_.find(name);
  return it == values_.end() ? std::nullopt : std::optional<std::string>(it->second);
}

std::string Arguments::Require(const std::string& name) const {
  const auto v = Get(name);
  if (!v || v->empty()) throw UsageError("--" + name + " is required");
  return *v;
}

bool Arguments::Has(const std::string& name) const { return values_.count(name) > 0; }

int Arguments::GetInt(const std::string& name, int fallback) const {
  const auto v = Get(name);
  if (!v) return fallback;
  int value = 0;
  const auto [ptr, ec] = std::from_chars(v->data(), v->data() + v->size(), value);
  if (ec != std::errc() || ptr != v->data() + v->size()) {
    throw UsageError("--" + name + " expects an integer, got '" + *v + "'");
  }
  return value;
}

double Arguments::GetDouble(const std::string& name, double fallback) const {
  const auto v = Get(name);
  if (!v) return fallback;
  double value = 0;
  const auto [ptr, ec] = std::from_chars(v->data(), v->data() + v->size(), value);
  if (ec != std::errc() || ptr != v->data() + v->size()) {
    throw UsageError("--" + name + " expects a number, got '" + *v + "'");
  }
  return value;
}

int RunInspectCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  const Arguments a(args, {"model", "mesh", "images", "lights", "json", "max-buffer-size"}, {});
  sfm::InspectOptions options;
  options.model_dir = a.Require("model");
  if (auto v = a.Get("mesh")) options.mesh = *v;
  if (auto v = a.Get("images")) options.images_dir = *v;
  if (auto v = a.Get("lights")) options.lights = *v;
  options.visibility.max_buffer_dimension = a.GetInt("max-buffer-size", 0);
  ProgressBar bar;
  const sfm::InspectReport report = sfm::RunInspect(options, bar.Callback());
  out << sfm::FormatInspectReport(report);
  if (auto path = a.Get("json")) {
    const std::string json = sfm::InspectReportToJson(report);
    WriteFileAtomically(
        *path, [&](std::ostream& o) { o << json << "\n"; }, false);
  }
  if (report.missing_images && !report.missing_images->empty()) {
    err << "error: " << options.images_dir->string() << ": " << report.missing_images->size()
        << " image(s) named in the model are missing, first: '" << report.missing_images->front()
        << "'\n";
    return kExitInputError;
  }
  return kExitOk;
}

int RunSceneCommand(const std::vector<std::string>& args, std::ostream& out,
                    std::ostream& /*err*/) {
  const Arguments a(args,
                    {"kind", "material", "out", "seed", "images", "camera-model", "width", "height",
                     "capture-size", "capture-lights", "held-out-lights", "texel-size", "relief",
                     "specular", "held-out-views", "samples"},
                    {"no-btf", "fixed-exposure"});
  datasets::SceneOptions options;
  const std::string kind = a.Get("kind").value_or("sphere");
  const auto shape = datasets::SceneShapeFromName(kind);
  if (!shape)
    throw UsageError("--kind must be sphere, cylinder, plane or torus, got '" + kind + "'");
  options.shape = *shape;
  const std::string material = a.Get("material").value_or("stone");
  const auto material_kind = datasets::MaterialKindFromName(material);
  if (!material_kind) {
    throw UsageError("--material must be stone, brick or grooves, got '" + material + "'");
  }
  options.material.kind = *material_kind;
  options.material.texel_size = a.GetDouble("texel-size", options.material.texel_size);
  options.material.relief_height = a.GetDouble("relief", options.material.relief_height);
  options.material.specular = a.GetDouble("specular", options.material.specular);
  options.seed = static_cast<std::uint32_t>(a.GetInt("seed", 1));
  options.material.seed = options.seed;
  options.num_images = a.GetInt("images", options.num_images);
  options.image_width = a.GetInt("width", options.image_width);
  options.image_height = a.GetInt("height", options.image_height);
  options.focal_px *= options.image_width / 640.0;
  const std::string camera_model = a.Get("camera-model").value_or("pinhole");
  if (camera_model == "opencv") {
    options.camera_model = sfm::CameraModelId::kOpenCV;
  } else if (camera_model != "pinhole") {
    throw UsageError("--camera-model must be pinhole or opencv");
  }
  options.capture_size = a.GetInt("capture-size", options.capture_size);
  options.num_capture_lights = a.GetInt("capture-lights", options.num_capture_lights);
  options.num_held_out_capture_lights =
      a.GetInt("held-out-lights", options.num_held_out_capture_lights);
  options.num_held_out_views = a.GetInt("held-out-views", options.num_held_out_views);
  options.shading.samples_per_axis = a.GetInt("samples", options.shading.samples_per_axis);
  options.write_btf = !a.Has("no-btf");
  options.vary_exposure = !a.Has("fixed-exposure");
  const std::filesystem::path dir = a.Require("out");
  ProgressBar bar;
  const datasets::SceneSummary summary = datasets::GenerateScene(options, dir, bar.Callback());
  out << "Scene written to " << dir.string() << ": " << summary.num_files << " files, "
      << summary.displaced_triangles << " displaced triangles, " << summary.seconds_total
      << " s (see MANIFEST.md and scene.json)\n";
  return kExitOk;
}

int RunDemoCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& /*err*/) {
  const Arguments a(args, {"out", "seed", "kind", "material"}, {});
  const std::filesystem::path dir = a.Get("out").value_or("texlume_demo");
  datasets::SceneOptions options;
  options.seed = static_cast<std::uint32_t>(a.GetInt("seed", 1));
  options.material.seed = options.seed;
  const std::string kind = a.Get("kind").value_or("sphere");
  const std::string material = a.Get("material").value_or("stone");
  if (!datasets::SceneShapeFromName(kind)) throw UsageError("--kind: unknown shape '" + kind + "'");
  if (!datasets::MaterialKindFromName(material)) {
    throw UsageError("--material: unknown material '" + material + "'");
  }
  options.shape = *datasets::SceneShapeFromName(kind);
  options.material.kind = *datasets::MaterialKindFromName(material);
  options.Check();

  ProgressBar bar;
  const auto t0 = std::chrono::steady_clock::now();
  out << "1. A synthetic heritage scene: a " << material << " " << kind
      << " photographed under known lights, and an RTI capture of the " << material
      << " sample (texlume scene)\n";
  const datasets::SceneSummary scene =
      datasets::GenerateScene(options, dir / "scene", bar.Callback());
  out << "   " << scene.num_files << " files in " << (dir / "scene").string() << " ("
      << scene.seconds_total << " s); see MANIFEST.md there\n\n";
  const auto t1 = std::chrono::steady_clock::now();

  sfm::InspectOptions inspect;
  inspect.model_dir = dir / "scene/object/sparse";
  inspect.mesh = dir / "scene/object/mesh.ply";
  inspect.lights = dir / "scene/object/lights.json";
  inspect.images_dir = dir / "scene/object/images";
  out << "2. texlume inspect --model " << inspect.model_dir.string() << " --mesh "
      << inspect.mesh->string() << " --lights " << inspect.lights->string() << " --images "
      << inspect.images_dir->string() << "\n";
  const sfm::InspectReport report = sfm::RunInspect(inspect, bar.Callback());
  const auto t2 = std::chrono::steady_clock::now();
  out << sfm::FormatInspectReport(report);

  nlohmann::json run;
  run["command"] = "demo";
  run["settings"] = {{"shape", kind},
                     {"material", material},
                     {"seed", options.seed},
                     {"num_images", options.num_images}};
  run["timings_s"] = {{"scene", std::chrono::duration<double>(t1 - t0).count()},
                      {"inspect", std::chrono::duration<double>(t2 - t1).count()}};
  run["inspect"] = nlohmann::json::parse(sfm::InspectReportToJson(report));
  WriteFileAtomically(
      dir / "run.json", [&](std::ostream& o) { o << run.dump(2) << "\n"; }, false);
  return kExitOk;
}

}  // namespace texlume::apps
