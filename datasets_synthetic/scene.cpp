#include "datasets_synthetic/scene.h"

#include <chrono>
#include <cmath>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <sstream>

#include "core/errors.h"
#include "core/file_util.h"
#include "core/image_io.h"
#include "core/partial_output.h"
#include "datasets_synthetic/object_scene.h"
#include "ptm/exr_io.h"
#include "ptm/fit.h"
#include "sfm/colmap_io.h"

namespace texlume::datasets {
namespace {

constexpr int kSampleMarginTexels = 24;  // geometry around the captured area casts shadows in

Eigen::Vector3d FromAngles(double azimuth_rad, double elevation_rad) {
  return {std::cos(elevation_rad) * std::cos(azimuth_rad),
          std::cos(elevation_rad) * std::sin(azimuth_rad), std::sin(elevation_rad)};
}

// BTF view directions: straight down first, then rings at 60 and 35 degrees elevation.
std::vector<Eigen::Vector3d> BtfViewDirections(int count) {
  std::vector<Eigen::Vector3d> views = {Eigen::Vector3d::UnitZ()};
  const int rest = count - 1;
  const int high = (rest + 1) / 2, low = rest - high;
  for (int i = 0; i < high; ++i) {
    views.push_back(FromAngles(2 * std::numbers::pi * i / high, 60.0 * std::numbers::pi / 180.0));
  }
  for (int i = 0; i < low; ++i) {
    views.push_back(
        FromAngles(2 * std::numbers::pi * (i + 0.5) / low, 35.0 * std::numbers::pi / 180.0));
  }
  return views;
}

class StageTimer {
 public:
  explicit StageTimer(SceneSummary& summary) : summary_(summary) {}
  void Done(const std::string& stage) {
    const auto now = std::chrono::steady_clock::now();
    summary_.stage_seconds.emplace_back(stage, std::chrono::duration<double>(now - last_).count());
    last_ = now;
  }

