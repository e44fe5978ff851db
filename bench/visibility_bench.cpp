// Visibility on a ~100k-triangle mesh seen by 50 photos of 1 megapixel (issue 2).
// Run: build/bench/visibility_bench
// The full-resolution run is the figure asked for; the 512-pixel buffer run is a
// baseline in the same process, so the ratio between them is what to compare
// across machines.
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>

#include "datasets_synthetic/object_scene.h"
#include "sfm/visibility.h"

namespace {

using namespace texlume;

struct Scene {
  mesh::TriangleMesh mesh;
  sfm::Reconstruction reconstruction;
};

const Scene& BenchScene() {
  static const Scene scene = [] {
    Scene s;
    // Icosphere (81,920 faces) and a column in front of it (20,480 faces): 102,400.
    s.mesh = datasets::MakeIcosphere(6, 1.0);
    const mesh::TriangleMesh column = datasets::MakeCylinder(160, 64, 0.25, 2.5);
    const int offset = static_cast<int>(s.mesh.NumVertices());
    for (const auto& v : column.vertices) s.mesh.vertices.push_back(v + Eigen::Vector3d(1.6, 0, 0));
    for (const auto& f : column.faces) {
      s.mesh.faces.push_back({f[0] + offset, f[1] + offset, f[2] + offset});
    }
    sfm::Camera camera;
    camera.camera_id = sfm::CameraId(1);
    camera.model = sfm::CameraModelId::kOpenCV;
    camera.width = 1152;
    camera.height = 864;  // 0.995 MP
    camera.params = {1000, 1000, 576, 432, -0.05, 0.01, 0.0, 0.0};
    s.reconstruction.cameras[camera.camera_id] = camera;
    for (int i = 0; i < 50; ++i) {
      const double azimuth = 2 * std::numbers::pi * i / 50.0;
      const double elevation = (i % 3 - 1) * 0.4;
      sfm::Image image;
      image.image_id = sfm::ImageId(static_cast<std::uint32_t>(i + 1));
      image.camera_id = camera.camera_id;
      image.name = "img" + std::to_string(i) + ".jpg";
      image.cam_from_world = datasets::LookAt(
          4.0 * Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                                std::cos(elevation) * std::sin(azimuth), std::sin(elevation)),
          Eigen::Vector3d::Zero());
      s.reconstruction.images[image.image_id] = image;
    }
    return s;
  }();
  return scene;
}

void BM_Visibility(benchmark::State& state) {
  const Scene& scene = BenchScene();
  sfm::VisibilityOptions options;
  options.max_buffer_dimension = static_cast<int>(state.range(0));
  std::size_t fully_seen = 0;
  for (auto _ : state) {
    const auto result = sfm::ComputeVisibility(scene.mesh, scene.reconstruction, options);
    fully_seen = result.num_fully_seen;
    benchmark::DoNotOptimize(result.triangles.data());
  }
  state.counters["triangles"] = static_cast<double>(scene.mesh.NumFaces());
  state.counters["images"] = static_cast<double>(scene.reconstruction.images.size());
  state.counters["fully_seen"] = static_cast<double>(fully_seen);
}
// 0 = full resolution (1152 x 864); 512 = baseline with downscaled buffers.
BENCHMARK(BM_Visibility)->Arg(0)->Arg(512)->Unit(benchmark::kMillisecond)->Iterations(2);

}  // namespace

BENCHMARK_MAIN();
