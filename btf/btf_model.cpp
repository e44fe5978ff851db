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

BtfSynthJobSummary RunBtfSynthJob(const BtfSynthJobOptions& options,
                                  const ProgressCallback& progress) {
  const auto start = std::chrono::steady_clock::now();
  options.Check();
  const synth::SynthJobOptions& job = options.job;
  if (fs::exists(job.out_dir) &&
      (!fs::is_directory(job.out_dir) ||
       (!fs::exists(job.out_dir / "manifest.json") && !fs::is_empty(job.out_dir)))) {
    throw InputError(job.out_dir.string(),
                     "exists and is not a texlume model folder; not replacing it");
  }
  BtfSynthJobSummary summary;

  synth::SynthInputs inputs = synth::LoadSynthInputs(job);
  // The sample: a factorisation as it is, or a capture factorised here.
  auto t = std::chrono::steady_clock::now();
  BtfFactorisation sample;
  std::vector<SvdError> errors;
  if (fs::exists(options.btf / "btf_svd.json")) {
    sample = ReadBtfFactorisation(options.btf);
  } else {
    const BtfCapture capture = ReadBtfCapture(options.btf);
    sample = FactoriseBtf(capture, options.components, progress);
  }
  {
    std::vector<int> ns;
    for (int k = 1; k < sample.Components(); k *= 2) ns.push_back(k);
    ns.push_back(sample.Components());
    errors = SvdErrorTable(sample, ns);
  }
  summary.seconds_factorise = Since(t);
  synth::BtfMeshSynthesisOptions so = options.synthesis;
  if (so.sample_texel_size == 0.0) so.sample_texel_size = sample.texel_size;
  so.Check();

  synth::PrepareSynthMesh(inputs, job, std::min(sample.width, sample.height), so.sample_texel_size,
                          so.strip, progress);
  summary.warnings = inputs.warnings;
  summary.photos_used = inputs.photos.size();
  summary.subdivisions = inputs.subdivisions;
  summary.faces = inputs.mesh.faces.size();

  const synth::BtfMeshSynthesis synthesis = synth::SynthesizeMeshBtf(
      inputs.mesh, inputs.reconstruction, inputs.visibility, inputs.photos, sample, so, progress);
  summary.seconds_synthesis = synthesis.seconds_synthesis;
  summary.seconds_seams = synthesis.seconds_seams;
  summary.from_photos = synthesis.num_from_photos;
  summary.from_neighbours = synthesis.num_from_neighbours;
  summary.random = synthesis.num_random;
  summary.seam_edges = synthesis.seam_edges;
  summary.seam_cost_per_link = synthesis.seam_cost_per_link;
  summary.edge_cost_per_link = synthesis.edge_cost_per_link;

  t = std::chrono::steady_clock::now();
  const BtfAtlases atlases = BuildBtfAtlases(inputs.mesh, synthesis, sample, job.atlas, progress);
  summary.seconds_atlas = Since(t);
  summary.atlases = atlases.geometry.size();
  summary.charts = static_cast<std::size_t>(atlases.layout.num_charts);
  summary.chart_flattening = job.atlas.mode == synth::AtlasMode::kCharts
                                 ? synth::ChartFlatteningName(atlases.layout.flattening)
                                 : "none";
  summary.occupancy = atlases.occupancy;
  t = std::chrono::steady_clock::now();
  synth::TexturedModel model;
  model.mesh = inputs.mesh;
  model.atlases = PreviewPtms(atlases, sample, progress);
  for (const synth::FacePlacement& fp : atlases.layout.faces) {
    model.face_atlas.push_back(fp.atlas);
    model.corner_px.push_back({fp.corners_px[0].cast<float>(), fp.corners_px[1].cast<float>(),
                               fp.corners_px[2].cast<float>()});
  }
  summary.seconds_preview = Since(t);

  // The baselines `texlume render` draws, as for PTM models.
  const std::vector<cv::Mat> baked = synth::BakePhotoTextures(
      model, inputs.reconstruction, inputs.visibility, inputs.photos, synthesis.photo_gains);
  const Eigen::Vector3f flat_albedo = synth::MeanAlbedoFromPhotos(
      inputs.mesh, inputs.reconstruction, inputs.visibility, inputs.photos, synthesis.photo_gains);

  nlohmann::json record;
  record["command"] = "synth --btf";
  record["inputs"] = {{"model", job.model_dir.string()},
                      {"images", job.images_dir.string()},
                      {"lights", job.lights_file.string()},
                      {"mesh", job.mesh_file.string()},
                      {"btf", options.btf.string()}};
  record["settings"] = {{"sample_texel_size", so.sample_texel_size},
                        {"components", sample.Components()},
                        {"strip", so.strip},
                        {"seam_band", so.seam_band},
                        {"top_k", so.top_k},
                        {"max_views", so.max_views},
                        {"tangent_frame", synth::TangentFrameName(so.tangent_frame)},
                        {"tolerance", so.tolerance},
                        {"photo_correction", so.photo_correction},
                        {"correction_noise", so.correction_noise},
                        {"correction_sigma", so.correction_sigma},
                        {"seed", so.seed},
                        {"horizon_elevation_deg", synth::kHorizonElevationDeg}};
  record["settings"].update(synth::AtlasSettingsJson(job.atlas));
  record["summary"] = {{"photos_used", summary.photos_used},
                       {"faces", summary.faces},
                       {"subdivisions", summary.subdivisions},
                       {"from_photos", summary.from_photos},
                       {"from_neighbours_only", summary.from_neighbours},
                       {"random", summary.random},
                       {"atlases", summary.atlases},
                       {"charts", summary.charts},
                       {"chart_flattening", summary.chart_flattening},
                       {"occupancy", summary.occupancy},
                       {"seam_edges", summary.seam_edges},
                       {"seam_cost_per_link", summary.seam_cost_per_link},
                       {"straight_edge_cost_per_link", summary.edge_cost_per_link},
                       {"photo_rms_quilted", synthesis.photo_rms_quilted},
                       {"photo_rms_corrected", synthesis.photo_rms_corrected},
                       {"photo_gains", synthesis.photo_gains},
                       {"tangent_frame", synth::TangentFrameName(synthesis.tangent_frame)},
                       {"sample_coherence", synthesis.sample_coherence >= 0.0
                                                ? nlohmann::json(synthesis.sample_coherence)
                                                : nlohmann::json(nullptr)}};
  record["warnings"] = summary.warnings;
  std::vector<std::pair<std::string, cv::Mat>> extra =
      synth::RecordBaselines(flat_albedo, baked, record);
  nlohmann::json btf_files = nlohmann::json::array();
  for (std::size_t a = 0; a < atlases.geometry.size(); ++a) btf_files.push_back(AtlasFileName(a));
  record["btf"] = {
      {"format", "texlume-btf-model-1"},
      {"factorisation", "btf/btf_svd.json"},
      {"atlases", btf_files},
      {"atlas_channels", "sample_x, sample_y, angle, gain_r, gain_g, gain_b (docs/btf.md)"},
      {"ptm_atlases", "a preview: the BTF seen head-on, fitted per texel"}};
  record["timings_s"] = {
      {"load", inputs.seconds_load},
      {"visibility", inputs.seconds_visibility},
      {"factorise", summary.seconds_factorise},
      {"synthesis", summary.seconds_synthesis},
      {"seams", summary.seconds_seams},
      {"atlas", summary.seconds_atlas},
      {"ptm_preview", summary.seconds_preview},
      {"synthesis_per_triangle", (summary.seconds_synthesis + summary.seconds_seams) /
                                     static_cast<double>(std::max<std::size_t>(1, summary.faces))}};
  // The geometry maps baked per atlas texel, for export: 8 bits per component
  // with a scale and bias each, four components per RGBA PNG (docs/btf.md).
  t = std::chrono::steady_clock::now();
  std::vector<std::pair<std::string, std::vector<unsigned char>>> geometry_png;
  nlohmann::json geometry_json = nlohmann::json::array();
  for (std::size_t a = 0; a < atlases.geometry.size(); ++a) {
    const auto& planes = atlases.geometry[a];
    const int w = planes[0].cols, h = planes[0].rows;
    std::vector<synth::QuantisedPlane> quantised(planes.size());
#pragma omp parallel for schedule(dynamic, 1)
    for (std::size_t i = 0; i < planes.size(); ++i) {
      const cv::Mat flat = planes[i].reshape(1, 1);
      quantised[i] =
          synth::QuantisePlane(std::vector<float>(flat.begin<float>(), flat.end<float>()));
    }
    nlohmann::json files = nlohmann::json::array();
    geometry_png.resize(geometry_png.size() + (planes.size() + 3) / 4);
    const std::size_t first = geometry_png.size() - (planes.size() + 3) / 4;
#pragma omp parallel for schedule(dynamic, 1)
    for (std::size_t part = 0; part < (planes.size() + 3) / 4; ++part) {
      std::vector<const synth::QuantisedPlane*> group;
      for (std::size_t i = part * 4; i < std::min(planes.size(), part * 4 + 4); ++i)
        group.push_back(&quantised[i]);
      const std::string name = GeometryFileName(a, part);
      geometry_png[first + part] = {name, synth::PlanesPng(group, w, h, name)};
    }
    for (std::size_t part = 0; part < (planes.size() + 3) / 4; ++part) {
      nlohmann::json scale = nlohmann::json::array(), bias = nlohmann::json::array();
      for (std::size_t i = part * 4; i < std::min(planes.size(), part * 4 + 4); ++i)
        scale.push_back(quantised[i].scale), bias.push_back(quantised[i].bias);
      files.push_back({{"file", GeometryFileName(a, part)}, {"scale", scale}, {"bias", bias}});
    }
    geometry_json.push_back(files);
  }
  record["btf"]["geometry_atlases"] = geometry_json;
  summary.seconds_export = Since(t);
  record["timings_s"]["export_geometry"] = summary.seconds_export;
  synth::WriteModelFolder(job.out_dir, model, record, extra, [&](const fs::path& folder) {
    WriteBtfFactorisation(sample, errors, folder / "btf");
    for (std::size_t a = 0; a < atlases.sample_coords.size(); ++a) {
      std::vector<cv::Mat> planes, gain;
      cv::split(atlases.sample_coords[a], planes);
      cv::split(atlases.colour_gain[a], gain);
      planes.insert(planes.end(), gain.begin(), gain.end());
      std::vector<std::string> names = kCoordinateChannels;
      names.insert(names.end(), kGainChannels.begin(), kGainChannels.end());
      ptm::WriteExr(folder / AtlasFileName(a), planes, names);
    }
    for (const auto& [name, bytes] : geometry_png) WriteBytesAtomically(folder / name, bytes);
  });
  summary.seconds_total = Since(start);
  return summary;
}

}  // namespace texlume::btf
