#include "ptm/sphere_lights.h"

#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "core/errors.h"
#include "core/image_io.h"

namespace texlume::ptm {

std::optional<Eigen::Vector2d> FindHighlight(const cv::Mat& gray, const SphereCircle& circle,
                                             const HighlightOptions& options) {
  CV_Assert(gray.type() == CV_32FC1);
  const double r = circle.radius * options.search_radius_fraction;
  const int x0 = std::max(0, static_cast<int>(std::floor(circle.center_x - r)));
  const int x1 = std::min(gray.cols - 1, static_cast<int>(std::ceil(circle.center_x + r)));
  const int y0 = std::max(0, static_cast<int>(std::floor(circle.center_y - r)));
  const int y1 = std::min(gray.rows - 1, static_cast<int>(std::ceil(circle.center_y + r)));
  auto inside = [&](int x, int y) {
    return std::hypot(x + 0.5 - circle.center_x, y + 0.5 - circle.center_y) <= r;
  };
  float peak = 0.0f;
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x)
      if (inside(x, y)) peak = std::max(peak, gray.at<float>(y, x));
  if (!(peak > 0.0f)) return std::nullopt;
  const float threshold = static_cast<float>(options.threshold_fraction) * peak;
  double sx = 0, sy = 0, sw = 0;
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const float v = gray.at<float>(y, x);
      if (!inside(x, y) || v < threshold) continue;
      const double w = v - threshold + 1e-6;
      sx += w * (x + 0.5);
      sy += w * (y + 0.5);
      sw += w;
    }
  }
  if (sw <= 0) return std::nullopt;
  return Eigen::Vector2d(sx / sw, sy / sw);
}

Eigen::Vector3d LightFromHighlight(const SphereCircle& circle,
                                   const Eigen::Vector2d& highlight_px) {
  double nx = (highlight_px.x() - circle.center_x) / circle.radius;
  double ny = -(highlight_px.y() - circle.center_y) / circle.radius;  // image rows go down
  const double r2 = nx * nx + ny * ny;
  if (r2 > 1.0) {
    nx /= std::sqrt(r2);
    ny /= std::sqrt(r2);
  }
  const double nz = std::sqrt(std::max(0.0, 1.0 - nx * nx - ny * ny));
  const Eigen::Vector3d n(nx, ny, nz);
  return (2.0 * nz * n - Eigen::Vector3d::UnitZ()).normalized();
}

