#include "quilt/work_patch.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace texlume::quilt {
namespace {

/// Longest link a work image keeps (pixels): links are about a texel long
/// (DenseSurface), a chart's stretch makes them at most twice that.
constexpr double kMostLinkPx = 3.0;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

Eigen::Vector2d Centre(const DenseSample& d) { return {d.x + 0.5, d.y + 0.5}; }

// A rotation of y-up angle `rad` acting on pixel vectors (rows down).
Eigen::Matrix2d PixelRotation(double rad) {
  const double c = std::cos(rad), s = std::sin(rad);
  Eigen::Matrix2d m;
  m << c, s, -s, c;
  return m;
}

}  // namespace

WorkPatchBuilder::WorkPatchBuilder(const DenseSurface& surface, const atlas::AtlasLayout& layout,
                                   int copy_side, bool conformal)
    : surface_(surface), layout_(layout), copy_side_(copy_side), conformal_(conformal) {
  for (std::size_t f = 0; f < layout_.faces.size(); ++f) {
    const AtlasAxes axes = AtlasAxesOf(surface_, layout_, static_cast<int>(f));
    atlas_x_.push_back(axes.x);
    atlas_y_.push_back(axes.y);
    normal_.push_back(axes.normal);
  }
}

// Breadth-first; each sample placed in the work image through its chart's
// rigid map (charts met across a border are turned by the angle between their
// atlas frames), then, across charts, by the conformal map.
WorkPatch WorkPatchBuilder::Build(int v, int levels) const {
  WorkPatch patch;
  std::unordered_map<int, std::pair<double, Eigen::Vector2d>> chart_maps;  // angle, translation
  const auto place = [&](int s, const Eigen::Vector2d& w, double angle) {
    patch.local.emplace(s, static_cast<int>(patch.samples.size()));
    patch.samples.push_back({s, w, angle});
  };
  const DenseSample& seed = surface_.samples()[static_cast<std::size_t>(v)];
  chart_maps[seed.chart] = {0.0, -Centre(seed)};
  place(v, Eigen::Vector2d::Zero(), 0.0);
  std::vector<int> frontier{v}, next;
  Eigen::Vector2d lo = Eigen::Vector2d::Zero(), hi = lo;  // the image so far
  const double widest = copy_side_;
  for (int level = 0; level < levels && !frontier.empty(); ++level) {
    if ((hi - lo).maxCoeff() >= widest) break;  // it outgrew the copies: no use growing on
    next.clear();
    for (const int a : frontier)
      for (const int b : surface_.Neighbours(a)) {
        if (patch.local.count(b)) continue;
        const PatchSample& pa = patch.samples[static_cast<std::size_t>(patch.local.at(a))];
        const DenseSample& db = surface_.samples()[static_cast<std::size_t>(b)];
        auto it = chart_maps.find(db.chart);
        if (it == chart_maps.end()) {
          const double angle = pa.chart_to_work_rad + TurnBetween(b, a);
          const Eigen::Vector2d w = pa.w + PixelRotation(pa.chart_to_work_rad) * StepPx(a, b);
          it = chart_maps
                   .emplace(db.chart,
                            std::make_pair(angle,
                                           Eigen::Vector2d(w - PixelRotation(angle) * Centre(db))))
                   .first;
        }
        const auto& [angle, t] = it->second;
        const Eigen::Vector2d w = PixelRotation(angle) * Centre(db) + t;
        // A chart met again where it does not join on (a rigid chart's crack,
        // or a chart that winds round): b stays out of this patch.
        if ((w - pa.w).norm() > kMostLinkPx) continue;
        place(b, w, angle);
        lo = lo.cwiseMin(w), hi = hi.cwiseMax(w);
        next.push_back(b);
      }
    frontier.swap(next);
  }
  if (chart_maps.size() > 1 && conformal_) FlattenConformally(patch);
  patch.fits = FrameWorkImage(patch);
  patch.distortion = AreaDistortion(patch);
  return patch;
}

