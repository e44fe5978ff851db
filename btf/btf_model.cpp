#include "btf/btf_model.h"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>

#include "core/errors.h"
#include "ptm/coefficient_space.h"
#include "ptm/exr_io.h"
#include "synth/model_io.h"
#include "synth/web_model.h"

namespace texlume::btf {
namespace fs = std::filesystem;
namespace {

double Since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

double WrapAngle(double a) { return std::remainder(a, 2.0 * std::numbers::pi); }

std::string AtlasFileName(std::size_t k) { return "btf_atlas_" + std::to_string(k) + ".exr"; }

const std::vector<std::string> kCoordinateChannels = {"sample_x", "sample_y", "angle"};
const std::vector<std::string> kGainChannels = {"gain_r", "gain_g", "gain_b"};

std::string GeometryFileName(std::size_t atlas, std::size_t part) {
  return "btf_geometry_" + std::to_string(atlas) + "_" + std::to_string(part) + ".png";
}

// Preview lights: the zenith and rings of 6 at 60, 40, 25 and 15 degrees.
std::vector<Eigen::Vector3d> PreviewLights() {
  std::vector<Eigen::Vector3d> out = {Eigen::Vector3d::UnitZ()};
  const double elevations[] = {60, 40, 25, 15};
  for (int r = 0; r < 4; ++r) {
    const double e = elevations[r] * std::numbers::pi / 180.0;
    for (int k = 0; k < 6; ++k) {
      const double a = (k + 0.5 * (r % 2)) * std::numbers::pi / 3.0;
      out.emplace_back(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
    }
  }
  return out;
}

}  // namespace

BtfAtlases BuildBtfAtlases(const sfm::TriangleMesh& mesh, const synth::BtfMeshSynthesis& synthesis,
                           const BtfFactorisation& sample, const synth::AtlasOptions& options,
                           const ProgressCallback& progress) {
  BtfAtlases out;
  out.layout = synth::LayoutAtlases(mesh, synthesis.patches, synthesis.unfoldings,
                                    synthesis.texel_size, options, progress);
  const int n = sample.Components();
  // Planes: sample x, sample y, angle, the factors r, g, b, then g_0 .. g_{n-1}.
  std::vector<std::vector<cv::Mat>> planes(out.layout.atlas_sizes.size());
  for (std::size_t a = 0; a < planes.size(); ++a)
    for (int c = 0; c < 6 + n; ++c)
      planes[a].push_back(cv::Mat::zeros(out.layout.atlas_sizes[a], CV_32FC1));
  std::vector<double> face_angle;
  for (const synth::FacePlacement& fp : out.layout.faces)
    face_angle.push_back(-fp.AtlasFrameAngle());  // the atlas frame's turn from the face frame
  std::vector<float> g(static_cast<std::size_t>(n));
  synth::AtlasCoverage coverage = synth::VisitAtlasTexels(
      out.layout, synthesis.texel_size, options.gutter,
      [&](int atlas, int x, int y, int face, const Eigen::Vector2d& p_in_frame) {
        const synth::BtfSampleLookup look = synthesis.Lookup(face, p_in_frame);
        auto& p = planes[static_cast<std::size_t>(atlas)];
        p[0].at<float>(y, x) = static_cast<float>(look.sample_px.x());
        p[1].at<float>(y, x) = static_cast<float>(look.sample_px.y());
        // d_sample = R(look) d_face and d_face = R(-face) d_atlas.
        p[2].at<float>(y, x) = static_cast<float>(
            WrapAngle(look.angle_rad - face_angle[static_cast<std::size_t>(face)]));
        for (int c = 0; c < 3; ++c)
          p[static_cast<std::size_t>(3 + c)].at<float>(y, x) = look.colour_gain[c];
        synth::SampleGeometry(sample, look.sample_px, g.data());
        for (int i = 0; i < n; ++i) p[static_cast<std::size_t>(6 + i)].at<float>(y, x) = g[i];
      },
      progress);
  std::size_t total = 0;
  for (std::size_t a = 0; a < planes.size(); ++a) {
    synth::DilateGutters(planes[a], coverage.coverage[a], options.gutter);
    total += coverage.coverage[a].total();
    cv::Mat coords;
    cv::merge(std::vector<cv::Mat>(planes[a].begin(), planes[a].begin() + 3), coords);
    out.sample_coords.push_back(coords);
    cv::Mat gain;
    cv::merge(std::vector<cv::Mat>(planes[a].begin() + 3, planes[a].begin() + 6), gain);
    out.colour_gain.push_back(gain);
    out.geometry.emplace_back(planes[a].begin() + 6, planes[a].end());
  }
  out.coverage = std::move(coverage.coverage);
  out.occupancy = total ? static_cast<double>(coverage.inside_texels) / total : 0.0;
  return out;
}

std::vector<ptm::Ptm> PreviewPtms(const BtfAtlases& atlases, const BtfFactorisation& sample,
                                  const ProgressCallback& progress) {
  const int n = sample.Components();
  const std::vector<Eigen::Vector3d> lights = PreviewLights();
  const int count = static_cast<int>(lights.size());
  // p_i(head-on, l_j) stacked: (count * 3) x n.
  Eigen::MatrixXf appearance(count * 3, n);
  Eigen::MatrixXd basis(count, 6);
  for (int j = 0; j < count; ++j) {
    appearance.middleRows(j * 3, 3) =
        InterpolateAppearance(sample, Eigen::Vector3d::UnitZ(), lights[static_cast<std::size_t>(j)])
            .transpose();
    const auto phi = ptm::PtmBasis(lights[static_cast<std::size_t>(j)].x(),
                                   lights[static_cast<std::size_t>(j)].y());
    for (int m = 0; m < 6; ++m) basis(j, m) = phi[static_cast<std::size_t>(m)];
  }
  const Eigen::MatrixXd fit = basis.completeOrthogonalDecomposition().pseudoInverse();  // 6 x J
  std::vector<ptm::Ptm> out;
  for (std::size_t a = 0; a < atlases.geometry.size(); ++a) {
    const cv::Mat& coords = atlases.sample_coords[a];
    ptm::Ptm p;
    p.Resize(ptm::PtmFormat::kLrgb, coords.cols, coords.rows);
    const auto& planes = atlases.geometry[a];
#pragma omp parallel for schedule(dynamic, 8)
    for (int y = 0; y < coords.rows; ++y) {
      Eigen::VectorXf g(n);
      Eigen::VectorXd lum(count);
      for (int x = 0; x < coords.cols; ++x) {
        const std::size_t t = static_cast<std::size_t>(y) * coords.cols + x;
        for (int i = 0; i < n; ++i) g[i] = planes[static_cast<std::size_t>(i)].at<float>(y, x);
        Eigen::VectorXf linear = appearance * g;
        const cv::Vec3f k = atlases.colour_gain[a].at<cv::Vec3f>(y, x);
        for (int j = 0; j < count; ++j)
          for (int c = 0; c < 3; ++c) linear[j * 3 + c] *= k[c];
        Eigen::Vector3d channel_sum = Eigen::Vector3d::Zero();
        for (int j = 0; j < count; ++j) {
          double s = 0.0;
          for (int c = 0; c < 3; ++c) {
            const double d = LinearToSrgb(linear[j * 3 + c]);
            channel_sum[c] += d;
            s += d;
          }
          lum[j] = s / 3.0;
        }
        Eigen::Matrix<double, 6, 1> coefficients = fit * lum;
        // Eq. 2: colour = L (R, G, B), the colour's largest channel 1.
        const double total = lum.sum();
        Eigen::Vector3d colour =
            total > 1e-9 ? Eigen::Vector3d(channel_sum / total) : Eigen::Vector3d::Ones();
        const double top = std::max(colour.maxCoeff(), 1e-6);
        colour /= top;
        coefficients *= top;
        // Into the atlas frame: its x axis is R(angle) x in the sample frame.
        coefficients = ptm::FrameRotation(coords.at<cv::Vec3f>(y, x)[2]) * coefficients;
        float* a_out = p.Coefficients(t);
        for (int m = 0; m < 6; ++m) a_out[m] = static_cast<float>(coefficients[m]);
        for (int c = 0; c < 3; ++c) p.colour[t * 3 + c] = static_cast<float>(colour[c]);
      }
    }
    out.push_back(std::move(p));
    if (progress) progress("ptm preview", a + 1, atlases.geometry.size());
  }
  return out;
}

BtfModel ReadBtfModel(const fs::path& dir, const synth::TexturedModel& model) {
  const nlohmann::json manifest = synth::ReadModelManifest(dir);
  const fs::path manifest_path = dir / "manifest.json";
  if (!manifest.contains("btf") || !manifest["btf"].is_object())
    throw InputError(manifest_path.string(),
                     "describes no BTF model (made by texlume synth --btf)");
  BtfModel out;
  out.sample = ReadBtfFactorisation(dir / "btf");
  for (std::size_t k = 0; k < model.atlases.size(); ++k) {
    const fs::path file = dir / AtlasFileName(k);
    if (!fs::exists(file)) throw InputError(file.string(), "is missing");
    std::vector<std::string> names;
    const std::vector<cv::Mat> planes = ptm::ReadExr(file, &names);
    std::vector<cv::Mat> ordered;  // EXR keeps channels sorted by name
    for (const std::string& want : kCoordinateChannels) {
      const auto it = std::find(names.begin(), names.end(), want);
      if (it == names.end())
        throw InputError(file.string(),
                         "has no channel " + want + " (expected sample_x, sample_y, angle)");
      ordered.push_back(planes[static_cast<std::size_t>(it - names.begin())]);
    }
    if (ordered[0].cols != model.atlases[k].width || ordered[0].rows != model.atlases[k].height)
      throw InputError(file.string(), "is not the size of its atlas");
    cv::Mat coords;
    cv::merge(ordered, coords);
    out.sample_coords.push_back(coords);
    // The photo-consistency factors (absent from models made without them: 1).
    std::vector<cv::Mat> gain;
    for (const std::string& want : kGainChannels) {
      const auto it = std::find(names.begin(), names.end(), want);
      if (it != names.end()) gain.push_back(planes[static_cast<std::size_t>(it - names.begin())]);
    }
    if (!gain.empty() && gain.size() != 3)
      throw InputError(file.string(), "has some but not all of gain_r, gain_g, gain_b");
    cv::Mat factors(coords.size(), CV_32FC3, cv::Scalar::all(1.0));
    if (!gain.empty()) cv::merge(gain, factors);
    out.colour_gain.push_back(factors);
  }
  return out;
}

Eigen::Vector3f ShadeBtf(const BtfModel& model, const synth::ModelRenderer::SurfaceSample& s,
                         const std::vector<sfm::ObjectLight>& lights) {
  const cv::Mat& coords = model.sample_coords[static_cast<std::size_t>(s.atlas)];
  const int n = model.sample.Components();
  // Paper 004's lookup: the nearest texel's sample position, moved by the hit's
  // offset from that texel's centre turned into the sample frame (atlas and
  // sample texels have the same size); g bilinear in the sample. Across a seam
  // the nearest texel decides, so the cut stays sharp.
  const int nx = std::clamp(static_cast<int>(std::floor(s.atlas_px.x())), 0, coords.cols - 1);
  const int ny = std::clamp(static_cast<int>(std::floor(s.atlas_px.y())), 0, coords.rows - 1);
  const cv::Vec3f texel = coords.at<cv::Vec3f>(ny, nx);
  const double angle = texel[2];
  const double ca = std::cos(angle), sa = std::sin(angle);
  const double ox = s.atlas_px.x() - (nx + 0.5), oy = -(s.atlas_px.y() - (ny + 0.5));  // y up
  const Eigen::Vector2d sample_px(texel[0] + (ca * ox - sa * oy), texel[1] - (sa * ox + ca * oy));
  Eigen::VectorXf g(n);
  synth::SampleGeometry(model.sample, sample_px, g.data());
  auto to_sample = [&](const Eigen::Vector3d& world) {
    const Eigen::Vector3d d = s.frame.transpose() * world;
    return Eigen::Vector3d(ca * d.x() - sa * d.y(), sa * d.x() + ca * d.y(), d.z());
  };
  Eigen::Vector3d view = to_sample(s.to_viewer);
  if (view.z() < 0.02) {  // grazing (the smooth normal turns away): the horizon
    view.z() = 0.02;
    view.normalize();
  }
  Eigen::Vector3f linear = Eigen::Vector3f::Zero();
  for (const sfm::ObjectLight& light : lights) {
    const Eigen::Vector3d l = to_sample(light.DirectionFrom(s.point));
    if (l.z() <= 0.0) continue;
    linear += static_cast<float>(light.intensity) *
              (InterpolateAppearance(model.sample, view, l).transpose() * g);
  }
  const cv::Vec3f k = model.colour_gain[static_cast<std::size_t>(s.atlas)].at<cv::Vec3f>(ny, nx);
  return {LinearToSrgb(linear[0] * k[0]), LinearToSrgb(linear[1] * k[1]),
          LinearToSrgb(linear[2] * k[2])};
}

void BtfSynthJobOptions::Check() const {
  job.CheckInputsAndLayout();
  if (btf.empty()) throw OptionError("synth --btf needs a BTF capture or factorisation folder");
  if (components < 1) throw OptionError("components must be >= 1");
  if (!(synthesis.sample_texel_size >= 0.0))
    throw OptionError("sample texel size must be >= 0 (0: the capture's)");
  synth::BtfMeshSynthesisOptions resolved = synthesis;
  if (resolved.sample_texel_size == 0.0) resolved.sample_texel_size = 1.0;  // any valid size
  resolved.Check();
}

namespace {

// The BTF job's steps, each a method (RunBtfSynthJob).
class BtfSynthJob {
 public:
  BtfSynthJob(const BtfSynthJobOptions& options, const ProgressCallback& progress)
      : options_(options), job_(options.job), progress_(progress) {}

