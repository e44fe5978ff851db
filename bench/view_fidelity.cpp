// Measures folders of rendered views against their ground truth (issue 29):
// PSNR and SSIM at full resolution and reduced, and the appearance figures of
// render/fidelity.h, averaged over the views. bench/fidelity_bench.sh uses it to
// put texlume, the baselines and "another instance" of the material side by side.
//
//   view_fidelity TRUTH_DIR MASKS_DIR REDUCED_FACTOR LABEL=DIR [LABEL=DIR ...]
//
// Every PNG of TRUTH_DIR is a view; each DIR must hold an image of that name.
//
// Then the display luma bias taken apart: what the truth's own display luma
// becomes when only its linear light is scaled by a row's linear bias, and when
// it is only made smoother (a Gaussian blur of the linear values): the sRGB
// curve is concave, so a smoother image with the same light reads brighter.
//
// Then what two resamplings cost the truth itself: each view turned about a
// point off the pixel grid and back, read bilinearly or Catmull-Rom each time
// (as an atlas is baked from a sample and then read by the renderer), and its
// gradient figures against the untouched view's.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "core/cubic_interpolation.h"
#include "core/errors.h"
#include "core/image_io.h"
#include "pipeline/render_job.h"
#include "render/fidelity.h"
#include "synth/material_sample.h"

namespace fs = std::filesystem;
using namespace texlume;

