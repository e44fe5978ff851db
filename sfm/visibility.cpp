#include "sfm/visibility.h"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "core/errors.h"
#include "core/memory_budget.h"

namespace texlume::sfm {
namespace {

// One photo's z-buffer: nearest camera-frame depth and the face that has it.
struct DepthBuffer {
  int width = 0, height = 0;
  std::vector<float> depth;
  std::vector<std::int32_t> face;

  DepthBuffer(int w, int h)
      : width(w),
        height(h),
        depth(static_cast<std::size_t>(w) * static_cast<std::size_t>(h),
              std::numeric_limits<float>::infinity()),
        face(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), -1) {}
  std::size_t Index(int x, int y) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
           static_cast<std::size_t>(x);
  }
};

// A face projected into the buffer: corners in buffer pixels and their depths.
struct ProjectedFace {
  Eigen::Vector2d p[3];
  double inv_z[3];
};

double Edge(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double x, double y) {
  return (b.x() - a.x()) * (y - a.y()) - (b.y() - a.y()) * (x - a.x());
}

// Calls visit(x, y, depth) for every buffer pixel whose centre lies inside the
// projected face (closed triangle), with the perspective-correct depth there.
template <typename Visit>
void RasteriseFace(const ProjectedFace& t, int width, int height, const Visit& visit) {
  const double area = Edge(t.p[0], t.p[1], t.p[2].x(), t.p[2].y());
  if (!(std::abs(area) > 1e-12)) return;
  const double min_x = std::min({t.p[0].x(), t.p[1].x(), t.p[2].x()});
  const double max_x = std::max({t.p[0].x(), t.p[1].x(), t.p[2].x()});
  const double min_y = std::min({t.p[0].y(), t.p[1].y(), t.p[2].y()});
  const double max_y = std::max({t.p[0].y(), t.p[1].y(), t.p[2].y()});
  const int x0 = std::max(0, static_cast<int>(std::ceil(min_x - 0.5)));
  const int x1 = std::min(width - 1, static_cast<int>(std::floor(max_x - 0.5)));
  const int y0 = std::max(0, static_cast<int>(std::ceil(min_y - 0.5)));
  const int y1 = std::min(height - 1, static_cast<int>(std::floor(max_y - 0.5)));
  const double inv_area = 1.0 / area;
  for (int y = y0; y <= y1; ++y) {
    const double cy = y + 0.5;
    for (int x = x0; x <= x1; ++x) {
      const double cx = x + 0.5;
      const double b0 = Edge(t.p[1], t.p[2], cx, cy) * inv_area;
      const double b1 = Edge(t.p[2], t.p[0], cx, cy) * inv_area;
      const double b2 = 1.0 - b0 - b1;
      if (b0 < 0.0 || b1 < 0.0 || b2 < 0.0) continue;
      const double inv_z = b0 * t.inv_z[0] + b1 * t.inv_z[1] + b2 * t.inv_z[2];
      visit(x, y, 1.0 / inv_z);
    }
  }
}

// Visibility records of one image: (face, view).
struct ImageViews {
  std::vector<std::pair<int, TriangleView>> records;
};

// The z-buffers of `threads` photos at once (depth and face, 8 bytes a pixel), for
// the largest camera, against the memory limit.
void RequireBufferMemory(const Reconstruction& reconstruction, const VisibilityOptions& options,
                         int threads) {
  for (const auto& [id, camera] : reconstruction.cameras) {
    double pixels = static_cast<double>(camera.width) * static_cast<double>(camera.height);
    if (options.max_buffer_dimension > 0) {
      const double scale =
          std::min(1.0, options.max_buffer_dimension /
                            static_cast<double>(std::max(camera.width, camera.height)));
      pixels *= scale * scale;
    }
    RequireMemory(8.0 * pixels * threads,
                  "the visibility depth buffers of camera " + std::to_string(id.value) + " (" +
                      std::to_string(threads) + " at once; --max-buffer-size makes them smaller)",
                  "the COLMAP model");
  }
}

