// How much light a horizon map's shadows take: for lights at a few elevations, the
// mean light factor (SelfShadowing::LightFactor) over the map's texels and 16
// azimuths. Compares a sample's horizon (texlume fit --horizon) with a model's
// atlas horizons (texlume synth --sample-horizon): given the atlas's PTM, only the
// texels a chart covers (any coefficient not 0) count.
// Usage: horizon_stats HORIZON.exr [PTM.exr]
#include <cmath>
#include <cstdio>
#include <exception>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "ptm/horizon.h"
#include "ptm/ptm_io.h"

namespace {

// Per texel, whether it counts: every texel, or those a chart of `ptm` covers.
std::vector<char> CountedTexels(const texlume::ptm::SelfShadowing& s, const char* ptm_path) {
  if (!ptm_path) return std::vector<char>(s.horizon.NumTexels(), 1);
  const texlume::ptm::Ptm ptm = texlume::ptm::ReadPtmExr(ptm_path);
  if (ptm.width != s.horizon.width || ptm.height != s.horizon.height)
    throw std::runtime_error(std::string(ptm_path) + " is not the horizon map's size");
  return texlume::ptm::CoveredTexels(ptm);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2 && argc != 3) {
    std::fprintf(stderr, "usage: %s HORIZON.exr [PTM.exr]\n", argv[0]);
    return 2;
  }
  try {
    using namespace texlume::ptm;
    const SelfShadowing s = ReadSelfShadowingExr(argv[1]);
    const std::vector<char> counted = CountedTexels(s, argc == 3 ? argv[2] : nullptr);
    std::size_t texels = 0;
    for (const char c : counted) texels += c ? 1 : 0;
    std::printf("%s: %d x %d, %zu texels counted, height scale %.3f, floor %.3f\n", argv[1],
                s.horizon.width, s.horizon.height, texels, s.height_scale, s.shadow_floor);
    std::printf("| elevation deg | mean light factor | share in shadow |\n|---|---|---|\n");
    for (const double elevation_deg : {5.0, 10.0, 15.0, 20.0, 30.0, 45.0, 60.0}) {
      const double e = elevation_deg * std::numbers::pi / 180.0;
      double factor = 0.0, shadowed = 0.0;
      for (int a = 0; a < 16; ++a) {
        const double phi = 2.0 * std::numbers::pi * (a + 0.5) / 16.0;
        const Eigen::Vector3d l(std::cos(e) * std::cos(phi), std::cos(e) * std::sin(phi),
                                std::sin(e));
        for (std::size_t t = 0; t < counted.size(); ++t) {
          if (!counted[t]) continue;
          factor += s.LightFactor(t, l);
          shadowed += HorizonVisibility(s.horizon, t, l, s.penumbra_rad) < 0.5 ? 1.0 : 0.0;
        }
      }
      const double n = 16.0 * static_cast<double>(texels);
      std::printf("| %.0f | %.4f | %.4f |\n", elevation_deg, factor / n, shadowed / n);
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "horizon_stats: %s\n", e.what());
    return 1;
  }
}
