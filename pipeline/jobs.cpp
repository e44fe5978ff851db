#include "pipeline/jobs.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "btf/btf.h"
#include "core/errors.h"
#include "core/file_util.h"
#include "core/image_io.h"
#include "core/memory_budget.h"
#include "core/partial_output.h"
#include "core/timing.h"
#include "model/model_io.h"
#include "pipeline/btf_synth_job.h"
#include "ptm/horizon.h"
#include "ptm/hsh.h"
#include "ptm/ptm_io.h"
#include "ptm/shadowed_fit.h"
#include "sfm/lights.h"

namespace texlume::pipeline {
namespace fs = std::filesystem;
namespace {

void WriteJson(const fs::path& path, const nlohmann::json& record) {
  WriteFileAtomically(
      path, [&](std::ostream& o) { o << record.dump(2) << "\n"; }, false);
}

void RequirePath(const fs::path& path, const char* what) {
  if (path.empty()) throw OptionError(std::string("give ") + what);
}

// An RGB float image (rows of width x 3 values) as an 8-bit image file whose
// format follows the extension (PNG without one); `signed_unit` maps [-1, 1].
void WriteRgbImage(const fs::path& path, const std::vector<float>& rgb, int width, int height,
                   bool signed_unit) {
  cv::Mat image(height, width, CV_8UC3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < 3; ++c) {
        float v = rgb[(static_cast<std::size_t>(y) * width + x) * 3 + static_cast<std::size_t>(c)];
        if (signed_unit) v = 0.5f * v + 0.5f;
        image.at<cv::Vec3b>(y, x)[2 - c] =
            static_cast<std::uint8_t>(std::clamp(std::lround(255.0f * v), 0L, 255L));
      }
    }
  }
  std::vector<unsigned char> bytes;
  bool encoded = false;
  try {
    encoded = cv::imencode(path.extension().string().empty() ? ".png" : path.extension().string(),
                           image, bytes);
  } catch (const cv::Exception&) {
    encoded = false;
  }
  if (!encoded) throw InputError(path.string(), "cannot be encoded (use .png, .jpg or .tif)");
  WriteBytesAtomically(path, bytes);
}

// Refuses an output image name whose extension WriteRgbImage cannot encode.
void RequireImageExtension(const fs::path& path, const char* what) {
  const std::string ext = LowerCaseExtension(path);
  for (const char* ok : {"", ".png", ".jpg", ".jpeg", ".tif", ".tiff"}) {
    if (ext == ok) return;
  }
  throw OptionError(std::string(what) + " '" + path.string() +
                    "' must end in .png, .jpg or .tif (no extension writes PNG)");
}

}  // namespace

nlohmann::json InspectJobOptions::ToJson() const {
  return {{"model", inspect.model_dir.string()},
          {"mesh", inspect.mesh ? inspect.mesh->string() : ""},
          {"images", inspect.images_dir ? inspect.images_dir->string() : ""},
          {"lights", inspect.lights ? inspect.lights->string() : ""},
          {"max_buffer_size", inspect.visibility.max_buffer_dimension}};
}

bool RunInspectJob(const InspectJobOptions& options, std::ostream& out, std::ostream& err,
                   const ProgressCallback& progress) {
  options.Check();
  const sfm::InspectReport report = sfm::RunInspect(options.inspect, progress);
  out << sfm::FormatInspectReport(report);
  if (!options.json_file.empty()) {
    const std::string json = sfm::InspectReportToJson(report);
    WriteFileAtomically(
        options.json_file, [&](std::ostream& o) { o << json << "\n"; }, false);
  }
  if (report.missing_images && !report.missing_images->empty()) {
    err << "error: " << options.inspect.images_dir->string() << ": "
        << report.missing_images->size() << " image(s) named in the model are missing, first: '"
        << report.missing_images->front() << "'\n";
    return false;
  }
  return true;
}

