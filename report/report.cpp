#include "report/report.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "core/check.h"
#include "core/errors.h"
#include "core/file_util.h"
#include "core/partial_output.h"
#include "core/provenance.h"
#include "core/timing.h"
#include "core/units.h"
#include "model/web_model.h"

namespace texlume::report {
namespace fs = std::filesystem;
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string Fixed(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
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

// The error maps' colour scale: 256 x 24, from 0 at the left to the maximum at the
// right (the caption gives the values), with a white tick every quarter.
cv::Mat ErrorScale() {
  cv::Mat ramp(24, 256, CV_8UC1);
  for (int x = 0; x < ramp.cols; ++x) ramp.col(x).setTo(x);
  cv::Mat colour;
  cv::applyColorMap(ramp, colour, cv::COLORMAP_INFERNO);
  for (int q = 1; q < 4; ++q) colour(cv::Rect(q * 64, 16, 1, 8)).setTo(cv::Scalar(255, 255, 255));
  return colour;
}

// A length for a scale bar: millimetre units when the world unit is known, else world units.
std::string ScaleBarLabel(double world_units, double mm_per_world_unit) {
  if (mm_per_world_unit > 0.0) return MillimetreText(world_units * mm_per_world_unit);
  return ThreeSignificantDigits(world_units) + " units";
}

// `bgr8` with a scale bar at its lower left: the longest 1-2-5 length (in mm when
// `mm_per_world_unit` > 0, else in world units) that fits in a quarter of its width, given
// that one pixel spans `world_per_px` world units. Unchanged when that is not positive.
cv::Mat WithScaleBar(const cv::Mat& bgr8, double world_per_px, double mm_per_world_unit) {
  cv::Mat out = bgr8.clone();
  if (!(world_per_px > 0.0) || out.cols < 40 || out.rows < 30) return out;
  const double unit = mm_per_world_unit > 0.0 ? mm_per_world_unit : 1.0;  // display per world
  const double length = NiceLengthAtMost(0.25 * out.cols * world_per_px * unit);
  const int bar_px = static_cast<int>(std::lround(length / (world_per_px * unit)));
  if (bar_px < 4) return out;
  const std::string label = ScaleBarLabel(length / unit, mm_per_world_unit);
  const cv::Point left(6, out.rows - 8), right(6 + bar_px, out.rows - 8);
  cv::line(out, left, right, cv::Scalar(0, 0, 0), 5);
  cv::line(out, left, right, cv::Scalar(255, 255, 255), 3);
  const cv::Point text_at(6, out.rows - 14);
  cv::putText(out, label, text_at, cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0), 3,
              cv::LINE_AA);
  cv::putText(out, label, text_at, cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(255, 255, 255), 1,
              cv::LINE_AA);
  return out;
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
  std::vector<double> occupancy;
  for (const cv::Mat& charts : model::AtlasChartRegions(model))
    occupancy.push_back(charts.total() ? static_cast<double>(cv::countNonZero(charts >= 0)) /
                                             static_cast<double>(charts.total())
                                       : 0.0);
  return occupancy;
}

namespace {

// The report's sections, each a method, written into one page and a folder of
// pictures (WriteReport).
class ReportWriter {
 public:
  ReportWriter(const ReportInputs& in, const fs::path& pictures, const fs::path& tmp,
               const ProgressCallback& progress)
      : in_(in), pictures_(pictures), tmp_(tmp), progress_(progress) {
    photo_ids_ = render::EvenlySpread(in.photos.size(), in.max_photos);
    steps_ = (in.sample_relit.empty() ? 0 : 1) + photo_ids_.size() + in.views.size() +
             (in.sweep.empty() ? 0 : 1) + in.model->atlases.size();
  }

  void Write() {
    Header();
    Sample();
    Lights();
    Photos();
    Views();
    Sweep();
    Atlases();
    Metrics();
  }

