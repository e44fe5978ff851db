#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "ptm/horizon.h"

// Planes of 8-bit values packed four to an RGBA PNG: what the web model, the BTF
// files and the GLB carry (docs/viewer.md, "Web model").
namespace texlume::model {

/// Quantises one channel (a plane of PTM values) to 8 bits: value = byte / 255 * scale + bias,
/// bias = the plane's minimum, scale = its range (1 when the plane is constant).
struct QuantisedPlane {
  std::vector<unsigned char> bytes;
  double scale = 1.0, bias = 0.0;
};
QuantisedPlane QuantisePlane(const std::vector<float>& values);
/// PNG bytes (8-bit RGBA) of up to four quantised planes of `width` x `height`
/// (R, G, B, A; missing planes are 0). Throws InputError(label) on failure.
std::vector<unsigned char> PlanesPng(const std::vector<const QuantisedPlane*>& planes, int width,
                                     int height, const std::string& label);

/// The relief's horizon of one atlas (its SelfShadowing) as the web model and the
/// GLB carry it (docs/viewer.md, "The relief's shadows"): 16 azimuths 2 pi s / 16,
/// four per RGBA PNG, byte = elevation / (pi / 2) x 255; and how the light falls in
/// shadow (`sectors`, `elevation_scale`, `shadow_floor`, `penumbra_rad`).
struct HorizonTextures {
  std::vector<std::vector<unsigned char>> pngs;  ///< PNG i holds sectors 4i .. 4i + 3
  nlohmann::json fields;
};
/// Throws InputError(label) when a PNG cannot be encoded.
HorizonTextures EncodeHorizonTextures(const ptm::SelfShadowing& shadowing,
                                      const std::string& label);

}  // namespace texlume::model
