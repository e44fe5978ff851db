// Atlas layout alone (issue 6): the coarse meshes of the synthetic shapes at the
// default material's texel size (split 1-to-4 once, at 4 times the resolution,
// vertex-jittered, and decimated from a fine mesh), laid out in charts and in
// per-triangle boxes, without synthesis.
// Run: build/bench/atlas_bench [--gutter G] [--chart-size N] [--max-stretch S]
//      (rigid, conformal, strips, boxes); ATLAS_BENCH_ONLY=dense|jittered|decimated
// ATLAS_BENCH_DUMP=DIR writes each atlas's coverage (inside, gutter) as a PNG at
// quarter size, or full size with ATLAS_BENCH_DUMP_FULL=1.
// ATLAS_BENCH_MONUMENT=N lays out only bench/monument_bench.sh's column of about N
// faces (texlume scene --kind cylinder --mesh-faces N) at its texel size, 0.001,
// with the main job's default atlas settings (issue 33: layout at monument scale).
// Prints per mesh and mode: occupancy (texels inside triangles / atlas texels),
// charts, atlases, layout seconds, and the charts' texel stretch (area-weighted
// mean and extremes of the per-face singular values of texels per texel size).
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Tools/Decimater/DecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "atlas/atlas.h"
#include "datasets_synthetic/material.h"
#include "datasets_synthetic/shapes.h"
#include "pipeline/synth_job.h"
#include "synth/mesh_synthesis.h"

using namespace texlume;

namespace {
cv::Mat Thumbnail(const cv::Mat& coverage) {
  if (std::getenv("ATLAS_BENCH_DUMP_FULL")) return coverage;
  cv::Mat small;
  cv::resize(coverage, small, cv::Size(), 0.25, 0.25, cv::INTER_AREA);
  return small;
}
mesh::TriangleMesh Jittered(mesh::TriangleMesh mesh) {
  double edge = 0;
  for (std::size_t f = 0; f < mesh.faces.size(); ++f)
    edge += (mesh.Corner(f, 1) - mesh.Corner(f, 0)).norm();
  edge /= static_cast<double>(std::max<std::size_t>(1, mesh.faces.size()));
  std::vector<Eigen::Vector3d> normal(mesh.vertices.size(), Eigen::Vector3d::Zero());
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    const Eigen::Vector3d n =
        (mesh.Corner(f, 1) - mesh.Corner(f, 0)).cross(mesh.Corner(f, 2) - mesh.Corner(f, 0));
    for (const int v : mesh.faces[f]) normal[static_cast<std::size_t>(v)] += n;
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    const Eigen::Vector3d n = normal[v].normalized();
    // Drawn one at a time, last first: a call's arguments are evaluated in an
    // unspecified order (GCC right to left, clang left to right).
    const double dz = u(rng), dy = u(rng), dx = u(rng);
    Eigen::Vector3d d(dx, dy, dz);
    d -= d.dot(n) * n;  // along the surface
    mesh.vertices[v] += (edge / 3.0) * d;
  }
  return mesh;
}
/// A fine mesh of the shape decimated by quadric edge collapses (OpenMesh) to
/// `num_faces`: irregular triangles of varying size and valence, as a
/// photogrammetry mesh decimated for texturing has.
mesh::TriangleMesh Decimated(const mesh::TriangleMesh& fine, std::size_t num_faces) {
  struct Traits : OpenMesh::DefaultTraits {
    using Point = OpenMesh::Vec3d;
  };
  using OmMesh = OpenMesh::TriMesh_ArrayKernelT<Traits>;
  OmMesh om;
  std::vector<OmMesh::VertexHandle> handles;
  for (const Eigen::Vector3d& v : fine.vertices)
    handles.push_back(om.add_vertex(OmMesh::Point(v.x(), v.y(), v.z())));
  for (const auto& f : fine.faces)
    om.add_face(handles[static_cast<std::size_t>(f[0])], handles[static_cast<std::size_t>(f[1])],
                handles[static_cast<std::size_t>(f[2])]);
  OpenMesh::Decimater::DecimaterT<OmMesh> decimater(om);
  OpenMesh::Decimater::ModQuadricT<OmMesh>::Handle quadric;
  decimater.add(quadric);
  decimater.initialize();
  decimater.decimate_to_faces(0, num_faces);
  om.garbage_collection();
  mesh::TriangleMesh mesh;
  for (const auto& vh : om.vertices()) {
    const auto& p = om.point(vh);
    mesh.vertices.emplace_back(p[0], p[1], p[2]);
  }
  for (const auto& fh : om.faces()) {
    std::array<int, 3> f{};
    int k = 0;
    for (const auto& vh : om.fv_range(fh)) f[static_cast<std::size_t>(k++)] = vh.idx();
    mesh.faces.push_back(f);
  }
  return mesh;
}

/// The shape at 2^`doublings` times the coarse mesh's resolution along each
/// direction (icosphere 3, cylinder 48 x 12, torus 48 x 20), on the surface.
mesh::TriangleMesh FinerMesh(datasets::SceneShape shape, int doublings) {
  const int k = 1 << doublings;
  switch (shape) {
    case datasets::SceneShape::kSphere:
      return datasets::MakeIcosphere(3 + doublings, 1.0);
    case datasets::SceneShape::kCylinder:
      return datasets::MakeCylinder(48 * k, 12 * k, 0.6, 1.6);
    default:
      return datasets::MakeTorus(48 * k, 20 * k, 0.8, 0.35);
  }
}
}  // namespace