namespace {

struct Row {
  std::string label;
  render::ViewMetrics mean;
  std::vector<double> linear_luma_bias;  ///< per view
};

Row MeasureFolder(const std::string& label, const fs::path& dir, const std::vector<fs::path>& views,
                  const fs::path& truth_dir, const fs::path& masks_dir, int reduced_factor) {
  std::vector<render::ViewMetrics> metrics;
  for (const fs::path& view : views) {
    const std::string name = view.filename().string();
    const cv::Mat rgb = ReadPhotoRgb(dir / name);
    const cv::Mat coverage(rgb.size(), CV_8UC1, cv::Scalar(255));
    metrics.push_back(
        pipeline::MeasureAgainstTruth(name, rgb, coverage, truth_dir, masks_dir, reduced_factor));
  }
  std::vector<double> per_view;
  for (const render::ViewMetrics& m : metrics) per_view.push_back(m.fidelity.linear_luma_bias);
  return {label, render::MeanViewMetrics(metrics), per_view};
}

// The truth views' display and linear luma inside their masks, after `change`
// of their linear values.
struct LumaMeans {
  double display = 0, linear = 0;
};

template <typename Change>
LumaMeans TruthLuma(const std::vector<fs::path>& views, const fs::path& masks_dir,
                    const Change& change) {
  LumaMeans sum;
  for (const fs::path& view : views) {
    cv::Mat linear = ReadPhotoRgb(view);
    linear.forEach<cv::Vec3f>([](cv::Vec3f& p, const int*) {
      for (int c = 0; c < 3; ++c) p[c] = SrgbToLinear(p[c]);
    });
    linear = change(linear);
    linear.forEach<cv::Vec3f>([](cv::Vec3f& p, const int*) {
      for (int c = 0; c < 3; ++c) p[c] = LinearToSrgb(p[c]);
    });
    const cv::Mat mask = ReadImageGrey(masks_dir / view.filename()) > 0.5f;
    const render::AppearanceStats stats = render::MeasureAppearance(linear, mask);
    sum.display += stats.mean_luma, sum.linear += stats.mean_linear_luma;
  }
  return sum;
}

void PrintLumaBiasApart(const std::vector<Row>& rows, const std::vector<fs::path>& views,
                        const fs::path& masks_dir) {
  const LumaMeans truth = TruthLuma(views, masks_dir, [](const cv::Mat& m) { return m; });
  std::printf("\nThe display luma bias taken apart (the truth changed in its linear values):\n");
  for (const Row& row : rows) {
    const double scale = 1.0 + row.mean.fidelity.linear_luma_bias;
    const LumaMeans scaled =
        TruthLuma(views, masks_dir, [&](const cv::Mat& m) -> cv::Mat { return m * scale; });
    std::printf("- %s: linear %+.2f %%, display %+.2f %%; its linear bias alone gives %+.2f %%\n",
                row.label.c_str(), 100 * row.mean.fidelity.linear_luma_bias,
                100 * row.mean.fidelity.luma_bias, 100 * (scaled.display / truth.display - 1));
  }
  for (const double sigma_px : {0.5, 1.0, 1.5}) {
    const LumaMeans blurred = TruthLuma(views, masks_dir, [&](const cv::Mat& m) {
      cv::Mat out;
      cv::GaussianBlur(m, out, cv::Size(0, 0), sigma_px);
      return out;
    });
    std::printf("- the truth blurred by %.1f px: linear %+.2f %%, display %+.2f %%\n", sigma_px,
                100 * (blurred.linear / truth.linear - 1),
                100 * (blurred.display / truth.display - 1));
  }
}

// Each view's linear luma bias: a response that is wrong for one kind of lighting
// (a side light, a low one) shows in the views lit so.
void PrintLinearBiasPerView(const std::vector<Row>& rows, const std::vector<fs::path>& views) {
  std::printf("\nLinear luma bias per view (%%):\n| view |");
  for (const Row& row : rows) std::printf(" %s |", row.label.c_str());
  std::printf("\n|---|");
  for (std::size_t r = 0; r < rows.size(); ++r) std::printf("---|");
  std::printf("\n");
  for (std::size_t v = 0; v < views.size(); ++v) {
    std::printf("| %s |", views[v].stem().string().c_str());
    for (const Row& row : rows) std::printf(" %+.1f |", 100 * row.linear_luma_bias[v]);
    std::printf("\n");
  }
}

// `rgb` resampled at M (x, y, 1) for every pixel (x, y), centres at integers:
// bilinear or Catmull-Rom, both with exact weights and the taps clamped to the image.
cv::Mat Resampled(const cv::Mat& rgb, const cv::Matx23d& m, bool catmull_rom) {
  cv::Mat out(rgb.size(), rgb.type());
  const auto texel = [&](int tx, int ty, int c) { return rgb.at<cv::Vec3f>(ty, tx)[c]; };
  for (int y = 0; y < rgb.rows; ++y)
    for (int x = 0; x < rgb.cols; ++x) {
      const double sx = m(0, 0) * x + m(0, 1) * y + m(0, 2),
                   sy = m(1, 0) * x + m(1, 1) * y + m(1, 2);
      float* value = &out.at<cv::Vec3f>(y, x)[0];
      if (catmull_rom) {
        CatmullRomTaps(rgb.size(), sx, sy).Read(3, texel, value);
        continue;
      }
      std::array<double, 3> rgb_at{};
      synth::BilinearTaps(rgb.size(), sx, sy).OfChannels(rgb, rgb_at);
      for (int c = 0; c < 3; ++c)
        value[c] = static_cast<float>(rgb_at[static_cast<std::size_t>(c)]);
    }
  return out;
}

void PrintResamplingCost(const std::vector<fs::path>& views, const fs::path& masks_dir) {
  std::printf("\nThe truth turned 23 degrees about a point off the pixel grid and back:\n");
  for (const bool catmull_rom : {false, true}) {
    double emd = 0.0, p90 = 0.0, p90_truth = 0.0;
    for (const fs::path& view : views) {
      const cv::Mat truth = ReadPhotoRgb(view);
      cv::Mat mask = ReadImageGrey(masks_dir / view.filename()) > 0.5f;
      cv::erode(mask, mask, cv::Mat(), cv::Point(-1, -1), 3);  // the outline's blur left out
      const cv::Point2d centre(0.5 * truth.cols + 0.37, 0.5 * truth.rows + 0.61);
      const cv::Matx23d turn = cv::getRotationMatrix2D(centre, 23.0, 1.0);
      cv::Matx23d back;
      cv::invertAffineTransform(turn, back);
      const cv::Mat twice = Resampled(Resampled(truth, turn, catmull_rom), back, catmull_rom);
      const render::FidelityMetrics f = render::CompareAppearance(
          render::MeasureAppearance(twice, mask), render::MeasureAppearance(truth, mask));
      emd += f.gradient_histogram_distance, p90 += f.gradient_p90,
          p90_truth += f.gradient_p90_truth;
    }
    const double n = static_cast<double>(views.size());
    std::printf("- read %s each time: gradient EMD %.5f, p90 %.4f (the truth's %.4f)\n",
                catmull_rom ? "Catmull-Rom" : "bilinearly", emd / n, p90 / n, p90_truth / n);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: %s TRUTH_DIR MASKS_DIR REDUCED_FACTOR LABEL=DIR...\n", argv[0]);
    return 2;
  }
  try {
    const fs::path truth_dir = argv[1], masks_dir = argv[2];
    const int reduced_factor = std::stoi(argv[3]);
    std::vector<fs::path> views;
    for (const auto& e : fs::directory_iterator(truth_dir))
      if (e.path().extension() == ".png") views.push_back(e.path());
    std::sort(views.begin(), views.end());
    if (views.empty()) throw InputError(truth_dir.string(), "holds no PNG views");
    std::printf(
        "| %-16s | PSNR dB | SSIM | PSNR/%d | SSIM/%d | luma bias %% | linear %% | chroma %% | "
        "grad EMD | grad p90 (truth) | spectrum dB "
        "|\n|---|---|---|---|---|---|---|---|---|---|---|\n",
        "", reduced_factor, reduced_factor);
    std::vector<Row> rows;
    for (int i = 4; i < argc; ++i) {
      const std::string arg = argv[i];
      const std::size_t eq = arg.find('=');
      if (eq == std::string::npos) throw OptionError("expected LABEL=DIR, got " + arg);
      const Row row = MeasureFolder(arg.substr(0, eq), arg.substr(eq + 1), views, truth_dir,
                                    masks_dir, reduced_factor);
      const render::FidelityMetrics& f = row.mean.fidelity;
      std::printf(
          "| %-16s | %.2f | %.3f | %.2f | %.3f | %+.1f | %+.1f | %+.1f | %.5f | %.4f (%.4f) | %.2f "
          "|\n",
          row.label.c_str(), row.mean.psnr, row.mean.ssim, row.mean.psnr_reduced,
          row.mean.ssim_reduced, 100 * f.luma_bias, 100 * f.linear_luma_bias,
          100 * f.chroma_spread_ratio, f.gradient_histogram_distance, f.gradient_p90,
          f.gradient_p90_truth, f.power_spectrum_db);
      rows.push_back(row);
    }
    std::printf(
        "\nPower against the truth's per band (dB; band centre in cycles per pixel):\n| %-16s |",
        "");
    for (int k = 0; k < render::kSpectrumBands; ++k)
      std::printf(" %.3f |", std::pow(2.0, -7.0 + 6.0 * (k + 0.5) / render::kSpectrumBands));
    std::printf("\n|---|");
    for (int k = 0; k < render::kSpectrumBands; ++k) std::printf("---|");
    std::printf("\n");
    for (const Row& row : rows) {
      std::printf("| %-16s |", row.label.c_str());
      for (double db : row.mean.fidelity.band_power_db) std::printf(" %+.1f |", db);
      std::printf("\n");
    }
    PrintLumaBiasApart(rows, views, masks_dir);
    PrintLinearBiasPerView(rows, views);
    PrintResamplingCost(views, masks_dir);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "view_fidelity: %s\n", e.what());
    return 1;
  }
  return 0;
}