SphereCircle DetectSphere(const std::vector<cv::Mat>& gray_images, const std::string& label) {
  if (gray_images.empty()) throw InputError(label, "no images to find the sphere in");
  cv::Mat mean = cv::Mat::zeros(gray_images[0].size(), CV_32FC1);
  for (const cv::Mat& g : gray_images) mean += g;
  mean /= static_cast<double>(gray_images.size());
  cv::Mat bytes;
  mean.convertTo(bytes, CV_8UC1, 255.0);
  cv::GaussianBlur(bytes, bytes, cv::Size(5, 5), 1.5);
  std::vector<cv::Vec3f> circles;
  const int min_side = std::min(bytes.rows, bytes.cols);
  cv::HoughCircles(bytes, circles, cv::HOUGH_GRADIENT, 1.5, min_side / 4.0, 100, 30, min_side / 20,
                   min_side / 2);
  if (circles.empty()) {
    throw InputError(label, "no sphere found in the photos; give its circle (--circle cx,cy,r)");
  }
  // Refine to sub-pixel on the maximum over the photos (cast shadows vanish there,
  // the sphere stays dark but for small highlights): the dark disk's coverage,
  // interpolated between the inside and the surrounding ring, gives the centre
  // (centroid) and radius (area). OpenCV's pixel centres are integers.
  cv::Mat brightest = gray_images[0].clone();
  for (const cv::Mat& g : gray_images) brightest = cv::max(brightest, g);
  mean = brightest;
  const double hx = circles[0][0] + 0.5, hy = circles[0][1] + 0.5, hr = circles[0][2];
  std::vector<float> inside, ring;
  for (int y = 0; y < mean.rows; ++y) {
    for (int x = 0; x < mean.cols; ++x) {
      const double d = std::hypot(x + 0.5 - hx, y + 0.5 - hy);
      if (d < 0.6 * hr) inside.push_back(mean.at<float>(y, x));
      if (d > 1.15 * hr && d < 1.35 * hr) ring.push_back(mean.at<float>(y, x));
    }
  }
  auto median = [](std::vector<float>& v) {
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  if (inside.empty() || ring.empty()) return {hx, hy, hr};
  const float inner = median(inside), outer = median(ring);
  if (!(outer > inner)) return {hx, hy, hr};  // not a dark disk: keep the Hough circle
  double sx = 0, sy = 0, area = 0;
  for (int y = 0; y < mean.rows; ++y) {
    for (int x = 0; x < mean.cols; ++x) {
      if (std::hypot(x + 0.5 - hx, y + 0.5 - hy) > 1.25 * hr) continue;
      // Partial coverage by linear interpolation between the two levels.
      const double w = std::clamp((outer - mean.at<float>(y, x)) / (outer - inner), 0.0f, 1.0f);
      sx += w * (x + 0.5);
      sy += w * (y + 0.5);
      area += w;
    }
  }
  if (area < 10) return {hx, hy, hr};
  return {sx / area, sy / area, std::sqrt(area / M_PI)};
}

void HighlightOptions::Check() const {
  if (!(threshold_fraction > 0.0 && threshold_fraction <= 1.0))
    throw OptionError("highlight threshold must be in (0, 1]");
  if (!(search_radius_fraction > 0.0 && search_radius_fraction <= 1.0))
    throw OptionError("highlight search radius must be in (0, 1] of the sphere's");
}

// A circle given by the user must have its centre in the photos and a radius no
// larger than they are wide, or every search below runs off the image.
static void CheckCircleInPhotos(const SphereCircle& c, const cv::Size& size,
                                const std::string& label) {
  const bool inside = c.center_x >= 0.0 && c.center_x <= size.width && c.center_y >= 0.0 &&
                      c.center_y <= size.height && c.radius > 0.0 &&
                      c.radius <= std::max(size.width, size.height);
  if (!inside) {
    std::ostringstream message;
    message << "the sphere's circle (" << c.center_x << ", " << c.center_y << ", radius "
            << c.radius << ") does not lie in the " << size.width << " x " << size.height
            << " photos of " << label;
    throw OptionError(message.str());
  }
}

std::vector<sfm::LpEntry> LightsFromSphere(const std::vector<std::filesystem::path>& files,
                                           std::optional<SphereCircle> circle,
                                           const HighlightOptions& options,
                                           std::vector<std::string>* skipped,
                                           SphereCircle* used_circle) {
  options.Check();
  std::vector<cv::Mat> gray;
  for (const auto& file : files) {
    cv::Mat f = ReadImageGrey(file);
    if (!gray.empty() && f.size() != gray[0].size()) {
      throw InputError(file.string(), "differs in size from " + files[0].string());
    }
    gray.push_back(f);
  }
  const std::string label = files.empty() ? "images" : files[0].parent_path().string();
  if (circle && !gray.empty()) CheckCircleInPhotos(*circle, gray[0].size(), label);
  const SphereCircle c = circle ? *circle : DetectSphere(gray, label);
  if (!(c.radius > 2.0)) throw InputError(label, "sphere radius must be more than 2 pixels");
  if (used_circle) *used_circle = c;
  std::vector<sfm::LpEntry> entries;
  for (std::size_t i = 0; i < files.size(); ++i) {
    const auto highlight = FindHighlight(gray[i], c, options);
    if (!highlight) {
      if (skipped) skipped->push_back(files[i].filename().string());
      continue;
    }
    entries.push_back({files[i].filename().string(), LightFromHighlight(c, *highlight)});
  }
  return entries;
}

}  // namespace texlume::ptm
