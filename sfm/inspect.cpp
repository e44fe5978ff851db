#include "sfm/inspect.h"

#include <iomanip>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "core/errors.h"
#include "core/file_util.h"
#include "sfm/lights.h"

namespace texlume::sfm {

void InspectOptions::Check() const {
  if (model_dir.empty()) throw OptionError("inspect needs a COLMAP model folder");
  mesh_clean.Check();
  visibility.Check();
}

InspectReport RunInspect(const InspectOptions& options, const ProgressCallback& progress) {
  options.Check();
  InspectReport report;
  LoadedModel model = ReadModel(options.model_dir);
  const Reconstruction& r = model.reconstruction;
  report.format = model.format;
  report.model_folder = model.folder;
  report.model_choice = model.choice;
  report.ignored_files = model.ignored_files;
  report.num_cameras = r.cameras.size();
  report.num_images = r.images.size();
  report.num_registered_images = r.images.size();
  report.num_points3d = r.points3d.size();
  report.num_observations = r.NumObservations();
  report.mean_track_length = r.MeanTrackLength();
  report.mean_observations_per_image = r.MeanObservationsPerImage();
  report.mean_reprojection_error_px = r.MeanReprojectionError();
  for (const auto& [id, camera] : r.cameras)
    ++report.camera_models[std::string(CameraModelName(camera.model))];

  if (options.lights) {
    const std::filesystem::path& path = *options.lights;
    if (LowerCaseExtension(path) == ".lp") {
      report.lights_kind = ".lp";
      const auto entries = ReadLpFile(path);
      std::set<std::string> model_names;
      for (const auto& [id, image] : r.images) model_names.insert(BaseName(image.name));
      for (const auto& e : entries) {
        if (!model_names.count(BaseName(e.filename))) {
          throw InputError(path.string(), "lights are given for image '" + e.filename +
                                              "', which is not in the COLMAP model");
        }
      }
      report.num_lit_images = entries.size();
      for (const auto& [id, image] : r.images) {
        if (!FindLpEntry(entries, image.name)) report.images_without_lights.push_back(image.name);
      }
    } else {
      report.lights_kind = "object-lights JSON";
      const ObjectLights lights = ReadObjectLightsFile(path);
      const LightsModelMatch match = CheckLightsAgainstModel(lights, r, path.string());
      report.images_without_lights = match.images_without_lights;
      report.lights_without_images = match.lights_without_images;
      report.num_lit_images = lights.size();
    }
  }

  if (options.images_dir) {
    std::error_code ec;
    if (!std::filesystem::is_directory(*options.images_dir, ec)) {
      throw InputError(options.images_dir->string(), "image folder not found");
    }
    report.missing_images.emplace();
    for (const auto& [id, image] : r.images) {
      if (!std::filesystem::is_regular_file(*options.images_dir / image.name, ec)) {
        report.missing_images->push_back(image.name);
      }
    }
  }

  if (options.mesh) {
    mesh::LoadedMesh loaded = mesh::LoadMesh(*options.mesh, options.mesh_clean);
    report.mesh_stats = mesh::ComputeMeshStats(loaded.mesh);
    report.mesh_report = loaded.report;
    const VisibilityResult vis = ComputeVisibility(loaded.mesh, r, options.visibility, progress);
    report.triangles_fully_seen = vis.num_fully_seen;
    report.triangles_partially_seen = vis.num_partially_seen;
    report.triangles_unseen = vis.num_unseen;
    report.visibility_seconds = vis.seconds;
  }
  return report;
}

std::string FormatInspectReport(const InspectReport& rep) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(6);
  if (!rep.model_choice.empty()) out << "Model: " << rep.model_choice << "\n";
  out << "Model format: " << ModelFormatName(rep.format) << "\n";
  for (const auto& f : rep.ignored_files) out << "Ignored (newer COLMAP): " << f.string() << "\n";
  out << "Cameras: " << rep.num_cameras;
  if (!rep.camera_models.empty()) {
    out << " (";
    bool first = true;
    for (const auto& [name, n] : rep.camera_models) {
      out << (first ? "" : ", ") << n << " " << name;
      first = false;
    }
    out << ")";
  }
  out << "\n";
  out << "Images: " << rep.num_images << "\n";
  out << "Registered images: " << rep.num_registered_images << "\n";
  out << "Points: " << rep.num_points3d << "\n";
  out << "Observations: " << rep.num_observations << "\n";
  out << "Mean track length: " << rep.mean_track_length << "\n";
  out << "Mean observations per image: " << rep.mean_observations_per_image << "\n";
  out << "Mean reprojection error: " << rep.mean_reprojection_error_px << "px\n";
  if (rep.mesh_stats) {
    const mesh::MeshStats& s = *rep.mesh_stats;
    out << std::setprecision(4);
    out << "Mesh: " << s.vertices << " vertices, " << s.faces << " faces, " << s.edges << " edges, "
        << s.boundary_edges << " boundary edges, " << s.components << " components\n";
    out << "Mesh surface area: " << s.surface_area << ", mean edge length: " << s.mean_edge_length
        << "\n";
    out << "Mesh bounding box: [" << s.bbox_min.transpose() << "] - [" << s.bbox_max.transpose()
        << "]\n";
    const auto problems = rep.mesh_report->Problems();
    if (problems.empty()) {
      out << "Mesh problems: none\n";
    } else {
      for (const auto& p : problems) out << "Mesh problem: " << p << "\n";
    }
  }
  if (rep.triangles_fully_seen) {
    const std::size_t total =
        *rep.triangles_fully_seen + *rep.triangles_partially_seen + *rep.triangles_unseen;
    auto pct = [&](std::size_t n) { return total ? 100.0 * static_cast<double>(n) / total : 0.0; };
    out << std::setprecision(1);
    out << "Triangles fully seen by >= 1 photo: " << *rep.triangles_fully_seen << " ("
        << pct(*rep.triangles_fully_seen) << "%)\n";
    out << "Triangles fully seen by none: " << *rep.triangles_partially_seen + *rep.triangles_unseen
        << " (partly seen " << *rep.triangles_partially_seen << ", unseen " << *rep.triangles_unseen
        << ")\n";
    out << std::setprecision(3) << "Visibility time: " << rep.visibility_seconds << " s\n";
  }
  if (rep.lights_kind) {
    out << "Lights (" << *rep.lights_kind << "): " << rep.num_lit_images << " images lit, "
        << rep.images_without_lights.size() << " model images without a light, "
        << rep.lights_without_images.size() << " lights for images not in the model\n";
  }
  if (rep.missing_images) {
    out << "Images missing on disk: " << rep.missing_images->size() << "\n";
    for (const auto& name : *rep.missing_images) out << "  missing: " << name << "\n";
  }
  return out.str();
}