// The paper's work image for a patch across charts: the least-squares
// conformal map of the faces under it (Lévy et al. 2002), each sample placed
// by its face's map, then turned so that the seed's chart keeps its atlas
// frame (the work frame an image term lays the photos' lights in) and the
// seed lies at the origin. The charts' rigid maps stay when the faces have
// no such map.
void WorkPatchBuilder::FlattenConformally(WorkPatch& patch) const {
  std::vector<int> faces;
  std::unordered_map<int, std::size_t> index;  // face -> in faces
  for (const PatchSample& p : patch.samples) {
    const int f = surface_.samples()[static_cast<std::size_t>(p.sample)].face;
    if (index.emplace(f, faces.size()).second) faces.push_back(f);
  }
  std::vector<std::pair<Eigen::Matrix2d, Eigen::Vector2d>> maps;  // frame -> chart, texels
  if (!surface_.ConformalMap(faces, &maps)) return;
  const double t = surface_.texel_size();
  for (PatchSample& p : patch.samples) {
    const DenseSample& d = surface_.samples()[static_cast<std::size_t>(p.sample)];
    const auto& [linear, translation] = maps[index.at(d.face)];
    const Eigen::Vector2d q = linear * (d.p_in_frame / t) + translation;
    p.w = Eigen::Vector2d(q.x(), -q.y());  // rows down
    // The atlas frame's x axis lies at AtlasFrameAngle in the face frame; the
    // map turns the face frame by its rotation (polar decomposition).
    p.chart_to_work_rad = layout_.faces[static_cast<std::size_t>(d.face)].AtlasFrameAngle() +
                          std::atan2(linear(1, 0) - linear(0, 1), linear(0, 0) + linear(1, 1));
  }
  const double seed_rad = patch.samples[0].chart_to_work_rad;
  const Eigen::Vector2d seed_w = patch.samples[0].w;
  for (PatchSample& p : patch.samples) {
    p.w = PixelRotation(-seed_rad) * (p.w - seed_w);
    p.chart_to_work_rad -= seed_rad;
  }
}

// The step from a to b on the surface in a's atlas pixels (rows down).
Eigen::Vector2d WorkPatchBuilder::StepPx(int a, int b) const {
  const Eigen::Vector3d d = surface_.PointInWorld(b) - surface_.PointInWorld(a);
  const int f = surface_.samples()[static_cast<std::size_t>(a)].face;
  const double t = surface_.texel_size();
  return {d.dot(atlas_x_[static_cast<std::size_t>(f)]) / t,
          -d.dot(atlas_y_[static_cast<std::size_t>(f)]) / t};
}

// The angle (y up) that takes directions of b's atlas frame into a's: b's
// atlas x axis laid onto a's tangent plane.
double WorkPatchBuilder::TurnBetween(int b, int a) const {
  const auto fa = static_cast<std::size_t>(surface_.samples()[static_cast<std::size_t>(a)].face);
  const auto fb = static_cast<std::size_t>(surface_.samples()[static_cast<std::size_t>(b)].face);
  const Eigen::Vector3d x = atlas_x_[fb] - atlas_x_[fb].dot(normal_[fa]) * normal_[fa];
  return std::atan2(x.dot(atlas_y_[fa]), x.dot(atlas_x_[fa]));
}

// The work image's frame: each sample on the pixel nearest to it.
bool WorkPatchBuilder::FrameWorkImage(WorkPatch& patch) const {
  Eigen::Vector2d lo = patch.samples[0].w, hi = lo;
  for (const PatchSample& p : patch.samples) lo = lo.cwiseMin(p.w), hi = hi.cwiseMax(p.w);
  patch.origin = Eigen::Vector2d(std::floor(lo.x()), std::floor(lo.y()));
  patch.width = static_cast<int>(std::lround(hi.x() - patch.origin.x())) + 1;
  patch.height = static_cast<int>(std::lround(hi.y() - patch.origin.y())) + 1;
  return patch.width <= copy_side_ && patch.height <= copy_side_;
}

void WorkPatchBuilder::TrimToCopySide(WorkPatch& patch) const {
  const double reach = std::floor((copy_side_ - 3) / 2.0);
  WorkPatch trimmed;
  for (const PatchSample& p : patch.samples)
    if (std::abs(p.w.x()) <= reach && std::abs(p.w.y()) <= reach) {
      trimmed.local.emplace(p.sample, static_cast<int>(trimmed.samples.size()));
      trimmed.samples.push_back(p);
    }
  trimmed.fits = FrameWorkImage(trimmed);
  trimmed.distortion = AreaDistortion(trimmed);
  patch = std::move(trimmed);
}

// How much the work image stretches the patch's area: the summed squared
// link lengths in the image over those on the surface, either way round (1:
// none). Links shorter than a quarter texel on the surface are left out.
double WorkPatchBuilder::AreaDistortion(const WorkPatch& patch) const {
  double image2 = 0, surface2 = 0;
  for (const PatchSample& p : patch.samples)
    for (const int n : surface_.Neighbours(p.sample)) {
      const auto it = patch.local.find(n);
      if (it == patch.local.end() || n < p.sample) continue;
      const double surface = (surface_.PointInWorld(n) - surface_.PointInWorld(p.sample)).norm() /
                             surface_.texel_size();
      if (surface < 0.25) continue;
      image2 += (patch.samples[static_cast<std::size_t>(it->second)].w - p.w).squaredNorm();
      surface2 += surface * surface;
    }
  if (!(image2 > 0) || !(surface2 > 0)) return surface2 > 0 ? kInfinity : 1.0;
  return std::max(image2 / surface2, surface2 / image2);
}

}  // namespace texlume::quilt