// The monument column's layout with the job's default settings: seconds and atlases.
int LayOutMonumentColumn(std::int64_t faces) {
  const double texel_size = 0.001;
  const mesh::TriangleMesh column =
      datasets::ShapeMeshWithFaces(datasets::SceneShape::kCylinder, faces);
  const synth::PatchGeometry geometry = synth::MakePatchGeometry(
      column, texel_size, 8, synth::TangentFrame::kFirstEdge, Eigen::Vector3d::UnitZ());
  const auto t0 = std::chrono::steady_clock::now();
  const atlas::AtlasLayout layout =
      atlas::LayoutAtlases(column, geometry.patches, geometry.unfoldings, texel_size, {});
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("column %zu faces: layout %.2f s, %d charts, %zu atlases\n", column.faces.size(),
              seconds, layout.num_charts, layout.atlas_sizes.size());
  return 0;
}

int main(int argc, char** argv) {
  if (const char* monument = std::getenv("ATLAS_BENCH_MONUMENT"))
    return LayOutMonumentColumn(std::atoll(monument));
  atlas::AtlasOptions charts;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--gutter")) charts.gutter = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--chart-size")) charts.max_chart_size = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--max-stretch")) charts.max_chart_stretch = std::atof(argv[i + 1]);
  }
  atlas::AtlasOptions boxes = charts, conformal = charts, strips = charts;
  charts.flattening = atlas::ChartFlattening::kRigid;
  boxes.mode = atlas::AtlasMode::kPerTriangle;
  conformal.flattening = atlas::ChartFlattening::kConformal;
  strips.flattening = atlas::ChartFlattening::kStrips;
  // Strips are as long as an atlas row allows, whatever --chart-size says.
  strips.max_chart_size = 0;
  const double texel_size = datasets::MaterialOptions{}.texel_size;
  for (const datasets::SceneShape shape :
       {datasets::SceneShape::kSphere, datasets::SceneShape::kCylinder,
        datasets::SceneShape::kTorus}) {
    // The coarse mesh, split 1-to-4, and the coarse mesh with every vertex moved
    // along the surface by up to a third of the mean edge (irregular triangles,
    // as decimated photogrammetry meshes have), normals kept.
    const mesh::TriangleMesh coarse = datasets::CoarseMesh(shape);
    std::vector<std::pair<std::string, mesh::TriangleMesh>> meshes = {
        {"", coarse},
        {"", mesh::SubdivideMidpoint(coarse)},
        {" dense", FinerMesh(shape, 2)},  // 16 times the triangles
        {" jittered", Jittered(coarse)},
        {" decimated", Decimated(FinerMesh(shape, 3), coarse.faces.size())}};
    if (const char* only = std::getenv("ATLAS_BENCH_ONLY"))
      std::erase_if(meshes, [&](const auto& m) { return m.first != std::string(" ") + only; });
    for (const auto& [label, mesh] : meshes) {
      const synth::PatchGeometry geometry = synth::MakePatchGeometry(
          mesh, texel_size, 8, synth::TangentFrame::kFirstEdge, Eigen::Vector3d::UnitZ());
      for (const atlas::AtlasOptions& options : {charts, conformal, strips, boxes}) {
        const auto t0 = std::chrono::steady_clock::now();
        const atlas::AtlasLayout layout =
            atlas::LayoutAtlases(mesh, geometry.patches, geometry.unfoldings, texel_size, options);
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const atlas::AtlasCoverage coverage = atlas::VisitAtlasTexels(
            layout, texel_size, options.gutter, [](int, int, int, int, const Eigen::Vector2d&) {});
        if (const char* dump = std::getenv("ATLAS_BENCH_DUMP"))
          for (std::size_t a = 0; a < coverage.coverage.size(); ++a)
            cv::imwrite(std::string(dump) + "/" + std::string(datasets::SceneShapeName(shape)) +
                            std::to_string(mesh.faces.size()) +
                            (label.empty() ? "" : label.substr(1)) + "_" +
                            (options.mode == atlas::AtlasMode::kPerTriangle
                                 ? std::string("boxes")
                                 : std::string(atlas::ChartFlatteningName(options.flattening))) +
                            std::to_string(a) + ".png",
                        Thumbnail(coverage.coverage[a]));
        double texels = 0, written = 0;
        for (const cv::Mat& c : coverage.coverage) written += cv::countNonZero(c);
        for (const cv::Size& s : layout.atlas_sizes) texels += static_cast<double>(s.area());
        const atlas::AtlasStretch stretch = atlas::MeasureStretch(geometry.patches, layout);
        std::printf(
            "%-17s %6zu faces %-12s occupancy %.3f  charts %4d  atlases %zu (last %dx%d)  "
            "%.2f s  inside/outline %.3f  packing %.3f  stretch mean %.3f  min %.3f  max %.3f\n",
            (std::string(datasets::SceneShapeName(shape)) + label).c_str(), mesh.faces.size(),
            options.mode == atlas::AtlasMode::kPerTriangle
                ? "per-triangle"
                : atlas::ChartFlatteningName(options.flattening),
            static_cast<double>(coverage.inside_texels) / texels, layout.num_charts,
            layout.atlas_sizes.size(), layout.atlas_sizes.back().width,
            layout.atlas_sizes.back().height, seconds,
            static_cast<double>(coverage.inside_texels) / written, written / texels, stretch.mean,
            stretch.min, stretch.max);
        std::fflush(stdout);
      }
    }
  }
  return 0;
}