std::string InspectReportToJson(const InspectReport& rep) {
  nlohmann::json j;
  j["model_folder"] = rep.model_folder.string();
  j["model_format"] = ModelFormatName(rep.format);
  j["cameras"] = rep.num_cameras;
  j["images"] = rep.num_images;
  j["registered_images"] = rep.num_registered_images;
  j["points"] = rep.num_points3d;
  j["observations"] = rep.num_observations;
  j["mean_track_length"] = rep.mean_track_length;
  j["mean_observations_per_image"] = rep.mean_observations_per_image;
  j["mean_reprojection_error_px"] = rep.mean_reprojection_error_px;
  j["camera_models"] = rep.camera_models;
  if (rep.mesh_stats) {
    j["mesh"] = {{"vertices", rep.mesh_stats->vertices},
                 {"faces", rep.mesh_stats->faces},
                 {"edges", rep.mesh_stats->edges},
                 {"boundary_edges", rep.mesh_stats->boundary_edges},
                 {"components", rep.mesh_stats->components},
                 {"surface_area", rep.mesh_stats->surface_area},
                 {"problems", rep.mesh_report->Problems()}};
  }
  if (rep.triangles_fully_seen) {
    j["visibility"] = {{"fully_seen", *rep.triangles_fully_seen},
                       {"partially_seen", *rep.triangles_partially_seen},
                       {"unseen", *rep.triangles_unseen},
                       {"seconds", rep.visibility_seconds}};
  }
  if (rep.missing_images) j["missing_images"] = *rep.missing_images;
  if (rep.lights_kind) {
    j["lights"] = {{"kind", *rep.lights_kind},
                   {"lit_images", rep.num_lit_images},
                   {"images_without_lights", rep.images_without_lights},
                   {"lights_without_images", rep.lights_without_images}};
  }
  return j.dump(2);
}

}  // namespace texlume::sfm
