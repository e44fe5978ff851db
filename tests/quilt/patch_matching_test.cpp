#include "quilt/patch_matching.h"

#include <gtest/gtest.h>

#include <numbers>
#include <opencv2/imgproc.hpp>
#include <random>

#include "core/errors.h"
#include "ptm/coefficient_space.h"
#include "quilt/patch_energy.h"
#include "tests/quilt/lit_samples.h"

namespace texlume::quilt {
namespace {

// An LRGB PTM of random smooth-ish coefficients (seeded).
ptm::Ptm RandomPtm(int width, int height, unsigned seed) {
  ptm::Ptm p;
  p.Resize(ptm::PtmFormat::kLrgb, width, height);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-0.3f, 0.3f);
  for (float& c : p.coefficients) c = u(rng);
  for (std::size_t t = 0; t < p.NumTexels(); ++t) p.Coefficients(t)[5] += 0.5f;
  std::fill(p.colour.begin(), p.colour.end(), 1.0f);
  return p;
}

std::vector<cv::Mat> Crop(const RotatedCopy& copy, const cv::Rect& r) {
  std::vector<cv::Mat> out;
  for (const cv::Mat& plane : copy.planes) out.push_back(plane(r).clone());
  return out;
}

// Turned a quarter turn counter-clockwise, a surface lit most from +x is lit
// most from +y: the features turn with the texels.
TEST(RotatedSample, AQuarterTurnCarriesTheLightResponseFromXToY) {
  const ptm::Ptm ptm = testing::LitFromPlusX(32);  // PtmSample keeps a reference
  const synth::PtmSample sample(ptm);
  RotatedSample rotated(sample);
  const RotatedCopy& copy = rotated.Copy(RotatedSample::kRotations / 4);
  EXPECT_NEAR(copy.angle_rad, std::numbers::pi / 2, 1e-12);
  Eigen::Matrix<double, 6, 1> o;
  for (int c = 0; c < 6; ++c) o[c] = copy.planes[static_cast<std::size_t>(c)].at<float>(10, 10);
  const Eigen::Matrix<double, 6, 1> a = ptm::OrthonormalBasis::Hemisphere().FromOrthonormal() * o;
  EXPECT_NEAR(a[3], 0.0, 1e-5);  // lu
  EXPECT_NEAR(a[4], 0.4, 1e-5);  // lv
  EXPECT_NEAR(a[5], 0.5, 1e-5);
}

// The copy's texels come from the sample turned about its centre: a quarter
// turn counter-clockwise (y up) takes the copy's right-hand side from the
// sample's bottom.
TEST(RotatedSample, CopyPositionsTurnAboutTheCentre) {
  const ptm::Ptm sample_ptm = RandomPtm(40, 40, 1);
  const synth::PtmSample sample(sample_ptm);
  RotatedSample rotated(sample);
  EXPECT_EQ(rotated.side(), 28);
  const Eigen::Vector2d centre = rotated.SamplePosition(18, Eigen::Vector2d(14, 14));
  EXPECT_NEAR(centre.x(), 20, 1e-12);
  EXPECT_NEAR(centre.y(), 20, 1e-12);
  const Eigen::Vector2d right = rotated.SamplePosition(18, Eigen::Vector2d(24, 14));
  EXPECT_NEAR(right.x(), 20, 1e-9);
  EXPECT_NEAR(right.y(), 30, 1e-9);  // rows down: the sample's bottom
  EXPECT_EQ(RotatedSample::RotationNearest(-std::numbers::pi / 2), 54);
  EXPECT_EQ(RotatedSample::RotationNearest(2 * std::numbers::pi + 0.01), 0);
}

// A work image cut out of a copy is found where it was cut, by the FFT and by
// brute force, with a cost of zero.
TEST(MatchEntirePatch, FindsAPlantedPlacement) {
  const ptm::Ptm sample_ptm = RandomPtm(64, 64, 2);
  const synth::PtmSample sample(sample_ptm);
  RotatedSample rotated(sample);
  const RotatedCopy& copy = rotated.Copy(7);
  const cv::Rect cut(13, 21, 17, 12);
  cv::Mat mask(cut.size(), CV_32FC1, cv::Scalar(1));
  mask(cv::Rect(5, 0, 12, 6)).setTo(0);  // an unsynthesised corner
  const auto work = Crop(copy, cut);
  for (const Placement& p :
       {MatchEntirePatch(copy, work, mask), MatchEntirePatchBruteForce(copy, work, mask)}) {
    EXPECT_EQ(p.x, cut.x);
    EXPECT_EQ(p.y, cut.y);
    EXPECT_EQ(p.rotation, 7);
    EXPECT_NEAR(p.cost, 0.0, 1e-4);
  }
}

// On unrelated work images the FFT makes the brute force's choices.
TEST(MatchEntirePatch, FftMakesTheBruteForceChoices) {
  const ptm::Ptm sample_ptm = RandomPtm(48, 48, 3);
  const synth::PtmSample sample(sample_ptm);
  const ptm::Ptm other_ptm = RandomPtm(20, 20, 4);
  const synth::PtmSample other(other_ptm);
  RotatedSample rotated(sample), rotated_other(other);
  const RotatedCopy& source = rotated_other.Copy(0);
  std::mt19937 rng(5);
  for (int trial = 0; trial < 6; ++trial) {
    const RotatedCopy& copy = rotated.Copy(trial * 11);
    cv::Mat mask(source.side(), source.side(), CV_32FC1);
    cv::randu(mask, 0, 1);
    cv::threshold(mask, mask, 0.5, 1.0, cv::THRESH_BINARY);
    const Placement fast = MatchEntirePatch(copy, source.planes, mask);
    const Placement slow = MatchEntirePatchBruteForce(copy, source.planes, mask);
    EXPECT_EQ(fast.x, slow.x) << "trial " << trial;
    EXPECT_EQ(fast.y, slow.y) << "trial " << trial;
    EXPECT_NEAR(fast.cost, slow.cost, 1e-4 * slow.cost);
  }
}

TEST(RotatedSample, RefusesASampleTooSmallToTurn) {
  const ptm::Ptm sample_ptm = RandomPtm(10, 40, 6);
  const synth::PtmSample sample(sample_ptm);
  EXPECT_THROW(RotatedSample{sample}, InputError);
}

}  // namespace
}  // namespace texlume::quilt

