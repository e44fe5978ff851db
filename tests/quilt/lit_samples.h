#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "btf/btf.h"
#include "ptm/ptm.h"

// Samples lit most from their +x axis, which the quilting tests share: where
// such a sample lies turned, its values say which way.
namespace texlume::testing {

/// The same LRGB PTM everywhere, lit most from its +x axis (a3 = 0.4, a5 =
/// 0.5): where it lies turned, its coefficients say which way.
inline ptm::Ptm LitFromPlusX(int side) {
  ptm::Ptm lit;
  lit.Resize(ptm::PtmFormat::kLrgb, side, side);
  for (std::size_t t = 0; t < lit.NumTexels(); ++t) {
    lit.Coefficients(t)[3] = 0.4f;
    lit.Coefficients(t)[5] = 0.5f;
  }
  std::fill(lit.colour.begin(), lit.colour.end(), 1.0f);
  return lit;
}

/// A BTF of one component, side x side texels of 0.01, seen head-on under 8
/// lights at 45 degrees of elevation, brighter the more a light lies toward +x.
inline btf::BtfFactorisation LitBtfFromPlusX(int side) {
  btf::BtfFactorisation lit;
  lit.width = lit.height = side;
  lit.texel_size = 0.01;
  lit.views = {Eigen::Vector3d::UnitZ()};
  for (int k = 0; k < 8; ++k) {
    const double a = k * std::numbers::pi / 4, e = std::numbers::pi / 4;
    lit.lights.emplace_back(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
  }
  lit.geometry = Eigen::MatrixXf::Ones(side * side, 1);
  lit.appearance.resize(8 * 3, 1);
  for (int k = 0; k < 8; ++k)
    lit.appearance.middleRows(k * 3, 3).setConstant(
        static_cast<float>(0.1 + 0.3 * std::max(0.0, lit.lights[static_cast<std::size_t>(k)].x())));
  lit.singular_values = {1.0};
  return lit;
}

}  // namespace texlume::testing
