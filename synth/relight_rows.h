#pragma once

#include <array>
#include <vector>

#include "ptm/light_response.h"
#include "ptm/ptm.h"

namespace texlume::synth {

/// A PTM sample relit along rows of cells under lights that are the same at every
/// cell (no relief shadows): paper 003 eq. 3's model values, RelightEffective's
/// expressions in its order (so the same values, to the bit), eight cells at a time
/// with AVX2 where the processor has it (the lights' sums kept in registers, the sRGB
/// conversions by core/srgb_avx2.h), else one light at a time over the whole row (by
/// core/srgb_rows.h).
class PtmRowRelighter {
 public:
  PtmRowRelighter(ptm::PtmFormat format, std::vector<ptm::EffectiveLight> lights, double gain);

  /// `planes`: a row of each raw coefficient plane (6 per polynomial) then, LRGB, of
  /// each colour plane; `out`: the same row of the 3 relit planes; `cols` cells.
  void Relight(const float* const* planes, int cols, const std::array<float*, 3>& out);

 private:
  static constexpr int kMaxPlanes = 18;  ///< an RGB PTM's 3 polynomials
  // Relight's steps one light at a time over the whole row (the cells AVX2 leaves).
  void RelightByLight(const float* const* planes, int cols, const std::array<float*, 3>& out);

  ptm::PtmFormat format_;
  std::vector<ptm::EffectiveLight> lights_;
  float gain_;
  std::vector<double> polynomial_;            ///< one light's polynomial per cell
  std::vector<float> display_;                ///< one light's display value per cell
  std::array<std::vector<float>, 3> linear_;  ///< per channel, the lights' linear sum per cell
};

}  // namespace texlume::synth
