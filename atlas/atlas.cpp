#include "atlas/atlas.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <functional>
#include <iterator>
#include <limits>
#include <optional>
#include <unordered_map>

#include "atlas/chart_packing.h"
#include "atlas/charts.h"
#include "core/check.h"
#include "core/errors.h"
#include "ptm/coefficient_space.h"
#include "synth/planar_synthesis.h"

namespace texlume::atlas {
using namespace chart_packing;

Eigen::Vector2d FacePlacement::FrameFromAtlas(const Eigen::Vector2d& px, double texel_size) const {
  const Eigen::Vector2d r((px.x() - offset.x()) * texel_size, (offset.y() - px.y()) * texel_size);
  return linear.inverse() * r;
}

double FacePlacement::AtlasFrameAngle() const {
  const Eigen::Vector2d x_in_frame = linear.inverse().col(0);
  return std::atan2(x_in_frame.y(), x_in_frame.x());
}

const char* ChartFlatteningName(ChartFlattening flattening) {
  switch (flattening) {
    case ChartFlattening::kRigid:
      return "rigid";
    case ChartFlattening::kConformal:
      return "conformal";
    case ChartFlattening::kStrips:
      return "strips";
    case ChartFlattening::kAuto:
      return "auto";
  }
  return "rigid";
}

std::int64_t AtlasLayout::Texels() const {
  std::int64_t texels = 0;
  for (const cv::Size& size : atlas_sizes) texels += static_cast<std::int64_t>(size.area());
  return texels;
}

AtlasStretch MeasureStretch(const std::vector<synth::TrianglePatch>& patches,
                            const AtlasLayout& layout) {
  AtlasStretch s;
  double weighted = 0, area = 0;
  s.min = std::numeric_limits<double>::max();
  s.max = 0;
  for (std::size_t f = 0; f < layout.faces.size() && f < patches.size(); ++f) {
    const auto& c = patches[f].corners_in_frame;
    const double a = 0.5 * std::abs((c[1] - c[0]).x() * (c[2] - c[0]).y() -
                                    (c[1] - c[0]).y() * (c[2] - c[0]).x());
    const Eigen::Vector2d sigma = SingularValues2(layout.faces[f].linear);
    weighted += a * std::sqrt(sigma.x() * sigma.y());
    area += a;
    s.min = std::min(s.min, sigma.y());
    s.max = std::max(s.max, sigma.x());
  }
  if (area > 0) s.mean = weighted / area;
  if (s.max == 0) s.min = s.max = 1.0;
  return s;
}

void AtlasOptions::Check() const {
  if (atlas_size < 64 || atlas_size > 16384) throw OptionError("atlas size must be in [64, 16384]");
  // Catmull-Rom reads (render, viewer) reach 2 texels past a chart's last centre.
  if (gutter < 2 || gutter > 16) throw OptionError("gutter must be in [2, 16] texels");
  if (blend_strip < 2 || blend_strip > 32) throw OptionError("blend strip must be in [2, 32]");
  if (max_chart_size < 0 || max_chart_size > atlas_size)
    throw OptionError("max chart size must be in [0, atlas size]");
  if (!(max_chart_normal_angle_deg > 0.0 && max_chart_normal_angle_deg <= 180.0))
    throw OptionError("max chart normal angle must be in (0, 180] degrees");
  if (!(max_chart_stretch >= 1.01 && max_chart_stretch <= 4.0))
    throw OptionError("max chart stretch must be in [1.01, 4]");
}

std::vector<std::array<int, 3>> PackSkyline(const std::vector<std::pair<int, int>>& sizes,
                                            int bin_width, int bin_height) {
  std::vector<std::size_t> order(sizes.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return sizes[a].second != sizes[b].second ? sizes[a].second > sizes[b].second
                                              : sizes[a].first > sizes[b].first;
  });
  std::vector<std::array<int, 3>> out(sizes.size());
  std::vector<std::vector<std::pair<int, int>>> skylines;  // per bin: (x start, height) segments
  auto new_bin = [&]() { skylines.push_back({{0, 0}}); };
  new_bin();
  for (const std::size_t i : order) {
    const auto [w, h] = sizes[i];
    if (w > bin_width || h > bin_height) {
      throw OptionError("a chart of " + std::to_string(w) + " x " + std::to_string(h) +
                        " texels does not fit an atlas of " + std::to_string(bin_width) + " x " +
                        std::to_string(bin_height));
    }
    bool placed = false;
    for (std::size_t bin = 0; bin < skylines.size() && !placed; ++bin) {
      auto& sky = skylines[bin];
      int best_y = std::numeric_limits<int>::max(), best_x = -1;
      for (std::size_t s = 0; s < sky.size(); ++s) {
        const int x = sky[s].first;
        if (x + w > bin_width) break;
        int y = 0;
        for (std::size_t r = s; r < sky.size() && sky[r].first < x + w; ++r)
          y = std::max(y, sky[r].second);
        if (y + h <= bin_height && y < best_y) best_y = y, best_x = x;
      }
      if (best_x < 0) continue;
      out[i] = {static_cast<int>(bin), best_x, best_y};
      // Raise the skyline over [best_x, best_x + w) to best_y + h.
      std::vector<std::pair<int, int>> next;
      int height_after = 0;
      for (std::size_t s = 0; s < sky.size(); ++s) {
        const int x0 = sky[s].first;
        const int x1 = s + 1 < sky.size() ? sky[s + 1].first : bin_width;
        if (x1 <= best_x || x0 >= best_x + w) {
          next.push_back(sky[s]);
          continue;
        }
        if (x0 < best_x) next.emplace_back(x0, sky[s].second);
        if (x1 > best_x + w) height_after = sky[s].second;
        if (next.empty() || next.back().first != best_x) next.emplace_back(best_x, best_y + h);
        if (x1 > best_x + w) next.emplace_back(best_x + w, height_after);
      }
      // Merge equal neighbours.
      sky.clear();
      for (const auto& seg : next)
        if (sky.empty() || sky.back().second != seg.second) sky.push_back(seg);
      placed = true;
    }
    if (!placed) {
      new_bin();
      skylines.back() = {{0, h}, {w, 0}};
      if (w == bin_width) skylines.back() = {{0, h}};
      out[i] = {static_cast<int>(skylines.size() - 1), 0, 0};
    }
  }
  return out;
}

