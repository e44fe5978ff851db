#pragma once

namespace texlume::srgb {

/// The sRGB conversions of srgb.h over a row of values, eight at a time with AVX2
/// where the processor has it (the tables read by gathers; asked on the first call),
/// one at a time otherwise; the values are those of ToLinear and FromLinear, to the
/// bit, either way. A row read and the row written are the same or do not overlap.

/// linear[i] += weight * ToLinear(display[i]) for i < n.
void AddWeightedLinear(const float* display, float weight, int n, float* linear);

/// display[i] = FromLinear(scale * linear[i]) for i < n.
void ScaledFromLinear(const float* linear, float scale, int n, float* display);

/// Whether the processor runs the eight-at-a-time kernels.
bool RowsUseAvx2();

}  // namespace texlume::srgb
