#include "datasets_synthetic/noise.h"

#include <cmath>

namespace texlume::datasets {
namespace {

std::uint64_t Mix(std::uint64_t z) {
  // splitmix64 finaliser
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

std::int64_t Wrap(std::int64_t i, std::int64_t period) {
  if (period <= 0) return i;
  const std::int64_t m = i % period;
  return m < 0 ? m + period : m;
}

double Quintic(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

}  // namespace

double Lattice::Hash(std::int64_t ix, std::int64_t iy, std::uint32_t channel) const {
  const auto x = static_cast<std::uint64_t>(Wrap(ix, period_x));
  const auto y = static_cast<std::uint64_t>(Wrap(iy, period_y));
  const std::uint64_t h =
      Mix(Mix(Mix(seed * 0x100000001b3ull + channel) ^ x) ^ (y * 0x9e3779b1ull));
  return static_cast<double>(h >> 11) * (1.0 / 9007199254740992.0);
}

double Lattice::ValueNoise(double x, double y) const {
  const double fx = std::floor(x), fy = std::floor(y);
  const auto ix = static_cast<std::int64_t>(fx), iy = static_cast<std::int64_t>(fy);
  const double tx = Quintic(x - fx), ty = Quintic(y - fy);
  const double v00 = Hash(ix, iy), v10 = Hash(ix + 1, iy);
  const double v01 = Hash(ix, iy + 1), v11 = Hash(ix + 1, iy + 1);
  const double a = v00 + (v10 - v00) * tx;
  const double b = v01 + (v11 - v01) * tx;
  return 2.0 * (a + (b - a) * ty) - 1.0;
}

double FractalNoise(const Lattice& lattice, double x, double y, int octaves) {
  double sum = 0.0, amplitude = 1.0, norm = 0.0;
  Lattice layer = lattice;
  for (int o = 0; o < octaves; ++o) {
    layer.seed = lattice.seed + 1013u * static_cast<std::uint32_t>(o);
    sum += amplitude * layer.ValueNoise(x, y);
    norm += amplitude;
    amplitude *= 0.5;
    x *= 2.0;
    y *= 2.0;
    layer.period_x *= 2;
    layer.period_y *= 2;
  }
  return sum / norm;
}

CellularSample Cellular(const Lattice& lattice, double x, double y) {
  const auto ix = static_cast<std::int64_t>(std::floor(x));
  const auto iy = static_cast<std::int64_t>(std::floor(y));
  CellularSample s;
  s.f1 = s.f2 = 1e9;
  for (std::int64_t dy = -1; dy <= 1; ++dy) {
    for (std::int64_t dx = -1; dx <= 1; ++dx) {
      const std::int64_t cx = ix + dx, cy = iy + dy;
      const double px = static_cast<double>(cx) + 0.1 + 0.8 * lattice.Hash(cx, cy, 1);
      const double py = static_cast<double>(cy) + 0.1 + 0.8 * lattice.Hash(cx, cy, 2);
      const double d = std::hypot(px - x, py - y);
      if (d < s.f1) {
        s.f2 = s.f1;
        s.f1 = d;
        s.cell_random = lattice.Hash(cx, cy, 3);
        s.cell_random2 = lattice.Hash(cx, cy, 4);
      } else if (d < s.f2) {
        s.f2 = d;
      }
    }
  }
  return s;
}

}  // namespace texlume::datasets