namespace {

// Lays out the faces of a mesh in atlases with one flattening (not kAuto): the charts, their
// outlines, the packing of the charts into atlases, each face's placement, the atlas sizes.
class AtlasLayouter {
 public:
  AtlasLayouter(const mesh::TriangleMesh& mesh, const std::vector<synth::TrianglePatch>& patches,
                const std::vector<std::array<synth::Unfolding, 3>>& unfoldings, double texel_size,
                const AtlasOptions& options, const ProgressCallback& progress)
      : mesh_(mesh),
        patches_(patches),
        unfoldings_(unfoldings),
        t_(texel_size),
        gutter_(options.gutter),
        options_(options),
        progress_(progress),
        num_faces_(mesh.faces.size()) {}

  // Runs the stages in turn.
  AtlasLayout Run();

 private:
  // 1. Charts by the chosen flattening (strip charts are made while packing).
  void MakeCharts();
  // One chart per face, turned to the minimal bounding box of its triangle.
  void MakePerTriangleCharts();
  // 2. Chart boxes in texels (with gutters), packed.
  void Pack();
  // Per triangle: the charts' boxes, skyline-packed.
  void PackPerTriangle();
  // Strip charts in every variant, packed in rows; the fewest atlas texels win.
  void PackStrips();
  // Charts packed by their outlines, at both drop rules; the fewest atlas texels win.
  void PackByOutlines();
  // Each chart's outlines at its packing rotations, and the largest outline area per chart.
  std::vector<std::vector<ChartOutline>> OutlineCharts(std::vector<double>& area);
  // Throws when a chart fits an atlas at none of its rotations.
  void CheckOutlinesFit(const std::vector<std::vector<ChartOutline>>& outlines) const;
  // Records a packed chart, turned to its outline's rotation, at (atlas, x, y).
  void DropChart(std::vector<ChartFace>& chart, const ChartOutline& o,
                 const std::array<int, 3>& at);
  // 3. Each face's placement in its atlas.
  void PlaceFaces();
  // 4. The atlases' sizes, each cropped to the rows it uses.
  void SizeAtlases();

