// Mesh reading and repair on a fan of n triangles around one vertex (issue 30:
// 80,000 took 49 s when duplicate faces were searched among the faces of their
// smallest vertex), against a grid of as many triangles, read and repaired in
// the same process: the ratio fan / grid is the figure to compare across machines
// (1 when repair is linear whatever the mesh's shape).
// Run: build/bench/mesh_repair_bench
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include "mesh/mesh.h"

namespace {

using namespace texlume;
namespace fs = std::filesystem;

// An OBJ of a fan of n triangles around vertex 1, on the unit circle.
fs::path FanObj(int n) {
  const fs::path path = fs::temp_directory_path() / ("texlume_fan_" + std::to_string(n) + ".obj");
  std::ofstream out(path);
  out << "v 0 0 0\n";
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * std::numbers::pi * i / n;
    out << "v " << std::cos(a) << " " << std::sin(a) << " 0\n";
  }
  for (int i = 0; i < n; ++i) out << "f 1 " << 2 + i << " " << 2 + (i + 1) % n << "\n";
  return path;
}

// An OBJ of a square grid cut into n triangles (n even).
fs::path GridObj(int n) {
  const fs::path path = fs::temp_directory_path() / ("texlume_grid_" + std::to_string(n) + ".obj");
  const int side = static_cast<int>(std::ceil(std::sqrt(n / 2.0)));
  std::ofstream out(path);
  for (int y = 0; y <= side; ++y)
    for (int x = 0; x <= side; ++x) out << "v " << x << " " << y << " 0\n";
  int written = 0;
  for (int y = 0; y < side && written < n; ++y)
    for (int x = 0; x < side && written < n; ++x, written += 2) {
      const int a = 1 + y * (side + 1) + x, b = a + 1, c = a + side + 1, d = c + 1;
      out << "f " << a << " " << b << " " << d << "\nf " << a << " " << d << " " << c << "\n";
    }
  return path;
}

void BM_LoadFan(benchmark::State& state) {
  const fs::path path = FanObj(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(mesh::LoadMesh(path));
  fs::remove(path);
}

void BM_LoadGrid(benchmark::State& state) {
  const fs::path path = GridObj(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(mesh::LoadMesh(path));
  fs::remove(path);
}

BENCHMARK(BM_LoadFan)->Arg(20000)->Arg(80000)->Arg(320000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LoadGrid)->Arg(20000)->Arg(80000)->Arg(320000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
