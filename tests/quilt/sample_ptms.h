#pragma once

#include <algorithm>

#include "ptm/ptm.h"

// Small PTM samples the quilting tests share.
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

}  // namespace texlume::testing