  // The timings table (with this report's own time) and the page's end.
  std::string Finish(double seconds) {
    html_ << "<h2>Timings</h2>\n<table class=\"m\" border=\"1\"><tr><th>stage</th><th>seconds</th>"
             "</tr>\n";
    for (const auto& [stage, s] : in_.timings_s)
      html_ << "<tr><th>" << HtmlEscape(stage) << "</th><td>" << Fixed(s, 2) << "</td></tr>\n";
    html_ << "<tr><th>this report</th><td>" << Fixed(seconds, 2)
          << "</td></tr>\n</table>\n</body></html>\n";
    return html_.str();
  }

  ReportSummary& summary() { return summary_; }

 private:
  void Advance() {
    ++step_;
    if (progress_) progress_("report", step_, steps_);
  }

  // "; its texel spans 0.002 world units (2 mm) on the object, ..." for the sample and atlas
  // sections (`whose`: "its", "an atlas"); empty when the texel size is unknown.
  std::string ScaleText(const std::string& whose) const {
    if (!(in_.texel_size > 0.0)) return "";
    return "; " + whose + " texel spans " + WorldLengthText(in_.texel_size, in_.mm_per_world_unit) +
           " on the object, a bar at the lower left of a picture large enough for it (the "
           "sample's head-on one, each atlas) gives the scale" +
           (in_.mm_per_world_unit > 0.0 ? "" : " (no --world-unit was given: world units)");
  }

  std::string WritePicture(const std::string& name, const cv::Mat& bgr8) {
    WriteBytesAtomically(tmp_ / name, EncodePng(bgr8, (pictures_ / name).string()));
    ++summary_.pictures;
    return "report/" + name;
  }

  // Title, introduction, facts and links.
  void Header() {
    html_ << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>"
          << HtmlEscape(in_.title)
          << "</title>\n<style>body{font-family:sans-serif;margin:2em;max-width:110em}"
             "td,th{padding:3px 9px;text-align:left;vertical-align:top}"
             "table.m td{text-align:right}figure{display:inline-block;margin:4px}"
             "figcaption{font-size:smaller;max-width:24em}.strip img{margin:0}"
             "h2{margin-top:1.6em}</style></head><body>\n<h1>"
          << HtmlEscape(in_.title) << "</h1>\n<p>" << HtmlEscape(in_.intro) << "</p>\n";
    if (!in_.facts.empty()) {
      html_ << "<table>";
      for (const auto& [name, value] : in_.facts)
        html_ << "<tr><th>" << HtmlEscape(name) << "</th><td>" << HtmlEscape(value) << "</td></tr>";
      html_ << "</table>\n";
    }
    if (!in_.links.empty()) {
      html_ << "<p>Files: ";
      for (std::size_t i = 0; i < in_.links.size(); ++i)
        html_ << (i ? ", " : "") << "<a href=\"" << HtmlEscape(in_.links[i].second) << "\">"
              << HtmlEscape(in_.links[i].first) << "</a>";
      html_ << ".</p>\n";
    }
    if (!in_.view_folder.empty())
      html_ << "<p>Preview the model under any light: <code>texlume view "
            << HtmlEscape(in_.view_folder) << "</code> (a page at http://127.0.0.1:8080/).</p>\n";
    Provenance();
  }

  // texlume's version, the command line and the inputs' checksums.
  void Provenance() {
    html_ << "<details><summary>Provenance</summary><table>"
          << "<tr><th>texlume</th><td>" << HtmlEscape(TexlumeVersion()) << "</td></tr>";
    if (!RecordedCommandLine().empty())
      html_ << "<tr><th>command</th><td><code>" << HtmlEscape(RecordedCommandLine())
            << "</code></td></tr>";
    for (const auto& [name, file] : in_.inputs)
      html_ << "<tr><th>" << HtmlEscape(name) << "</th><td><code>" << HtmlEscape(file.string())
            << "</code>, CRC-32 " << FileCrc32(file) << "</td></tr>";
    html_ << "</table></details>\n";
  }

