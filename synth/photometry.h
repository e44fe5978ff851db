#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "ptm/light_response.h"

// Photometric calibration of the photos against the sample (beyond paper 003;
// docs/synth.md, "Light response"): a gain per photo, and how the object
// answers light beyond the sample's own model, estimated together from every
// face seen fully in a photo.

namespace texlume::synth {

/// One face seen fully in one photo.
struct PhotometricObservation {
  std::size_t face = 0, photo = 0;
  int cells = 0;  ///< photo cells summed (the face's rectified mask)
  /// The photo's R, G and B over those cells, linear, as taken; and their sum
  /// once the photo's white balance is taken out.
  std::array<double, 3> photo_channels{};
  double photo_linear = 0.0;
  /// One light at one shading point of the face (TriangleEngine::ShadingTurns: the
  /// face frame turned onto the smooth normal there, as the renderer shades).
  struct Light {
    double elevation_deg = 0.0;
    /// The sample's mean relit linear R + G + B under it alone (intensity and
    /// horizon fade included) over the point's share (a third) of the cells.
    double relit = 0.0;
    /// ptm::OrenNayarTerm of the light and the photo's view there.
    double oren_nayar = 0.0;
  };
  /// Per light and shading point, when the light is above the tangent plane there.
  std::vector<Light> lights;
  double zenith_linear = 0.0;  ///< the same under a unit light at the zenith
  /// Every light and the view steep (RectifiedView::steep): the gains trust it.
  bool steep = false;

  /// sum_l r(elevation_l) (1 + b s_l) P_l + ambient Z: the sample's prediction under a
  /// response (b its Oren-Nayar ratio, s_l the light's term).
  double Predicted(const ptm::LightResponse& response) const;
};

struct Photometry {
  std::vector<double> photo_gains;  ///< per photo, linear
  ptm::LightResponse response;      ///< the identity unless estimated
  /// Per photo, the factor on each of R, G, B (linear) by which it departs from
  /// the photos' common white balance (all 1 unless estimated).
  std::vector<std::array<double, 3>> white_balance;
};

/// Each photo's white balance against the others': per channel c, the log of the
/// face's chromaticity in the photo, log(photo_c / (R + G + B)), is
/// log k_f,c + log w_n,c, solved as SolvePhotoGains solves the gains, over the
/// steep observations; then log w is centred over each photo's channels (the
/// brightness is the gains') and over the photos for each channel (on average
/// the photos are neutral). Stains and the object's colour stay in k.
std::vector<std::array<double, 3>> SolveWhiteBalance(
    const std::vector<PhotometricObservation>& observations, std::size_t num_faces,
    std::size_t num_photos);

/// The faces a photometry observes (1 per face; issue 33). `photos_of_face[f]`
/// lists the photos (indices below num_photos) that see face f fully. All faces
/// when there are at most `limit`; else every k-th face, k = ceil(faces / limit),
/// and for each photo then seeing fewer than `min_per_photo` observed faces, every
/// j-th of its faces as well, j = max(1, its faces / min_per_photo).
std::vector<char> PhotometryFaces(const std::vector<std::vector<std::uint32_t>>& photos_of_face,
                                  std::size_t num_photos, std::size_t limit,
                                  std::size_t min_per_photo);

/// Solves photo_linear = g_n a_f (sum_l r(theta_l) (1 + b s_l) P_l + alpha Z) for
/// the photo gains g_n, the faces' albedos a_f relative to the sample, the elevation
/// factors r (ptm::LightResponse's knots), the ambient alpha and, with
/// `estimate_view_term` (a sample that does not hold the view's effect itself), the
/// Oren-Nayar ratio b = B / A (s_l = ptm::OrenNayarTerm), alternating:
///  - g and a from the steep observations under the current response
///    (SolvePhotoGains: log ratios, the mean log a at 0), then the gains scaled
///    so that their mean log is 0: on average the photos are exposed as the
///    lights file states, and what sets the object apart from the sample in
///    brightness goes into the response;
///  - r and alpha from every observation by weighted least squares on
///    photo / (g a): relative errors (a floor for the unlit), Huber weights
///    against cast shadows and highlights, second differences of r penalised,
///    and knots without observations drawn to the best single factor;
///  - b, in [0, 2], jointly with r and alpha, its rows linearised about the
///    current response (Gauss-Newton).
/// Without `estimate_response`, the gains alone as SolvePhotoGains gives them.
/// With `estimate_white_balance`, first each photo's white balance
/// (SolveWhiteBalance), taken out of the photo sums before the rest.
Photometry SolvePhotometry(std::vector<PhotometricObservation> observations, std::size_t num_faces,
                           std::size_t num_photos, bool estimate_response,
                           bool estimate_white_balance, bool estimate_view_term = false);

}  // namespace texlume::synth
