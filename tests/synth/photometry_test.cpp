#include "synth/photometry.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>

namespace texlume::synth {
namespace {

// A capture whose photometry is known: per photo a gain and a white balance,
// per face an albedo and a chromaticity, the object's elevation response r
// linear in the knots (so the smoothness penalty does not bias it) and an
// ambient. Every face has one steep observation (its albedo is then known).
struct KnownCapture {
  static constexpr std::size_t kFaces = 240, kPhotos = 24;
  std::vector<double> gain, albedo;
  std::vector<std::array<double, 3>> white_balance, chroma;
  ptm::LightResponse response;
  std::vector<PhotometricObservation> observations;

  // `oren_nayar`: the response's B / A, each light then seen at a term in [0, 1.5).
  explicit KnownCapture(double shadowed_share = 0.0, double oren_nayar = 0.0) {
    std::mt19937_64 rng(29);
    std::normal_distribution<double> normal(0.0, 1.0);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    gain = Centred(kPhotos, 0.1, rng);
    albedo = Centred(kFaces, 0.15, rng);
    white_balance.assign(kPhotos, {});
    for (std::size_t c = 0; c < 3; ++c) {
      const std::vector<double> w = Centred(kPhotos, 0.03, rng);
      for (std::size_t n = 0; n < kPhotos; ++n) white_balance[n][c] = w[n];
    }
    for (auto& w : white_balance) {  // geometric mean 1 over each photo's channels
      const double g = std::cbrt(w[0] * w[1] * w[2]);
      for (double& v : w) v /= g;
    }
    for (std::size_t c = 0; c < 3; ++c) {  // and over the photos for each channel
      double mean = 0.0;
      for (const auto& w : white_balance) mean += std::log(w[c]);
      for (auto& w : white_balance) w[c] /= std::exp(mean / kPhotos);
    }
    for (std::size_t k = 0; k < ptm::LightResponse::kKnots; ++k)
      response.elevation_factor[k] = 1.15 - 0.04 * static_cast<double>(k);
    response.ambient = 0.03;
    response.oren_nayar_b_over_a = oren_nayar;
    chroma.assign(kFaces, {});
    for (auto& k : chroma) {
      for (double& v : k) v = 0.3 + 0.05 * uniform(rng);
      const double sum = k[0] + k[1] + k[2];
      for (double& v : k) v /= sum;
    }
    for (std::size_t f = 0; f < kFaces; ++f)
      for (int i = 0; i < 6; ++i) {
        PhotometricObservation o;
        o.face = f;
        o.photo = static_cast<std::size_t>(uniform(rng) * kPhotos) % kPhotos;
        o.cells = 40 + static_cast<int>(uniform(rng) * 40);
        const int lights = i == 0 ? 1 : (uniform(rng) < 0.1 ? 0 : 1 + (uniform(rng) < 0.5));
        for (int l = 0; l < lights; ++l) {
          const double elevation = i == 0 ? 60.0 : 3.0 + 85.0 * uniform(rng);
          const double relit = o.cells * 1.5 * std::sin(elevation * std::numbers::pi / 180.0) *
                               (0.8 + 0.4 * uniform(rng));
          o.lights.push_back({elevation, relit, oren_nayar > 0.0 ? 1.5 * uniform(rng) : 0.0});
        }
        o.steep = lights > 0;
        for (const auto& l : o.lights) o.steep = o.steep && l.elevation_deg > 30.0;
        o.zenith_linear = o.cells * 1.5;
        double sum = gain[o.photo] * albedo[f] * o.Predicted(response);
        if (i > 0 && uniform(rng) < shadowed_share) sum *= 0.3;  // a cast shadow
        for (std::size_t c = 0; c < 3; ++c) {
          o.photo_channels[c] = sum * chroma[f][c] * white_balance[o.photo][c];
          o.photo_linear += o.photo_channels[c];
        }
        observations.push_back(o);
      }
  }