  // The material sample relit: head-on, then four lights around it.
  void Sample() {
    if (in_.sample_relit.empty()) return;
    html_ << "<h2>Material sample</h2>\n<p>The sample PTM (" << in_.sample_width << " &times; "
          << in_.sample_height << " texels) relit in its own frame" << ScaleText("its")
          << ".</p>\n";
    for (std::size_t k = 0; k < in_.sample_relit.size(); ++k) {
      const auto& [light, image] = in_.sample_relit[k];
      const double world_per_px = in_.texel_size * in_.sample_width / std::max(1, image.cols);
      const cv::Mat bgr8 =
          k == 0 ? WithScaleBar(ToBgr8(image), world_per_px, in_.mm_per_world_unit) : ToBgr8(image);
      const std::string src = WritePicture("sample_light_" + std::to_string(k) + ".png", bgr8);
      html_ << Figure(src, "light " + DirectionText(light), image.cols);
    }
    html_ << "\n";
    Advance();
  }

  // The constraint photos.
  void Photos() {
    if (photo_ids_.empty()) return;
    html_ << "<h2>Constraint photos</h2>\n<p>" << photo_ids_.size() << " of the "
          << in_.photos.size()
          << " photos that constrain the synthesis, with their lights (world frame).</p>\n";
    for (const std::size_t i : photo_ids_) {
      const ReportPhoto& p = in_.photos[i];
      const cv::Mat image =
          render::ResizedToWidth(p.image.empty() ? ReadPhotoRgb(p.file) : p.image, 200);
      const std::string src = WritePicture("photo_" + std::to_string(i) + ".png", ToBgr8(image));
      html_ << Figure(src, HtmlEscape(p.name) + "<br>" + LightsText(p.lights), 200);
      Advance();
    }
    html_ << "\n";
  }

  // Each set of lights on the hemisphere seen from above: the zenith at the centre, the
  // horizon on the outer circle, radius proportional to the angle from the zenith.
  void Lights() {
    if (in_.light_plots.empty()) return;
    html_ << "<h2>Lights</h2>\n<p>Seen from above: the zenith at the centre, rings at 60&deg;, "
             "30&deg; and 0&deg; elevation (the horizon), the distance from the centre "
             "proportional to the angle from the zenith; azimuth 0 to the right, growing "
             "counter-clockwise.</p>\n";
    for (const LightPlot& plot : in_.light_plots) {
      constexpr double kR = 100.0, kC = 110.0;
      html_ << "<figure><svg width=\"220\" height=\"220\" viewBox=\"0 0 220 220\">";
      for (const double ring : {1.0 / 3.0, 2.0 / 3.0, 1.0})
        html_ << "<circle cx=\"110\" cy=\"110\" r=\"" << Fixed(ring * kR, 1)
              << "\" fill=\"none\" stroke=\"#999\"/>";
      html_ << "<line x1=\"110\" y1=\"110\" x2=\"215\" y2=\"110\" stroke=\"#ccc\"/>";
      for (const Eigen::Vector3d& d : plot.directions) {
        const Eigen::Vector3d l = d.normalized();
        const double from_zenith = std::acos(std::clamp(l.z(), -1.0, 1.0)) / (M_PI / 2);
        const double azimuth = std::atan2(l.y(), l.x());
        html_ << "<circle cx=\"" << Fixed(kC + kR * from_zenith * std::cos(azimuth), 1)
              << "\" cy=\"" << Fixed(kC - kR * from_zenith * std::sin(azimuth), 1)
              << "\" r=\"3.5\" fill=\"" << (l.z() > 0 ? "#d93025" : "#999") << "\"/>";
      }
      html_ << "</svg><figcaption>" << HtmlEscape(plot.title) << " (" << plot.directions.size()
            << "): " << HtmlEscape(plot.frame) << "</figcaption></figure>\n";
    }
  }