  BtfSynthJobSummary Run() {
    const auto start = std::chrono::steady_clock::now();
    synth::RefuseForeignModelFolder(job_.out_dir);
    inputs_ = synth::LoadSynthInputs(job_);
    LoadSample();
    Synthesize();
    LayOut();
    nlohmann::json record = Record();
    // The geometry maps baked per atlas texel, for export (docs/btf.md).
    const auto t = std::chrono::steady_clock::now();
    record["btf"]["geometry_atlases"] = EncodeGeometryAtlases();
    summary_.seconds_export = Since(t);
    record["timings_s"]["export_geometry"] = summary_.seconds_export;
    synth::WriteModelFolder(job_.out_dir, model_, record, extra_images_,
                            [this](const fs::path& folder) { WriteBtfFiles(folder); });
    summary_.seconds_total = Since(start);
    return summary_;
  }

 private:
  // The sample: a factorisation as it is, or a capture factorised here; its
  // error table; the synthesis settings with its texel size; the mesh.
  void LoadSample() {
    const auto t = std::chrono::steady_clock::now();
    if (fs::exists(options_.btf / "btf_svd.json")) {
      sample_ = ReadBtfFactorisation(options_.btf);
    } else {
      const BtfCapture capture = ReadBtfCapture(options_.btf);
      sample_ = FactoriseBtf(capture, options_.components, progress_);
    }
    std::vector<int> ns;
    for (int k = 1; k < sample_.Components(); k *= 2) ns.push_back(k);
    ns.push_back(sample_.Components());
    errors_ = SvdErrorTable(sample_, ns);
    summary_.seconds_factorise = Since(t);
    so_ = options_.synthesis;
    if (so_.sample_texel_size == 0.0) so_.sample_texel_size = sample_.texel_size;
    so_.Check();
    synth::PrepareSynthMesh(inputs_, job_, std::min(sample_.width, sample_.height),
                            so_.sample_texel_size, so_.strip, progress_);
    summary_.CountInputs(inputs_);
  }