  const mesh::TriangleMesh& mesh_;
  const std::vector<synth::TrianglePatch>& patches_;
  const std::vector<std::array<synth::Unfolding, 3>>& unfoldings_;
  const double t_;  // texel size, world units
  const int gutter_;
  const AtlasOptions& options_;
  const ProgressCallback& progress_;
  const std::size_t num_faces_;

  std::vector<std::vector<ChartFace>> charts_;
  std::vector<std::pair<int, int>> sizes_;
  std::vector<Eigen::Vector2i> chart_lo_, chart_hi_;
  std::vector<std::array<int, 3>> packed_;
  AtlasLayout layout_;
  int num_atlases_ = 0;
  std::vector<int> used_height_;
};

AtlasLayout AtlasLayouter::Run() {
  MakeCharts();
  Pack();
  PlaceFaces();
  SizeAtlases();
  return std::move(layout_);
}

void AtlasLayouter::MakeCharts() {
  // 1. Charts: faces with their rigid placement in the chart plane.
  if (options_.mode == AtlasMode::kPerTriangle) {
    MakePerTriangleCharts();
  } else if (options_.flattening == ChartFlattening::kRigid) {
    RigidChartOptions ro;
    ro.texel_size = t_;
    ro.max_extent_texels =
        (options_.max_chart_size > 0 ? std::min(options_.max_chart_size, options_.atlas_size)
                                     : options_.atlas_size) -
        2 * gutter_ - 2;
    ro.max_normal_angle_deg = options_.max_chart_normal_angle_deg;
    ro.gutter = gutter_;
    charts_ = MakeRigidCharts(mesh_, patches_, unfoldings_, ro);
  } else if (options_.flattening == ChartFlattening::kStrips) {
    // Laid out below, with the packing.
  } else {
    ConformalChartOptions co;
    co.texel_size = t_;
    co.max_side_texels =
        options_.max_chart_size > 0 ? options_.max_chart_size : options_.atlas_size;
    co.max_normal_angle_deg = options_.max_chart_normal_angle_deg;
    co.max_stretch = options_.max_chart_stretch;
    co.max_extent_texels = options_.atlas_size - 2 * gutter_ - 2;
    charts_ = MakeConformalCharts(mesh_, patches_, unfoldings_, co);
  }
}

void AtlasLayouter::MakePerTriangleCharts() {
  const double t = t_;
  for (std::size_t f = 0; f < num_faces_; ++f) {
    // The minimal bounding box of a triangle has a side along one of its edges.
    const auto& c = patches_[f].corners_in_frame;
    double best_area = std::numeric_limits<double>::max();
    Eigen::Matrix2d best = Eigen::Matrix2d::Identity();
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2d e =
          c[static_cast<std::size_t>((k + 1) % 3)] - c[static_cast<std::size_t>(k)];
      const Eigen::Matrix2d r = Eigen::Rotation2Dd(-std::atan2(e.y(), e.x())).toRotationMatrix();
      Eigen::Vector2d lo = r * c[0], hi = lo;
      for (const auto& p : c) lo = lo.cwiseMin(r * p), hi = hi.cwiseMax(r * p);
      const double area = (std::ceil((hi.x() - lo.x()) / t) + 2 * gutter_) *
                          (std::ceil((hi.y() - lo.y()) / t) + 2 * gutter_);
      if (area < best_area) best_area = area, best = r;
    }
    charts_.push_back({{static_cast<int>(f), best, Eigen::Vector2d::Zero()}});
  }
}