  // The model from the views, beside the reference, the baselines and error maps.
  void Views() {
    if (in_.views.empty()) return;
    html_ << "<h2>" << HtmlEscape(in_.views_heading) << "</h2>\n<p>" << in_.views.size() << " of "
          << std::max(in_.views_total, in_.views.size())
          << " views. Error maps: mean absolute difference over the channels inside the mask, "
             "from black (0) to bright yellow ("
          << Fixed(in_.error_map_max, 2)
          << " or more, display values in [0, 1]); grey outside. PSNR (dB) and SSIM at the "
             "pictures' resolution. The bar on each reference gives the scale at the depth of the "
             "model's centre"
          << (in_.mm_per_world_unit > 0.0 ? "" : " (in world units: no --world-unit was given)")
          << ".</p>\n";
    html_ << "<p>"
          << Figure(WritePicture("error_scale.png", ErrorScale()),
                    "error scale: 0 (left) to " + Fixed(in_.error_map_max, 2) +
                        " or more (right), in steps of " + Fixed(in_.error_map_max / 4, 4),
                    256)
          << "</p>\n<table><tr><th>reference</th>";
    for (const auto& drawn : in_.views.front().drawn)
      html_ << "<th>" << drawn.model << " (and its error)</th>";
    html_ << "</tr>\n";
    for (std::size_t i = 0; i < in_.views.size(); ++i) {
      ViewRow(in_.views[i], "view_" + std::to_string(i));
      Advance();
    }
    html_ << "</table>\n";
  }

  void ViewRow(const render::ViewPictures& v, const std::string& stem) {
    const int width = v.drawn.empty() ? v.reference.cols : v.drawn.front().rgb.cols;
    html_ << "<tr>";
    if (!v.reference.empty()) {
      html_ << "<td>"
            << Figure(WritePicture(stem + "_reference.png",
                                   WithScaleBar(ToBgr8(v.reference), v.world_per_pixel,
                                                in_.mm_per_world_unit)),
                      HtmlEscape(v.name) + "<br>" + LightsText(v.lights) + PixelText(v), width)
            << "</td>";
    } else {
      html_ << "<td>" << HtmlEscape(v.name) << "<br>" << LightsText(v.lights) << "</td>";
    }
    for (const render::ViewPictures::Drawn& d : v.drawn) {
      html_ << "<td>"
            << Figure(WritePicture(stem + "_" + d.model + ".png", ToBgr8(d.rgb)), d.model, width);
      if (v.reference.empty()) {
        html_ << "</td>";
        continue;
      }
      html_ << "<br>"
            << Figure(WritePicture(stem + "_" + d.model + "_error.png",
                                   ErrorMap(d.rgb, v.reference, v.inside, in_.error_map_max)),
                      "error: " + Fixed(d.psnr, 2) + " dB, SSIM " + Fixed(d.ssim, 3), width)
            << "</td>";
      summary_.rows.push_back({v.name, d.model, d.psnr, d.ssim});
    }
    html_ << "</tr>\n";
  }

  // "<br>1 pixel: 0.0123 world units (1.23 mm) at the model's centre", or nothing.
  std::string PixelText(const render::ViewPictures& v) const {
    if (!(v.world_per_pixel > 0.0)) return "";
    return "<br>1 pixel: " + WorldLengthText(v.world_per_pixel, in_.mm_per_world_unit) +
           " at the model's centre";
  }

  // A light circling the first view.
  void Sweep() {
    if (in_.sweep.empty()) return;
    std::vector<cv::Mat> frames;
    for (const cv::Mat& f : in_.sweep) frames.push_back(ToBgr8(f));
    cv::Mat strip;
    cv::hconcat(frames, strip);
    html_ << "<h2>Light sweep</h2>\n<p>The model from " << HtmlEscape(in_.sweep_view)
          << " with the light circling the viewing axis at " << Fixed(in_.sweep_elevation_deg, 0)
          << "&deg; above the image plane, starting at the right and turning counter-clockwise "
             "in steps of "
          << Fixed(360.0 / static_cast<double>(in_.sweep.size()), 0)
          << "&deg;.</p>\n<div class=\"strip\"><img src=\""
          << WritePicture("light_sweep.png", strip) << "\" width=\"" << strip.cols
          << "\" alt=\"\"></div>\n";
    Advance();
  }