  void Synthesize() {
    synthesis_ = synth::SynthesizeMeshBtf(inputs_.mesh, inputs_.reconstruction, inputs_.visibility,
                                          inputs_.photos, sample_, so_, progress_);
    summary_.seconds_synthesis = synthesis_.seconds_synthesis;
    summary_.seconds_seams = synthesis_.seconds_seams;
    summary_.from_photos = synthesis_.num_from_photos;
    summary_.from_neighbours = synthesis_.num_from_neighbours;
    summary_.random = synthesis_.num_random;
    summary_.seam_edges = synthesis_.seam_edges;
    summary_.seam_cost_per_link = synthesis_.seam_cost_per_link;
    summary_.edge_cost_per_link = synthesis_.edge_cost_per_link;
  }

  // The atlases, the PTM preview as the model's atlases, and the baselines
  // `texlume render` draws, as for PTM models.
  void LayOut() {
    auto t = std::chrono::steady_clock::now();
    atlases_ = BuildBtfAtlases(inputs_.mesh, synthesis_, sample_, job_.atlas, progress_);
    summary_.seconds_atlas = Since(t);
    summary_.atlases = atlases_.geometry.size();
    summary_.charts = static_cast<std::size_t>(atlases_.layout.num_charts);
    summary_.chart_flattening = job_.atlas.mode == synth::AtlasMode::kCharts
                                    ? synth::ChartFlatteningName(atlases_.layout.flattening)
                                    : "none";
    summary_.occupancy = atlases_.occupancy;
    t = std::chrono::steady_clock::now();
    model_ = synth::TexturedModelOf(inputs_.mesh, PreviewPtms(atlases_, sample_, progress_),
                                    atlases_.layout.faces);
    summary_.seconds_preview = Since(t);
    baked_ = synth::BakePhotoTextures(model_, inputs_.reconstruction, inputs_.visibility,
                                      inputs_.photos, synthesis_.photo_gains);
    flat_albedo_ =
        synth::MeanAlbedoFromPhotos(inputs_.mesh, inputs_.reconstruction, inputs_.visibility,
                                    inputs_.photos, synthesis_.photo_gains);
  }