void FitJobOptions::Check() const {
  RequirePath(images_dir, "the capture's image folder");
  RequirePath(lights_file, "the capture's .lp file");
  RequirePath(out_file, basis == "hsh" ? "the .rti file to write" : "the .ptm file to write");
  fit.Check();
  if (basis != "ptm" && basis != "hsh") throw OptionError("--basis must be ptm or hsh");
  if (basis == "hsh") {
    if (hsh_order < ptm::kHshMinOrder || hsh_order > ptm::kHshMaxOrder)
      throw OptionError("--order must be 2 or 3 (4 or 9 HSH terms)");
    if (!exr_file.empty()) throw OptionError("--exr holds a PTM; an HSH fit writes .rti and --web");
    if (fit.robust) throw OptionError("--robust fits PTMs only");
    if (LowerCaseExtension(out_file) != ".rti")
      throw OptionError("an HSH fit writes RTIViewer's .rti: name --out FILE.rti");
  }
  if (!horizon_file.empty()) {
    if (basis != "ptm") throw OptionError("--horizon goes with a PTM fit (--basis ptm)");
    if (fit.robust) throw OptionError("--horizon and --robust both set shadows aside: choose one");
    if (LowerCaseExtension(horizon_file) != ".exr")
      throw OptionError("the horizon map is an OpenEXR file: name --horizon FILE.exr");
    if (fs::path(horizon_file).lexically_normal() == fs::path(exr_file).lexically_normal() ||
        fs::path(horizon_file).lexically_normal() == fs::path(out_file).lexically_normal())
      throw OptionError("--horizon must name another file than --out and --exr");
  }
}

nlohmann::json FitJobOptions::ToJson() const {
  if (basis == "hsh")
    return {{"images", images_dir.string()},
            {"lights", lights_file.string()},
            {"basis", "hsh"},
            {"order", hsh_order},
            {"band_rows", fit.band_rows}};
  nlohmann::json j = {{"images", images_dir.string()},
                      {"lights", lights_file.string()},
                      {"basis", "ptm"},
                      {"format", fit.format == ptm::PtmFormat::kLrgb ? "lrgb" : "rgb"},
                      {"robust", fit.robust},
                      {"band_rows", fit.band_rows},
                      {"robust_scale", fit.robust_scale}};
  if (!horizon_file.empty()) j["horizon"] = horizon_file.string();
  return j;
}