  // Atlases: base colour with the triangle outlines, and occupancy.
  void Atlases() {
    const std::vector<double> occupancy = AtlasOccupancies(*in_.model);
    html_ << "<h2>Atlases</h2>\n<p>" << in_.model->atlases.size()
          << " atlas(es), occupancy of the layout " << Fixed(in_.occupancy, 3)
          << " (atlas texels inside triangles); the PTM under a head-on light, triangle outlines "
             "in green"
          << ScaleText("an atlas") << ".</p>\n";
    for (std::size_t a = 0; a < in_.model->atlases.size(); ++a) {
      const ptm::Ptm& atlas = in_.model->atlases[a];
      const int width = std::min(480, atlas.width);
      html_ << Figure(WritePicture("atlas_" + std::to_string(a) + ".png", AtlasThumbnail(a, width)),
                      "atlas " + std::to_string(a) + ": " + std::to_string(atlas.width) +
                          " &times; " + std::to_string(atlas.height) + " texels, occupancy " +
                          Fixed(occupancy[a], 3),
                      width);
      Advance();
    }
    html_ << "\n";
  }

  // Atlas `a` under a head-on light, `width` texels wide, triangle outlines in green.
  cv::Mat AtlasThumbnail(std::size_t a, int width) const {
    const model::TexturedModel& model = *in_.model;
    const double s = static_cast<double>(width) / model.atlases[a].width;
    cv::Mat thumb = render::ResizedToWidth(model::BaseColourImage(model.atlases[a]), width);
    cv::Mat outlines = thumb.clone();
    constexpr int kShift = 3;
    for (std::size_t f = 0; f < model.corner_px.size(); ++f) {
      if (static_cast<std::size_t>(model.face_atlas[f]) != a) continue;
      std::vector<cv::Point> corners;
      for (int k = 0; k < 3; ++k)
        corners.emplace_back(
            static_cast<int>(std::lround(model.corner_px[f][k].x() * s * (1 << kShift))),
            static_cast<int>(std::lround(model.corner_px[f][k].y() * s * (1 << kShift))));
      cv::polylines(outlines, corners, true, cv::Scalar(60, 220, 60), 1, cv::LINE_AA, kShift);
    }
    cv::addWeighted(thumb, 0.7, outlines, 0.3, 0.0, thumb);
    return WithScaleBar(thumb, in_.texel_size / s, in_.mm_per_world_unit);
  }

  // The full-resolution tables given, and the pictures' own measurements.
  void Metrics() {
    if (!in_.metrics.empty() || !summary_.rows.empty()) html_ << "<h2>Metrics</h2>\n";
    if (!in_.metrics.empty()) {
      html_ << "<p>Every held-out view, inside the ground-truth masks, as <code>texlume "
               "render</code> measured it at full resolution and reduced to the photos' "
               "resolution.</p>\n<table class=\"m\" border=\"1\"><tr><th>model</th><th>PSNR "
               "full (dB)</th><th>SSIM full</th><th>PSNR reduced (dB)</th><th>SSIM "
               "reduced</th></tr>\n";
      for (const ReportMetrics& m : in_.metrics)
        html_ << "<tr><th>" << HtmlEscape(m.label) << "</th><td>" << Fixed(m.mean_psnr, 2)
              << "</td><td>" << Fixed(m.mean_ssim, 3) << "</td><td>"
              << Fixed(m.mean_psnr_reduced, 2) << "</td><td>" << Fixed(m.mean_ssim_reduced, 3)
              << "</td></tr>\n";
      html_ << "</table>\n<p>Per view (PSNR dB / SSIM at full resolution):</p>\n<table class=\"m\" "
               "border=\"1\"><tr><th>view</th>";
      for (const ReportMetrics& m : in_.metrics) html_ << "<th>" << HtmlEscape(m.label) << "</th>";
      html_ << "</tr>\n";
      for (std::size_t i = 0; i < in_.metrics.front().views.size(); ++i) {
        html_ << "<tr><th>" << HtmlEscape(in_.metrics.front().views[i].name) << "</th>";
        for (const ReportMetrics& m : in_.metrics) {
          if (i < m.views.size())
            html_ << "<td>" << Fixed(m.views[i].psnr, 2) << " / " << Fixed(m.views[i].ssim, 3)
                  << "</td>";
          else
            html_ << "<td></td>";
        }
        html_ << "</tr>\n";
      }
      html_ << "</table>\n";
    }
    BaselineNotes();
    if (!summary_.rows.empty()) {
      html_ << "<p>On the pictures above (their resolution, inside the mask):</p>\n<table "
               "class=\"m\" "
               "border=\"1\"><tr><th>view</th><th>model</th><th>PSNR (dB)</th><th>SSIM</th></tr>\n";
      for (const ReportSummary::Row& r : summary_.rows)
        html_ << "<tr><th>" << HtmlEscape(r.view) << "</th><td>" << r.model << "</td><td>"
              << Fixed(r.psnr, 2) << "</td><td>" << Fixed(r.ssim, 3) << "</td></tr>\n";
      html_ << "</table>\n";
    }
  }

