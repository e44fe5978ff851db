// The BTF sample module (issue 8): capture loading, SVD factorisation (paper
// 004 §III), the error table, interpolation over the direction grid, the files.
#include "btf/btf.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "core/errors.h"
#include "pipeline/btf_synth_job.h"
#include "synth/mesh_synthesis.h"
#include "tests/test_util.h"

namespace texlume::btf {
namespace {

Eigen::Vector3d Direction(double elevation_deg, double azimuth_deg) {
  const double e = elevation_deg * M_PI / 180.0, a = azimuth_deg * M_PI / 180.0;
  return {std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)};
}

// A capture whose data matrix has exactly `rank` terms:
// f(x, v, l)_c = sum_i g_i(x) p_i(v, l)_c with random positive g and p.
BtfCapture RankCapture(int rank, unsigned seed) {
  BtfCapture c;
  c.width = 16;
  c.height = 12;
  c.texel_size = 0.002;
  c.views = {Direction(90, 0), Direction(60, 0), Direction(60, 120), Direction(60, 240)};
  c.lights = {Direction(70, 10), Direction(45, 80), Direction(45, 170), Direction(45, 260),
              Direction(25, 300)};
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.05f, 0.3f);
  std::vector<cv::Mat> g(static_cast<std::size_t>(rank));
  for (auto& m : g) {
    m.create(c.height, c.width, CV_32FC1);
    for (auto it = m.begin<float>(); it != m.end<float>(); ++it) *it = u(rng);
  }
  for (std::size_t k = 0; k < c.views.size() * c.lights.size(); ++k) {
    cv::Mat image = cv::Mat::zeros(c.height, c.width, CV_32FC3);
    for (int i = 0; i < rank; ++i) {
      // Drawn one at a time, last first: a call's arguments are evaluated in an
      // unspecified order (GCC right to left, clang left to right).
      const float p2 = u(rng), p1 = u(rng), p0 = u(rng);
      const cv::Vec3f p(p0, p1, p2);
      for (int y = 0; y < c.height; ++y)
        for (int x = 0; x < c.width; ++x)
          image.at<cv::Vec3f>(y, x) += g[static_cast<std::size_t>(i)].at<float>(y, x) * p;
    }
    c.images.push_back(image);
  }
  return c;
}

double RmsDifference(const cv::Mat& a, const cv::Mat& b) {
  return std::sqrt(cv::norm(a, b, cv::NORM_L2SQR) / static_cast<double>(a.total() * 3));
}

// Writes a capture as 16-bit sRGB PNGs and btf.json (the documented layout).
void WriteCapture(const BtfCapture& c, const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  nlohmann::json j = {{"width", c.width},
                      {"height", c.height},
                      {"texel_size", c.texel_size},
                      {"file_pattern", "view_%02d_light_%02d.png"}};
  for (const auto& v : c.views) j["views"].push_back({v.x(), v.y(), v.z()});
  for (const auto& l : c.lights) j["lights"].push_back({l.x(), l.y(), l.z()});
  testing::WriteText(dir / "btf.json", j.dump());
  for (std::size_t a = 0; a < c.views.size(); ++a)
    for (std::size_t b = 0; b < c.lights.size(); ++b) {
      const cv::Mat& linear = c.Image(a, b);
      cv::Mat bgr16(linear.rows, linear.cols, CV_16UC3);
      for (int y = 0; y < linear.rows; ++y)
        for (int x = 0; x < linear.cols; ++x)
          for (int ch = 0; ch < 3; ++ch)
            bgr16.at<cv::Vec3w>(y, x)[2 - ch] = static_cast<std::uint16_t>(
                std::lround(LinearToSrgb(linear.at<cv::Vec3f>(y, x)[ch]) * 65535.0));
      char name[64];
      std::snprintf(name, sizeof name, "view_%02zu_light_%02zu.png", a, b);
      cv::imwrite((dir / name).string(), bgr16);
    }
}