namespace {

// What a fit wrote: the line it prints and its record.
struct FitOutcome {
  std::string summary;
  nlohmann::json result;
  double fit_seconds = 0, write_seconds = 0;
};

FitOutcome FitAndWritePtm(const FitJobOptions& options, const ptm::RtiCapture& capture,
                          const ProgressCallback& progress) {
  ptm::CheckLightSet(capture.lights, options.fit, options.lights_file.string());
  const ptm::FitResult result =
      ptm::FitPtmFromFiles(capture.files, capture.lights, options.fit, progress);
  const auto t0 = std::chrono::steady_clock::now();
  ptm::WritePtmFile(result.ptm, options.out_file);
  if (!options.exr_file.empty()) ptm::WritePtmExr(result.ptm, options.exr_file);
  if (!options.web_dir.empty()) ptm::WriteRelightWeb(result.ptm, options.web_dir);
  FitOutcome o;
  o.write_seconds = SecondsSince(t0);
  o.fit_seconds = result.seconds;
  std::ostringstream line;
  line << "Fitted a " << result.ptm.width << "x" << result.ptm.height << " "
       << (options.fit.format == ptm::PtmFormat::kLrgb ? "LRGB" : "RGB") << " PTM to "
       << result.num_images << " images in " << result.seconds << " s"
       << (options.fit.robust ? " (robust)" : "") << "; mean RMS residual "
       << result.mean_residual_rms * 255.0 << " / 255. Wrote " << options.out_file.string();
  o.summary = line.str();
  o.result = {{"width", result.ptm.width},
              {"height", result.ptm.height},
              {"images", result.num_images},
              {"mean_residual_rms", result.mean_residual_rms}};
  return o;
}

// The capture's images, all in memory (the memory limit is checked against the
// first image's size before the others are read).
std::vector<cv::Mat> ReadWholeCapture(const ptm::RtiCapture& capture, const std::string& label,
                                      const ProgressCallback& progress) {
  std::vector<cv::Mat> images;
  for (std::size_t k = 0; k < capture.files.size(); ++k) {
    if (progress) progress("reading the capture", k, capture.files.size());
    images.push_back(ReadPhotoRgb(capture.files[k]));
    if (images[k].size() != images[0].size())
      throw InputError(capture.files[k].string(),
                       std::to_string(images[k].cols) + " x " + std::to_string(images[k].rows) +
                           " pixels, where the capture's first image has " +
                           std::to_string(images[0].cols) + " x " + std::to_string(images[0].rows));
    // Per image and texel: 12 bytes of RGB and 8 of lit masks; per texel, the horizon
    // maps, heights and PTMs of the steps.
    if (k == 0)
      RequireMemory((20.0 * static_cast<double>(capture.files.size()) + 400.0) *
                        static_cast<double>(images[0].total()),
                    "the shadowed fit (every image of the capture in memory)", label);
  }
  return images;
}

FitOutcome FitAndWriteShadowedPtm(const FitJobOptions& options, const ptm::RtiCapture& capture,
                                  const ProgressCallback& progress) {
  ptm::CheckLightSet(capture.lights, options.fit, options.lights_file.string());
  if (capture.lights.size() < 8)
    throw InputError(options.lights_file.string(),
                     std::to_string(capture.lights.size()) +
                         " lights: a fit with --horizon needs at least 8 (a quarter of them "
                         "checks the horizon's height)");
  const auto t_read = std::chrono::steady_clock::now();
  const std::vector<cv::Mat> images =
      ReadWholeCapture(capture, options.images_dir.string(), progress);
  const double read_seconds = SecondsSince(t_read);
  const auto t_fit = std::chrono::steady_clock::now();
  ptm::ShadowedFitOptions shadowed;
  shadowed.format = options.fit.format;
  const ptm::ShadowedPtm fit = ptm::FitShadowedPtm(images, capture.lights, shadowed, progress);
  FitOutcome o;
  o.fit_seconds = read_seconds + SecondsSince(t_fit);
  const auto t0 = std::chrono::steady_clock::now();
  // The horizon first: a PTM of the lit samples is not left without it.
  ptm::WriteSelfShadowingExr(fit.shadowing, options.horizon_file);
  ptm::WritePtmFile(fit.ptm, options.out_file);
  if (!options.exr_file.empty()) ptm::WritePtmExr(fit.ptm, options.exr_file);
  if (!options.web_dir.empty()) ptm::WriteRelightWeb(fit.ptm, options.web_dir);
  o.write_seconds = SecondsSince(t0);
  std::ostringstream line;
  line << "Fitted a " << fit.ptm.width << "x" << fit.ptm.height << " "
       << (options.fit.format == ptm::PtmFormat::kLrgb ? "LRGB" : "RGB")
       << " PTM to the lit samples of " << images.size()
       << " images and its horizon map (height scale " << fit.shadowing.height_scale
       << ", shadows keep " << fit.shadowing.shadow_floor << " of the light) in " << o.fit_seconds
       << " s. Wrote " << options.out_file.string() << " and " << options.horizon_file.string();
  o.summary = line.str();
  o.result = {{"width", fit.ptm.width},
              {"height", fit.ptm.height},
              {"images", images.size()},
              {"horizon",
               {{"file", options.horizon_file.string()},
                {"sectors", fit.shadowing.horizon.sectors},
                {"height_scale", fit.shadowing.height_scale},
                {"shadow_floor", fit.shadowing.shadow_floor},
                {"penumbra_deg", fit.shadowing.penumbra_rad * 180.0 / std::numbers::pi}}}};
  return o;
}

FitOutcome FitAndWriteHsh(const FitJobOptions& options, const ptm::RtiCapture& capture,
                          const ProgressCallback& progress) {
  const ptm::HshFitResult result = ptm::FitHshFromFiles(
      capture.files, capture.lights, options.hsh_order, options.fit.band_rows, progress);
  const auto t0 = std::chrono::steady_clock::now();
  ptm::WriteRtiFile(result.hsh, options.out_file);
  if (!options.web_dir.empty()) ptm::WriteHshRelightWeb(result.hsh, options.web_dir);
  FitOutcome o;
  o.write_seconds = SecondsSince(t0);
  o.fit_seconds = result.seconds;
  std::ostringstream line;
  line << "Fitted a " << result.hsh.width << "x" << result.hsh.height << " order-"
       << result.hsh.order << " HSH (" << result.hsh.Terms() << " terms per channel) to "
       << capture.files.size() << " images in " << result.seconds << " s; mean RMS residual "
       << result.mean_residual_rms * 255.0 << " / 255. Wrote " << options.out_file.string();
  o.summary = line.str();
  o.result = {{"width", result.hsh.width},
              {"height", result.hsh.height},
              {"images", capture.files.size()},
              {"terms", result.hsh.Terms()},
              {"mean_residual_rms", result.mean_residual_rms}};
  return o;
}

}  // namespace

