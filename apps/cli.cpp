#include "apps/cli.h"

#include <algorithm>
#include <atomic>
#include <charconv>
#include <chrono>
#include <cmath>
#include <csignal>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "apps/http_server.h"
#include "apps/progress_bar.h"
#include "btf/btf.h"
#include "btf/btf_model.h"
#include "core/errors.h"
#include "core/file_util.h"
#include "datasets_synthetic/object_scene.h"
#include "datasets_synthetic/scene.h"
#include "ptm/fit.h"
#include "ptm/ptm_io.h"
#include "ptm/sphere_lights.h"
#include "sfm/inspect.h"
#include "sfm/lights.h"
#include "synth/pipeline.h"
#include "synth/planar_synthesis.h"
#include "synth/report.h"
#include "synth/web_model.h"

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

namespace {
// Parses the whole value of --name as a number of type T, or throws UsageError.
template <typename T>
T ParseOption(const std::string& name, const std::string& value, const char* what) {
  T parsed{};
  const auto [ptr, ec] = std::from_chars(value.data(), value.data() + value.size(), parsed);
  if (ec != std::errc() || ptr != value.data() + value.size()) {
    throw UsageError("--" + name + " expects " + what + ", got '" + value + "'");
  }
  return parsed;
}
}  // namespace

int Arguments::GetInt(const std::string& name, int fallback) const {
  const auto v = Get(name);
  return v ? ParseOption<int>(name, *v, "an integer") : fallback;
}

double Arguments::GetDouble(const std::string& name, double fallback) const {
  const auto v = Get(name);
  return v ? ParseOption<double>(name, *v, "a number") : fallback;
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

namespace {

// "a,b,c" -> numbers; throws UsageError naming the option.
std::vector<double> ParseList(const std::string& text, std::size_t count, const std::string& name) {
  std::vector<double> values;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    const std::string token = text.substr(start, comma - start);
    double v = 0;
    const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), v);
    if (token.empty() || ec != std::errc() || ptr != token.data() + token.size() ||
        !std::isfinite(v)) {
      throw UsageError("--" + name + " expects " + std::to_string(count) +
                       " comma-separated numbers, got '" + text + "'");
    }
    values.push_back(v);
    start = comma + 1;
  }
  if (values.size() != count) {
    throw UsageError("--" + name + " expects " + std::to_string(count) + " numbers, got '" + text +
                     "'");
  }
  return values;
}

void WriteRgbPng(const std::filesystem::path& path, const std::vector<float>& rgb, int width,
                 int height, bool signed_unit) {
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
  if (!cv::imencode(path.extension().string().empty() ? ".png" : path.extension().string(), image,
                    bytes)) {
    throw std::runtime_error(path.string() + ": cannot encode the image (use .png, .jpg or .tif)");
  }
  WriteBytesAtomically(path, bytes);
}

}  // namespace

int RunFitCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& /*err*/) {
  const Arguments a(args, {"images", "lights", "out", "format", "exr", "web", "band-rows"},
                    {"robust"});
  const std::filesystem::path images_dir = a.Require("images");
  const std::filesystem::path lp_path = a.Require("lights");
  const std::filesystem::path out_path = a.Require("out");
  ptm::FitOptions options;
  const std::string format = a.Get("format").value_or("lrgb");
  if (format == "rgb") {
    options.format = ptm::PtmFormat::kRgb;
  } else if (format != "lrgb") {
    throw UsageError("--format must be lrgb or rgb");
  }
  options.robust = a.Has("robust");
  options.band_rows = a.GetInt("band-rows", options.band_rows);
  options.Check();
  const ptm::RtiCapture capture = ptm::ReadRtiCapture(lp_path, images_dir);
  const std::vector<std::filesystem::path>& files = capture.files;
  const std::vector<Eigen::Vector3d>& lights = capture.lights;
  ProgressBar bar;
  ptm::CheckLightSet(lights, options, lp_path.string());
  const ptm::FitResult result = ptm::FitPtmFromFiles(files, lights, options, bar.Callback());
  const auto t0 = std::chrono::steady_clock::now();
  ptm::WritePtmFile(result.ptm, out_path);
  if (auto exr = a.Get("exr")) ptm::WritePtmExr(result.ptm, *exr);
  if (auto web = a.Get("web")) ptm::WriteRelightWeb(result.ptm, *web);
  const double write_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out << "Fitted a " << result.ptm.width << "x" << result.ptm.height << " "
      << (options.format == ptm::PtmFormat::kLrgb ? "LRGB" : "RGB") << " PTM to "
      << result.num_images << " images in " << result.seconds << " s"
      << (options.robust ? " (robust)" : "") << "; mean RMS residual "
      << result.mean_residual_rms * 255.0 << " / 255. Wrote " << out_path.string() << "\n";
  nlohmann::json record;
  record["command"] = "fit";
  record["settings"] = {{"images", images_dir.string()},
                        {"lights", lp_path.string()},
                        {"format", format},
                        {"robust", options.robust},
                        {"band_rows", options.band_rows},
                        {"robust_scale", options.robust_scale}};
  record["result"] = {{"width", result.ptm.width},
                      {"height", result.ptm.height},
                      {"images", result.num_images},
                      {"mean_residual_rms", result.mean_residual_rms},
                      {"intensity_space", "display (sRGB-encoded) values in [0, 1]"}};
  record["timings_s"] = {{"fit", result.seconds}, {"write", write_seconds}};
  std::filesystem::path record_path = out_path;
  record_path += ".json";
  WriteFileAtomically(
      record_path, [&](std::ostream& o) { o << record.dump(2) << "\n"; }, false);
  return kExitOk;
}

int RunBtfCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& /*err*/) {
  const Arguments a(args, {"capture", "out", "components"}, {});
  const std::filesystem::path capture_dir = a.Require("capture");
  const std::filesystem::path out_dir = a.Require("out");
  const int components = a.GetInt("components", 40);
  if (components < 1) throw UsageError("--components must be at least 1");
  ProgressBar bar;
  const auto t0 = std::chrono::steady_clock::now();
  const btf::BtfCapture capture = btf::ReadBtfCapture(capture_dir);
  const auto t1 = std::chrono::steady_clock::now();
  const btf::BtfFactorisation f = btf::FactoriseBtf(capture, components, bar.Callback());
  const auto t2 = std::chrono::steady_clock::now();
  // The error table: powers of two up to the rank, the chosen n included.
  std::vector<int> counts;
  for (int n = 1; n < static_cast<int>(f.singular_values.size()); n *= 2) counts.push_back(n);
  counts.push_back(static_cast<int>(f.singular_values.size()));
  counts.push_back(components);
  std::sort(counts.begin(), counts.end());
  counts.erase(std::unique(counts.begin(), counts.end()), counts.end());
  const std::vector<btf::SvdError> errors = btf::SvdErrorTable(f, counts);
  btf::WriteBtfFactorisation(f, errors, out_dir);
  const auto t3 = std::chrono::steady_clock::now();
  auto seconds = [](auto a0, auto a1) { return std::chrono::duration<double>(a1 - a0).count(); };
  out << "Factorised a " << capture.width << "x" << capture.height << " BTF of "
      << capture.views.size() << " views x " << capture.lights.size() << " lights into "
      << components << " components in " << seconds(t1, t2) << " s. Wrote " << out_dir.string()
      << "\n components | RMS error (linear) | relative\n";
  for (const btf::SvdError& e : errors)
    out << " " << e.components << (e.components == components ? " (kept)" : "") << " | " << e.rms
        << " | " << e.relative << "\n";
  nlohmann::json record;
  record["command"] = "btf";
  record["settings"] = {{"capture", capture_dir.string()}, {"components", components}};
  record["timings_s"] = {
      {"read", seconds(t0, t1)}, {"factorise", seconds(t1, t2)}, {"write", seconds(t2, t3)}};
  WriteFileAtomically(
      out_dir / "run.json", [&](std::ostream& o) { o << record.dump(2) << "\n"; }, false);
  return kExitOk;
}

int RunRelightCommand(const std::vector<std::string>& args, std::ostream& out,
                      std::ostream& /*err*/) {
  const Arguments a(args, {"ptm", "light", "out", "normals", "gain", "specular"}, {});
  const auto l = ParseList(a.Require("light"), 3, "light");
  Eigen::Vector3d light(l[0], l[1], l[2]);
  if (!(light.norm() > 1e-9)) throw UsageError("--light must not be zero");
  light.normalize();
  if (!(light.z() > 0)) throw UsageError("--light must be above the horizon (z > 0)");
  ptm::EnhancementOptions enhancement;
  enhancement.diffuse_gain = a.GetDouble("gain", 1.0);
  enhancement.specular = a.GetDouble("specular", 0.0);
  enhancement.Check();
  const std::filesystem::path out_path = a.Require("out");
  const ptm::Ptm ptm = ptm::ReadPtmAnyFormat(a.Require("ptm"));
  WriteRgbPng(out_path, ptm::Relight(ptm, light, enhancement), ptm.width, ptm.height, false);
  if (auto normals = a.Get("normals")) {
    WriteRgbPng(*normals, ptm::NormalMap(ptm), ptm.width, ptm.height, true);
  }
  out << "Relit " << ptm.width << "x" << ptm.height << " PTM under (" << light.transpose()
      << ") into " << out_path.string() << "\n";
  return kExitOk;
}

int RunLightsFromSphereCommand(const std::vector<std::string>& args, std::ostream& out,
                               std::ostream& err) {
  const Arguments a(args, {"images", "out", "circle", "threshold"}, {});
  const std::filesystem::path dir = a.Require("images");
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec))
    throw InputError(dir.string(), "image folder not found");
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    std::string ext = entry.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return std::tolower(c); });
    if (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".tif" || ext == ".tiff") {
      files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) throw InputError(dir.string(), "no images (.png, .jpg, .tif) in the folder");
  std::optional<ptm::SphereCircle> circle;
  if (auto c = a.Get("circle")) {
    const auto v = ParseList(*c, 3, "circle");
    circle = ptm::SphereCircle{v[0], v[1], v[2]};
  }
  ptm::HighlightOptions options;
  options.threshold_fraction = a.GetDouble("threshold", options.threshold_fraction);
  std::vector<std::string> skipped;
  ptm::SphereCircle used;
  const auto entries = ptm::LightsFromSphere(files, circle, options, &skipped, &used);
  const std::filesystem::path out_path = a.Require("out");
  sfm::WriteLpFile(entries, out_path);
  out << "Sphere at (" << used.center_x << ", " << used.center_y << "), radius " << used.radius
      << " px; wrote " << entries.size() << " light directions to " << out_path.string() << "\n";
  for (const auto& name : skipped) err << "warning: no highlight found in " << name << "\n";
  return kExitOk;
}