TEST(Btf, FactorisationOfARankThreeCaptureIsExactWithThreeTerms) {
  const BtfCapture capture = RankCapture(3, 7);
  const BtfFactorisation f = FactoriseBtf(capture, 3);
  ASSERT_EQ(f.Components(), 3);
  ASSERT_EQ(f.singular_values.size(), 4u * 5u * 3u);
  EXPECT_GT(f.singular_values[2], 1e-2);
  EXPECT_LT(f.singular_values[3], 1e-5 * f.singular_values[0]);
  // Every captured image back, at the grid's own directions.
  double worst = 0.0;
  for (std::size_t a = 0; a < capture.views.size(); ++a)
    for (std::size_t b = 0; b < capture.lights.size(); ++b)
      worst = std::max(worst, RmsDifference(EvaluateBtf(f, capture.views[a], capture.lights[b]),
                                            capture.Image(a, b)));
  EXPECT_LT(worst, 1e-5);
  const std::vector<SvdError> table = SvdErrorTable(f, {1, 2, 3});
  EXPECT_GT(table[0].rms, table[1].rms);
  EXPECT_LT(table[2].rms, 1e-5);
}

// The error table from the singular values equals the error measured by
// reconstructing every image with n terms.
TEST(Btf, ErrorTableMatchesTheMeasuredReconstructionError) {
  const BtfCapture capture = RankCapture(6, 11);
  const BtfFactorisation f = FactoriseBtf(capture, 6);
  for (int n : {1, 2, 4}) {
    double squared = 0.0;
    for (std::size_t a = 0; a < capture.views.size(); ++a)
      for (std::size_t b = 0; b < capture.lights.size(); ++b)
        squared += cv::norm(EvaluateBtf(f, capture.views[a], capture.lights[b], n),
                            capture.Image(a, b), cv::NORM_L2SQR);
    const double measured =
        std::sqrt(squared / (static_cast<double>(f.NumTexels()) * capture.images.size() * 3));
    const SvdError e = SvdErrorTable(f, {n})[0];
    EXPECT_NEAR(e.rms, measured, 1e-4 * measured + 1e-7) << n << " components";
    EXPECT_GT(e.relative, 0.0);
    EXPECT_LT(e.relative, 1.0);
  }
}

TEST(Btf, DirectionWeightsAreExactOnTheGridAndFavourTheNearest) {
  const std::vector<Eigen::Vector3d> grid = {Direction(90, 0), Direction(45, 0), Direction(45, 90),
                                             Direction(45, 180), Direction(45, 270)};
  const auto on = DirectionWeights(grid, grid[2]);
  ASSERT_EQ(on.size(), 1u);
  EXPECT_EQ(on[0].first, 2u);
  EXPECT_DOUBLE_EQ(on[0].second, 1.0);
  // Between the zenith and the 45-degree direction at azimuth 0, nearer the zenith.
  const auto between = DirectionWeights(grid, Direction(75, 0));
  ASSERT_EQ(between.size(), 3u);
  double sum = 0.0, zenith = 0.0, side = 0.0;
  for (const auto& [i, w] : between) {
    sum += w;
    if (i == 0) zenith = w;
    if (i == 1) side = w;
  }
  EXPECT_NEAR(sum, 1.0, 1e-12);
  EXPECT_GT(zenith, side);
  EXPECT_GT(side, 0.0);
}

// Interpolated appearance lies between its grid neighbours: a light halfway
// between two grid lights of a rank-1 capture gives values between theirs.
TEST(Btf, EvaluationBetweenGridDirectionsInterpolates) {
  const BtfCapture capture = RankCapture(1, 3);
  const BtfFactorisation f = FactoriseBtf(capture, 1);
  const Eigen::Vector3d mid = (capture.lights[1] + capture.lights[2]).normalized();
  const cv::Mat image = EvaluateBtf(f, capture.views[0], mid);
  const cv::Mat& a = capture.Image(0, 1);
  const cv::Mat& b = capture.Image(0, 2);
  int outside = 0;
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x)
      for (int c = 0; c < 3; ++c) {
        const float v = image.at<cv::Vec3f>(y, x)[c];
        const float lo = std::min(a.at<cv::Vec3f>(y, x)[c], b.at<cv::Vec3f>(y, x)[c]);
        const float hi = std::max(a.at<cv::Vec3f>(y, x)[c], b.at<cv::Vec3f>(y, x)[c]);
        // Three neighbours take part, so allow a third of the spread beyond.
        if (v < lo - 0.34f * (hi - lo) - 1e-5f || v > hi + 0.34f * (hi - lo) + 1e-5f) ++outside;
      }
  EXPECT_EQ(outside, 0);
}