void AtlasLayouter::Pack() {
  // 2. Chart boxes in texels (with gutters), packed.
  if (options_.mode == AtlasMode::kPerTriangle) {
    PackPerTriangle();
  } else if (options_.flattening == ChartFlattening::kStrips) {
    PackStrips();
  } else {
    PackByOutlines();
  }
}

void AtlasLayouter::PackPerTriangle() {
  for (const auto& chart : charts_) {
    const ChartOutline outline = Box(chart, 0.0, patches_, t_, gutter_, nullptr);
    chart_lo_.push_back(outline.lo);
    chart_hi_.push_back(outline.hi);
    sizes_.emplace_back(outline.Width(), outline.Height());
  }
  packed_ = PackSkyline(sizes_, options_.atlas_size, options_.atlas_size);
}

void AtlasLayouter::PackStrips() {
  // Strips (after fans) from each seed-side rule, unstacked; stacked up to
  // a seventh of the atlas or up to the whole (which wins on developable
  // surfaces such as a cylinder's side); and in stacks of 4 or 8 bands of
  // the preferred height, each band within half a band of the ends of the one
  // below (near-rectangles: on curved surfaces, where bands of small faces
  // lose most to gutters, but stacks of many bands turn into triangles).
  // Each is packed in rows; the layout with the fewest atlas texels wins.
  StripChartOptions so;
  so.texel_size = t_;
  so.max_stretch = options_.max_chart_stretch;
  so.max_length_texels = options_.atlas_size - 2 * gutter_ - 2;  // a whole row (rows cut them)
  so.max_normal_angle_deg = options_.max_chart_normal_angle_deg;
  so.gutter = gutter_;
  const double atlas_rows = so.max_length_texels;
  const double band = PreferredBandHeight(patches_, t_);
  struct Variant {
    StripSide side;
    double max_stack_texels, max_stack_overhang_texels;
  };
  const Variant variants[] = {{StripSide::kTallest, 0.0, -1.0},
                              {StripSide::kNearestPreferred, 0.0, -1.0},
                              {StripSide::kTallest, atlas_rows / 7.0, -1.0},
                              {StripSide::kTallest, atlas_rows, -1.0},
                              {StripSide::kTallest, 4.0 * band + 0.5, 0.5 * band},
                              {StripSide::kTallest, 8.0 * band + 0.5, 0.5 * band}};
  RowPacking best;
  std::int64_t best_texels = 0;
  // Every variant as it is and fitted to irregular faces (synth/charts.h), one
  // progress bar over all of them.
  const std::size_t passes = 2 * std::size(variants);
  std::size_t pass = 0;
  for (const bool fit_irregular_faces : {false, true})
    for (const Variant& variant : variants) {
      so.side = variant.side;
      so.max_stack_texels = variant.max_stack_texels;
      so.max_stack_overhang_texels = variant.max_stack_overhang_texels;
      so.fit_irregular_faces = fit_irregular_faces;
      RowPacking rows =
          PackStripsInRows(MakeStripCharts(mesh_, patches_, unfoldings_, so), patches_, t_, gutter_,
                           options_.atlas_size, PartOfStage(progress_, pass++, passes));
      if (best.pieces.empty() || rows.texels < best_texels)
        best_texels = rows.texels, best = std::move(rows);
    }
  charts_ = std::move(best.pieces);
  for (std::size_t c = 0; c < charts_.size(); ++c)
    DropChart(charts_[c], best.outlines[c], best.drops[c]);
}