  // Log-normal values with their mean log at 0.
  static std::vector<double> Centred(std::size_t n, double sigma, std::mt19937_64& rng) {
    std::normal_distribution<double> normal(0.0, sigma);
    std::vector<double> log_v(n);
    double mean = 0.0;
    for (double& v : log_v) v = normal(rng), mean += v;
    std::vector<double> out;
    for (double v : log_v) out.push_back(std::exp(v - mean / static_cast<double>(n)));
    return out;
  }
};

TEST(SolvePhotometry, RecoversGainsWhiteBalanceElevationResponseAndAmbient) {
  const KnownCapture capture;
  const Photometry p = SolvePhotometry(capture.observations, KnownCapture::kFaces,
                                       KnownCapture::kPhotos, true, true);
  ASSERT_EQ(p.photo_gains.size(), KnownCapture::kPhotos);
  for (std::size_t n = 0; n < KnownCapture::kPhotos; ++n) {
    EXPECT_NEAR(p.photo_gains[n] / capture.gain[n], 1.0, 0.01) << "photo " << n;
    for (std::size_t c = 0; c < 3; ++c)
      EXPECT_NEAR(p.white_balance[n][c], capture.white_balance[n][c], 1e-6);
  }
  // Knot 0 (the horizon) has only faded lights: no data to speak of.
  for (std::size_t k = 1; k < ptm::LightResponse::kKnots; ++k)
    EXPECT_NEAR(p.response.elevation_factor[k], capture.response.elevation_factor[k], 0.01)
        << "knot " << k;
  EXPECT_NEAR(p.response.ambient, capture.response.ambient, 0.002);
}

TEST(SolvePhotometry, CastShadowsHardlyMoveTheResponse) {
  const KnownCapture capture(0.05);
  const Photometry p = SolvePhotometry(capture.observations, KnownCapture::kFaces,
                                       KnownCapture::kPhotos, true, true);
  for (std::size_t k = 1; k < ptm::LightResponse::kKnots; ++k)
    EXPECT_NEAR(p.response.elevation_factor[k], capture.response.elevation_factor[k], 0.04)
        << "knot " << k;
  EXPECT_NEAR(p.response.ambient, capture.response.ambient, 0.01);
}

TEST(SolvePhotometry, RecoversTheViewsOrenNayarRatioWhenAskedAndOnlyThen) {
  const KnownCapture capture(0.0, 0.3);
  const Photometry p = SolvePhotometry(capture.observations, KnownCapture::kFaces,
                                       KnownCapture::kPhotos, true, true, true);
  EXPECT_NEAR(p.response.oren_nayar_b_over_a, 0.3, 0.01);
  for (std::size_t k = 1; k < ptm::LightResponse::kKnots; ++k)
    EXPECT_NEAR(p.response.elevation_factor[k], capture.response.elevation_factor[k], 0.02)
        << "knot " << k;
  for (std::size_t n = 0; n < KnownCapture::kPhotos; ++n)
    EXPECT_NEAR(p.photo_gains[n] / capture.gain[n], 1.0, 0.01) << "photo " << n;
  // A sample that holds the view's effect itself: no term.
  const Photometry without = SolvePhotometry(capture.observations, KnownCapture::kFaces,
                                             KnownCapture::kPhotos, true, true, false);
  EXPECT_EQ(without.response.oren_nayar_b_over_a, 0.0);
  // A view-blind object: the term stays near 0.
  const KnownCapture blind;
  EXPECT_LT(SolvePhotometry(blind.observations, KnownCapture::kFaces, KnownCapture::kPhotos, true,
                            true, true)
                .response.oren_nayar_b_over_a,
            0.01);
}

TEST(SolvePhotometry, WithoutResponseTheGainsCarryTheSamplesBrightness) {
  KnownCapture capture;
  const Photometry p = SolvePhotometry(capture.observations, KnownCapture::kFaces,
                                       KnownCapture::kPhotos, false, false);
  EXPECT_TRUE(p.response.IsIdentity());
  for (const auto& w : p.white_balance) EXPECT_EQ(w, (std::array<double, 3>{1.0, 1.0, 1.0}));
  // The gains then absorb the response at the steep observations' elevation
  // (60 degrees and above 30): they are no longer centred on 1.
  double mean_log = 0.0;
  for (double g : p.photo_gains) mean_log += std::log(g);
  EXPECT_LT(mean_log / KnownCapture::kPhotos, std::log(0.97));
}

TEST(PhotometryFaces, EveryKthFaceAndEnoughForEveryPhoto) {
  // 1000 faces; photo 0 sees every face, photo 1 only faces 3, 13, 23, ... (100).
  std::vector<std::vector<std::uint32_t>> photos_of_face(1000);
  for (std::size_t f = 0; f < 1000; ++f) {
    photos_of_face[f].push_back(0);
    if (f % 10 == 3) photos_of_face[f].push_back(1);
  }
  const std::vector<char> all = PhotometryFaces(photos_of_face, 2, 1000, 20);
  EXPECT_EQ(std::count(all.begin(), all.end(), 1), 1000);  // within the limit: all
  const std::vector<char> observed = PhotometryFaces(photos_of_face, 2, 100, 20);
  // Every 10th face (0, 10, 20, ...): none of photo 1's; then every 5th of its 100.
  std::size_t count = 0, of_photo_1 = 0;
  for (std::size_t f = 0; f < 1000; ++f) {
    if (f % 10 == 0) {
      EXPECT_TRUE(observed[f]) << f;
    }
    count += observed[f];
    of_photo_1 += f % 10 == 3 && observed[f];
  }
  EXPECT_EQ(of_photo_1, 20u);
  EXPECT_EQ(count, 120u);
}

TEST(PhotometryFaces, ASubsetOfTheFacesGivesTheSameGains) {
  const KnownCapture capture;
  std::vector<std::vector<std::uint32_t>> photos_of_face(KnownCapture::kFaces);
  for (const PhotometricObservation& o : capture.observations)
    photos_of_face[o.face].push_back(static_cast<std::uint32_t>(o.photo));
  const std::vector<char> observed =
      PhotometryFaces(photos_of_face, KnownCapture::kPhotos, KnownCapture::kFaces / 3, 8);
  std::vector<PhotometricObservation> subset;
  for (const PhotometricObservation& o : capture.observations)
    if (observed[o.face]) subset.push_back(o);
  ASSERT_LT(subset.size(), capture.observations.size() * 2 / 3);
  const Photometry p =
      SolvePhotometry(subset, KnownCapture::kFaces, KnownCapture::kPhotos, true, true);
  for (std::size_t n = 0; n < KnownCapture::kPhotos; ++n)
    EXPECT_NEAR(p.photo_gains[n] / capture.gain[n], 1.0, 0.01) << "photo " << n;
}

}  // namespace
}  // namespace texlume::synth