namespace texlume::quilt {
namespace {

// A window cut out of a turned copy is the sample itself: no energy. Noise of
// the sample's spread is far from every window of the sample.
TEST(NearestPatchEnergy, IsZeroForTheSampleAndLargeForNoise) {
  const ptm::Ptm sample_ptm = RandomPtm(48, 48, 8);
  const synth::PtmSample sample(sample_ptm);
  RotatedSample rotated(sample);
  const RotatedCopy& copy = rotated.Copy(12);
  const std::vector<cv::Mat> texture = Crop(copy, cv::Rect(3, 4, 24, 24));
  const cv::Mat inside(24, 24, CV_8UC1, cv::Scalar(255));
  PatchEnergyOptions o;
  o.windows = 6;
  const PatchEnergy own = NearestPatchEnergy(texture, inside, rotated, o);
  EXPECT_EQ(own.windows, 6);
  EXPECT_LT(own.per_texel, 1e-6);
  std::vector<cv::Mat> noise;
  cv::RNG rng(9);
  for (std::size_t c = 0; c < texture.size(); ++c) {
    noise.emplace_back(24, 24, CV_32FC1);
    rng.fill(noise.back(), cv::RNG::UNIFORM, -0.5, 0.5);
  }
  EXPECT_GT(NearestPatchEnergy(noise, inside, rotated, o).per_texel, 0.05);
}

}  // namespace
}  // namespace texlume::quilt