void RunFitJob(const FitJobOptions& options, std::ostream& out, std::ostream& err,
               const ProgressCallback& progress) {
  options.Check();
  RequireWritableFilePath(options.out_file);
  if (!options.exr_file.empty()) RequireWritableFilePath(options.exr_file);
  if (!options.horizon_file.empty()) RequireWritableFilePath(options.horizon_file);
  std::error_code ec;
  if (!options.web_dir.empty() && fs::exists(options.web_dir, ec) &&
      !fs::is_directory(options.web_dir, ec)) {
    throw InputError(options.web_dir.string(), "exists and is not a folder");
  }
  const ptm::RtiCapture capture = ptm::ReadRtiCapture(options.lights_file, options.images_dir);
  for (const std::string& w : capture.warnings) err << "warning: " << w << "\n";
  const FitOutcome fit = options.basis == "hsh" ? FitAndWriteHsh(options, capture, progress)
                         : !options.horizon_file.empty()
                             ? FitAndWriteShadowedPtm(options, capture, progress)
                             : FitAndWritePtm(options, capture, progress);
  out << fit.summary << "\n";
  nlohmann::json record;
  record["command"] = "fit";
  record["settings"] = options.ToJson();
  record["result"] = fit.result;
  record["result"]["intensity_space"] = "display (sRGB-encoded) values in [0, 1]";
  record["warnings"] = capture.warnings;
  record["timings_s"] = {{"fit", fit.fit_seconds}, {"write", fit.write_seconds}};
  fs::path record_path = options.out_file;
  record_path += ".json";
  WriteJson(record_path, record);
}

void BtfJobOptions::Check() const {
  RequirePath(capture_dir, "the BTF capture folder");
  RequirePath(out_dir, "the folder to write");
  if (components < 1) throw OptionError("components must be at least 1");
}

nlohmann::json BtfJobOptions::ToJson() const {
  return {{"capture", capture_dir.string()}, {"components", components}};
}

void RunBtfJob(const BtfJobOptions& options, std::ostream& out, const ProgressCallback& progress) {
  options.Check();
  RequireReplaceableFolder(options.out_dir, "btf_svd.json", "a texlume btf folder");
  const auto t0 = std::chrono::steady_clock::now();
  const btf::BtfCapture capture = btf::ReadBtfCapture(options.capture_dir);
  const double read_seconds = SecondsSince(t0);
  const auto t1 = std::chrono::steady_clock::now();
  const btf::BtfFactorisation f = btf::FactoriseBtf(capture, options.components, progress);
  const double factorise_seconds = SecondsSince(t1);
  const auto t2 = std::chrono::steady_clock::now();
  // The error table: powers of two up to the rank, the chosen n included.
  std::vector<int> counts;
  for (int n = 1; n < static_cast<int>(f.singular_values.size()); n *= 2) counts.push_back(n);
  counts.push_back(static_cast<int>(f.singular_values.size()));
  counts.push_back(options.components);
  std::sort(counts.begin(), counts.end());
  counts.erase(std::unique(counts.begin(), counts.end()), counts.end());
  const std::vector<btf::SvdError> errors = btf::SvdErrorTable(f, counts);
  PartialOutput output(options.out_dir, PartialOutput::Kind::kFolder);
  btf::WriteBtfFactorisation(f, errors, output.path());
  out << "Factorised a " << capture.width << "x" << capture.height << " BTF of "
      << capture.views.size() << " views x " << capture.lights.size() << " lights into "
      << options.components << " components in " << factorise_seconds << " s. Wrote "
      << options.out_dir.string() << "\n components | RMS error (linear) | relative\n";
  for (const btf::SvdError& e : errors)
    out << " " << e.components << (e.components == options.components ? " (kept)" : "") << " | "
        << e.rms << " | " << e.relative << "\n";
  nlohmann::json record;
  record["command"] = "btf";
  record["settings"] = options.ToJson();
  record["timings_s"] = {
      {"read", read_seconds}, {"factorise", factorise_seconds}, {"write", SecondsSince(t2)}};
  WriteJson(output.path() / "run.json", record);
  output.Commit();
}