void AtlasLayouter::PackByOutlines() {
  // Charts are packed by their outlines (the texels the bake writes), largest
  // first, each at the best of kPackingRotations turns and the first position
  // where it overlaps nothing, so charts nest in each other's concavities.
  std::vector<double> area(charts_.size(), 0.0);
  const std::vector<std::vector<ChartOutline>> outlines = OutlineCharts(area);
  std::vector<std::size_t> order(charts_.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return area[a] > area[b]; });
  CheckOutlinesFit(outlines);
  const std::vector<std::vector<OutlineSquare>> cores = LargestSquares(outlines);
  // Both drop rules; the layout with fewer atlas texels wins.
  OutlinePacking best_packing;
  std::size_t placed = 0;
  const std::size_t to_place = 2 * charts_.size();
  const auto count_placed = [&] {
    ++placed;
    if (progress_ && (placed % 8 == 0 || placed == to_place))
      progress_("packing outlines", placed, to_place);
  };
  for (const DropRule rule : {DropRule::kLowestBottom, DropRule::kLowestPosition}) {
    OutlinePacking packing =
        PackOutlines(outlines, cores, order, options_.atlas_size, rule, count_placed);
    if (best_packing.drops.empty() || packing.texels < best_packing.texels)
      best_packing = std::move(packing);
  }
  for (std::size_t c = 0; c < charts_.size(); ++c) {
    const OutlineDrop& drop = best_packing.drops[c];
    DropChart(charts_[c], outlines[c][static_cast<std::size_t>(drop.rotation)],
              {drop.bin, drop.x, drop.y});
  }
}

std::vector<std::vector<ChartOutline>> AtlasLayouter::OutlineCharts(std::vector<double>& area) {
  const double t = t_;
  const int gutter = gutter_;
  std::vector<std::vector<ChartOutline>> outlines(charts_.size());
  std::size_t outlined = 0;
#pragma omp parallel for schedule(dynamic, 1)
  for (std::size_t c = 0; c < charts_.size(); ++c) {
    const double upright = UprightBoxAngle(charts_[c], patches_);
    outlines[c].push_back(Outline(charts_[c], upright, patches_, t, gutter));
    // A long thin chart (a run of slivers) is tried at quarter turns only:
    // turned by less, its outline is a tall diagonal that never packs better
    // and is slow to place.
    const ChartOutline& upright_outline = outlines[c][0];
    const int long_side = std::max(upright_outline.Width(), upright_outline.Height());
    const int short_side = std::min(upright_outline.Width(), upright_outline.Height());
    const bool thin = long_side >= kThinChartAspect * short_side;
    for (int r = 1; r < kPackingRotations; ++r)
      if (!thin || r % (kPackingRotations / 4) == 0)
        outlines[c].push_back(
            Outline(charts_[c], upright + 2.0 * kPi * r / kPackingRotations, patches_, t, gutter));
    for (const auto& o : outlines[c]) area[c] = std::max(area[c], o.area);
#pragma omp critical(texlume_chart_outlines)
    {
      ++outlined;
      if (progress_ && (outlined % 8 == 0 || outlined == charts_.size()))
        progress_("chart outlines", outlined, charts_.size());
    }
  }
  return outlines;
}

void AtlasLayouter::CheckOutlinesFit(const std::vector<std::vector<ChartOutline>>& outlines) const {
  for (const auto& chart_outlines : outlines) {
    bool fits = false;
    for (const auto& o : chart_outlines)
      fits = fits || (o.Width() <= options_.atlas_size && o.Height() <= options_.atlas_size);
    if (!fits)
      throw OptionError("a chart of " + std::to_string(chart_outlines[0].Width()) + " x " +
                        std::to_string(chart_outlines[0].Height()) +
                        " texels does not fit an atlas of " + std::to_string(options_.atlas_size));
  }
}

