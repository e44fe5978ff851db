// One 640 x 480 photo of the displaced stone sphere (issue 3: aim about a second or
// less on 2 cores). Run: build/bench/render_bench
// Baseline in the same process: primary rays only (1 sample per pixel, no shadows),
// so the ratio shows what supersampling and shadow rays cost.
#include <benchmark/benchmark.h>

#include <memory>

#include "datasets_synthetic/object_scene.h"
#include "datasets_synthetic/renderer.h"

namespace {

using namespace texlume::datasets;

struct Fixture {
  std::vector<std::unique_ptr<BakedMaterial>> materials;
  std::unique_ptr<Renderer> renderer;
  ObjectScene scene;
};

const Fixture& SphereScene() {
  static const Fixture* fixture = [] {
    auto* f = new Fixture;
    MaterialOptions options;  // stone, texel 0.002
    const auto patches = ShapePatches(SceneShape::kSphere);
    std::vector<const BakedMaterial*> pointers;
    for (const auto& p : patches) {
      const Material m(options, p.periodic_u ? p.u1 - p.u0 : 0.0, p.periodic_v ? p.v1 - p.v0 : 0.0);
      f->materials.push_back(std::make_unique<BakedMaterial>(
          m, p.u0, p.u1, p.v0, p.v1, p.periodic_u, p.periodic_v, options.texel_size));
      pointers.push_back(f->materials.back().get());
    }
    f->renderer = std::make_unique<Renderer>(
        DisplacePatches(patches, pointers, 2 * options.texel_size), pointers);
    ObjectSceneOptions o;
    o.num_points = 0;
    f->scene = MakeObjectScene(o);
    return f;
  }();
  return *fixture;
}

void BM_RenderPhoto(benchmark::State& state) {
  const Fixture& f = SphereScene();
  const auto& [id, image] = *f.scene.reconstruction.images.begin();
  const auto& camera = f.scene.reconstruction.cameras.begin()->second;
  ShadingOptions shading;
  shading.samples_per_axis = static_cast<int>(state.range(0));
  shading.shadows = state.range(1) != 0;
  const std::vector<RenderLight> lights = {{Eigen::Vector3d(0.5, 0.3, 0.8).normalized(), 0.6},
                                           {Eigen::Vector3d(0.9, -0.2, 0.4).normalized(), 0.4}};
  for (auto _ : state) {
    const Rendering r =
        f.renderer->RenderPerspective(camera, image.cam_from_world, lights, shading);
    benchmark::DoNotOptimize(r.linear_rgb.data);
  }
  state.counters["triangles"] = static_cast<double>(f.renderer->NumTriangles());
}
// Args: samples per axis, shadows. {2, 1} is what `texlume scene` renders.
BENCHMARK(BM_RenderPhoto)->Args({1, 0})->Args({2, 1})->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