  // Says so where a baseline measures better than texlume (the first metrics row),
  // or, without metrics tables, on the pictures' own means.
  void BaselineNotes() {
    std::vector<std::pair<std::string, std::array<double, 4>>> means;
    if (!in_.metrics.empty()) {
      for (const ReportMetrics& m : in_.metrics)
        means.push_back(
            {m.label, {m.mean_psnr, m.mean_ssim, m.mean_psnr_reduced, m.mean_ssim_reduced}});
    } else {
      std::map<std::string, std::array<double, 3>> sums;  // psnr, ssim, count
      std::vector<std::string> order;
      for (const ReportSummary::Row& r : summary_.rows) {
        if (!sums.count(r.model)) order.push_back(r.model);
        auto& s = sums[r.model];
        s[0] += r.psnr, s[1] += r.ssim, s[2] += 1;
      }
      for (const std::string& model : order) {
        const auto& s = sums[model];
        means.push_back({model, {s[0] / s[2], s[1] / s[2], NAN, NAN}});
      }
    }
    if (means.size() < 2) return;
    static const char* kWhat[4] = {"PSNR", "SSIM", "PSNR at the photos' resolution",
                                   "SSIM at the photos' resolution"};
    std::vector<std::string> notes;
    for (std::size_t b = 1; b < means.size(); ++b)
      for (int k = 0; k < 4; ++k)
        if (std::isfinite(means[b].second[k]) && means[b].second[k] > means[0].second[k])
          notes.push_back(means[b].first + " beats " + means[0].first + " in " + kWhat[k] + " (" +
                          Fixed(means[b].second[k], k % 2 ? 3 : 2) + " against " +
                          Fixed(means[0].second[k], k % 2 ? 3 : 2) + ")");
    html_ << "<p><b>Against the baselines:</b> ";
    if (notes.empty()) html_ << HtmlEscape(means[0].first) << " measures best in every figure.";
    for (std::size_t i = 0; i < notes.size(); ++i) html_ << (i ? "; " : "") << HtmlEscape(notes[i]);
    html_ << (notes.empty() ? "" : ".") << "</p>\n";
  }

  const ReportInputs& in_;
  const fs::path pictures_, tmp_;
  const ProgressCallback& progress_;
  std::vector<std::size_t> photo_ids_;
  std::size_t steps_ = 0, step_ = 0;
  std::ostringstream html_;
  ReportSummary summary_;
};

}  // namespace

ReportSummary WriteReport(const fs::path& dir, const ReportInputs& in,
                          const ProgressCallback& progress) {
  TEXLUME_CHECK(in.model != nullptr, "the report needs a model");
  if (in.max_photos < 0) throw OptionError("report counts must be non-negative");
  const auto start = std::chrono::steady_clock::now();
  fs::create_directories(dir);
  const fs::path pictures = dir / "report";
  PartialOutput output(pictures, PartialOutput::Kind::kFolder);
  ReportWriter writer(in, pictures, output.path(), progress);
  std::string html;
  try {
    writer.Write();
    writer.summary().seconds = SecondsSince(start);
    html = writer.Finish(writer.summary().seconds);
    output.Commit();
  } catch (const fs::filesystem_error& e) {
    throw InputError(pictures.string(), std::string("cannot be written: ") + e.what());
  }
  WriteFileAtomically(
      dir / "report.html", [&](std::ostream& o) { o << html; }, false);
  return writer.summary();
}

}  // namespace texlume::report