 private:
  SceneSummary& summary_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

std::string Numbered(const char* pattern, int a, int b = 0) {
  char name[64];
  std::snprintf(name, sizeof(name), pattern, a, b);
  return name;
}

nlohmann::json Vec(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

void SceneOptions::Check() const {
  material.Check();
  if (mesh_resolution < 0 || mesh_resolution > 7)
    throw OptionError("mesh resolution must be in [0, 7]");
  RequireInRange(static_cast<double>(mesh_faces), 0,
                 static_cast<double>(ObjectSceneOptions::kMaxTargetFaces), "mesh_faces");
  RequireInRange(num_images, 3, 1000, "num_images");  // monument captures: 50-600
  RequireInRange(camera_rings, 1, 20, "camera_rings");
  if (camera_rings > num_images) throw OptionError("camera_rings must be at most num_images");
  RequireInRange(image_width, 64, 8192, "image_width");
  RequireInRange(image_height, 64, 8192, "image_height");
  RequireInRange(focal_px, 1, 1e6, "focal_px");
  RequireInRange(camera_distance, 1.6, 1000, "camera_distance");
  RequireInRange(max_lights_per_image, 1, 3, "max_lights_per_image");
  RequireInRange(photo_light_azimuth_spread_deg, 0.0, 360.0, "photo_light_azimuth_spread_deg");
  RequireInRange(num_held_out_views, 0, 100, "num_held_out_views");
  RequireInRange(held_out_lights_per_view, 1, 20, "held_out_lights_per_view");
  RequireInRange(held_out_scale, 1, 4, "held_out_scale");
  RequireInRange(held_out_min_elevation_deg, 0.0, 90.0, "held_out_min_elevation_deg");
  RequireInRange(held_out_max_elevation_deg, held_out_min_elevation_deg, 90.0,
                 "held_out_max_elevation_deg");
  RequireInRange(light_error_deg, 0.0, 20.0, "light_error_deg");
  RequireInRange(capture_size, 16, 4096, "capture_size");
  RequireInRange(num_capture_lights, 6, 500, "num_capture_lights");
  RequireInRange(num_held_out_capture_lights, 0, 500, "num_held_out_capture_lights");
  RequireInRange(btf_size, 16, 1024, "btf_size");
  RequireInRange(btf_view_count, 1, 64, "btf_view_count");
  RequireInRange(btf_light_count, 1, 128, "btf_light_count");
  RequireInRange(tessellation_step, 0, 1, "tessellation_step");
  shading.Check();
  sensor.Check();
  if (camera_model != sfm::CameraModelId::kPinhole && camera_model != sfm::CameraModelId::kOpenCV) {
    throw OptionError("camera_model must be PINHOLE or OPENCV");
  }
}

void UseRealisticCapture(SceneOptions& options) {
  options.sensor.shot_noise = 0.00005;
  options.sensor.read_noise = 0.0015;
  options.sensor.vignetting = 0.2;
  options.sensor.white_balance_spread = 0.05;
  options.sensor.jpeg_quality = 90;
  options.material.specular = 0.05;
  options.material.shininess = 30.0;
  options.material.sheen = 0.1;
  options.shading.interreflection_rays = 4;
  options.light_error_deg = 2.0;
}

namespace {

// `direction` turned about a random axis by a random angle of RMS rms_deg.
Eigen::Vector3d TurnedRandomly(const Eigen::Vector3d& direction, double rms_deg,
                               std::mt19937_64& rng) {
  // A 2-D Gaussian offset in the tangent plane, sigma = rms / sqrt(2) per axis:
  // the angle's RMS is rms_deg.
  std::normal_distribution<double> normal(0.0, rms_deg * std::numbers::pi / 180.0 / std::sqrt(2.0));
  const Eigen::Vector3d d = direction.normalized();
  const Eigen::Vector3d t = d.unitOrthogonal(), b = d.cross(t);
  const double a = normal(rng), c = normal(rng);
  const double angle = std::hypot(a, c);
  if (angle == 0.0) return d;
  return (d + std::tan(angle) * (a * t + c * b) / angle).normalized();
}

}  // namespace

SceneOptions SmallObjectSceneOptions(SceneShape shape, MaterialKind kind) {
  SceneOptions o;
  o.shape = shape;
  o.material.kind = kind;
  o.material.texel_size = 0.004;
  o.num_images = 12;
  o.image_width = 320;
  o.image_height = 240;
  o.focal_px = 300;
  o.capture_size = 128;
  o.num_capture_lights = 24;
  o.num_held_out_capture_lights = 0;
  o.write_btf = false;
  o.write_surface = false;
  return o;
}

ptm::Ptm FitSceneSample(const std::filesystem::path& scene_dir) {
  const std::filesystem::path capture = scene_dir / "material/capture";
  const ptm::RtiCapture rti = ptm::ReadRtiCapture(capture / "lights.lp", capture);
  return ptm::FitPtmFromFiles(rti.files, rti.lights, {}).ptm;
}

SceneOptions MaterialOnlySceneOptions(MaterialKind kind, int capture_size, int capture_lights) {
  SceneOptions o;
  o.material.kind = kind;
  o.shape = SceneShape::kPlane;
  o.capture_size = capture_size;
  o.num_capture_lights = capture_lights;
  o.write_btf = false;
  o.num_images = 3;
  o.num_held_out_views = 0;
  o.image_width = o.image_height = 64;
  o.focal_px = 60;
  return o;
}

std::vector<Eigen::Vector3d> DomeLights(int count, double min_elevation_deg,
                                        double max_elevation_deg, double offset) {
  std::vector<Eigen::Vector3d> lights;
  if (count <= 0) return lights;
  const int rings = std::max(1, static_cast<int>(std::round(std::sqrt(count / 1.6))));
  std::vector<double> elevations, weights;
  double total = 0;
  for (int r = 0; r < rings; ++r) {
    const double t = rings == 1 ? 0.5 : (r + 0.5 * offset) / (rings - 1 + 0.5 * offset);
    const double e = min_elevation_deg + (max_elevation_deg - min_elevation_deg) * std::min(1.0, t);
    elevations.push_back(e * std::numbers::pi / 180.0);
    weights.push_back(std::cos(e * std::numbers::pi / 180.0));
    total += weights.back();
  }
  // Ring sizes proportional to cos(elevation), at least one each, summing to count.
  std::vector<int> sizes(static_cast<std::size_t>(rings), 1);
  int assigned = rings;
  while (assigned < count) {
    std::size_t best = 0;
    double best_deficit = -1e9;
    for (std::size_t r = 0; r < sizes.size(); ++r) {
      const double deficit = weights[r] / total * count - sizes[r];
      if (deficit > best_deficit) best_deficit = deficit, best = r;
    }
    ++sizes[best];
    ++assigned;
  }
  for (std::size_t r = 0; r < sizes.size() && static_cast<int>(lights.size()) < count; ++r) {
    for (int i = 0; i < sizes[r] && static_cast<int>(lights.size()) < count; ++i) {
      const double azimuth =
          2 * std::numbers::pi * (i + offset + 0.37 * static_cast<double>(r)) / sizes[r];
      lights.push_back(FromAngles(azimuth, elevations[r]));
    }
  }
  return lights;
}

void WritePngAtomically(const std::filesystem::path& path, const cv::Mat& image) {
  WriteBytesAtomically(path, EncodePng(image, path.string()));
}

void PlanarSurfaceOptions::Check() const {
  material.Check();
  if (size < 1 || size > 16384) throw OptionError("surface size must be in [1, 16384] texels");
  if (scale < 1 || size % scale != 0) throw OptionError("scale must be >= 1 and divide size");
  if (offset < 0) throw OptionError("surface offset must be >= 0 texels");
  shading.Check();
}

PlanarSurfaceRenders RenderPlanarSurface(const PlanarSurfaceOptions& options,
                                         const std::vector<Eigen::Vector3d>& photo_lights,
                                         const std::vector<Eigen::Vector3d>& truth_lights) {
  options.Check();
  const double t = options.material.texel_size;
  const Material material(options.material);
  SurfacePatch patch = ShapePatches(SceneShape::kPlane)[0];
  const double u0 = options.offset * t, extent = options.size * t;
  const double margin = kSampleMarginTexels * t;
  patch.u0 = patch.v0 = u0 - margin;
  patch.u1 = patch.v1 = u0 + extent + margin;
  const BakedMaterial baked(material, patch.u0, patch.u1, patch.v0, patch.v1, false, false, t);
  const Renderer renderer(DisplacePatches({patch}, {&baked}, t), {&baked});
  PlanarSurfaceRenders out;
  const int small = options.size / options.scale;
  for (const auto& l : photo_lights) {
    const Rendering r =
        renderer.RenderOrthographic(small, small, u0, u0 + extent, t * options.scale,
                                    Eigen::Vector3d::UnitZ(), {{l, 1.0}}, options.shading);
    out.photos.push_back(LinearToSrgb8(r.linear_rgb));
  }
  for (const auto& l : truth_lights) {
    const Rendering r =
        renderer.RenderOrthographic(options.size, options.size, u0, u0 + extent, t,
                                    Eigen::Vector3d::UnitZ(), {{l, 1.0}}, options.shading);
    out.truth.push_back(LinearToSrgb8(r.linear_rgb));
  }
  return out;
}

cv::Mat CoverageMask(const Rendering& rendering) {
  cv::Mat mask;
  cv::compare(rendering.coverage, 0.5, mask, cv::CMP_GE);
  return mask;
}

namespace {

namespace fs = std::filesystem;

// Writes one synthetic scene into a folder (GenerateScene), a method per stage; the
// summary, the file count and the renderers the stages share are its members.
class SceneGenerator {
 public:
  SceneGenerator(const SceneOptions& options, const fs::path& dir, const ProgressCallback& progress)
      : options_(options),
        dir_(dir),
        progress_(progress),
        texel_(options.material.texel_size),
        extent_(options.capture_size * texel_) {
    summary_.dir = dir;
  }
  SceneGenerator(const SceneGenerator&) = delete;
  SceneGenerator& operator=(const SceneGenerator&) = delete;

  // Runs every stage in order, timing each, and returns what was written.
  SceneSummary Run() {
    MakeFolders();

    // ---------------------------------------------------------- material sample
    BuildSample();
    CaptureRti();
    timer_.Done("material_capture");
    WriteGroundTruth();
    timer_.Done("ground_truth");
    if (options_.write_surface) WritePlanarSurface();
    timer_.Done("planar_surface");
    if (options_.write_btf) CaptureBtf();
    timer_.Done("btf_capture");

    // ------------------------------------------------------------------- object
    BuildObject();
    timer_.Done("object_geometry");
    PhotographObject();
    timer_.Done("object_photos");
    if (options_.num_held_out_views > 0) RenderHeldOutViews();
    timer_.Done("held_out_views");

    // ------------------------------------------------------------------ records
    summary_.seconds_total =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    WriteSceneRecord();
    WriteManifest();
    summary_.num_files = files_;
    return summary_;
  }

 private:
  // Passes a stage's progress to the callback, if there is one.
  void Report(std::string_view stage, std::size_t done, std::size_t total) const {
    if (progress_) progress_(stage, done, total);
  }

  // Creates the scene's folder tree.
  void MakeFolders() const {
    for (const char* sub :
         {"material/capture", "material/held_out", "material/btf", "material/ground_truth",
          "object/images", "object/masks", "object/held_out/images", "object/held_out/masks"}) {
      fs::create_directories(dir_ / sub);
    }
  }

  // Bakes the flat material sample (with a margin around the captured area) and its renderer.
  void BuildSample() {
    const Material sample_material(options_.material);
    const double margin = kSampleMarginTexels * texel_;
    SurfacePatch sample_patch = ShapePatches(SceneShape::kPlane)[0];
    sample_patch.u0 = sample_patch.v0 = -margin;
    sample_patch.u1 = sample_patch.v1 = extent_ + margin;
    sample_baked_ = std::make_unique<const BakedMaterial>(sample_material, sample_patch.u0,
                                                          sample_patch.u1, sample_patch.v0,
                                                          sample_patch.v1, false, false, texel_);
    sample_renderer_ = std::make_unique<const Renderer>(
        DisplacePatches({sample_patch}, {sample_baked_.get()}, texel_),
        std::vector<const BakedMaterial*>{sample_baked_.get()});
    capture_shading_ = options_.shading;
    capture_shading_.exposure = 1.0;
  }

  // Renders the sample from above under each light into `folder`, with its lights.lp.
  void CaptureLightSet(const std::vector<Eigen::Vector3d>& lights, const fs::path& folder,
                       const char* pattern, const std::string& stage) {
    std::vector<sfm::LpEntry> entries;
    for (std::size_t i = 0; i < lights.size(); ++i) {
      const Rendering r = sample_renderer_->RenderOrthographic(
          options_.capture_size, options_.capture_size, 0.0, extent_, texel_,
          Eigen::Vector3d::UnitZ(), {{lights[i], 1.0}}, capture_shading_);
      const std::string name = Numbered(pattern, static_cast<int>(i));
      WritePngAtomically(folder / name, LinearToSrgb8(r.linear_rgb));
      entries.push_back({name, lights[i]});
      ++files_;
      Report(stage, i + 1, lights.size());
    }
    sfm::WriteLpFile(entries, folder / "lights.lp");
    ++files_;
  }

  // The sample's RTI capture, and its held-out lights if any.
  void CaptureRti() {
    CaptureLightSet(DomeLights(options_.num_capture_lights, 15, 80, 0.0), dir_ / "material/capture",
                    "rti_%03d.png", "rti capture");
    if (options_.num_held_out_capture_lights > 0) {
      CaptureLightSet(DomeLights(options_.num_held_out_capture_lights, 20, 75, 0.5),
                      dir_ / "material/held_out", "rti_held_%03d.png", "rti held-out");
    }
  }

  // Ground truth in the material frame, at the capture's texels (pixel centres).
  void WriteGroundTruth() {
    const int n = options_.capture_size;
    cv::Mat albedo(n, n, CV_32FC3), height(n, n, CV_32FC1), normals(n, n, CV_32FC3);
    const BakedMaterial& sample_baked = *sample_baked_;
    const double texel = texel_, extent = extent_;
#pragma omp parallel for schedule(dynamic, 8)
    for (int y = 0; y < n; ++y) {
      for (int x = 0; x < n; ++x) {
        const double u = (x + 0.5) * texel, v = extent - (y + 0.5) * texel;
        const Eigen::Vector3d a = sample_baked.Albedo(u, v);
        const Eigen::Vector2d g = sample_baked.HeightGradient(u, v);
        const Eigen::Vector3d nrm = Eigen::Vector3d(-g.x(), -g.y(), 1.0).normalized();
        albedo.at<cv::Vec3f>(y, x) = cv::Vec3f(static_cast<float>(a.x()), static_cast<float>(a.y()),
                                               static_cast<float>(a.z()));
        height.at<float>(y, x) = static_cast<float>(sample_baked.Height(u, v));
        normals.at<cv::Vec3f>(y, x) = cv::Vec3f(
            static_cast<float>(nrm.x()), static_cast<float>(nrm.y()), static_cast<float>(nrm.z()));
      }
    }
    std::vector<cv::Mat> a, nm;
    cv::split(albedo, a);
    cv::split(normals, nm);
    const fs::path gt = dir_ / "material/ground_truth";
    ptm::WriteExr(gt / "albedo.exr", a, {"R", "G", "B"});
    ptm::WriteExr(gt / "height.exr", {height}, {"Y"});
    ptm::WriteExr(gt / "normals.exr", nm, {"X", "Y", "Z"});
    WritePngAtomically(gt / "albedo.png", LinearToSrgb8(albedo));
    cv::Mat normals_png;
    normals.convertTo(normals_png, CV_8UC3, 127.5, 127.5);
    cv::cvtColor(normals_png, normals_png, cv::COLOR_RGB2BGR);
    WritePngAtomically(gt / "normals.png", normals_png);
    files_ += 5;
  }

  // Photos of an unseen planar surface of the material (synth2d input).
  void WritePlanarSurface() {
    fs::create_directories(dir_ / "material/surface/photos");
    fs::create_directories(dir_ / "material/surface/truth");
    PlanarSurfaceOptions surface;
    surface.material = options_.material;
    surface.size = options_.capture_size - options_.capture_size % 2;
    surface.scale = 2;
    surface.offset = options_.capture_size + 2 * kSampleMarginTexels;
    surface.shading = capture_shading_;
    const std::vector<Eigen::Vector3d> photo_lights = {
        Eigen::Vector3d(0.6, 0.2, 0.77).normalized(), Eigen::Vector3d(-0.4, 0.5, 0.77).normalized(),
        Eigen::Vector3d(-0.1, -0.65, 0.75).normalized()};
    std::vector<Eigen::Vector3d> truth_lights = photo_lights;
    for (const auto& l : DomeLights(4, 25, 70, 0.3)) truth_lights.push_back(l);
    const PlanarSurfaceRenders renders = RenderPlanarSurface(surface, photo_lights, truth_lights);
    std::vector<sfm::LpEntry> photo_entries, truth_entries;
    for (std::size_t i = 0; i < renders.photos.size(); ++i) {
      const std::string name = Numbered("photo_%02d.png", static_cast<int>(i));
      WritePngAtomically(dir_ / "material/surface/photos" / name, renders.photos[i]);
      photo_entries.push_back({name, photo_lights[i]});
    }
    for (std::size_t i = 0; i < renders.truth.size(); ++i) {
      const std::string name = Numbered("truth_%02d.png", static_cast<int>(i));
      WritePngAtomically(dir_ / "material/surface/truth" / name, renders.truth[i]);
      truth_entries.push_back({name, truth_lights[i]});
    }
    sfm::WriteLpFile(photo_entries, dir_ / "material/surface/photos/lights.lp");
    sfm::WriteLpFile(truth_entries, dir_ / "material/surface/truth/lights.lp");
    files_ += renders.photos.size() + renders.truth.size() + 2;
  }

  // BTF: views x lights, rectified to the material frame.
  void CaptureBtf() {
    nlohmann::json btf;
    const auto views = BtfViewDirections(options_.btf_view_count);
    const auto lights = DomeLights(options_.btf_light_count, 20, 75, 0.25);
    btf["texel_size"] = texel_;
    btf["size"] = options_.btf_size;
    btf["frame"] =
        "material: x right (u), y up (v), z out of the sample; directions towards viewer/light";
    btf["file_pattern"] = "view_%02d_light_%02d.png";
    for (const auto& v : views) btf["views"].push_back(Vec(v));
    for (const auto& l : lights) btf["lights"].push_back(Vec(l));
    std::size_t done = 0;
    for (std::size_t vi = 0; vi < views.size(); ++vi) {
      for (std::size_t li = 0; li < lights.size(); ++li) {
        const Rendering r = sample_renderer_->RenderOrthographic(
            options_.btf_size, options_.btf_size, 0.0, options_.btf_size * texel_, texel_,
            views[vi], {{lights[li], 1.0}}, capture_shading_);
        WritePngAtomically(
            dir_ / "material/btf" /
                Numbered("view_%02d_light_%02d.png", static_cast<int>(vi), static_cast<int>(li)),
            LinearToSrgb8(r.linear_rgb));
        ++files_;
        Report("btf capture", ++done, views.size() * lights.size());
      }
    }
    WriteFileAtomically(
        dir_ / "material/btf/btf.json", [&](std::ostream& o) { o << btf.dump(2) << "\n"; }, false);
    ++files_;
  }

  // The object's COLMAP scene and its displaced geometry, with the material baked per patch.
  void BuildObject() {
    ObjectSceneOptions object_options;
    object_options.shape = options_.shape;
    object_options.resolution = options_.mesh_resolution;
    object_options.target_faces = options_.mesh_faces;
    object_options.camera_rings = options_.camera_rings;
    object_options.num_images = options_.num_images;
    object_options.image_width = options_.image_width;
    object_options.image_height = options_.image_height;
    object_options.focal_px = options_.focal_px;
    object_options.camera_distance = options_.camera_distance;
    object_options.camera_model = options_.camera_model;
    object_options.max_lights_per_image = options_.max_lights_per_image;
    object_options.light_azimuth_spread_deg = options_.photo_light_azimuth_spread_deg;
    object_options.seed = options_.seed;
    object_ = MakeObjectScene(object_options);

    const std::vector<SurfacePatch> patches = ShapePatches(options_.shape);
    std::vector<const BakedMaterial*> material_ptrs;
    for (const SurfacePatch& p : patches) {
      const Material material(options_.material, p.periodic_u ? p.u1 - p.u0 : 0.0,
                              p.periodic_v ? p.v1 - p.v0 : 0.0);
      materials_.push_back(std::make_unique<BakedMaterial>(material, p.u0, p.u1, p.v0, p.v1,
                                                           p.periodic_u, p.periodic_v, texel_));
      material_ptrs.push_back(materials_.back().get());
    }
    step_ = options_.tessellation_step > 0 ? options_.tessellation_step : 2 * texel_;
    renderer_ = std::make_unique<const Renderer>(DisplacePatches(patches, material_ptrs, step_),
                                                 material_ptrs);
    summary_.displaced_triangles = renderer_->NumTriangles();
  }

  // The camera of the object's photos.
  const sfm::Camera& PhotoCamera() const { return object_.reconstruction.cameras.begin()->second; }

  // The object's photos and masks under their lights (exposure drawn per photo), and its model.
  void PhotographObject() {
    std::mt19937_64 rng(options_.seed * 31u + 7u);
    std::mt19937_64 sensor_rng(options_.seed * 1000003u + 17u);  // apart from the exposures'
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    const sfm::Camera& camera = PhotoCamera();
    std::size_t done = 0;
    for (const auto& [id, image] : object_.reconstruction.images) {
      ShadingOptions shading = options_.shading;
      shading.exposure = options_.vary_exposure ? 0.8 + 0.4 * uniform(rng) : 1.0;
      std::vector<RenderLight> lights;
      for (const auto& l : object_.lights.at(image.name)) {
        lights.push_back({l.direction_in_world, l.intensity});
      }
      const Rendering r =
          renderer_->RenderPerspective(camera, image.cam_from_world, lights, shading);
      SensorDraw draw;
      const cv::Mat photo = options_.sensor.Active()
                                ? ExposeOnSensor(r.linear_rgb, options_.sensor, sensor_rng, &draw)
                                : LinearToSrgb8(r.linear_rgb);
      WritePngAtomically(dir_ / "object/images" / image.name, photo);
      WritePngAtomically(dir_ / "object/masks" / image.name, CoverageMask(r));
      photos_[image.name] = {{"exposure", shading.exposure}, {"lights", lights.size()}};
      if (options_.sensor.white_balance_spread > 0)
        photos_[image.name]["white_balance"] = {draw.white_balance[0], draw.white_balance[1],
                                                draw.white_balance[2]};
      files_ += 2;
      Report("object photos", ++done, object_.reconstruction.images.size());
    }
    if (options_.light_error_deg > 0) MisrecordLights();
    WriteObjectScene(object_, dir_ / "object");
    files_ += 9;
  }

  // The photos' lights as a calibration would record them: each turned by a
  // random angle of light_error_deg RMS (the angles go into scene.json).
  void MisrecordLights() {
    std::mt19937_64 rng(options_.seed * 7919u + 3u);
    for (auto& [name, lights] : object_.lights) {
      nlohmann::json errors = nlohmann::json::array();
      for (sfm::ObjectLight& l : lights) {
        const Eigen::Vector3d recorded =
            TurnedRandomly(l.direction_in_world, options_.light_error_deg, rng);
        const double cosine =
            std::clamp(recorded.dot(l.direction_in_world.normalized()), -1.0, 1.0);
        errors.push_back(std::acos(cosine) * 180.0 / std::numbers::pi);
        l.direction_in_world = recorded;
      }
      photos_[name]["light_error_deg"] = errors;
    }
  }

  // Held-out views x held-out lights: ground truth for relighting from new views.
  void RenderHeldOutViews() {
    const sfm::Camera& camera = PhotoCamera();
    sfm::Reconstruction held;
    const sfm::Camera held_camera = camera.Scaled(options_.held_out_scale);
    held.cameras[held_camera.camera_id] = held_camera;
    sfm::ObjectLights held_lights;
    std::uint32_t next_id = 1;
    std::size_t done = 0;
    const std::size_t total =
        static_cast<std::size_t>(options_.num_held_out_views * options_.held_out_lights_per_view);
    const bool plane = options_.shape == SceneShape::kPlane;
    for (int v = 0; v < options_.num_held_out_views; ++v) {
      const double azimuth = 2 * std::numbers::pi * (v + 0.5) / options_.num_held_out_views + 0.2;
      const double elevation = (plane ? 50.0 : 22.0) * std::numbers::pi / 180.0;
      const sfm::Rigid3d pose = LookAt(options_.camera_distance * FromAngles(azimuth, elevation),
                                       Eigen::Vector3d::Zero());
      const auto dome =
          DomeLights(options_.held_out_lights_per_view, options_.held_out_min_elevation_deg,
                     options_.held_out_max_elevation_deg, 0.3);
      for (int k = 0; k < options_.held_out_lights_per_view; ++k) {
        // The dome is turned towards the view so the visible side is lit.
        const Eigen::Vector3d d = dome[static_cast<std::size_t>(k)];
        const Eigen::Vector3d light = Eigen::AngleAxisd(azimuth, Eigen::Vector3d::UnitZ()) *
                                      Eigen::Vector3d(std::abs(d.x()), d.y(), d.z());
        sfm::Image image;
        image.image_id = sfm::ImageId(next_id++);
        image.camera_id = camera.camera_id;
        image.name = Numbered("view_%02d_light_%02d.png", v, k);
        image.cam_from_world = pose;
        held.images[image.image_id] = image;
        sfm::ObjectLight object_light;
        object_light.direction_in_world = light.normalized();
        held_lights[image.name] = {object_light};
        ShadingOptions shading = options_.shading;
        shading.exposure = 1.0;
        const Rendering r =
            renderer_->RenderPerspective(held_camera, pose, {{light.normalized(), 1.0}}, shading);
        WritePngAtomically(dir_ / "object/held_out/images" / image.name,
                           LinearToSrgb8(r.linear_rgb));
        WritePngAtomically(dir_ / "object/held_out/masks" / image.name, CoverageMask(r));
        files_ += 2;
        Report("held-out views", ++done, total);
      }
    }
    sfm::WriteModel(held, dir_ / "object/held_out/sparse", sfm::ModelFormat::kBinary);
    sfm::WriteModel(held, dir_ / "object/held_out/sparse_txt", sfm::ModelFormat::kText);
    sfm::WriteObjectLightsFile(held_lights, dir_ / "object/held_out/lights.json");
    files_ += 7;
  }

  // scene.json: the settings, per-photo exposures and lights, and the stage timings.
  void WriteSceneRecord() {
    nlohmann::json record;
    record["generator"] = "texlume scene";
    record["shape"] = SceneShapeName(options_.shape);
    record["material"] = {{"kind", MaterialKindName(options_.material.kind)},
                          {"texel_size", texel_},
                          {"relief_height", options_.material.relief_height},
                          {"feature_scale", options_.material.feature_scale},
                          {"specular", options_.material.specular},
                          {"shininess", options_.material.shininess},
                          {"sheen", options_.material.sheen},
                          {"seed", options_.material.seed}};
    record["seed"] = options_.seed;
    record["coarse_mesh"] = {{"resolution", options_.mesh_resolution},
                             {"target_faces", options_.mesh_faces},
                             {"faces", object_.mesh.faces.size()}};
    record["units"] = "world units of the COLMAP model (the shapes are about 2 units across)";
    record["camera"] = {{"model", sfm::CameraModelName(options_.camera_model)},
                        {"width", options_.image_width},
                        {"height", options_.image_height},
                        {"focal_px", options_.focal_px},
                        {"distance", options_.camera_distance},
                        {"rings", options_.camera_rings},
                        {"held_out_scale", options_.held_out_scale}};
    record["held_out_light_elevations_deg"] = {options_.held_out_min_elevation_deg,
                                               options_.held_out_max_elevation_deg};
    record["shading"] = {{"ambient", options_.shading.ambient},
                         {"samples_per_pixel",
                          options_.shading.samples_per_axis * options_.shading.samples_per_axis},
                         {"shadows", options_.shading.shadows},
                         {"interreflection_rays", options_.shading.interreflection_rays}};
    record["light_error_deg"] = options_.light_error_deg;
    record["photo_light_azimuth_spread_deg"] = options_.photo_light_azimuth_spread_deg;
    record["sensor"] = options_.sensor.ToJson();
    record["capture"] = {{"size", options_.capture_size},
                         {"lights", options_.num_capture_lights},
                         {"held_out_lights", options_.num_held_out_capture_lights}};
    record["photos"] = photos_;
    record["displaced_triangles"] = summary_.displaced_triangles;
    record["tessellation_step"] = step_;
    for (const auto& [stage, s] : summary_.stage_seconds) record["timings_s"][stage] = s;
    record["timings_s"]["total"] = summary_.seconds_total;
    WriteFileAtomically(
        dir_ / "scene.json", [&](std::ostream& o) { o << record.dump(2) << "\n"; }, false);
    ++files_;
  }

  // The texlume commands that use the scene, run from its folder.
  void WriteCommands(std::ostream& out) const {
    out << "\n## Commands\n\nRun from this folder: fit the sample, synthesise the model from "
           "the photos, then render it at the held-out views under the held-out lights and "
           "measure it against the truth (at full resolution, and reduced to the photos' "
           "resolution).\n\n```\n"
        << "texlume fit --images material/capture --lights material/capture/lights.lp "
           "--out sample.ptm --exr sample.exr\n"
        << "texlume synth --model object/sparse --images object/images --lights "
           "object/lights.json --mesh object/mesh.ply --sample sample.exr --sample-texel-size "
        << texel_ << " --out model\n";
    if (options_.num_held_out_views > 0)
      out << "texlume render --model model --cameras object/held_out/sparse --lights "
             "object/held_out/lights.json --out render --truth object/held_out/images "
             "--truth-masks object/held_out/masks --reduced-factor "
          << options_.held_out_scale << "\n";
    out << "texlume view model\n";
    if (options_.write_btf)
      out << "texlume synth --model object/sparse --images object/images --lights "
             "object/lights.json --mesh object/mesh.ply --btf material/btf --out model_btf\n";
    out << "```\n";
  }

  // MANIFEST.md: what each path of the scene holds.
  void WriteManifest() {
    std::ostringstream manifest;
    manifest
        << "# Synthetic texlume scene: " << MaterialKindName(options_.material.kind) << " "
        << SceneShapeName(options_.shape) << " (seed " << options_.seed << ")\n\n"
        << "Generated by `texlume scene`; layout and conventions in texlume's "
           "docs/synthetic_scenes.md. Settings and timings: `scene.json`.\n\n"
        << "| path | what |\n| --- | --- |\n"
        << "| `material/capture/rti_NNN.png`, `lights.lp` | RTI capture of the flat sample: "
        << options_.capture_size << "x" << options_.capture_size << " texels of " << texel_
        << " world units, orthographic from above, " << options_.num_capture_lights
        << " directional lights (8-bit sRGB) |\n"
        << "| `material/held_out/` | the same sample under " << options_.num_held_out_capture_lights
        << " other lights, for leave-out tests |\n"
        << "| `material/surface/photos/`, `material/surface/truth/` | an unseen planar surface of "
           "the material: 3 photos at half resolution (`lights.lp`), and ground truth at full "
           "resolution under the photo lights then 4 others (`lights.lp`) |\n"
        << "| `material/btf/view_VV_light_LL.png`, `btf.json` | BTF capture, views x lights, "
           "rectified to the material frame |\n"
        << "| `material/ground_truth/` | albedo (linear EXR, sRGB PNG), height (EXR, world "
           "units), normals (EXR, material frame; PNG as 0.5 + 0.5 n) |\n"
        << "| `object/images/`, `object/masks/` | " << options_.num_images
        << " photos of the displaced " << SceneShapeName(options_.shape)
        << " and their object masks |\n"
        << "| `object/sparse/`, `object/sparse_txt/` | the COLMAP model (binary, text) |\n"
        << "| `object/lights.json` | object lights per photo (world frame) |\n"
        << "| `object/mesh.ply` | the coarse undisplaced mesh, in the model's frame |\n"
        << "| `object/held_out/` | held-out views x held-out lights: images, masks, COLMAP "
           "model, lights |\n\n"
        << "Light directions point from the surface to the light. In `.lp` files: x right, y "
           "up, z out of the sample. In JSON: world frame (Z up).\n";
    WriteCommands(manifest);
    WriteFileAtomically(
        dir_ / "MANIFEST.md", [&](std::ostream& o) { o << manifest.str(); }, false);
    ++files_;
  }

  const SceneOptions& options_;
  const fs::path& dir_;
  const ProgressCallback& progress_;
  const double texel_;
  const double extent_;  // the captured sample's side, world units
  const std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  SceneSummary summary_;
  StageTimer timer_{summary_};
  std::size_t files_ = 0;

  // The material sample (material stages).
  std::unique_ptr<const BakedMaterial> sample_baked_;
  std::unique_ptr<const Renderer> sample_renderer_;
  ShadingOptions capture_shading_;

  // The object (object stages).
  ObjectScene object_;
  std::vector<std::unique_ptr<BakedMaterial>> materials_;
  double step_ = 0.0;  // tessellation step of the displaced geometry
  std::unique_ptr<const Renderer> renderer_;
  nlohmann::json photos_ = nlohmann::json::object();
};

}  // namespace

SceneSummary GenerateScene(const SceneOptions& options, const std::filesystem::path& dir,
                           const ProgressCallback& progress) {
  options.Check();
  RequireReplaceableFolder(dir, "scene.json", "a texlume scene folder");
  PartialOutput output(dir, PartialOutput::Kind::kFolder);
  SceneSummary summary = SceneGenerator(options, output.path(), progress).Run();
  output.Commit();
  summary.dir = dir;
  return summary;
}

}  // namespace texlume::datasets
