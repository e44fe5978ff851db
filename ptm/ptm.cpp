#include "ptm/ptm.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/errors.h"

namespace texlume::ptm {

void Ptm::Resize(PtmFormat ptm_format, int ptm_width, int ptm_height) {
  if (ptm_width < 1 || ptm_height < 1 || ptm_width > 65536 || ptm_height > 65536) {
    throw std::invalid_argument("PTM size " + std::to_string(ptm_width) + "x" +
                                std::to_string(ptm_height) + " is out of range");
  }
  format = ptm_format;
  width = ptm_width;
  height = ptm_height;
  // Fresh buffers, value-initialised: zero without a pass over memory.
  decltype(coefficients)().swap(coefficients);
  decltype(colour)().swap(colour);
  coefficients.resize(NumTexels() * static_cast<std::size_t>(NumPolynomials()) * 6);
  colour.resize(format == PtmFormat::kLrgb ? NumTexels() * 3 : 0);
}

std::array<double, 6> PtmBasis(double lu, double lv) {
  return {lu * lu, lv * lv, lu * lv, lu, lv, 1.0};
}

Eigen::Matrix<double, Eigen::Dynamic, 6> PtmLightMatrix(
    const std::vector<Eigen::Vector3d>& lights) {
  Eigen::Matrix<double, Eigen::Dynamic, 6> a(static_cast<Eigen::Index>(lights.size()), 6);
  for (std::size_t k = 0; k < lights.size(); ++k) {
    const auto b = PtmBasis(lights[k].x(), lights[k].y());
    for (int i = 0; i < 6; ++i) a(static_cast<Eigen::Index>(k), i) = b[static_cast<std::size_t>(i)];
  }
  return a;
}

Eigen::Vector3f Ptm::Evaluate(std::size_t texel, double lu, double lv) const {
  if (format == PtmFormat::kLrgb) {
    const float l = static_cast<float>(EvaluatePolynomial(Coefficients(texel), lu, lv));
    return Eigen::Vector3f(colour[texel * 3], colour[texel * 3 + 1], colour[texel * 3 + 2]) * l;
  }
  return {static_cast<float>(EvaluatePolynomial(Coefficients(texel, 0), lu, lv)),
          static_cast<float>(EvaluatePolynomial(Coefficients(texel, 1), lu, lv)),
          static_cast<float>(EvaluatePolynomial(Coefficients(texel, 2), lu, lv))};
}

Eigen::Vector3d PtmNormal(const float* a) {
  // dL/dlu = 2 a0 lu + a2 lv + a3 = 0, dL/dlv = a2 lu + 2 a1 lv + a4 = 0.
  const double det = 4.0 * a[0] * a[1] - static_cast<double>(a[2]) * a[2];
  if (!(std::abs(det) > 1e-12) || !(a[0] < 0 && det > 0)) {
    // No maximum (not concave): fall back to the direction of the linear terms.
    const Eigen::Vector2d g(a[3], a[4]);
    const double len = g.norm();
    if (!(len > 1e-12)) return Eigen::Vector3d::UnitZ();
    const Eigen::Vector2d d = g / std::max(len, 1.0) * std::min(1.0, len);
    return Eigen::Vector3d(d.x(), d.y(), std::sqrt(std::max(0.0, 1.0 - d.squaredNorm())))
        .normalized();
  }
  double lu = (a[2] * a[4] - 2.0 * a[1] * a[3]) / det;
  double lv = (a[2] * a[3] - 2.0 * a[0] * a[4]) / det;
  const double r2 = lu * lu + lv * lv;
  if (r2 > 1.0) {
    const double r = std::sqrt(r2);
    lu /= r;
    lv /= r;
  }
  return Eigen::Vector3d(lu, lv, std::sqrt(std::max(0.0, 1.0 - lu * lu - lv * lv)));
}

namespace {

// The luminance polynomial of a texel: its own for LRGB, the mean of the three
// channel polynomials for RGB (`scratch` holds that mean).
const float* LuminanceCoefficients(const Ptm& ptm, std::size_t texel, float* scratch) {
  if (ptm.format == PtmFormat::kLrgb) return ptm.Coefficients(texel);
  for (int k = 0; k < 6; ++k) {
    scratch[k] = (ptm.Coefficients(texel, 0)[k] + ptm.Coefficients(texel, 1)[k] +
                  ptm.Coefficients(texel, 2)[k]) /
                 3.0f;
  }
  return scratch;
}

// Diffuse gain (Malzbender et al. 2001, §5.1): keeps the value and slope at the
// normal direction, scales the curvature by g.
void DiffuseGain(const float* a, double g, float* out) {
  const Eigen::Vector3d n = PtmNormal(a);
  const double u0 = n.x(), v0 = n.y();
  out[0] = static_cast<float>(g * a[0]);
  out[1] = static_cast<float>(g * a[1]);
  out[2] = static_cast<float>(g * a[2]);
  out[3] = static_cast<float>((1 - g) * (2 * a[0] * u0 + a[2] * v0) + a[3]);
  out[4] = static_cast<float>((1 - g) * (2 * a[1] * v0 + a[2] * u0) + a[4]);
  out[5] = static_cast<float>((1 - g) * (a[0] * u0 * u0 + a[1] * v0 * v0 + a[2] * u0 * v0) +
                              (a[3] - out[3]) * u0 + (a[4] - out[4]) * v0 + a[5]);
}

}  // namespace

void EnhancementOptions::Check() const {
  if (!(diffuse_gain >= 1.0 && diffuse_gain <= 100.0))
    throw OptionError("diffuse gain must be in [1, 100]");
  if (!(specular >= 0.0 && specular <= 10.0)) throw OptionError("specular must be in [0, 10]");
  if (!(specular_exponent > 0.0 && specular_exponent <= 1000.0))
    throw OptionError("specular exponent must be in (0, 1000]");
}

std::vector<float> Relight(const Ptm& ptm, const Eigen::Vector3d& light,
                           const EnhancementOptions& enhancement) {
  enhancement.Check();
  const Eigen::Vector3d l = light.normalized();
  const Eigen::Vector3d half = (l + Eigen::Vector3d::UnitZ()).normalized();
  std::vector<float> out(ptm.NumTexels() * 3);
  const bool gain = enhancement.diffuse_gain != 1.0;
#pragma omp parallel for schedule(static)
  for (long t = 0; t < static_cast<long>(ptm.NumTexels()); ++t) {
    const auto texel = static_cast<std::size_t>(t);
    Eigen::Vector3f rgb;
    float scratch[6];
    const float* a = LuminanceCoefficients(ptm, texel, scratch);
    if (gain) {
      for (int c = 0; c < ptm.NumPolynomials(); ++c) {
        float g[6];
        DiffuseGain(ptm.Coefficients(texel, c), enhancement.diffuse_gain, g);
        const float v = static_cast<float>(EvaluatePolynomial(g, l.x(), l.y()));
        if (ptm.format == PtmFormat::kLrgb) {
          rgb = Eigen::Vector3f(ptm.colour[texel * 3], ptm.colour[texel * 3 + 1],
                                ptm.colour[texel * 3 + 2]) *
                v;
        } else {
          rgb[c] = v;
        }
      }
    } else {
      rgb = ptm.Evaluate(texel, l.x(), l.y());
    }
    if (enhancement.specular > 0.0) {
      const Eigen::Vector3d n = PtmNormal(a);
      const double s = enhancement.specular *
                       std::pow(std::max(0.0, n.dot(half)), enhancement.specular_exponent);
      rgb.array() += static_cast<float>(s);
    }
    for (int c = 0; c < 3; ++c)
      out[texel * 3 + static_cast<std::size_t>(c)] = std::clamp(rgb[c], 0.0f, 1.0f);
  }
  return out;
}

Ptm AsRgb(const Ptm& ptm) {
  if (ptm.format == PtmFormat::kRgb) return ptm;
  Ptm rgb;
  rgb.Resize(PtmFormat::kRgb, ptm.width, ptm.height);
  for (std::size_t t = 0; t < ptm.NumTexels(); ++t)
    for (int c = 0; c < 3; ++c)
      for (int i = 0; i < 6; ++i)
        rgb.Coefficients(t, c)[i] =
            ptm.colour[t * 3 + static_cast<std::size_t>(c)] * ptm.Coefficients(t)[i];
  return rgb;
}

std::vector<char> CoveredTexels(const Ptm& ptm) {
  std::vector<char> covered(ptm.NumTexels(), 0);
  for (std::size_t t = 0; t < covered.size(); ++t)
    for (int q = 0; q < ptm.NumPolynomials() && !covered[t]; ++q)
      for (int m = 0; m < 6; ++m)
        if (ptm.Coefficients(t, q)[m] != 0.0f) covered[t] = 1;
  return covered;
}

std::vector<float> NormalMap(const Ptm& ptm) {
  std::vector<float> out(ptm.NumTexels() * 3);
  for (std::size_t t = 0; t < ptm.NumTexels(); ++t) {
    float scratch[6];
    const float* a = LuminanceCoefficients(ptm, t, scratch);
    const Eigen::Vector3d n = PtmNormal(a);
    for (int c = 0; c < 3; ++c) out[t * 3 + static_cast<std::size_t>(c)] = static_cast<float>(n[c]);
  }
  return out;
}

}  // namespace texlume::ptm
