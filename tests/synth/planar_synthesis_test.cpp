#include "synth/planar_synthesis.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>

#include "core/errors.h"
#include "datasets_synthetic/scene.h"
#include "ptm/fit.h"
#include "synth/template_match.h"
#include "tests/test_util.h"

namespace texlume::synth {
namespace {

TEST(TemplateMatch, FftPathEqualsTheBruteForceReferenceAndRanksAlike) {
  std::mt19937 rng(3);
  std::vector<cv::Mat> image(6), templ(6);
  for (int c = 0; c < 6; ++c) {
    image[static_cast<std::size_t>(c)] = cv::Mat(48, 40, CV_32FC1);
    cv::randu(image[static_cast<std::size_t>(c)], -1.0, 1.0);
    templ[static_cast<std::size_t>(c)] =
        image[static_cast<std::size_t>(c)](cv::Rect(11, 17, 12, 12)).clone();
    cv::Mat noise(12, 12, CV_32FC1);
    cv::randn(noise, 0.0, 0.05);
    templ[static_cast<std::size_t>(c)] += noise;
  }
  cv::Mat mask = cv::Mat::zeros(12, 12, CV_32FC1);
  mask(cv::Rect(0, 0, 4, 12)).setTo(1.0f);  // an L-shaped overlap
  mask(cv::Rect(0, 8, 12, 4)).setTo(1.0f);
  const cv::Mat fast = MaskedSsd(image, PlaneEnergy(image), templ, mask);
  const cv::Mat reference = MaskedSsdBruteForce(image, templ, mask);
  ASSERT_EQ(fast.size(), reference.size());
  double max_diff;
  cv::minMaxLoc(cv::abs(fast - reference), nullptr, &max_diff);
  EXPECT_LT(max_diff, 1e-3);
  cv::Point best_fast, best_reference;
  cv::minMaxLoc(fast, nullptr, nullptr, &best_fast);
  cv::minMaxLoc(reference, nullptr, nullptr, &best_reference);
  EXPECT_EQ(best_fast, best_reference);
  EXPECT_EQ(best_fast, cv::Point(11, 17));
  // The ten best positions are the same in the same order.
  auto top = [](const cv::Mat& m) {
    std::vector<std::pair<float, int>> v;
    for (int i = 0; i < static_cast<int>(m.total()); ++i) v.emplace_back(m.at<float>(i), i);
    std::partial_sort(v.begin(), v.begin() + 10, v.end());
    std::vector<int> ids;
    for (int i = 0; i < 10; ++i) ids.push_back(v[static_cast<std::size_t>(i)].second);
    return ids;
  };
  EXPECT_EQ(top(fast), top(reference));
}

class PlanarSynthesisTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // A stone sample PTM fitted to a small synthetic capture, and photos of an
    // unseen region of the same stone at half resolution.
    testing::TempDir* tmp = new testing::TempDir;
    datasets::SceneOptions scene =
        datasets::MaterialOnlySceneOptions(datasets::MaterialKind::kStone, 96, 24);
    scene.num_held_out_capture_lights = 0;
    scene.material.texel_size = 0.004;
    datasets::GenerateScene(scene, tmp->path());
    const ptm::RtiCapture capture = ptm::ReadRtiCapture(tmp->path() / "material/capture/lights.lp",
                                                        tmp->path() / "material/capture");
    sample_ = new ptm::Ptm(ptm::FitPtmFromFiles(capture.files, capture.lights, {}).ptm);
    datasets::PlanarSurfaceOptions surface;
    surface.material = scene.material;
    surface.size = 64;
    surface.scale = 2;
    surface.offset = 200;
    photo_lights_ = {Eigen::Vector3d(0.6, 0.2, 0.77).normalized(),
                     Eigen::Vector3d(-0.4, 0.5, 0.77).normalized(),
                     Eigen::Vector3d(-0.1, -0.65, 0.75).normalized()};
    held_out_lights_ = datasets::DomeLights(6, 25, 70, 0.3);  // as bench/synth2d_bench
    const auto renders = datasets::RenderPlanarSurface(surface, photo_lights_, held_out_lights_);
    photos_ = new std::vector<PlanarPhoto>;
    truth_ = new std::vector<cv::Mat>;
    for (std::size_t n = 0; n < photo_lights_.size(); ++n) {
      cv::Mat f;
      renders.photos[n].convertTo(f, CV_32FC3, 1 / 255.0);
      cv::cvtColor(f, f, cv::COLOR_BGR2RGB);
      PlanarPhoto p;
      p.image = {f.cols, f.rows,
                 std::vector<float>(reinterpret_cast<float*>(f.data),
                                    reinterpret_cast<float*>(f.data) + f.total() * 3)};
      p.light = photo_lights_[n];
      p.name = "photo_" + std::to_string(n) + ".png";
      photos_->push_back(p);
    }
    for (const cv::Mat& t : renders.truth) {
      cv::Mat f;
      t.convertTo(f, CV_32FC3, 1 / 255.0);
      cv::cvtColor(f, f, cv::COLOR_BGR2RGB);
      truth_->push_back(f);
    }
    delete tmp;
  }
  static double PhotoError(const PlanarSynthesisResult& r) {
    double sum = 0;
    for (std::size_t n = 0; n < photos_->size(); ++n) {
      const std::vector<float> relit = ptm::Relight(r.ptm, (*photos_)[n].light);
      cv::Mat full(r.ptm.height, r.ptm.width, CV_32FC3, const_cast<float*>(relit.data())), small;
      cv::resize(full, small, cv::Size(32, 32), 0, 0, cv::INTER_AREA);
      const cv::Mat photo(32, 32, CV_32FC3, const_cast<float*>((*photos_)[n].image.pixels.data()));
      cv::Mat d = small * r.photo_gains[n] - photo;
      sum += cv::norm(d) / std::sqrt(d.total() * 3.0);
    }
    return sum / static_cast<double>(photos_->size());
  }
  // Mean PSNR under the held-out lights against ground truth at full resolution.
  static double HeldOutPsnr(const ptm::Ptm& p) {
    double sum = 0;
    for (std::size_t h = 0; h < held_out_lights_.size(); ++h) {
      const std::vector<float> relit = ptm::Relight(p, held_out_lights_[h]);
      sum += cv::PSNR(cv::Mat(p.height, p.width, CV_32FC3, const_cast<float*>(relit.data())),
                      (*truth_)[h], 1.0);
    }
    return sum / static_cast<double>(held_out_lights_.size());
  }
  static ptm::Ptm* sample_;
  static std::vector<PlanarPhoto>* photos_;
  static std::vector<cv::Mat>* truth_;
  static std::vector<Eigen::Vector3d> photo_lights_, held_out_lights_;
};
ptm::Ptm* PlanarSynthesisTest::sample_ = nullptr;
std::vector<PlanarPhoto>* PlanarSynthesisTest::photos_ = nullptr;
std::vector<cv::Mat>* PlanarSynthesisTest::truth_ = nullptr;
std::vector<Eigen::Vector3d> PlanarSynthesisTest::photo_lights_;
std::vector<Eigen::Vector3d> PlanarSynthesisTest::held_out_lights_;

