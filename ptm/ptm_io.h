#pragma once

#include <filesystem>
#include <istream>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "ptm/ptm.h"

namespace texlume::ptm {

/// Writes an HP PTM 1.2 file (docs/ptm_format.md): `PTM_1.2`, the format name,
/// width, height, 6 scales, 6 biases (ASCII, LF), then bytes, rows bottom to top.
/// Coefficients are quantised per coefficient index over the whole image, on a
/// range from the 0.1 % and 99.9 % quantiles (always including 0), in the 0-255
/// display domain: coefficient = (byte - bias) * scale.
void WritePtm(const Ptm& ptm, std::ostream& out);
void WritePtmFile(const Ptm& ptm, const std::filesystem::path& path);

/// Reads PTM_1.2 (and PTM_1.1) files in PTM_FORMAT_RGB or PTM_FORMAT_LRGB.
/// Throws InputError naming the file (and header line) for anything else, a
/// corrupt header or a truncated payload; sizes are checked against the bytes
/// left before anything is allocated.
Ptm ReadPtm(std::istream& in, const std::string& label);
Ptm ReadPtmFile(const std::filesystem::path& path);

/// Lossless PTM as OpenEXR: float channels named `L.a0`..`L.a5`, `R`, `G`, `B`
/// (LRGB) or `R.a0`..`R.a5`, `G.a0`.., `B.a0`.. (RGB).
void WritePtmExr(const Ptm& ptm, const std::filesystem::path& path);
Ptm ReadPtmExr(const std::filesystem::path& path);
/// ReadPtmExr on the bytes of a PTM EXR in memory; errors name `label`.
Ptm ReadPtmExrBytes(std::string_view bytes, const std::string& label);

/// Reads a PTM by extension: .exr (lossless) or .ptm.
Ptm ReadPtmAnyFormat(const std::filesystem::path& path);

/// The PTM as the relight / OpenLIME web format holds it: planes in OpenLIME's basis
/// order (1, u, v, u^2, uv, v^2), after the colour for LRGB (per colour channel for
/// RGB), three planes per 8-bit image, each plane quantised over its range:
/// value = (byte / 255 - bias) * scale.
struct WebPlanes {
  int width = 0, height = 0;
  std::string type = "ptm";        ///< "ptm" or "hsh"
  std::string colorspace = "rgb";  ///< "rgb" or "lrgb"
  std::vector<cv::Mat> images;     ///< 8-bit BGR, plane 3j + c in channel c of image j
  std::vector<float> scales, biases;
  /// info.json's fields: width, height, type, colorspace, nplanes, materials.
  nlohmann::json Info() const;
};
WebPlanes QuantiseWebPlanes(const Ptm& ptm);
/// Planes of width x height values (row-major) quantised and packed three to an image
/// as QuantiseWebPlanes does; the last image's unused channels are 0. Type "ptm", RGB.
WebPlanes QuantisePlanes(const std::vector<std::vector<float>>& planes, int width, int height);
/// Writes `web` into `dir` (created) as relight's web format: `plane_N.jpg` and
/// `info.json` (Info, with format "jpg" and the quality), each atomically. Returns the
/// number of files written.
int WriteWebPlanes(const WebPlanes& web, const std::filesystem::path& dir, int jpeg_quality);

/// Writes the relight / OpenLIME web format into `dir`: `info.json` (type "ptm",
/// colorspace "rgb", nplanes, per-plane scale and bias) and the coefficient planes as
/// `plane_N.jpg`, three coefficients per JPEG (docs/ptm_format.md). An LRGB PTM is
/// written as its RGB equivalent (AsRgb), which OpenLIME draws correctly. Returns the
/// number of files written.
int WriteRelightWeb(const Ptm& ptm, const std::filesystem::path& dir, int jpeg_quality = 95);

}  // namespace texlume::ptm