ImageViews ComputeImageViews(const mesh::TriangleMesh& mesh,
                             const std::vector<Eigen::Vector3d>& normals,
                             const std::vector<Eigen::Vector3d>& centroids, const Image& image,
                             const Camera& camera, const VisibilityOptions& options) {
  const double full_w = static_cast<double>(camera.width);
  const double full_h = static_cast<double>(camera.height);
  double scale = 1.0;
  if (options.max_buffer_dimension > 0) {
    scale = std::min(1.0, options.max_buffer_dimension / std::max(full_w, full_h));
  }
  const int bw = std::max(1, static_cast<int>(std::ceil(full_w * scale)));
  const int bh = std::max(1, static_cast<int>(std::ceil(full_h * scale)));

  // Project every vertex once.
  const std::size_t nv = mesh.vertices.size();
  std::vector<Eigen::Vector2d> pixel(nv);
  std::vector<double> depth(nv);
  std::vector<char> valid(nv, 0);
  for (std::size_t v = 0; v < nv; ++v) {
    const Eigen::Vector3d x_cam = image.cam_from_world * mesh.vertices[v];
    depth[v] = x_cam.z();
    if (x_cam.z() <= options.near_depth) continue;
    const auto px = camera.ImageFromCam(x_cam);
    if (!px || !px->allFinite()) continue;
    pixel[v] = *px;
    valid[v] = 1;
  }
  auto project_face = [&](std::size_t f, ProjectedFace& t) {
    for (int k = 0; k < 3; ++k) {
      const auto v = static_cast<std::size_t>(mesh.faces[f][static_cast<std::size_t>(k)]);
      if (!valid[v]) return false;
      t.p[k] = pixel[v] * scale;
      t.inv_z[k] = 1.0 / depth[v];
    }
    return true;
  };

  // Pass 1: z-buffer of all faces, whichever way they face.
  DepthBuffer buffer(bw, bh);
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    ProjectedFace t;
    if (!project_face(f, t)) continue;
    RasteriseFace(t, bw, bh, [&](int x, int y, double z) {
      const std::size_t i = buffer.Index(x, y);
      if (z < buffer.depth[i]) {
        buffer.depth[i] = static_cast<float>(z);
        buffer.face[i] = static_cast<std::int32_t>(f);
      }
    });
  }

  // Pass 2: each front-facing face checks its own footprint against the buffer.
  ImageViews out;
  const Eigen::Vector3d center = image.ProjectionCenter();
  const double keep = 1.0 - options.depth_tolerance_relative;
  auto shows = [&](int x, int y, double z, std::size_t f) {
    const std::size_t i = buffer.Index(x, y);
    return buffer.face[i] == static_cast<std::int32_t>(f) || buffer.depth[i] >= z * keep;
  };
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    const Eigen::Vector3d to_camera = center - centroids[f];
    const double distance = to_camera.norm();
    if (!(distance > 0.0)) continue;
    const double cos_angle = normals[f].dot(to_camera) / distance;
    if (!(cos_angle > 0.0)) continue;  // back-facing (or degenerate)
    ProjectedFace t;
    if (!project_face(f, t)) continue;
    // Whole triangle inside the image: corners and points along each edge,
    // each projected with the lens distortion.
    bool inside = true;
    for (int k = 0; k < 3 && inside; ++k) {
      const Eigen::Vector3d& a = mesh.Corner(f, k);
      const Eigen::Vector3d& b = mesh.Corner(f, (k + 1) % 3);
      for (int s = 0; s <= options.edge_samples && inside; ++s) {
        const double u = static_cast<double>(s) / (options.edge_samples + 1);
        const auto px = camera.ImageFromCam(image.cam_from_world * ((1.0 - u) * a + u * b));
        inside = px.has_value() && camera.IsInImage(*px);
      }
    }
    std::size_t total = 0, seen = 0;
    RasteriseFace(t, bw, bh, [&](int x, int y, double z) {
      ++total;
      seen += shows(x, y, z, f) ? 1 : 0;
    });
    const double area_buffer_px = 0.5 * std::abs(Edge(t.p[0], t.p[1], t.p[2].x(), t.p[2].y()));
    double fraction;
    if (total == 0) {
      // Smaller than a buffer pixel: test the centroid and corners instead.
      const double z_c = 3.0 / (t.inv_z[0] + t.inv_z[1] + t.inv_z[2]);
      const Eigen::Vector2d pts[4] = {(t.p[0] + t.p[1] + t.p[2]) / 3.0, t.p[0], t.p[1], t.p[2]};
      const double zs[4] = {z_c, 1.0 / t.inv_z[0], 1.0 / t.inv_z[1], 1.0 / t.inv_z[2]};
      for (int k = 0; k < 4; ++k) {
        const int x = static_cast<int>(std::floor(pts[k].x()));
        const int y = static_cast<int>(std::floor(pts[k].y()));
        ++total;
        if (x >= 0 && y >= 0 && x < bw && y < bh && shows(x, y, zs[k], f)) ++seen;
      }
      fraction = static_cast<double>(seen) / static_cast<double>(total);
    } else {
      fraction = std::min(
          1.0, static_cast<double>(seen) / std::max(static_cast<double>(total), area_buffer_px));
      if (inside && seen == total) fraction = 1.0;
    }
    if (seen == 0) continue;
    TriangleView view;
    view.image_id = image.image_id;
    view.fully_visible = inside && seen == total;
    view.visible_fraction = static_cast<float>(fraction);
    view.projected_area_px = static_cast<float>(area_buffer_px / (scale * scale));
    view.angle_rad = static_cast<float>(std::acos(std::clamp(cos_angle, -1.0, 1.0)));
    out.records.emplace_back(static_cast<int>(f), view);
  }
  return out;
}

}  // namespace

