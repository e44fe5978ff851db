#pragma once

#include <cstdint>

namespace texlume::datasets {

/// Deterministic 2D lattice noise with optional periodicity, the building block
/// of the procedural materials. Coordinates are in lattice cells; a period of n
/// cells (n > 0) makes the function repeat every n cells along that axis, so a
/// material wraps seamlessly around a cylinder, sphere or torus. Period 0 = none.
struct Lattice {
  std::uint32_t seed = 0;
  std::int64_t period_x = 0;  ///< cells, 0 = not periodic
  std::int64_t period_y = 0;  ///< cells, 0 = not periodic

  /// Uniform hash of an integer lattice point (wrapped by the periods) in [0, 1).
  double Hash(std::int64_t ix, std::int64_t iy, std::uint32_t channel = 0) const;
  /// Value noise in [-1, 1], C1-smooth (quintic interpolation of lattice values).
  double ValueNoise(double x, double y) const;
};

/// Fractal sum of `octaves` value-noise layers, each of double frequency and half
/// amplitude, normalised to about [-1, 1]. Periods double with the frequency.
double FractalNoise(const Lattice& lattice, double x, double y, int octaves);

/// Worley (cellular) noise: one jittered feature point per cell.
struct CellularSample {
  double f1 = 0.0;          ///< distance to the nearest feature point, cells
  double f2 = 0.0;          ///< distance to the second nearest, cells
  double cell_random = 0;   ///< a uniform value in [0, 1) attached to the nearest cell
  double cell_random2 = 0;  ///< another one, independent of the first
};
CellularSample Cellular(const Lattice& lattice, double x, double y);

}  // namespace texlume::datasets