  nlohmann::json Settings() const {
    nlohmann::json settings = {{"sample_texel_size", so_.sample_texel_size},
                               {"components", sample_.Components()},
                               {"strip", so_.strip},
                               {"seam_band", so_.seam_band},
                               {"top_k", so_.top_k},
                               {"max_views", so_.max_views},
                               {"tangent_frame", synth::TangentFrameName(so_.tangent_frame)},
                               {"tolerance", so_.tolerance},
                               {"photo_correction", so_.photo_correction},
                               {"correction_noise", so_.correction_noise},
                               {"correction_sigma", so_.correction_sigma},
                               {"seed", so_.seed},
                               {"horizon_elevation_deg", synth::kHorizonElevationDeg}};
    settings.update(synth::AtlasSettingsJson(job_.atlas));
    return settings;
  }

  nlohmann::json Summary() const {
    const BtfSynthJobSummary& s = summary_;
    nlohmann::json summary = s.ToJson();
    summary.update({{"seam_edges", s.seam_edges},
                    {"seam_cost_per_link", s.seam_cost_per_link},
                    {"straight_edge_cost_per_link", s.edge_cost_per_link},
                    {"photo_rms_quilted", synthesis_.photo_rms_quilted},
                    {"photo_rms_corrected", synthesis_.photo_rms_corrected}});
    summary.update(synth::EngineSummaryJson(synthesis_));
    return summary;
  }

