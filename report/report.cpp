#include "report/report.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "core/check.h"
#include "core/errors.h"
#include "core/file_util.h"
#include "render/model_render.h"

namespace texlume::report {
namespace fs = std::filesystem;
namespace {

constexpr double kPi = 3.14159265358979323846;
// Elevation of the light-sweep and sample lights above the image (or sample) plane.
constexpr double kSweepElevationDeg = 40.0;

std::string Fixed(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

cv::Mat ResizedToWidth(const cv::Mat& image, int width, int interpolation = cv::INTER_AREA) {
  if (image.cols <= width) return image.clone();
  const int height = std::max(
      1, static_cast<int>(std::lround(static_cast<double>(image.rows) * width / image.cols)));
  cv::Mat out;
  cv::resize(image, out, cv::Size(width, height), 0, 0, interpolation);
  return out;
}

// Azimuth (degrees, from +x towards +y) and elevation (degrees above the xy plane).
std::string DirectionText(const Eigen::Vector3d& d) {
  const double az = std::atan2(d.y(), d.x()) * 180.0 / kPi;
  const double el = std::asin(std::clamp(d.z(), -1.0, 1.0)) * 180.0 / kPi;
  return "azimuth " + Fixed(az, 0) + "&deg;, elevation " + Fixed(el, 0) + "&deg;";
}

std::string LightsText(const std::vector<sfm::ObjectLight>& lights) {
  std::string text;
  for (const sfm::ObjectLight& l : lights) {
    if (!text.empty()) text += "; ";
    if (l.kind == sfm::ObjectLight::Kind::kDirectional) {
      text += "light " + DirectionText(l.direction_in_world);
    } else {
      text += "point light at (" + Fixed(l.position_in_world.x(), 2) + ", " +
              Fixed(l.position_in_world.y(), 2) + ", " + Fixed(l.position_in_world.z(), 2) + ")";
    }
    if (l.intensity != 1.0) text += " &times;" + Fixed(l.intensity, 2);
  }
  return text;
}

// The reference divided by its exposure (linear domain), back to display values.
cv::Mat WithoutGain(const cv::Mat& rgb, double gain) {
  if (gain == 1.0) return rgb;
  cv::Mat out = rgb.clone();
  out.forEach<cv::Vec3f>([gain](cv::Vec3f& p, const int*) {
    for (int c = 0; c < 3; ++c)
      p[c] = LinearToSrgb(std::min(1.0f, static_cast<float>(SrgbToLinear(p[c]) / gain)));
  });
  return out;
}

// Mean absolute difference over the channels, black (0) to bright at `max`,
// grey outside the mask.
cv::Mat ErrorMap(const cv::Mat& a, const cv::Mat& b, const cv::Mat& inside, double max) {
  cv::Mat diff;
  cv::absdiff(a, b, diff);
  std::vector<cv::Mat> channels;
  cv::split(diff, channels);
  cv::Mat mean = (channels[0] + channels[1] + channels[2]) / 3.0;
  cv::Mat scaled;
  mean.convertTo(scaled, CV_8UC1, 255.0 / max);
  cv::Mat colour;
  cv::applyColorMap(scaled, colour, cv::COLORMAP_INFERNO);
  colour.setTo(cv::Scalar(60, 60, 60), inside == 0);
  return colour;
}

std::string Figure(const std::string& src, const std::string& caption, int width) {
  return "<figure><img src=\"" + src + "\" width=\"" + std::to_string(width) +
         "\" alt=\"\"><figcaption>" + caption + "</figcaption></figure>";
}

}  // namespace

std::string HtmlEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::vector<double> AtlasOccupancies(const model::TexturedModel& model) {
  std::vector<cv::Mat> inside;
  for (const ptm::Ptm& a : model.atlases) inside.emplace_back(a.height, a.width, CV_8UC1, 0);
  constexpr int kShift = 4;  // sub-texel vertex positions
  for (std::size_t f = 0; f < model.corner_px.size(); ++f) {
    const std::size_t a = static_cast<std::size_t>(model.face_atlas[f]);
    if (a >= inside.size()) continue;
    cv::Point corners[3];
    for (int k = 0; k < 3; ++k) {
      // Texel centres at +0.5: texel (x, y) is inside when its centre is.
      corners[k] = cv::Point(
          static_cast<int>(std::lround((model.corner_px[f][k].x() - 0.5f) * (1 << kShift))),
          static_cast<int>(std::lround((model.corner_px[f][k].y() - 0.5f) * (1 << kShift))));
    }
    cv::fillConvexPoly(inside[a], corners, 3, cv::Scalar(255), cv::LINE_8, kShift);
  }
  std::vector<double> occupancy;
  for (const cv::Mat& m : inside)
    occupancy.push_back(m.total() ? static_cast<double>(cv::countNonZero(m)) /
                                        static_cast<double>(m.total())
                                  : 0.0);
  return occupancy;
}

ReportSummary WriteReport(const fs::path& dir, const ReportInputs& in,
                          const ProgressCallback& progress) {
  TEXLUME_CHECK(in.model != nullptr, "the report needs a model");
  if (in.picture_width < 32 || in.picture_width > 4096)
    throw OptionError("report picture width must be in [32, 4096]");
  if (in.max_views < 0 || in.max_photos < 0 || in.sweep_frames < 0 || in.sweep_frames > 64)
    throw OptionError("report counts must be non-negative (sweep frames at most 64)");
  const auto start = std::chrono::steady_clock::now();
  ReportSummary summary;
  fs::create_directories(dir);
  const fs::path pictures = dir / "report";
  const fs::path tmp = dir / ("report.partial-" + std::to_string(::getpid()));
  fs::remove_all(tmp);
  fs::create_directories(tmp);
  std::ostringstream html;
  try {
    // Which views and photos are drawn: evenly spread over the lists.
    auto spread = [](std::size_t n, int wanted) {
      std::vector<std::size_t> picked;
      const std::size_t k = std::min<std::size_t>(n, static_cast<std::size_t>(wanted));
      for (std::size_t i = 0; i < k; ++i) picked.push_back(i * n / k);
      return picked;
    };
    const std::vector<std::size_t> view_ids = spread(in.views.size(), in.max_views);
    const std::vector<std::size_t> photo_ids = spread(in.photos.size(), in.max_photos);
    const bool has_sweep = !in.views.empty() && in.sweep_frames > 0;
    const std::size_t steps = (in.sample ? 1 : 0) + photo_ids.size() + view_ids.size() +
                              (has_sweep ? 1 : 0) + in.model->atlases.size();
    std::size_t step = 0;
    auto advance = [&] {
      ++step;
      if (progress) progress("report", step, steps);
    };
    auto write_picture = [&](const std::string& name, const cv::Mat& bgr8) {
      WriteBytesAtomically(tmp / name, EncodePng(bgr8, (pictures / name).string()));
      ++summary.pictures;
      return "report/" + name;
    };

    html << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>"
         << HtmlEscape(in.title)
         << "</title>\n<style>body{font-family:sans-serif;margin:2em;max-width:110em}"
            "td,th{padding:3px 9px;text-align:left;vertical-align:top}"
            "table.m td{text-align:right}figure{display:inline-block;margin:4px}"
            "figcaption{font-size:smaller;max-width:24em}.strip img{margin:0}"
            "h2{margin-top:1.6em}</style></head><body>\n<h1>"
         << HtmlEscape(in.title) << "</h1>\n<p>" << HtmlEscape(in.intro) << "</p>\n";
    if (!in.facts.empty()) {
      html << "<table>";
      for (const auto& [name, value] : in.facts)
        html << "<tr><th>" << HtmlEscape(name) << "</th><td>" << HtmlEscape(value) << "</td></tr>";
      html << "</table>\n";
    }
    if (!in.links.empty()) {
      html << "<p>Files: ";
      for (std::size_t i = 0; i < in.links.size(); ++i)
        html << (i ? ", " : "") << "<a href=\"" << HtmlEscape(in.links[i].second) << "\">"
             << HtmlEscape(in.links[i].first) << "</a>";
      html << ".</p>\n";
    }

    // The material sample relit: head-on, then four lights around it.
    if (in.sample) {
      html << "<h2>Material sample</h2>\n<p>The sample PTM (" << in.sample->width << " &times; "
           << in.sample->height << " texels) relit in its own frame.</p>\n";
      std::vector<Eigen::Vector3d> lights = {Eigen::Vector3d::UnitZ()};
      const double el = kSweepElevationDeg * kPi / 180.0;
      for (int k = 0; k < 4; ++k) {
        const double az = k * kPi / 2.0;
        lights.emplace_back(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
      }
      const int width = std::min(200, in.sample->width);
      for (std::size_t k = 0; k < lights.size(); ++k) {
        const std::vector<float> rgb = ptm::Relight(*in.sample, lights[k]);
        const cv::Mat image(in.sample->height, in.sample->width, CV_32FC3,
                            const_cast<float*>(rgb.data()));
        const std::string src = write_picture("sample_light_" + std::to_string(k) + ".png",
                                              ToBgr8(ResizedToWidth(image, width)));
        html << Figure(src, "light " + DirectionText(lights[k]), width);
      }
      html << "\n";
      advance();
    }

    // The constraint photos.
    if (!photo_ids.empty()) {
      html << "<h2>Constraint photos</h2>\n<p>" << photo_ids.size() << " of the "
           << in.photos.size()
           << " photos that constrain the synthesis, with their lights (world frame).</p>\n";
      for (const std::size_t i : photo_ids) {
        const ReportPhoto& p = in.photos[i];
        const cv::Mat image = ResizedToWidth(p.image.empty() ? ReadPhotoRgb(p.file) : p.image, 200);
        const std::string src = write_picture("photo_" + std::to_string(i) + ".png", ToBgr8(image));
        html << Figure(src, HtmlEscape(p.name) + "<br>" + LightsText(p.lights), 200);
        advance();
      }
      html << "\n";
    }

    // The model from the views, beside the reference, the baselines and error maps.
    render::ModelRenderer renderer(*in.model);
    renderer.flat_albedo = in.flat_albedo;
    renderer.baked = in.baked;
    std::vector<std::pair<std::string, render::RenderMode>> modes = {{"texlume", render::RenderMode::kPtm},
                                                             {"flat", render::RenderMode::kFlat}};
    if (!in.baked.empty()) modes.emplace_back("baked", render::RenderMode::kBaked);
    auto scaled_camera = [&](const sfm::Camera& camera) {
      const double factor =
          std::min(1.0, static_cast<double>(in.picture_width) / static_cast<double>(camera.width));
      return factor < 1.0 ? camera.Scaled(factor) : camera;
    };
    if (!view_ids.empty()) {
      html << "<h2>" << HtmlEscape(in.views_heading) << "</h2>\n<p>" << view_ids.size() << " of "
           << in.views.size()
           << " views. Error maps: mean absolute difference over the channels inside the mask, "
              "from black (0) to bright yellow ("
           << Fixed(in.error_map_max, 2)
           << " or more, display values in [0, 1]); grey outside. PSNR (dB) and SSIM at the "
              "pictures' resolution.</p>\n<table><tr><th>reference</th>";
      for (const auto& [name, mode] : modes) html << "<th>" << name << " (and its error)</th>";
      html << "</tr>\n";
      for (const std::size_t i : view_ids) {
        const ReportView& v = in.views[i];
        const sfm::Camera camera = scaled_camera(v.camera);
        const std::string stem = "view_" + std::to_string(i);
        cv::Mat reference, inside;
        html << "<tr>";
        if (!v.reference_image.empty() || !v.reference.empty()) {
          const cv::Mat full = v.reference.empty() ? ReadPhotoRgb(v.reference_image) : v.reference;
          if (full.cols != static_cast<int>(v.camera.width) ||
              full.rows != static_cast<int>(v.camera.height))
            throw InputError(v.reference_image.string(), "does not match its camera's size");
          cv::resize(WithoutGain(full, v.reference_gain), reference,
                     cv::Size(static_cast<int>(camera.width), static_cast<int>(camera.height)), 0,
                     0, cv::INTER_AREA);
          if (!v.reference_mask.empty()) {
            const cv::Mat mask = ReadImageGrey(v.reference_mask) > 0.5f;
            if (mask.size() != full.size())
              throw InputError(v.reference_mask.string(), "does not match its image's size");
            cv::resize(mask, inside, reference.size(), 0, 0, cv::INTER_NEAREST);
            inside = inside > 127;
          }
          html << "<td>"
               << Figure(write_picture(stem + "_reference.png", ToBgr8(reference)),
                         HtmlEscape(v.name) + "<br>" + LightsText(v.lights), camera.width)
               << "</td>";
        } else {
          html << "<td>" << HtmlEscape(v.name) << "<br>" << LightsText(v.lights) << "</td>";
        }
        for (const auto& [name, mode] : modes) {
          const render::RenderedView r = renderer.Render(camera, v.cam_from_world, v.lights, mode, 2);
          html << "<td>"
               << Figure(write_picture(stem + "_" + name + ".png", ToBgr8(r.rgb)), name,
                         camera.width);
          if (reference.empty()) {
            html << "</td>";
            continue;
          }
          if (inside.empty()) inside = r.coverage > 0.5f;
          ReportSummary::Row row{v.name, name, render::MaskedPsnr(r.rgb, reference, inside),
                                 render::MaskedSsim(r.rgb, reference, inside)};
          html << "<br>"
               << Figure(write_picture(stem + "_" + name + "_error.png",
                                       ErrorMap(r.rgb, reference, inside, in.error_map_max)),
                         "error: " + Fixed(row.psnr, 2) + " dB, SSIM " + Fixed(row.ssim, 3),
                         camera.width)
               << "</td>";
          summary.rows.push_back(row);
        }
        html << "</tr>\n";
        advance();
      }
      html << "</table>\n";
    }

    // A light circling the first view.
    if (has_sweep) {
      const ReportView& v = in.views[view_ids.front()];
      const sfm::Camera camera =
          v.camera.Scaled(std::min(1.0, 160.0 / static_cast<double>(v.camera.width)));
      const Eigen::Matrix3d world_from_cam =
          v.cam_from_world.rotation.toRotationMatrix().transpose();
      const double el = kSweepElevationDeg * kPi / 180.0;
      std::vector<cv::Mat> frames;
      for (int k = 0; k < in.sweep_frames; ++k) {
        const double az = 2.0 * kPi * k / in.sweep_frames;
        // Camera frame: x right, y down, z forward; the light on the viewer's side.
        const Eigen::Vector3d towards_light_in_cam(std::cos(el) * std::cos(az),
                                                   -std::cos(el) * std::sin(az), -std::sin(el));
        sfm::ObjectLight light;
        light.direction_in_world = (world_from_cam * towards_light_in_cam).normalized();
        frames.push_back(
            ToBgr8(renderer.Render(camera, v.cam_from_world, {light}, render::RenderMode::kPtm, 2).rgb));
      }
      cv::Mat strip;
      cv::hconcat(frames, strip);
      html << "<h2>Light sweep</h2>\n<p>The model from " << HtmlEscape(v.name)
           << " with the light circling the viewing axis at " << Fixed(kSweepElevationDeg, 0)
           << "&deg; above the image plane, starting at the right and turning counter-clockwise "
              "in steps of "
           << Fixed(360.0 / in.sweep_frames, 0) << "&deg;.</p>\n<div class=\"strip\"><img src=\""
           << write_picture("light_sweep.png", strip) << "\" width=\"" << strip.cols
           << "\" alt=\"\"></div>\n";
      advance();
    }

    // Atlases: base colour with the triangle outlines, and occupancy.
    {
      const std::vector<double> occupancy = AtlasOccupancies(*in.model);
      html << "<h2>Atlases</h2>\n<p>" << in.model->atlases.size()
           << " atlas(es), occupancy of the layout " << Fixed(in.occupancy, 3)
           << " (atlas texels inside triangles); the PTM under a head-on light, triangle outlines "
              "in green.</p>\n";
      for (std::size_t a = 0; a < in.model->atlases.size(); ++a) {
        const ptm::Ptm& atlas = in.model->atlases[a];
        const int width = std::min(480, atlas.width);
        const double s = static_cast<double>(width) / atlas.width;
        cv::Mat thumb = ResizedToWidth(model::BaseColourImage(atlas), width);
        cv::Mat outlines = thumb.clone();
        constexpr int kShift = 3;
        for (std::size_t f = 0; f < in.model->corner_px.size(); ++f) {
          if (static_cast<std::size_t>(in.model->face_atlas[f]) != a) continue;
          std::vector<cv::Point> corners;
          for (int k = 0; k < 3; ++k)
            corners.emplace_back(
                static_cast<int>(std::lround(in.model->corner_px[f][k].x() * s * (1 << kShift))),
                static_cast<int>(std::lround(in.model->corner_px[f][k].y() * s * (1 << kShift))));
          cv::polylines(outlines, corners, true, cv::Scalar(60, 220, 60), 1, cv::LINE_AA, kShift);
        }
        cv::addWeighted(thumb, 0.7, outlines, 0.3, 0.0, thumb);
        html << Figure(write_picture("atlas_" + std::to_string(a) + ".png", thumb),
                       "atlas " + std::to_string(a) + ": " + std::to_string(atlas.width) +
                           " &times; " + std::to_string(atlas.height) + " texels, occupancy " +
                           Fixed(occupancy[a], 3),
                       width);
        advance();
      }
      html << "\n";
    }

    // Metrics.
    if (!in.metrics.empty() || !summary.rows.empty()) html << "<h2>Metrics</h2>\n";
    if (!in.metrics.empty()) {
      html << "<p>Every held-out view, inside the ground-truth masks, as <code>texlume "
              "render</code> measured it at full resolution and reduced to the photos' "
              "resolution.</p>\n<table class=\"m\" border=\"1\"><tr><th>model</th><th>PSNR "
              "full (dB)</th><th>SSIM full</th><th>PSNR reduced (dB)</th><th>SSIM "
              "reduced</th></tr>\n";
      for (const ReportMetrics& m : in.metrics)
        html << "<tr><th>" << HtmlEscape(m.label) << "</th><td>" << Fixed(m.mean_psnr, 2)
             << "</td><td>" << Fixed(m.mean_ssim, 3) << "</td><td>"
             << Fixed(m.mean_psnr_reduced, 2) << "</td><td>"
             << Fixed(m.mean_ssim_reduced, 3) << "</td></tr>\n";
      html << "</table>\n<p>Per view (PSNR dB / SSIM at full resolution):</p>\n<table class=\"m\" "
              "border=\"1\"><tr><th>view</th>";
      for (const ReportMetrics& m : in.metrics) html << "<th>" << HtmlEscape(m.label) << "</th>";
      html << "</tr>\n";
      for (std::size_t i = 0; i < in.metrics.front().views.size(); ++i) {
        html << "<tr><th>" << HtmlEscape(in.metrics.front().views[i].name) << "</th>";
        for (const ReportMetrics& m : in.metrics) {
          if (i < m.views.size())
            html << "<td>" << Fixed(m.views[i].psnr, 2) << " / "
                 << Fixed(m.views[i].ssim, 3) << "</td>";
          else
            html << "<td></td>";
        }
        html << "</tr>\n";
      }
      html << "</table>\n";
    }
    if (!summary.rows.empty()) {
      html << "<p>On the pictures above (their resolution, inside the mask):</p>\n<table "
              "class=\"m\" "
              "border=\"1\"><tr><th>view</th><th>model</th><th>PSNR (dB)</th><th>SSIM</th></tr>\n";
      for (const ReportSummary::Row& r : summary.rows)
        html << "<tr><th>" << HtmlEscape(r.view) << "</th><td>" << r.model << "</td><td>"
             << Fixed(r.psnr, 2) << "</td><td>" << Fixed(r.ssim, 3) << "</td></tr>\n";
      html << "</table>\n";
    }

    summary.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    html << "<h2>Timings</h2>\n<table class=\"m\" border=\"1\"><tr><th>stage</th><th>seconds</th>"
            "</tr>\n";
    for (const auto& [stage, seconds] : in.timings_s)
      html << "<tr><th>" << HtmlEscape(stage) << "</th><td>" << Fixed(seconds, 2) << "</td></tr>\n";
    html << "<tr><th>this report</th><td>" << Fixed(summary.seconds, 2)
         << "</td></tr>\n</table>\n</body></html>\n";

    fs::remove_all(pictures);
    fs::rename(tmp, pictures);
  } catch (const fs::filesystem_error& e) {
    std::error_code ec;
    fs::remove_all(tmp, ec);
    throw InputError(pictures.string(), std::string("cannot be written: ") + e.what());
  } catch (...) {
    std::error_code ec;
    fs::remove_all(tmp, ec);
    throw;
  }
  WriteFileAtomically(
      dir / "report.html", [&](std::ostream& o) { o << html.str(); }, false);
  return summary;
}

}  // namespace texlume::report