TEST(Btf, CaptureFilesAndFactorisationFilesRoundTrip) {
  testing::TempDir tmp;
  const BtfCapture original = RankCapture(4, 5);
  WriteCapture(original, tmp / "capture");
  const BtfCapture read = ReadBtfCapture(tmp / "capture");
  ASSERT_EQ(read.width, original.width);
  ASSERT_EQ(read.height, original.height);
  ASSERT_EQ(read.images.size(), original.images.size());
  double worst = 0.0;
  for (std::size_t k = 0; k < read.images.size(); ++k)
    worst = std::max(worst, cv::norm(read.images[k], original.images[k], cv::NORM_INF));
  EXPECT_LT(worst, 2e-4);  // 16-bit sRGB
  const BtfFactorisation f = FactoriseBtf(read, 4);
  WriteBtfFactorisation(f, SvdErrorTable(f, {1, 4}), tmp / "svd");
  const BtfFactorisation back = ReadBtfFactorisation(tmp / "svd");
  EXPECT_EQ(back.Components(), 4);
  EXPECT_EQ(back.geometry, f.geometry);
  EXPECT_EQ(back.appearance, f.appearance);
  EXPECT_EQ(back.singular_values, f.singular_values);
  EXPECT_EQ(back.views.size(), f.views.size());
}

TEST(Btf, BadCapturesAndOptionsAreClearErrors) {
  testing::TempDir tmp;
  const BtfCapture capture = RankCapture(2, 9);
  WriteCapture(capture, tmp / "missing");
  std::filesystem::remove(tmp / "missing/view_01_light_03.png");
  EXPECT_NE(testing::InputErrorMessage([&] { ReadBtfCapture(tmp / "missing"); })
                .find("view_01_light_03.png: is missing: the capture has no image for view 1 "
                      "and light 3"),
            std::string::npos);

  WriteCapture(capture, tmp / "size");
  cv::imwrite((tmp / "size/view_02_light_00.png").string(), cv::Mat::zeros(5, 7, CV_8UC3));
  EXPECT_NE(testing::InputErrorMessage([&] {
              ReadBtfCapture(tmp / "size");
            }).find("view_02_light_00.png: is 7 x 5, not 16 x 12"),
            std::string::npos);

  WriteCapture(capture, tmp / "direction");
  nlohmann::json j = nlohmann::json::parse(testing::ReadText(tmp / "direction/btf.json"));
  j["lights"][2] = {0.5, 0.5, 0.5};
  testing::WriteText(tmp / "direction/btf.json", j.dump());
  EXPECT_NE(testing::InputErrorMessage([&] {
              ReadBtfCapture(tmp / "direction");
            }).find("lights[2] is not a unit vector"),
            std::string::npos);
  j["lights"][2] = {0.6, 0.8, -0.0};
  testing::WriteText(tmp / "direction/btf.json", j.dump());
  EXPECT_NE(testing::InputErrorMessage([&] {
              ReadBtfCapture(tmp / "direction");
            }).find("lights[2] is not above the sample"),
            std::string::npos);
  j["width"] = 1000000;
  testing::WriteText(tmp / "direction/btf.json", j.dump());
  EXPECT_NE(testing::InputErrorMessage([&] {
              ReadBtfCapture(tmp / "direction");
            }).find("'width' must be in [1, 16384]"),
            std::string::npos);

  // n larger than the data allows: 4 views x 5 lights x 3 channels = 60 columns.
  try {
    FactoriseBtf(capture, 61);
    ADD_FAILURE() << "61 components were accepted";
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("[1, 60]"), std::string::npos) << e.what();
  }
  EXPECT_THROW(FactoriseBtf(capture, 0), OptionError);
}

TEST(BtfSynthJobOptions, MissingPathsAndOutOfRangeSettingsAreRefused) {
  pipeline::BtfSynthJobOptions o;
  o.job.model_dir = "sparse";
  o.job.images_dir = "images";
  o.job.lights_file = "lights.json";
  o.job.mesh_file = "mesh.ply";
  o.job.out_dir = "model";
  o.btf = "btf";
  EXPECT_NO_THROW(o.Check());  // texel size 0: the capture's
  o.components = 0;
  EXPECT_THROW(o.Check(), OptionError);
  o.components = 40;
  o.synthesis.seam_band = 40;  // wider than the strip
  EXPECT_THROW(o.Check(), OptionError);
  o.synthesis.seam_band = 4;
  o.btf.clear();
  EXPECT_THROW(o.Check(), OptionError);
  EXPECT_THROW(pipeline::RunBtfSynthJob(o), OptionError);
}

}  // namespace
}  // namespace texlume::btf