  nlohmann::json Record() {
    nlohmann::json record;
    record["command"] = "synth --btf";
    record["inputs"] = job_.InputsJson();
    record["inputs"]["btf"] = options_.btf.string();
    record["settings"] = Settings();
    record["summary"] = Summary();
    record["warnings"] = summary_.warnings;
    extra_images_ = synth::RecordBaselines(flat_albedo_, baked_, record);
    nlohmann::json btf_files = nlohmann::json::array();
    for (std::size_t a = 0; a < atlases_.geometry.size(); ++a)
      btf_files.push_back(AtlasFileName(a));
    record["btf"] = {
        {"format", "texlume-btf-model-1"},
        {"factorisation", "btf/btf_svd.json"},
        {"atlases", btf_files},
        {"atlas_channels", "sample_x, sample_y, angle, gain_r, gain_g, gain_b (docs/btf.md)"},
        {"ptm_atlases", "a preview: the BTF seen head-on, fitted per texel"}};
    const BtfSynthJobSummary& s = summary_;
    record["timings_s"] = {
        {"load", inputs_.seconds_load},
        {"visibility", inputs_.seconds_visibility},
        {"factorise", s.seconds_factorise},
        {"synthesis", s.seconds_synthesis},
        {"seams", s.seconds_seams},
        {"atlas", s.seconds_atlas},
        {"ptm_preview", s.seconds_preview},
        {"synthesis_per_triangle", (s.seconds_synthesis + s.seconds_seams) /
                                       static_cast<double>(std::max<std::size_t>(1, s.faces))}};
    return record;
  }

