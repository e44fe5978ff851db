#pragma once

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <vector>

#include "core/progress.h"

namespace texlume::ptm {

/// Hemispherical harmonics (Gautron, Křivánek, Pattanaik and Bouatouch 2004), the RTI
/// basis of RTIBuilder's and relight's HSH fits, RTIViewer's `.rti` files and OpenLIME:
/// functions of the light's polar angle theta (from the normal) and azimuth phi in the
/// texel frame, orthonormal over the upper hemisphere. Order 2 has 4 terms, order 3 9.
inline constexpr int kHshMinOrder = 2;
inline constexpr int kHshMaxOrder = 3;
inline int HshTerms(int order) { return order * order; }

/// The 9 basis functions of order 3 at a unit light direction (texel frame, z up;
/// below the horizon evaluated at it). Lower orders take the first HshTerms(order).
std::array<double, 9> HshBasis(const Eigen::Vector3d& light);

/// An HSH texture: per texel and colour channel, HshTerms(order) coefficients of the
/// display-domain values (as PTMs hold them), row 0 at the top.
struct Hsh {
  int order = 3;
  int width = 0, height = 0;
  /// Texel-major: for texel t, R's terms, then G's, then B's.
  std::vector<float> coefficients;

  int Terms() const { return HshTerms(order); }
  std::size_t NumTexels() const { return static_cast<std::size_t>(width) * height; }
  const float* At(std::size_t texel, int channel) const {
    return coefficients.data() + (texel * 3 + static_cast<std::size_t>(channel)) * Terms();
  }
  float* At(std::size_t texel, int channel) {
    return coefficients.data() + (texel * 3 + static_cast<std::size_t>(channel)) * Terms();
  }
};

struct HshFitResult {
  Hsh hsh;
  double mean_residual_rms = 0;  ///< per texel and channel, display units of [0, 1]
  double seconds = 0;
};

/// Least-squares HSH fit of an RTI capture, streamed by bands of `band_rows` rows (in
/// parallel over the texels). The light set is refused (InputError) with fewer lights
/// than terms, a light that is not a unit vector or is at or below the horizon, or a
/// normal matrix of the basis with a condition number over 1e7
/// (ptm::CheckLightsForBasis, as for PTMs with at least 6 lights).
HshFitResult FitHshFromFiles(const std::vector<std::filesystem::path>& files,
                             const std::vector<Eigen::Vector3d>& lights, int order, int band_rows,
                             const ProgressCallback& progress = {});

/// The texture relit under a unit light (texel frame), RGB display values clamped to
/// [0, 1]. As texlume evaluates PTMs (ptm::Effective), a light below
/// kHorizonElevationDeg is evaluated at that elevation (same azimuth) and faded by
/// l_z / sin(kHorizonElevationDeg).
std::vector<float> RelightHsh(const Hsh& hsh, const Eigen::Vector3d& light);

/// RTIViewer's universal `.rti` (HSH): the header lines `#HSH1.2`, `3` (HSH), `W H 3`,
/// `TERMS 2 1`, then float32 scale and bias per term (value = byte / 255 * scale +
/// bias), then per texel, rows bottom to top, R's terms, G's, B's as bytes.
void WriteRtiFile(const Hsh& hsh, const std::filesystem::path& path);

/// The relight / OpenLIME web format of an HSH: info.json (type "hsh", colorspace
/// "rgb", 3 x terms planes: plane 3j + c is term j of channel c) and the planes as
/// JPEGs of three. Returns the number of files written.
int WriteHshRelightWeb(const Hsh& hsh, const std::filesystem::path& dir, int jpeg_quality = 95);

}  // namespace texlume::ptm