void RelightJobOptions::Check() const {
  RequirePath(ptm_file, "the PTM to relight");
  RequirePath(out_file, "the image to write");
  RequireImageExtension(out_file, "the image to write");
  if (!normals_file.empty()) RequireImageExtension(normals_file, "the normal map to write");
  if (!(light.allFinite() && light.norm() > 1e-9))
    throw OptionError("the light direction must be a nonzero vector");
  if (!(light.normalized().z() > 0))
    throw OptionError("the light must be above the horizon (z > 0)");
  enhancement.Check();
  if (!horizon_file.empty() && (enhancement.diffuse_gain != 1.0 || enhancement.specular > 0.0))
    throw OptionError("--horizon relights the PTM as captured: no --gain or --specular with it");
}

nlohmann::json RelightJobOptions::ToJson() const {
  return {{"ptm", ptm_file.string()},
          {"light", {light.x(), light.y(), light.z()}},
          {"gain", enhancement.diffuse_gain},
          {"specular", enhancement.specular}};
}

void RunRelightJob(const RelightJobOptions& options, std::ostream& out) {
  options.Check();
  RequireWritableFilePath(options.out_file);
  if (!options.normals_file.empty()) RequireWritableFilePath(options.normals_file);
  const Eigen::Vector3d light = options.light.normalized();
  const ptm::Ptm ptm = ptm::ReadPtmAnyFormat(options.ptm_file);
  std::vector<float> relit;
  if (options.horizon_file.empty()) {
    relit = ptm::Relight(ptm, light, options.enhancement);
  } else {
    const ptm::SelfShadowing shadowing = ptm::ReadSelfShadowingExr(
        options.horizon_file, ptm.width, ptm.height, "the PTM " + options.ptm_file.string());
    relit = ptm::RelightShadowed(ptm, shadowing, light);
  }
  WriteRgbImage(options.out_file, relit, ptm.width, ptm.height, false);
  if (!options.normals_file.empty())
    WriteRgbImage(options.normals_file, ptm::NormalMap(ptm), ptm.width, ptm.height, true);
  out << "Relit " << ptm.width << "x" << ptm.height << " PTM under (" << light.transpose()
      << ") into " << options.out_file.string() << "\n";
}

void SphereLightsJobOptions::Check() const {
  RequirePath(images_dir, "the folder of sphere photos");
  RequirePath(out_file, "the .lp file to write");
  highlight.Check();
  if (circle && !(circle->radius > 0.0)) throw OptionError("the sphere's radius must be > 0");
}

nlohmann::json SphereLightsJobOptions::ToJson() const {
  nlohmann::json j = {{"images", images_dir.string()}, {"threshold", highlight.threshold_fraction}};
  if (circle) j["circle"] = {circle->center_x, circle->center_y, circle->radius};
  return j;
}

void RunSphereLightsJob(const SphereLightsJobOptions& options, std::ostream& out,
                        std::ostream& err) {
  options.Check();
  RequireWritableFilePath(options.out_file);
  std::error_code ec;
  if (!fs::is_directory(options.images_dir, ec))
    throw InputError(options.images_dir.string(), "image folder not found");
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(options.images_dir)) {
    const std::string ext = LowerCaseExtension(entry.path());
    if (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".tif" || ext == ".tiff")
      files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  if (files.empty())
    throw InputError(options.images_dir.string(), "no images (.png, .jpg, .tif) in the folder");
  std::vector<std::string> skipped;
  ptm::SphereCircle used;
  const auto entries =
      ptm::LightsFromSphere(files, options.circle, options.highlight, &skipped, &used);
  sfm::WriteLpFile(entries, options.out_file);
  out << "Sphere at (" << used.center_x << ", " << used.center_y << "), radius " << used.radius
      << " px; wrote " << entries.size() << " light directions to " << options.out_file.string()
      << "\n";
  for (const auto& name : skipped) err << "warning: no highlight found in " << name << "\n";
}