int RunSynth2dCommand(const std::vector<std::string>& args, std::ostream& out,
                      std::ostream& /*err*/) {
  const Arguments a(args,
                    {"sample", "photos", "lights", "out", "scale", "width", "height", "block",
                     "overlap", "top-k", "seed", "correction-iterations"},
                    {"seam", "unconstrained"});
  const ptm::Ptm sample = ptm::ReadPtmAnyFormat(a.Require("sample"));
  const std::filesystem::path out_dir = a.Require("out");
  synth::PlanarSynthesisOptions options;
  options.scale = a.GetInt("scale", 1);
  options.width = a.GetInt("width", 0);
  options.height = a.GetInt("height", 0);
  options.block_size = a.GetInt("block", options.block_size);
  options.overlap = a.GetInt("overlap", options.overlap);
  options.top_k = a.GetInt("top-k", options.top_k);
  options.seed = static_cast<std::uint32_t>(a.GetInt("seed", 1));
  options.correction_iterations = a.GetInt("correction-iterations", options.correction_iterations);
  options.stitch = a.Has("seam") ? synth::Stitch::kSeamCut : synth::Stitch::kBlend;
  options.use_photos = !a.Has("unconstrained");
  options.Check();
  std::vector<synth::PlanarPhoto> photos;
  if (options.use_photos) {
    const std::filesystem::path dir = a.Require("photos");
    const std::filesystem::path lp = a.Require("lights");
    const ptm::RtiCapture capture = ptm::ReadRtiCapture(lp, dir);
    for (std::size_t k = 0; k < capture.files.size(); ++k) {
      const std::filesystem::path& file = capture.files[k];
      const cv::Mat f = ReadPhotoRgb(file);
      synth::PlanarPhoto photo;
      photo.image = {f.cols, f.rows,
                     std::vector<float>(reinterpret_cast<float*>(f.data),
                                        reinterpret_cast<float*>(f.data) + f.total() * 3)};
      photo.light = capture.lights[k];
      photo.name = file.string();
      photos.push_back(std::move(photo));
    }
  } else if (options.width == 0 || options.height == 0) {
    throw UsageError("--unconstrained needs --width and --height");
  }
  const synth::PlanarSynthesisResult result = synth::SynthesizePlanarPtm(sample, photos, options);
  std::filesystem::create_directories(out_dir);
  ptm::WritePtmFile(result.ptm, out_dir / "ptm_out.ptm");
  ptm::WritePtmExr(result.ptm, out_dir / "ptm_out.exr");
  const int w = result.ptm.width, h = result.ptm.height;
  for (std::size_t n = 0; n < photos.size(); ++n) {
    const std::string stem = std::filesystem::path(photos[n].name).stem().string();
    std::vector<float> relit = ptm::Relight(result.ptm, photos[n].light);
    for (float& v : relit) v = std::min(1.0f, static_cast<float>(v * result.photo_gains[n]));
    WriteRgbPng(out_dir / ("relit_" + stem + ".png"), relit, w, h, false);
    // Side by side: the photo (nearest upscale), relit PTM_out, bicubic upscale.
    const cv::Mat photo(photos[n].image.height, photos[n].image.width, CV_32FC3,
                        const_cast<float*>(photos[n].image.pixels.data()));
    cv::Mat nearest, bicubic;
    cv::resize(photo, nearest, cv::Size(w, h), 0, 0, cv::INTER_NEAREST);
    cv::resize(photo, bicubic, cv::Size(w, h), 0, 0, cv::INTER_CUBIC);
    cv::Mat row;
    cv::hconcat(std::vector<cv::Mat>{nearest, cv::Mat(h, w, CV_32FC3, relit.data()), bicubic}, row);
    WriteRgbPng(out_dir / ("comparison_" + stem + ".png"),
                std::vector<float>(reinterpret_cast<float*>(row.data),
                                   reinterpret_cast<float*>(row.data) + row.total() * 3),
                row.cols, row.rows, false);
  }
  const std::vector<Eigen::Vector3d> new_lights = {Eigen::Vector3d(0.7, 0.0, 0.71).normalized(),
                                                   Eigen::Vector3d(-0.35, 0.6, 0.71).normalized(),
                                                   Eigen::Vector3d(0.0, 0.0, 1.0)};
  for (std::size_t k = 0; k < new_lights.size(); ++k) {
    WriteRgbPng(out_dir / ("relit_new_" + std::to_string(k) + ".png"),
                ptm::Relight(result.ptm, new_lights[k]), w, h, false);
  }
  nlohmann::json record;
  record["command"] = "synth2d";
  record["settings"] = {{"block_size", options.block_size},
                        {"overlap", options.overlap},
                        {"top_k", options.top_k},
                        {"stitch", a.Has("seam") ? "seam_cut" : "blend"},
                        {"constrained", options.use_photos},
                        {"seed", options.seed},
                        {"width", w},
                        {"height", h},
                        {"scale", result.scale},
                        {"correction_iterations", options.correction_iterations}};
  record["photo_gains"] = result.photo_gains;
  record["photo_rms"] = {{"quilted", result.photo_rms_quilted},
                         {"corrected", result.photo_rms_corrected}};
  record["seam_cost_per_texel"] = result.seam_cost_per_texel;
  record["blocks"] = result.blocks.size();
  record["new_lights"] = nlohmann::json::array();
  for (const auto& l : new_lights) record["new_lights"].push_back({l.x(), l.y(), l.z()});
  record["timings_s"] = {{"synthesis", result.seconds}};
  WriteFileAtomically(
      out_dir / "synth2d.json", [&](std::ostream& o) { o << record.dump(2) << "\n"; }, false);
  out << "Synthesised a " << w << "x" << h << " PTM from " << result.blocks.size() << " blocks of "
      << options.block_size << " texels (" << photos.size() << " photos, scale " << result.scale
      << ") in " << result.seconds << " s into " << out_dir.string() << "\n";
  return kExitOk;
}

int RunSynthCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  const Arguments a(args,
                    {"model",
                     "images",
                     "lights",
                     "mesh",
                     "sample",
                     "btf",
                     "components",
                     "seam-band",
                     "sample-texel-size",
                     "out",
                     "strip",
                     "top-k",
                     "max-views",
                     "atlas",
                     "atlas-size",
                     "gutter",
                     "seed",
                     "tangent-field",
                     "tangent-frame",
                     "max-subdivisions",
                     "max-buffer-size",
                     "correction-iterations",
                     "correction-sigma",
                     "correction-noise",
                     "correction-prior-shrink",
                     "chart-angle",
                     "chart-size",
                     "chart-flattening",
                     "chart-stretch"},
                    {"best-view-only", "no-additive-correction", "no-channel-correction",
                     "no-detail-transfer", "no-report"});
  synth::SynthJobOptions o;
  o.model_dir = a.Require("model");
  o.images_dir = a.Require("images");
  o.lights_file = a.Require("lights");
  o.mesh_file = a.Require("mesh");
  const auto btf_dir = a.Get("btf");
  if (btf_dir && a.Has("sample")) throw UsageError("give --sample (a PTM) or --btf, not both");
  if (!btf_dir) o.sample_file = a.Require("sample");
  o.out_dir = a.Require("out");
  o.synthesis.sample_texel_size = a.GetDouble("sample-texel-size", 0.0);
  if (!btf_dir && !(o.synthesis.sample_texel_size > 0.0)) {
    throw UsageError(
        "--sample-texel-size: give the sample's texel size in world units of the model");
  }
  o.synthesis.strip = a.GetInt("strip", o.synthesis.strip);
  o.synthesis.top_k = a.GetInt("top-k", o.synthesis.top_k);
  o.synthesis.all_views = !a.Has("best-view-only");
  o.synthesis.max_views = a.GetInt("max-views", o.synthesis.max_views);
  o.synthesis.seed = static_cast<std::uint32_t>(a.GetInt("seed", 1));
  o.synthesis.correction_iterations =
      a.GetInt("correction-iterations", o.synthesis.correction_iterations);
  o.synthesis.correction_sigma = a.GetDouble("correction-sigma", o.synthesis.correction_sigma);
  o.synthesis.additive_correction = !a.Has("no-additive-correction");
  o.synthesis.channel_correction = !a.Has("no-channel-correction");
  o.synthesis.detail_transfer = !a.Has("no-detail-transfer");
  o.synthesis.correction_noise = a.GetDouble("correction-noise", o.synthesis.correction_noise);
  if (const auto shrink = a.Get("correction-prior-shrink"); shrink && *shrink != "auto") {
    o.synthesis.correction_prior_shrink = a.GetDouble("correction-prior-shrink", 0.0);
    if (!(o.synthesis.correction_prior_shrink >= 0.0 && o.synthesis.correction_prior_shrink <= 1.0))
      throw UsageError("--correction-prior-shrink: give auto or a number in [0, 1]");
  }
  if (const auto frame = a.Get("tangent-frame")) {
    if (a.Has("tangent-field"))
      throw UsageError("give --tangent-frame or --tangent-field, not both");
    if (*frame == "first-edge")
      o.synthesis.tangent_frame = synth::TangentFrame::kFirstEdge;
    else if (*frame == "photos")
      o.synthesis.tangent_frame = synth::TangentFrame::kPhotos;
    else if (*frame == "auto")
      o.synthesis.tangent_frame = synth::TangentFrame::kAuto;
    else
      throw UsageError("--tangent-frame: give first-edge, photos or auto");
  }
  if (const auto field = a.Get("tangent-field")) {
    const std::vector<double> d = ParseList(*field, 3, "--tangent-field");
    o.synthesis.tangent_frame = synth::TangentFrame::kSmoothField;
    o.synthesis.field_direction_in_world = Eigen::Vector3d(d[0], d[1], d[2]);
  }
  const std::string atlas = a.Get("atlas").value_or("charts");
  if (atlas != "charts" && atlas != "per-triangle") {
    throw UsageError("--atlas: charts or per-triangle, not '" + atlas + "'");
  }
  o.atlas.mode = atlas == "charts" ? synth::AtlasMode::kCharts : synth::AtlasMode::kPerTriangle;
  o.atlas.atlas_size = a.GetInt("atlas-size", o.atlas.atlas_size);
  o.atlas.gutter = a.GetInt("gutter", o.atlas.gutter);
  o.atlas.max_chart_normal_angle_deg =
      a.GetDouble("chart-angle", o.atlas.max_chart_normal_angle_deg);
  o.atlas.max_chart_size = a.GetInt("chart-size", o.atlas.max_chart_size);
  const std::string flattening =
      a.Get("chart-flattening").value_or(synth::ChartFlatteningName(o.atlas.flattening));
  bool known_flattening = false;
  for (const synth::ChartFlattening f :
       {synth::ChartFlattening::kRigid, synth::ChartFlattening::kConformal,
        synth::ChartFlattening::kStrips, synth::ChartFlattening::kAuto})
    if (flattening == synth::ChartFlatteningName(f))
      o.atlas.flattening = f, known_flattening = true;
  if (!known_flattening)
    throw UsageError("--chart-flattening: auto, strips, rigid or conformal, not '" + flattening +
                     "'");
  o.atlas.max_chart_stretch = a.GetDouble("chart-stretch", o.atlas.max_chart_stretch);
  o.atlas.blend_strip = o.synthesis.strip;
  o.max_subdivisions = a.GetInt("max-subdivisions", o.max_subdivisions);
  o.visibility.max_buffer_dimension = a.GetInt("max-buffer-size", 0);
  o.write_report = !a.Has("no-report");
  ProgressBar bar;
  if (btf_dir) {
    btf::BtfSynthJobOptions b;
    b.btf = *btf_dir;
    b.components = a.GetInt("components", b.components);
    b.synthesis.sample_texel_size = o.synthesis.sample_texel_size;
    b.synthesis.strip = o.synthesis.strip;
    b.synthesis.seam_band =
        a.GetInt("seam-band", std::min(b.synthesis.seam_band, o.synthesis.strip));
    b.synthesis.top_k = o.synthesis.top_k;
    b.synthesis.max_views = o.synthesis.all_views ? o.synthesis.max_views : 1;
    b.synthesis.seed = o.synthesis.seed;
    // The photo-consistency pass: --correction-iterations 0 turns it off, as for PTMs.
    b.synthesis.photo_correction = o.synthesis.correction_iterations > 0;
    b.synthesis.correction_noise = a.GetDouble("correction-noise", b.synthesis.correction_noise);
    b.synthesis.correction_sigma = a.GetDouble("correction-sigma", b.synthesis.correction_sigma);
    b.synthesis.tangent_frame = o.synthesis.tangent_frame;
    b.synthesis.field_direction_in_world = o.synthesis.field_direction_in_world;
    b.job = std::move(o);
    const btf::BtfSynthJobSummary s = btf::RunBtfSynthJob(b, bar.Callback());
    for (const std::string& w : s.warnings) err << "warning: " << w << "\n";
    out << "Synthesised a BTF over " << s.faces << " triangles (" << s.from_photos
        << " from photos, " << s.from_neighbours << " from neighbours only, " << s.random
        << " seeds) from " << s.photos_used << " photos; graph-cut seams on " << s.seam_edges
        << " edges (cost per cut pair " << s.seam_cost_per_link << ", straight edge "
        << s.edge_cost_per_link << "); " << s.atlases << " atlas(es), " << s.charts
        << " charts, occupancy " << s.occupancy << ", in " << s.seconds_total
        << " s: " << b.job.out_dir.string() << " (see manifest.json)\n";
    return kExitOk;
  }
  const synth::SynthJobSummary s = synth::RunSynthJob(o, bar.Callback());
  for (const std::string& w : s.warnings) err << "warning: " << w << "\n";
  out << "Synthesised " << s.faces << " triangles (" << s.from_photos << " from photos, "
      << s.from_neighbours << " from neighbours only, " << s.random << " seeds) from "
      << s.photos_used << " photos into " << s.atlases << " atlas(es), " << s.charts
      << " charts, occupancy " << s.occupancy << ", in " << s.seconds_total
      << " s: " << o.out_dir.string() << " (see manifest.json"
      << (o.write_report ? " and report.html" : "") << ")\n";
  return kExitOk;
}

int RunRenderCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  const Arguments a(args,
                    {"model", "cameras", "lights", "out", "baseline", "samples", "truth",
                     "truth-masks", "reduced-factor"},
                    {});
  synth::RenderJobOptions o;
  o.model_folder = a.Require("model");
  o.cameras_dir = a.Require("cameras");
  o.lights_file = a.Require("lights");
  o.out_dir = a.Require("out");
  if (const auto b = a.Get("baseline")) {
    if (*b == "flat") {
      o.mode = synth::RenderMode::kFlat;
    } else if (*b == "baked") {
      o.mode = synth::RenderMode::kBaked;
    } else if (*b == "ptm") {
      o.mode = synth::RenderMode::kPtm;
    } else {
      throw UsageError("--baseline: flat, baked or ptm, not '" + *b + "'");
    }
  }
  // A BTF model (texlume synth --btf) is drawn as a BTF unless a baseline is asked for.
  std::shared_ptr<btf::BtfModel> btf_model;
  if (!a.Has("baseline") && synth::ReadModelManifest(o.model_folder).contains("btf")) {
    o.renderer_name = "btf";
    o.renderer = [&btf_model, &o](const synth::ModelRenderer& renderer,
                                  const synth::TexturedModel& model, const sfm::Camera& camera,
                                  const sfm::Rigid3d& cam_from_world,
                                  const std::vector<sfm::ObjectLight>& lights) {
      if (!btf_model)
        btf_model = std::make_shared<btf::BtfModel>(btf::ReadBtfModel(o.model_folder, model));
      return renderer.RenderWith(camera, cam_from_world, o.samples_per_axis,
                                 [&](const synth::ModelRenderer::SurfaceSample& s) {
                                   return btf::ShadeBtf(*btf_model, s, lights);
                                 });
    };
  }
  o.samples_per_axis = a.GetInt("samples", o.samples_per_axis);
  if (const auto t = a.Get("truth")) o.truth_images_dir = *t;
  if (const auto m = a.Get("truth-masks")) o.truth_masks_dir = *m;
  o.reduced_factor = a.GetInt("reduced-factor", 1);
  ProgressBar bar;
  const synth::RenderJobSummary s = synth::RunRenderJob(o, bar.Callback());
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
  return kExitOk;
}