  // 8 bits per component with a scale and bias each, four components per RGBA
  // PNG (docs/btf.md); the PNGs go into geometry_png_, the manifest's entries
  // are returned.
  nlohmann::json EncodeGeometryAtlases() {
    nlohmann::json geometry_json = nlohmann::json::array();
    for (std::size_t a = 0; a < atlases_.geometry.size(); ++a) {
      const auto& planes = atlases_.geometry[a];
      const int w = planes[0].cols, h = planes[0].rows;
      std::vector<synth::QuantisedPlane> quantised(planes.size());
#pragma omp parallel for schedule(dynamic, 1)
      for (std::size_t i = 0; i < planes.size(); ++i) {
        const cv::Mat flat = planes[i].reshape(1, 1);
        quantised[i] =
            synth::QuantisePlane(std::vector<float>(flat.begin<float>(), flat.end<float>()));
      }
      const std::size_t parts = (planes.size() + 3) / 4;
      geometry_png_.resize(geometry_png_.size() + parts);
      const std::size_t first = geometry_png_.size() - parts;
#pragma omp parallel for schedule(dynamic, 1)
      for (std::size_t part = 0; part < parts; ++part) {
        std::vector<const synth::QuantisedPlane*> group;
        for (std::size_t i = part * 4; i < std::min(planes.size(), part * 4 + 4); ++i)
          group.push_back(&quantised[i]);
        const std::string name = GeometryFileName(a, part);
        geometry_png_[first + part] = {name, synth::PlanesPng(group, w, h, name)};
      }
      nlohmann::json files = nlohmann::json::array();
      for (std::size_t part = 0; part < parts; ++part) {
        nlohmann::json scale = nlohmann::json::array(), bias = nlohmann::json::array();
        for (std::size_t i = part * 4; i < std::min(planes.size(), part * 4 + 4); ++i)
          scale.push_back(quantised[i].scale), bias.push_back(quantised[i].bias);
        files.push_back({{"file", GeometryFileName(a, part)}, {"scale", scale}, {"bias", bias}});
      }
      geometry_json.push_back(files);
    }
    return geometry_json;
  }

  // The factorisation, the per-texel sample coordinates and factors, and the
  // geometry-map PNGs, into the model folder being written.
  void WriteBtfFiles(const fs::path& folder) const {
    WriteBtfFactorisation(sample_, errors_, folder / "btf");
    for (std::size_t a = 0; a < atlases_.sample_coords.size(); ++a) {
      std::vector<cv::Mat> planes, gain;
      cv::split(atlases_.sample_coords[a], planes);
      cv::split(atlases_.colour_gain[a], gain);
      planes.insert(planes.end(), gain.begin(), gain.end());
      std::vector<std::string> names = kCoordinateChannels;
      names.insert(names.end(), kGainChannels.begin(), kGainChannels.end());
      ptm::WriteExr(folder / AtlasFileName(a), planes, names);
    }
    for (const auto& [name, bytes] : geometry_png_) WriteBytesAtomically(folder / name, bytes);
  }

  const BtfSynthJobOptions& options_;
  const synth::SynthJobOptions& job_;
  const ProgressCallback& progress_;
  BtfSynthJobSummary summary_;
  synth::SynthInputs inputs_;
  BtfFactorisation sample_;
  std::vector<SvdError> errors_;
  synth::BtfMeshSynthesisOptions so_;
  synth::BtfMeshSynthesis synthesis_;
  BtfAtlases atlases_;
  synth::TexturedModel model_;
  std::vector<cv::Mat> baked_;
  Eigen::Vector3f flat_albedo_ = Eigen::Vector3f::Constant(0.5f);
  std::vector<std::pair<std::string, cv::Mat>> extra_images_;
  std::vector<std::pair<std::string, std::vector<unsigned char>>> geometry_png_;
};

}  // namespace

BtfSynthJobSummary RunBtfSynthJob(const BtfSynthJobOptions& options,
                                  const ProgressCallback& progress) {
  options.Check();
  return BtfSynthJob(options, progress).Run();
}

}  // namespace texlume::btf