void VisibilityOptions::Check() const {
  if (max_buffer_dimension != 0 && max_buffer_dimension < 16) {
    throw OptionError("max_buffer_dimension must be 0 (full resolution) or >= 16");
  }
  if (!(depth_tolerance_relative > 0.0 && depth_tolerance_relative <= 0.1)) {
    throw OptionError("depth_tolerance_relative must be in (0, 0.1]");
  }
  if (edge_samples < 0 || edge_samples > 64) throw OptionError("edge_samples must be in [0, 64]");
  if (!(near_depth > 0.0)) throw OptionError("near_depth must be positive");
}

std::vector<ImageId> TriangleVisibility::FullyVisibleViews() const {
  std::vector<ImageId> ids;
  for (const auto& v : views) {
    if (v.fully_visible) ids.push_back(v.image_id);
  }
  return ids;
}

VisibilityResult ComputeVisibility(const mesh::TriangleMesh& mesh,
                                   const Reconstruction& reconstruction,
                                   const VisibilityOptions& options,
                                   const ProgressCallback& progress) {
  options.Check();
  const auto start = std::chrono::steady_clock::now();
  const std::vector<Eigen::Vector3d> normals = mesh::FaceNormals(mesh);
  std::vector<Eigen::Vector3d> centroids(mesh.faces.size());
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    centroids[f] = (mesh.Corner(f, 0) + mesh.Corner(f, 1) + mesh.Corner(f, 2)) / 3.0;
  }

  std::vector<const Image*> images;
  for (const auto& [id, image] : reconstruction.images) images.push_back(&image);
  const int n_images = static_cast<int>(images.size());

  VisibilityResult result;
  result.triangles.resize(mesh.faces.size());
  std::size_t done = 0;
  if (progress) progress("visibility", 0, images.size());
  // Images are processed in chunks of one per thread; each chunk's records are
  // merged in image order, so the result does not depend on the thread count.
  const int chunk = std::max(1, omp_get_max_threads());
  RequireBufferMemory(reconstruction, options, chunk);
  for (int first = 0; first < n_images; first += chunk) {
    const int last = std::min(n_images, first + chunk);
    std::vector<ImageViews> views(static_cast<std::size_t>(last - first));
#pragma omp parallel for schedule(dynamic, 1)
    for (int i = first; i < last; ++i) {
      const Image& image = *images[static_cast<std::size_t>(i)];
      views[static_cast<std::size_t>(i - first)] = ComputeImageViews(
          mesh, normals, centroids, image, reconstruction.cameras.at(image.camera_id), options);
    }
    for (auto& v : views) {
      for (auto& [f, view] : v.records)
        result.triangles[static_cast<std::size_t>(f)].views.push_back(view);
      v.records.clear();
      v.records.shrink_to_fit();
    }
    done = static_cast<std::size_t>(last);
    if (progress) progress("visibility", done, images.size());
  }

  for (TriangleVisibility& tri : result.triangles) {
    const TriangleView* best = nullptr;
    for (const TriangleView& v : tri.views) {
      if (v.fully_visible && (!best || v.angle_rad < best->angle_rad)) best = &v;
    }
    if (best) {
      tri.best_view = best->image_id;
      tri.best_view_source = BestViewSource::kFullyVisible;
      ++result.num_fully_seen;
      continue;
    }
    for (const TriangleView& v : tri.views) {
      if (!best || v.visible_fraction > best->visible_fraction ||
          (v.visible_fraction == best->visible_fraction && v.angle_rad < best->angle_rad)) {
        best = &v;
      }
    }
    if (best) {
      tri.best_view = best->image_id;
      tri.best_view_source = BestViewSource::kPartiallyVisible;
      ++result.num_partially_seen;
    } else {
      ++result.num_unseen;
    }
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace texlume::sfm