TEST_F(PlanarSynthesisTest, PhotoConstraintsMakeTheRelitOutputAgreeWithThePhotos) {
  PlanarSynthesisOptions o;
  o.block_size = 16;
  o.overlap = 4;
  o.scale = 2;
  const PlanarSynthesisResult constrained = SynthesizePlanarPtm(*sample_, *photos_, o);
  EXPECT_EQ(constrained.ptm.width, 64);
  EXPECT_EQ(constrained.scale, 2);
  o.use_photos = false;
  o.width = o.height = 64;
  PlanarSynthesisResult unconstrained = SynthesizePlanarPtm(*sample_, {}, o);
  unconstrained.photo_gains = constrained.photo_gains;
  EXPECT_LT(PhotoError(constrained), 0.8 * PhotoError(unconstrained));
  // Every block comes from inside the sample and covers the output.
  for (const BlockPlacement& b : constrained.blocks) {
    EXPECT_GE(b.sample_x, 0);
    EXPECT_LE(b.sample_x + 16, sample_->width);
  }
  EXPECT_EQ(constrained.blocks.size(), 25u);  // 5 x 5 positions over 64 with step 12
}

TEST_F(PlanarSynthesisTest, UnderHeldOutLightsConstrainedBeatsUnconstrainedAndBicubic) {
  PlanarSynthesisOptions o;
  o.block_size = 16;
  o.overlap = 4;
  o.scale = 2;
  o.correction_iterations = 0;
  const PlanarSynthesisResult quilted = SynthesizePlanarPtm(*sample_, *photos_, o);
  o.correction_iterations = 2;
  const PlanarSynthesisResult corrected = SynthesizePlanarPtm(*sample_, *photos_, o);
  // The photo-consistency pass brings the photo residual down by more than half.
  EXPECT_LT(corrected.photo_rms_corrected, 0.5 * quilted.photo_rms_corrected);
  EXPECT_DOUBLE_EQ(corrected.photo_rms_quilted, quilted.photo_rms_corrected);
  o.use_photos = false;
  o.width = o.height = 64;
  const PlanarSynthesisResult unconstrained = SynthesizePlanarPtm(*sample_, {}, o);
  // Bicubic upscale of the photo whose light is nearest each held-out light.
  double bicubic = 0;
  for (std::size_t h = 0; h < held_out_lights_.size(); ++h) {
    std::size_t nearest = 0;
    for (std::size_t n = 1; n < photo_lights_.size(); ++n)
      if (photo_lights_[n].dot(held_out_lights_[h]) >
          photo_lights_[nearest].dot(held_out_lights_[h]))
        nearest = n;
    cv::Mat up;
    cv::resize(cv::Mat(32, 32, CV_32FC3, (*photos_)[nearest].image.pixels.data()), up,
               cv::Size(64, 64), 0, 0, cv::INTER_CUBIC);
    bicubic += cv::PSNR(up, (*truth_)[h], 1.0) / static_cast<double>(held_out_lights_.size());
  }
  const double psnr_corrected = HeldOutPsnr(corrected.ptm);
  EXPECT_GT(HeldOutPsnr(quilted.ptm), HeldOutPsnr(unconstrained.ptm));
  EXPECT_GT(psnr_corrected, HeldOutPsnr(quilted.ptm) + 1.0);
  EXPECT_GT(psnr_corrected, bicubic + 1.0);
  std::printf("held-out PSNR: corrected %.2f, quilted %.2f, unconstrained %.2f, bicubic %.2f dB\n",
              psnr_corrected, HeldOutPsnr(quilted.ptm), HeldOutPsnr(unconstrained.ptm), bicubic);
}