void AtlasLayouter::DropChart(std::vector<ChartFace>& chart, const ChartOutline& o,
                              const std::array<int, 3>& at) {
  const Eigen::Matrix2d turn = Eigen::Rotation2Dd(o.angle).toRotationMatrix();
  for (ChartFace& cf : chart) {
    cf.linear = turn * cf.linear;
    cf.translation = turn * cf.translation;
  }
  chart_lo_.push_back(o.lo);
  chart_hi_.push_back(o.hi);
  sizes_.emplace_back(o.Width(), o.Height());
  packed_.push_back(at);
}

void AtlasLayouter::PlaceFaces() {
  const double t = t_;
  layout_.num_charts = static_cast<int>(charts_.size());
  layout_.flattening = options_.flattening;
  layout_.faces.resize(num_faces_);
  for (std::size_t c = 0; c < charts_.size(); ++c) {
    const auto [bin, x0, y0] = packed_[c];
    num_atlases_ = std::max(num_atlases_, bin + 1);
    used_height_.resize(static_cast<std::size_t>(num_atlases_), 0);
    used_height_[static_cast<std::size_t>(bin)] =
        std::max(used_height_[static_cast<std::size_t>(bin)], y0 + sizes_[c].second);
    for (const ChartFace& cf : charts_[c]) {
      FacePlacement& fp = layout_.faces[static_cast<std::size_t>(cf.face)];
      fp.atlas = bin;
      fp.chart = static_cast<int>(c);
      fp.linear = cf.linear;
      fp.offset = Eigen::Vector2d(x0 + cf.translation.x() / t - chart_lo_[c].x(),
                                  y0 + chart_hi_[c].y() - cf.translation.y() / t);
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector2d q = cf.linear * patches_[static_cast<std::size_t>(cf.face)]
                                                  .corners_in_frame[static_cast<std::size_t>(k)];
        fp.corners_px[static_cast<std::size_t>(k)] =
            Eigen::Vector2d(fp.offset.x() + q.x() / t, fp.offset.y() - q.y() / t);
      }
    }
  }
}

void AtlasLayouter::SizeAtlases() {
  for (int a = 0; a < num_atlases_; ++a)
    layout_.atlas_sizes.emplace_back(options_.atlas_size,
                                     std::max(1, used_height_[static_cast<std::size_t>(a)]));
}

}  // namespace

AtlasLayout LayoutAtlases(const mesh::TriangleMesh& mesh,
                          const std::vector<synth::TrianglePatch>& patches,
                          const std::vector<std::array<synth::Unfolding, 3>>& unfoldings,
                          double texel_size, const AtlasOptions& options,
                          const ProgressCallback& progress) {
  options.Check();
  if (!(texel_size > 0.0)) throw OptionError("atlas texel size must be > 0");
  const std::size_t num_faces = mesh.faces.size();
  TEXLUME_CHECK(patches.size() == num_faces && unfoldings.size() == num_faces,
                "an atlas layout needs one patch and one unfolding per face");
  if (options.mode == AtlasMode::kCharts && options.flattening == ChartFlattening::kAuto) {
    // Strips fill atlases best on regular meshes; on irregular ones (decimated
    // photogrammetry) they fragment and rigid charts do better. Both are laid
    // out and the one with fewer atlas texels is kept (strips on a tie).
    AtlasOptions strips = options, rigid = options;
    strips.flattening = ChartFlattening::kStrips;
    rigid.flattening = ChartFlattening::kRigid;
    AtlasLayout best = LayoutAtlases(mesh, patches, unfoldings, texel_size, strips, progress);
    AtlasLayout other = LayoutAtlases(mesh, patches, unfoldings, texel_size, rigid, progress);
    return other.Texels() < best.Texels() ? other : best;
  }
  return AtlasLayouter(mesh, patches, unfoldings, texel_size, options, progress).Run();
}