void Synth2dJobOptions::Check() const {
  RequirePath(sample_file, "the sample PTM");
  RequirePath(out_dir, "the folder to write");
  synthesis.Check();
  if (synthesis.use_photos) {
    RequirePath(photos_dir, "the photos' folder (or --unconstrained)");
    RequirePath(lights_file, "the photos' .lp file (or --unconstrained)");
  } else if (synthesis.width == 0 || synthesis.height == 0) {
    throw OptionError("unconstrained synthesis needs a width and a height");
  }
}

nlohmann::json Synth2dJobOptions::ToJson() const {
  const synth::PlanarSynthesisOptions& o = synthesis;
  return {{"block_size", o.block_size},
          {"overlap", o.overlap},
          {"top_k", o.top_k},
          {"stitch", o.stitch == synth::Stitch::kSeamCut ? "seam_cut" : "blend"},
          {"constrained", o.use_photos},
          {"seed", o.seed},
          {"correction_iterations", o.correction_iterations}};
}

namespace {

std::vector<synth::PlanarPhoto> ReadPlanarPhotos(const Synth2dJobOptions& options,
                                                 std::ostream& err) {
  std::vector<synth::PlanarPhoto> photos;
  if (!options.synthesis.use_photos) return photos;
  const ptm::RtiCapture capture = ptm::ReadRtiCapture(options.lights_file, options.photos_dir);
  for (const std::string& w : capture.warnings) err << "warning: " << w << "\n";
  for (std::size_t k = 0; k < capture.files.size(); ++k) {
    const cv::Mat f = ReadPhotoRgb(capture.files[k]);
    synth::PlanarPhoto photo;
    photo.image = {f.cols, f.rows,
                   std::vector<float>(reinterpret_cast<const float*>(f.data),
                                      reinterpret_cast<const float*>(f.data) + f.total() * 3)};
    photo.light = capture.lights[k];
    photo.name = capture.files[k].string();
    photos.push_back(std::move(photo));
  }
  return photos;
}

// Per photo: the output relit under its light, and side by side the photo
// (nearest upscale), that relit output and the bicubic upscale.
void WriteRelitPhotos(const synth::PlanarSynthesisResult& result,
                      const std::vector<synth::PlanarPhoto>& photos, const fs::path& out_dir) {
  const int w = result.ptm.width, h = result.ptm.height;
  for (std::size_t n = 0; n < photos.size(); ++n) {
    const std::string stem = fs::path(photos[n].name).stem().string();
    std::vector<float> relit = ptm::Relight(result.ptm, photos[n].light);
    for (float& v : relit) v = std::min(1.0f, static_cast<float>(v * result.photo_gains[n]));
    WriteRgbImage(out_dir / ("relit_" + stem + ".png"), relit, w, h, false);
    const cv::Mat photo(photos[n].image.height, photos[n].image.width, CV_32FC3,
                        const_cast<float*>(photos[n].image.pixels.data()));
    cv::Mat nearest, bicubic;
    cv::resize(photo, nearest, cv::Size(w, h), 0, 0, cv::INTER_NEAREST);
    cv::resize(photo, bicubic, cv::Size(w, h), 0, 0, cv::INTER_CUBIC);
    cv::Mat row;
    cv::hconcat(std::vector<cv::Mat>{nearest, cv::Mat(h, w, CV_32FC3, relit.data()), bicubic}, row);
    WriteRgbImage(out_dir / ("comparison_" + stem + ".png"),
                  std::vector<float>(reinterpret_cast<float*>(row.data),
                                     reinterpret_cast<float*>(row.data) + row.total() * 3),
                  row.cols, row.rows, false);
  }
}

}  // namespace