TEST_F(PlanarSynthesisTest, SeamCuttingLowersTheSeamCostOfBlending) {
  PlanarSynthesisOptions o;
  o.block_size = 16;
  o.overlap = 6;
  o.scale = 2;
  const double blend = SynthesizePlanarPtm(*sample_, *photos_, o).seam_cost_per_texel;
  o.stitch = Stitch::kSeamCut;
  const double cut = SynthesizePlanarPtm(*sample_, *photos_, o).seam_cost_per_texel;
  EXPECT_LT(cut, blend);
}

TEST_F(PlanarSynthesisTest, OrthonormalPlanesRoundTrip) {
  const ptm::Ptm back = FromOrthonormalPlanes(ToOrthonormalPlanes(*sample_), sample_->format);
  for (std::size_t i = 0; i < back.coefficients.size(); ++i) {
    ASSERT_NEAR(back.coefficients[i], sample_->coefficients[i], 1e-5);
  }
  EXPECT_LT(NearestPatchEnergy(*sample_, *sample_, 16), 1e-6);  // every patch is in the sample
}

TEST_F(PlanarSynthesisTest, BadPhotosAndOptionsAreCleanErrors) {
  PlanarSynthesisOptions o;
  o.block_size = 16;
  o.overlap = 4;
  o.width = 50;  // not a whole number of texels per photo pixel (photos are 32 wide)
  EXPECT_THROW(SynthesizePlanarPtm(*sample_, *photos_, o), InputError);
  o.width = 0;
  o.scale = 2;
  auto photos = *photos_;
  photos[1].image.width = 31;
  EXPECT_THROW(SynthesizePlanarPtm(*sample_, photos, o), InputError);
  o.block_size = 15;  // odd block with a photo scale of 2
  EXPECT_THROW(SynthesizePlanarPtm(*sample_, *photos_, o), OptionError);
  o.block_size = 128;  // larger than the sample
  EXPECT_THROW(SynthesizePlanarPtm(*sample_, *photos_, o), OptionError);
  o = {};
  o.overlap = 40;
  EXPECT_THROW(o.Check(), OptionError);
  EXPECT_THROW(SynthesizePlanarPtm(*sample_, {}, PlanarSynthesisOptions{}), InputError);
}

}  // namespace
}  // namespace texlume::synth