AtlasCoverage VisitAtlasTexels(const AtlasLayout& layout, double texel_size, int gutter,
                               const AtlasTexelVisitor& visit, const ProgressCallback& progress) {
  const double t = texel_size;
  AtlasCoverage out;
  std::vector<cv::Mat> claim;  // distance of the claim, per atlas
  for (const cv::Size& size : layout.atlas_sizes) {
    claim.emplace_back(size, CV_32FC1, cv::Scalar(std::numeric_limits<float>::max()));
    out.coverage.push_back(cv::Mat::zeros(size, CV_8UC1));
  }
  const std::size_t num_faces = layout.faces.size();
  for (std::size_t f = 0; f < num_faces; ++f) {
    const FacePlacement& fp = layout.faces[f];
    cv::Mat& claims = claim[static_cast<std::size_t>(fp.atlas)];
    cv::Mat& coverage = out.coverage[static_cast<std::size_t>(fp.atlas)];
    Eigen::Vector2d lo = fp.corners_px[0], hi = lo;
    for (const auto& p : fp.corners_px) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    const int x0 = std::max(0, static_cast<int>(std::floor(lo.x())) - gutter);
    const int x1 = std::min(coverage.cols - 1, static_cast<int>(std::ceil(hi.x())) + gutter);
    const int y0 = std::max(0, static_cast<int>(std::floor(lo.y())) - gutter);
    const int y1 = std::min(coverage.rows - 1, static_cast<int>(std::ceil(hi.y())) + gutter);
    for (int y = y0; y <= y1; ++y) {
      const auto [x_first, x_last] =
          TexelColumns(mesh::TriangleRowSpan(fp.corners_px, y + 0.5, gutter + 0.5), coverage.cols);
      for (int x = std::max(x0, x_first); x <= std::min(x1, x_last); ++x) {
        const Eigen::Vector2d q(x + 0.5, y + 0.5);
        const double d = mesh::SignedDistanceToTriangle(fp.corners_px, q);
        if (d > gutter + 0.5) continue;
        const float key = static_cast<float>(std::max(d, 0.0));
        if (d <= 0.0) {
          if (coverage.at<std::uint8_t>(y, x) == 255) continue;  // shared edge: first face wins
        } else if (coverage.at<std::uint8_t>(y, x) == 255 || key >= claims.at<float>(y, x)) {
          continue;
        }
        const Eigen::Vector2d r((q.x() - fp.offset.x()) * t, (fp.offset.y() - q.y()) * t);
        visit(fp.atlas, x, y, static_cast<int>(f), fp.linear.inverse() * r);
        claims.at<float>(y, x) = key;
        if (d <= 0.0) {
          coverage.at<std::uint8_t>(y, x) = 255;
          ++out.inside_texels;
        } else {
          coverage.at<std::uint8_t>(y, x) = 128;
        }
      }
    }
    if (progress && ((f + 1) % 256 == 0 || f + 1 == num_faces)) progress("atlas", f + 1, num_faces);
  }
  return out;
}

void DilateGutters(std::vector<cv::Mat>& planes, cv::Mat& coverage, int rings) {
  const std::size_t num_planes = planes.size();
  std::vector<double> sum(num_planes);
  for (int ring = 0; ring < rings; ++ring) {
    const cv::Mat before = coverage.clone();
    for (int y = 0; y < coverage.rows; ++y) {
      for (int x = 0; x < coverage.cols; ++x) {
        if (before.at<std::uint8_t>(y, x)) continue;
        int n = 0;
        std::fill(sum.begin(), sum.end(), 0.0);
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int yy = y + dy, xx = x + dx;
            if (yy < 0 || xx < 0 || yy >= coverage.rows || xx >= coverage.cols ||
                !before.at<std::uint8_t>(yy, xx))
              continue;
            for (std::size_t c = 0; c < num_planes; ++c) sum[c] += planes[c].at<float>(yy, xx);
            ++n;
          }
        if (n == 0) continue;
        for (std::size_t c = 0; c < num_planes; ++c)
          planes[c].at<float>(y, x) = static_cast<float>(sum[c] / n);
        coverage.at<std::uint8_t>(y, x) = 64;
      }
    }
  }
}

