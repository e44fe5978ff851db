#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "core/zeroed_allocator.h"
#include "ptm/light_response.h"

namespace texlume::ptm {

/// The two PTM layouts of paper 003 §2.1 (Malzbender et al.).
enum class PtmFormat {
  kLrgb,  ///< one luminance polynomial (eq. 1) per texel and a normalised colour (eq. 2)
  kRgb,   ///< one polynomial per colour channel
};

/// A Polynomial Texture Map, float planes, row 0 at the top (image order).
///
/// Intensity space: values are in the display domain of the photos they were
/// fitted to (sRGB-encoded, scaled to [0, 1]), as RTI tools fit and show them;
/// `.ptm` files store the same values times 255.
///
/// Light directions are given in the texel's tangent frame: (lu, lv) are the x
/// (right) and y (up) components of the unit vector towards the light.
struct Ptm {
  PtmFormat format = PtmFormat::kLrgb;
  int width = 0;
  int height = 0;
  /// Texel-major: for texel t, NumPolynomials() blocks of 6 coefficients a0..a5
  /// (eq. 1); RGB orders the blocks R, G, B. Sized by Resize only (the allocator
  /// leaves zeroing to the kernel, page by page as the planes are first written).
  std::vector<float, ZeroedAllocator<float>> coefficients;
  /// LRGB only, texel-major R G B: colour = L * (R, G, B) (eq. 2). The colour is
  /// normalised so that its largest channel is 1.
  std::vector<float, ZeroedAllocator<float>> colour;

  /// 1 for LRGB, 3 for RGB.
  int NumPolynomials() const { return format == PtmFormat::kLrgb ? 1 : 3; }
  std::size_t NumTexels() const {
    return static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  }
  /// Allocates zeroed planes. Throws std::invalid_argument for sizes outside [1, 65536].
  void Resize(PtmFormat ptm_format, int ptm_width, int ptm_height);

  const float* Coefficients(std::size_t texel, int polynomial = 0) const {
    return coefficients.data() + (texel * static_cast<std::size_t>(NumPolynomials()) +
                                  static_cast<std::size_t>(polynomial)) *
                                     6;
  }
  float* Coefficients(std::size_t texel, int polynomial = 0) {
    return coefficients.data() + (texel * static_cast<std::size_t>(NumPolynomials()) +
                                  static_cast<std::size_t>(polynomial)) *
                                     6;
  }

  /// RGB value of a texel under the light (lu, lv) (eq. 1-2), not clamped.
  Eigen::Vector3f Evaluate(std::size_t texel, double lu, double lv) const;
};

/// The same PTM as RGB: each channel's polynomial is the LRGB colour's channel times
/// the luminance polynomial (eq. 2), so it relights identically. An RGB PTM is copied.
Ptm AsRgb(const Ptm& ptm);

/// The six monomials of eq. 1 at (lu, lv): (lu^2, lv^2, lu lv, lu, lv, 1).
std::array<double, 6> PtmBasis(double lu, double lv);
/// The light matrix A of a fit to images under `lights` (unit, tangent frame):
/// row k is PtmBasis of light k.
Eigen::Matrix<double, Eigen::Dynamic, 6> PtmLightMatrix(const std::vector<Eigen::Vector3d>& lights);
/// L(lu, lv) = a0 lu^2 + a1 lv^2 + a2 lu lv + a3 lu + a4 lv + a5 (paper 003 eq. 1).
/// Inline: the relighting loops (synth/) evaluate it per texel and light.
inline double EvaluatePolynomial(float a0, float a1, float a2, float a3, float a4, float a5,
                                 double lu, double lv) {
  return a0 * lu * lu + a1 * lv * lv + a2 * lu * lv + a3 * lu + a4 * lv + a5;
}
/// The same of a texel's coefficients a0..a5 in a row.
inline double EvaluatePolynomial(const float* a, double lu, double lv) {
  return EvaluatePolynomial(a[0], a[1], a[2], a[3], a[4], a[5], lu, lv);
}

/// The surface normal of a texel from its (luminance) coefficients: the light
/// direction of the biquadratic's maximum (Malzbender et al. 2001, eq. 16),
/// clamped to the unit disk; (0, 0, 1) when the polynomial has no maximum.
/// Tangent frame: x right, y up, z out of the surface.
Eigen::Vector3d PtmNormal(const float* a);

/// RTI viewing enhancements for previews.
struct EnhancementOptions {
  /// Diffuse gain g (Malzbender et al.): curvature scaled by g about the normal;
  /// 1 = off. [1, 100].
  double diffuse_gain = 1.0;
  /// Specular enhancement: ks (n.h)^exponent added per texel with the PTM normal
  /// and the viewer along +z; 0 = off. [0, 10].
  double specular = 0.0;
  /// Exponent of that lobe. (0, 1000].
  double specular_exponent = 40.0;

  /// Throws OptionError naming the first setting out of range.
  void Check() const;
};

/// Renders the PTM under the light (unit direction, tangent frame) into an
/// RGB float image (row-major, 3 floats per texel, values clamped to [0, 1]).
std::vector<float> Relight(const Ptm& ptm, const Eigen::Vector3d& light,
                           const EnhancementOptions& enhancement = {});

/// Per texel, whether a chart of an atlas covers it: 1 where any coefficient is not 0.
std::vector<char> CoveredTexels(const Ptm& ptm);

/// Per-texel normals (row-major, 3 floats per texel) from the luminance of the PTM
/// (for RGB: of the mean of the three polynomials).
std::vector<float> NormalMap(const Ptm& ptm);

}  // namespace texlume::ptm