int RunSceneCommand(const std::vector<std::string>& args, std::ostream& out,
                    std::ostream& /*err*/) {
  const Arguments a(args, {"kind",           "material",        "out",
                           "seed",           "images",          "camera-model",
                           "width",          "height",          "capture-size",
                           "capture-lights", "held-out-lights", "texel-size",
                           "relief",         "specular",        "held-out-views",
                           "held-out-scale", "samples",         "mesh-resolution",
                           "btf-size",       "btf-views",       "btf-lights"},
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
  options.held_out_scale = a.GetInt("held-out-scale", options.held_out_scale);
  options.mesh_resolution = a.GetInt("mesh-resolution", options.mesh_resolution);
  options.shading.samples_per_axis = a.GetInt("samples", options.shading.samples_per_axis);
  options.write_btf = !a.Has("no-btf");
  options.btf_size = a.GetInt("btf-size", options.btf_size);
  options.btf_view_count = a.GetInt("btf-views", options.btf_view_count);
  options.btf_light_count = a.GetInt("btf-lights", options.btf_light_count);
  options.vary_exposure = !a.Has("fixed-exposure");
  const std::filesystem::path dir = a.Require("out");
  ProgressBar bar;
  const datasets::SceneSummary summary = datasets::GenerateScene(options, dir, bar.Callback());
  out << "Scene written to " << dir.string() << ": " << summary.num_files << " files, "
      << summary.displaced_triangles << " displaced triangles, " << summary.seconds_total
      << " s (see MANIFEST.md and scene.json)\n";
  return kExitOk;
}

namespace {
std::atomic<bool> g_stop_serving{false};
extern "C" void StopServing(int /*signal*/) { g_stop_serving.store(true); }

/// Where the viewer's page and npm packages are: $TEXLUME_WEB_DIR, else the
/// source tree's web/ (the build records it).
std::filesystem::path WebDir() {
  if (const char* env = std::getenv("TEXLUME_WEB_DIR")) return env;
  return TEXLUME_SOURCE_WEB_DIR;
}

/// A file below `root` for a request path below a prefix; nullopt when the path
/// tries to leave `root` or names no regular file.
std::optional<std::filesystem::path> FileBelow(const std::filesystem::path& root,
                                               const std::string& rest) {
  if (rest.empty() || rest.find("..") != std::string::npos || rest.find('\\') != std::string::npos)
    return std::nullopt;
  const std::filesystem::path file = root / rest;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) return std::nullopt;
  return file;
}
}  // namespace

int RunViewCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  std::vector<std::string> rest;
  std::filesystem::path model_dir;
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i].rfind("--", 0) == 0) {
      rest.push_back(args[i]);
      if (i + 1 < args.size()) rest.push_back(args[++i]);
    } else if (model_dir.empty()) {
      model_dir = args[i];
    } else {
      throw UsageError("view takes one model folder, not also '" + args[i] + "'");
    }
  }
  const Arguments a(rest, {"port", "host"}, {});
  if (model_dir.empty()) throw UsageError("view: give the model folder written by texlume synth");
  const int port = a.GetInt("port", 8080);
  if (port < 0 || port > 65535) throw UsageError("--port must be in [0, 65535]");
  const std::string host = a.Get("host").value_or("127.0.0.1");
  const std::filesystem::path web = WebDir();
  // The page loads web/viewer/viewer.js bundled with three.js by esbuild
  // (`npm run build` in web/, run by ./scripts/install_deps.sh).
  const std::filesystem::path bundle = web / "dist/viewer.js";
  if (!std::filesystem::exists(web / "viewer/index.html") || !std::filesystem::exists(bundle))
    throw InputError(web.string(),
                     "has no viewer or no viewer bundle (dist/viewer.js); run "
                     "./scripts/install_deps.sh (it runs npm ci and npm run build in web/), or "
                     "set TEXLUME_WEB_DIR");
  for (const char* source : {"viewer/viewer.js", "package-lock.json"}) {
    std::error_code ec;
    const auto source_time = std::filesystem::last_write_time(web / source, ec);
    if (!ec && source_time > std::filesystem::last_write_time(bundle))
      throw InputError(bundle.string(), std::string("is older than ") + source +
                                            "; run `npm run build` in " + web.string() +
                                            " (or ./scripts/install_deps.sh)");
  }
  const auto t0 = std::chrono::steady_clock::now();
  synth::WebModel model = synth::BuildWebModel(model_dir);
  const double prepare_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // Served without a copy per request.
  std::map<std::string, std::shared_ptr<const std::vector<unsigned char>>> model_files;
  for (auto& [name, bytes] : model.files)
    model_files[name] = std::make_shared<const std::vector<unsigned char>>(std::move(bytes));
  HttpServer server(host, port);
  const HttpHandler handler = [&](const std::string& path) -> HttpResponse {
    auto file_response = [](const std::filesystem::path& f) {
      std::ifstream in(f, std::ios::binary);
      HttpResponse r;
      r.content_type = ContentTypeOf(f.filename().string());
      r.body = std::make_shared<const std::vector<unsigned char>>(
          std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
      return r;
    };
    if (path == "/" || path == "/index.html") return file_response(web / "viewer/index.html");
    if (path.rfind("/viewer/", 0) == 0)
      if (const auto f = FileBelow(web / "viewer", path.substr(8))) return file_response(*f);
    if (path.rfind("/dist/", 0) == 0)
      if (const auto f = FileBelow(web / "dist", path.substr(6))) return file_response(*f);
    if (path.rfind("/model/", 0) == 0) {
      const auto it = model_files.find(path.substr(7));
      if (it != model_files.end()) return {200, ContentTypeOf(it->first), it->second};
    }
    return {404, "text/plain", {}};
  };
  out << "texlume view: " << model.scene["faces"].get<std::size_t>() << " triangles, "
      << model.scene["atlases"].size() << " atlas(es), prepared in " << prepare_s << " s\n"
      << "Serving " << model_dir.string() << " at http://" << host << ":" << server.port()
      << "/ (Ctrl-C stops)" << std::endl;
  g_stop_serving.store(false);
  std::signal(SIGINT, StopServing);
  std::signal(SIGTERM, StopServing);
  server.Serve(handler, g_stop_serving);
  err << "texlume view: stopped\n";
  return kExitOk;
}

int RunDemoCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  const Arguments a(args, {"out", "seed", "kind", "material"}, {});
  const std::filesystem::path dir = a.Get("out").value_or("out");
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
  options.write_btf = false;
  options.write_surface = false;
  // Held-out views at twice the photos' resolution: metrics at full resolution
  // and, reduced by 2, at the photos'.
  options.held_out_scale = 2;
  options.Check();

  ProgressBar bar;
  const auto t0 = std::chrono::steady_clock::now();
  auto since = [](std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  };
  out << "1. A synthetic heritage scene: a " << material << " " << kind
      << " photographed under known lights, and an RTI capture of the " << material
      << " sample (texlume scene)\n";
  const std::filesystem::path scene_dir = dir / "scene";
  const datasets::SceneSummary scene = datasets::GenerateScene(options, scene_dir, bar.Callback());
  out << "   " << scene.num_files << " files in " << scene_dir.string() << " ("
      << scene.seconds_total << " s); see MANIFEST.md there\n\n";
  const double seconds_scene = since(t0);

  auto t = std::chrono::steady_clock::now();
  sfm::InspectOptions inspect;
  inspect.model_dir = scene_dir / "object/sparse";
  inspect.mesh = scene_dir / "object/mesh.ply";
  inspect.lights = scene_dir / "object/lights.json";
  inspect.images_dir = scene_dir / "object/images";
  out << "2. texlume inspect --model " << inspect.model_dir.string() << " --mesh "
      << inspect.mesh->string() << " --lights " << inspect.lights->string() << " --images "
      << inspect.images_dir->string() << "\n";
  const sfm::InspectReport report = sfm::RunInspect(inspect, bar.Callback());
  out << sfm::FormatInspectReport(report) << "\n";
  const double seconds_inspect = since(t);

  t = std::chrono::steady_clock::now();
  const std::filesystem::path capture = scene_dir / "material/capture";
  const std::filesystem::path sample = dir / "sample.ptm";
  out << "3. texlume fit --images " << capture.string() << " --lights "
      << (capture / "lights.lp").string() << " --out " << sample.string() << "\n";
  const ptm::RtiCapture rti = ptm::ReadRtiCapture(capture / "lights.lp", capture);
  const ptm::Ptm sample_ptm = ptm::FitPtmFromFiles(rti.files, rti.lights, {}, bar.Callback()).ptm;
  ptm::WritePtmFile(sample_ptm, sample);
  ptm::WritePtmExr(sample_ptm, dir / "sample.exr");
  const double seconds_fit = since(t);

  t = std::chrono::steady_clock::now();
  synth::SynthJobOptions job;
  job.model_dir = scene_dir / "object/sparse";
  job.images_dir = scene_dir / "object/images";
  job.lights_file = scene_dir / "object/lights.json";
  job.mesh_file = scene_dir / "object/mesh.ply";
  job.sample_file = dir / "sample.exr";
  job.out_dir = dir / "model";
  job.synthesis.sample_texel_size = options.material.texel_size;
  out << "\n4. texlume synth --model " << job.model_dir.string() << " --images "
      << job.images_dir.string() << " --lights " << job.lights_file.string() << " --mesh "
      << job.mesh_file.string() << " --sample " << job.sample_file.string()
      << " --sample-texel-size " << job.synthesis.sample_texel_size << " --out "
      << job.out_dir.string() << "\n";
  const synth::SynthJobSummary synthesis = synth::RunSynthJob(job, bar.Callback());
  for (const std::string& w : synthesis.warnings) err << "warning: " << w << "\n";
  out << "   " << synthesis.faces << " triangles (" << synthesis.from_photos << " from photos), "
      << synthesis.atlases << " atlas(es), occupancy " << synthesis.occupancy << ", "
      << synthesis.seconds_total << " s\n";
  const double seconds_synth = since(t);

  t = std::chrono::steady_clock::now();
  const std::filesystem::path held = scene_dir / "object/held_out";
  auto render = [&](synth::RenderMode mode, const std::string& name) {
    synth::RenderJobOptions r;
    r.model_folder = job.out_dir;
    r.cameras_dir = held / "sparse";
    r.lights_file = held / "lights.json";
    r.out_dir = dir / ("render_" + name);
    r.mode = mode;
    r.truth_images_dir = held / "images";
    r.truth_masks_dir = held / "masks";
    r.reduced_factor = options.held_out_scale;
    out << "\n5. texlume render --model " << r.model_folder.string() << " --cameras "
        << r.cameras_dir.string() << " --lights " << r.lights_file.string() << " --out "
        << r.out_dir.string() << (name == "texlume" ? "" : " --baseline " + name) << " --truth "
        << r.truth_images_dir.string() << " --truth-masks " << r.truth_masks_dir.string()
        << " --reduced-factor " << r.reduced_factor << "\n";
    const synth::RenderJobSummary s = synth::RunRenderJob(r, bar.Callback());
    out << "   held-out views under held-out lights, inside the masks: PSNR " << s.mean_psnr
        << " dB, SSIM " << s.mean_ssim << " at full resolution; " << s.mean_psnr_reduced << " dB, "
        << s.mean_ssim_reduced << " at the photos' resolution\n";
    return s;
  };
  const synth::RenderJobSummary ours = render(synth::RenderMode::kPtm, "texlume");
  const synth::RenderJobSummary flat = render(synth::RenderMode::kFlat, "flat");
  const synth::RenderJobSummary baked = render(synth::RenderMode::kBaked, "baked");
  const double seconds_render = since(t);

  // The report: the sample, the photos, held-out views beside the truth and the
  // baselines, error maps, a light sweep, the atlases, metrics and timings.
  t = std::chrono::steady_clock::now();
  out << "\n6. The report\n";
  const synth::TexturedModel model = synth::ReadModelFolder(job.out_dir);
  const synth::ModelBaselines baselines = synth::ReadModelBaselines(job.out_dir, model);
  synth::ReportInputs rep;
  rep.title = "texlume demo: a " + material + " " + kind;
  rep.intro =
      "A synthetic heritage scene with ground truth: the " + material + " " + kind +
      " photographed under known lights, and an RTI capture of the material sample. texlume "
      "fitted the sample PTM, synthesised the relightable model from the photos and rendered it "
      "from held-out views under held-out lights (twice the photos' resolution), beside the "
      "ground truth and two baselines: the coarse mesh flat-shaded with the mean albedo, and the "
      "photos baked into an ordinary texture.";
  rep.model = &model;
  rep.flat_albedo = baselines.flat_albedo;
  rep.baked = baselines.baked;
  rep.sample = &sample_ptm;
  {
    const sfm::LoadedModel photos_model = sfm::ReadModel(job.model_dir);
    const sfm::ObjectLights photo_lights = sfm::ReadObjectLightsFile(job.lights_file);
    for (const auto& [id, image] : photos_model.reconstruction.images)
      if (const auto it = photo_lights.find(image.name); it != photo_lights.end())
        rep.photos.push_back({image.name, job.images_dir / image.name, it->second, {}});
    const sfm::LoadedModel held_model = sfm::ReadModel(held / "sparse");
    const sfm::ObjectLights held_lights = sfm::ReadObjectLightsFile(held / "lights.json");
    for (const auto& [id, image] : held_model.reconstruction.images) {
      const auto it = held_lights.find(image.name);
      if (it == held_lights.end()) continue;
      synth::ReportView view;
      view.name = image.name;
      view.camera = held_model.reconstruction.cameras.at(image.camera_id);
      view.cam_from_world = image.cam_from_world;
      view.lights = it->second;
      view.reference_image = held / "images" / image.name;
      view.reference_mask = held / "masks" / image.name;
      rep.views.push_back(std::move(view));
    }
  }
  rep.views_heading = "Held-out views under held-out lights";
  rep.metrics = {
      {"texlume (PTM atlases)", ours}, {"flat baseline", flat}, {"baked baseline", baked}};
  rep.occupancy = synthesis.occupancy;
  rep.facts = {{"triangles", std::to_string(synthesis.faces) + " (" +
                                 std::to_string(synthesis.from_photos) + " constrained by photos)"},
               {"photos", std::to_string(synthesis.photos_used)},
               {"atlases", std::to_string(synthesis.atlases) + ", " +
                               std::to_string(synthesis.charts) + " charts"}};
  rep.timings_s = {{"scene", seconds_scene},
                   {"inspect", seconds_inspect},
                   {"fit", seconds_fit},
                   {"synth (with the model's report)", seconds_synth},
                   {"render (3 models)", seconds_render}};
  rep.links = {{"model.glb", "model/model.glb"},
               {"model.obj", "model/model.obj"},
               {"manifest.json", "model/manifest.json"},
               {"the model's own report (photo views)", "model/report.html"},
               {"run.json", "run.json"}};
  synth::WriteReport(dir, rep, bar.Callback());
  const double seconds_report = since(t);

  nlohmann::json run;
  run["command"] = "demo";
  run["settings"] = {{"shape", kind},
                     {"material", material},
                     {"seed", options.seed},
                     {"num_images", options.num_images},
                     {"held_out_scale", options.held_out_scale}};
  run["timings_s"] = {{"scene", seconds_scene},   {"inspect", seconds_inspect},
                      {"fit", seconds_fit},       {"synth", seconds_synth},
                      {"render", seconds_render}, {"report", seconds_report},
                      {"total", since(t0)}};
  run["inspect"] = nlohmann::json::parse(sfm::InspectReportToJson(report));
  auto metrics = [](const synth::RenderJobSummary& s) {
    return nlohmann::json{{"psnr_db", s.mean_psnr},
                          {"ssim", s.mean_ssim},
                          {"psnr_db_photo_resolution", s.mean_psnr_reduced},
                          {"ssim_photo_resolution", s.mean_ssim_reduced}};
  };
  run["metrics"] = {{"texlume", metrics(ours)},
                    {"flat", metrics(flat)},
                    {"baked", metrics(baked)},
                    {"held_out_scale", options.held_out_scale}};
  WriteFileAtomically(
      dir / "run.json", [&](std::ostream& o) { o << run.dump(2) << "\n"; }, false);
  out << "\nReport: " << (dir / "report.html").string() << " (run.json: settings, timings)\n";
  return kExitOk;
}

}  // namespace texlume::apps