BakedPlanes BakeAtlasPlanes(const AtlasLayout& layout, double texel_size, int gutter,
                            int num_planes, const TexelLookup& lookup,
                            const ProgressCallback& progress) {
  BakedPlanes out;
  out.planes.resize(layout.atlas_sizes.size());
  for (std::size_t a = 0; a < layout.atlas_sizes.size(); ++a)
    for (int c = 0; c < num_planes; ++c)
      out.planes[a].push_back(cv::Mat::zeros(layout.atlas_sizes[a], CV_32FC1));
  std::vector<float> value(static_cast<std::size_t>(num_planes));
  AtlasCoverage coverage = VisitAtlasTexels(
      layout, texel_size, gutter,
      [&](int atlas, int x, int y, int face, const Eigen::Vector2d& p_in_frame) {
        lookup(face, p_in_frame, value.data());
        std::vector<cv::Mat>& planes = out.planes[static_cast<std::size_t>(atlas)];
        for (int c = 0; c < num_planes; ++c)
          planes[static_cast<std::size_t>(c)].at<float>(y, x) = value[static_cast<std::size_t>(c)];
      },
      progress);
  std::size_t total_texels = 0;
  for (std::size_t a = 0; a < out.planes.size(); ++a) {
    // Dilate into the few gutter texels no face reached (one ring per gutter texel).
    DilateGutters(out.planes[a], coverage.coverage[a], gutter);
    total_texels += coverage.coverage[a].total();
  }
  out.coverage = std::move(coverage.coverage);
  out.occupancy =
      total_texels ? static_cast<double>(coverage.inside_texels) / static_cast<double>(total_texels)
                   : 0.0;
  return out;
}

Atlases BuildAtlases(const mesh::TriangleMesh& mesh, const synth::MeshSynthesis& synthesis,
                     const AtlasOptions& options, const ProgressCallback& progress) {
  const auto start = std::chrono::steady_clock::now();
  const AtlasLayout layout = LayoutAtlases(mesh, synthesis.patches, synthesis.unfoldings,
                                           synthesis.texel_size, options, progress);
  // Bake: every texel inside a face (and its gutter ring) from the blended
  // synthesis, coefficients rotated into the atlas frame.
  const int num_planes = static_cast<int>(synthesis.sample_planes.size());
  const int coefficient_planes = synthesis.CoefficientPlanes();
  std::vector<Eigen::Matrix<double, 6, 6>> to_atlas;
  for (const FacePlacement& fp : layout.faces)
    to_atlas.push_back(ptm::OrthonormalFrameRotation(fp.AtlasFrameAngle()));
  BakedPlanes baked = BakeAtlasPlanes(
      layout, synthesis.texel_size, options.gutter, num_planes,
      [&](int face, const Eigen::Vector2d& p_frame, float* value) {
        synthesis.SampleBlended(face, p_frame, options.blend_strip, value);
        for (int poly = 0; poly < coefficient_planes / 6; ++poly) {
          Eigen::Matrix<double, 6, 1> v;
          for (int i = 0; i < 6; ++i) v[i] = value[poly * 6 + i];
          v = to_atlas[static_cast<std::size_t>(face)] * v;
          for (int i = 0; i < 6; ++i) value[poly * 6 + i] = static_cast<float>(v[i]);
        }
      },
      progress);
  Atlases atlases;
  atlases.num_charts = layout.num_charts;
  atlases.flattening = layout.flattening;
  atlases.faces = layout.faces;
  atlases.stretch = MeasureStretch(synthesis.patches, layout);
  for (const std::vector<cv::Mat>& planes : baked.planes)
    atlases.ptms.push_back(synth::FromOrthonormalPlanes(planes, synthesis.format));
  atlases.coverage = std::move(baked.coverage);
  atlases.occupancy = baked.occupancy;
  atlases.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return atlases;
}

}  // namespace texlume::atlas