void RunSynth2dJob(const Synth2dJobOptions& options, std::ostream& out, std::ostream& err) {
  options.Check();
  RequireReplaceableFolder(options.out_dir, "synth2d.json", "a texlume synth2d folder");
  const ptm::Ptm sample = ptm::ReadPtmAnyFormat(options.sample_file);
  const std::vector<synth::PlanarPhoto> photos = ReadPlanarPhotos(options, err);
  const synth::PlanarSynthesisResult result =
      synth::SynthesizePlanarPtm(sample, photos, options.synthesis);
  PartialOutput output(options.out_dir, PartialOutput::Kind::kFolder);
  const fs::path& out_dir = output.path();
  ptm::WritePtmFile(result.ptm, out_dir / "ptm_out.ptm");
  ptm::WritePtmExr(result.ptm, out_dir / "ptm_out.exr");
  WriteRelitPhotos(result, photos, out_dir);
  const int w = result.ptm.width, h = result.ptm.height;
  const std::vector<Eigen::Vector3d> new_lights = {Eigen::Vector3d(0.7, 0.0, 0.71).normalized(),
                                                   Eigen::Vector3d(-0.35, 0.6, 0.71).normalized(),
                                                   Eigen::Vector3d(0.0, 0.0, 1.0)};
  for (std::size_t k = 0; k < new_lights.size(); ++k)
    WriteRgbImage(out_dir / ("relit_new_" + std::to_string(k) + ".png"),
                  ptm::Relight(result.ptm, new_lights[k]), w, h, false);
  nlohmann::json record;
  record["command"] = "synth2d";
  record["settings"] = options.ToJson();
  record["settings"].update({{"width", w}, {"height", h}, {"scale", result.scale}});
  record["photo_gains"] = result.photo_gains;
  record["photo_rms"] = {{"quilted", result.photo_rms_quilted},
                         {"corrected", result.photo_rms_corrected}};
  record["seam_cost_per_texel"] = result.seam_cost_per_texel;
  record["blocks"] = result.blocks.size();
  record["new_lights"] = nlohmann::json::array();
  for (const auto& l : new_lights) record["new_lights"].push_back({l.x(), l.y(), l.z()});
  record["timings_s"] = {{"synthesis", result.seconds}};
  WriteJson(out_dir / "synth2d.json", record);
  output.Commit();
  out << "Synthesised a " << w << "x" << h << " PTM from " << result.blocks.size() << " blocks of "
      << options.synthesis.block_size << " texels (" << photos.size() << " photos, scale "
      << result.scale << ") in " << result.seconds << " s into " << options.out_dir.string()
      << "\n";
}

void SynthCommandOptions::Check() const {
  if (btf.empty()) {
    job.Check();
    return;
  }
  if (!job.sample_file.empty()) throw OptionError("give a PTM sample or a BTF, not both");
  job.CheckInputsAndLayout();
  if (components < 1) throw OptionError("components must be >= 1");
  if (!job.compare_regions.empty())
    throw OptionError("--compare-regions measures a PTM or colour sample's edges, not a BTF's");
}

namespace {

// The BTF job's options from the command's: its paths, layout and the
// synthesis settings both samples share.
pipeline::BtfSynthJobOptions BtfJobFrom(const SynthCommandOptions& c) {
  pipeline::BtfSynthJobOptions b;
  b.btf = c.btf;
  b.components = c.components;
  const synth::MeshSynthesisOptions& ptm = c.job.synthesis;
  b.synthesis.sample_texel_size = ptm.sample_texel_size;
  b.synthesis.strip = ptm.strip;
  b.synthesis.seam_band = c.seam_band.value_or(std::min(b.synthesis.seam_band, ptm.strip));
  b.synthesis.top_k = ptm.top_k;
  b.synthesis.search = ptm.search;
  b.synthesis.search_candidates = ptm.search_candidates;
  b.synthesis.photometry_faces = ptm.photometry_faces;
  b.synthesis.max_views = ptm.all_views ? ptm.max_views : 1;
  b.synthesis.seed = ptm.seed;
  // The photo-consistency pass: --correction-iterations 0 turns it off, as for PTMs.
  b.synthesis.photo_correction = ptm.correction_iterations > 0;
  b.synthesis.correction_noise = c.correction_noise.value_or(b.synthesis.correction_noise);
  b.synthesis.correction_sigma = c.correction_sigma.value_or(b.synthesis.correction_sigma);
  b.synthesis.tangent_frame = ptm.tangent_frame;
  b.synthesis.field_direction_in_world = ptm.field_direction_in_world;
  b.synthesis.light_response = ptm.light_response;
  b.synthesis.white_balance = ptm.white_balance;
  b.synthesis.photo_blur = ptm.photo_blur;
  b.job = c.job;
  return b;
}

}  // namespace

void RunSynthCommandJob(const SynthCommandOptions& options, std::ostream& out, std::ostream& err,
                        const ProgressCallback& progress) {
  options.Check();
  if (!options.btf.empty()) {
    const pipeline::BtfSynthJobOptions b = BtfJobFrom(options);
    const pipeline::BtfSynthJobSummary s = pipeline::RunBtfSynthJob(b, progress);
    if (s.rank_share_only) return;  // rank 0 reports the distributed run
    for (const std::string& w : s.warnings) err << "warning: " << w << "\n";
    out << "Synthesised a BTF over " << s.faces << " triangles (" << s.from_photos
        << " from photos, " << s.from_neighbours << " from neighbours only, " << s.random
        << " seeds) from " << s.photos_used << " photos; graph-cut seams on " << s.seam_edges
        << " edges (cost per cut pair " << s.seam_cost_per_link << ", straight edge "
        << s.edge_cost_per_link << "); " << s.atlases << " atlas(es), " << s.charts
        << " charts, occupancy " << s.occupancy << ", in " << s.seconds_total
        << " s: " << b.job.out_dir.string() << " (see manifest.json)\n";
    return;
  }
  pipeline::SynthJobOptions job = options.job;
  job.synthesis.correction_noise =
      options.correction_noise.value_or(job.synthesis.correction_noise);
  job.synthesis.correction_sigma =
      options.correction_sigma.value_or(job.synthesis.correction_sigma);
  const pipeline::SynthJobSummary s = pipeline::RunSynthJob(job, progress);
  if (s.rank_share_only) return;  // rank 0 reports the distributed run
  for (const std::string& w : s.warnings) err << "warning: " << w << "\n";
  out << "Synthesised " << s.faces << " triangles (" << s.from_photos << " from photos, "
      << s.from_neighbours << " from neighbours only, " << s.random << " seeds) from "
      << s.photos_used << " photos into " << s.atlases << " atlas(es), " << s.charts
      << " charts, occupancy " << s.occupancy << ", in " << s.seconds_total
      << " s: " << job.out_dir.string() << " (see manifest.json"
      << (job.write_report ? " and report.html" : "") << ")\n";
}

void RunQuiltCommandJob(const QuiltJobOptions& options, std::ostream& out, std::ostream& err,
                        const ProgressCallback& progress) {
  const QuiltJobSummary s = RunQuiltJob(options, progress);
  for (const std::string& w : s.warnings) err << "warning: " << w << "\n";
  const quilt::QuiltStats& q = s.stats;
  out << "Quilted " << s.samples << " surface samples of " << s.faces << " triangles with "
      << q.patches << " graph-cut patches (" << q.forced << " above the seam threshold; seam cost "
      << quilt::SeamShare(q) << " of an unrelated cut) into " << s.atlases << " atlas(es), "
      << s.charts << " charts, occupancy " << s.occupancy << ", in " << s.seconds_total
      << " s: " << options.out_dir.string() << " (see manifest.json)\n";
}

void RunRenderCommandJob(pipeline::RenderJobOptions o, bool baseline_asked, std::ostream& out,
                         std::ostream& err, const ProgressCallback& progress) {
  o.Check();
  o.btf_as_btf = !baseline_asked;
  const pipeline::RenderJobSummary s = pipeline::RunRenderJob(o, progress);
  for (const std::string& w : s.warnings) err << "warning: " << w << "\n";
  out << "Rendered " << s.rendered << " views into " << o.out_dir.string() << " in " << s.seconds
      << " s";
  if (!s.metrics.empty()) {
    out << "; inside the masks: PSNR " << s.mean_psnr << " dB, SSIM " << s.mean_ssim;
    if (o.reduced_factor > 1)
      out << " (reduced by " << o.reduced_factor << ": " << s.mean_psnr_reduced << " dB, "
          << s.mean_ssim_reduced << ")";
  }
  out << "\n";
}

void RunSceneJob(const datasets::SceneOptions& options, const fs::path& out_dir, std::ostream& out,
                 const ProgressCallback& progress) {
  RequirePath(out_dir, "the folder to write");
  const datasets::SceneSummary summary = datasets::GenerateScene(options, out_dir, progress);
  out << "Scene written to " << out_dir.string() << ": " << summary.num_files << " files, "
      << summary.displaced_triangles << " displaced triangles, " << summary.seconds_total
      << " s (see MANIFEST.md and scene.json)\n";
}

}  // namespace texlume::pipeline
