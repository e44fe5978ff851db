#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "atlas/charts.h"
#include "core/progress.h"
#include "synth/triangle_parts.h"

// Packing charts into atlases (synth/atlas.cpp's LayoutAtlases): chart
// outlines at turns, free-run bins, first-fit outline packing, and strip
// charts packed row by row by best fit.
namespace texlume::atlas::chart_packing {

inline constexpr double kPi = 3.14159265358979323846;

/// Turns tried for every chart when packing (every 360/16 = 22.5 degrees).
inline constexpr int kPackingRotations = 16;

/// Charts whose upright box is this many times longer than wide are turned by
/// quarter turns only.
inline constexpr int kThinChartAspect = 4;

/// Strip charts compared for the best fit at each place in a row.
inline constexpr int kBestFitCandidates = 64;

/// A chart turned by `angle`: its texel box (chart units / t, x right, y up;
/// gutters included) and, row by row (y down from the box top), the runs of
/// texels the bake writes: those within the gutter of one of its triangles.
struct ChartOutline {
  struct Run {
    int row, x, length;
  };
  double angle = 0.0;
  Eigen::Vector2i lo, hi;
  std::vector<Run> runs;
  /// Per row, the x of its first run (INT_MAX for a row without runs).
  std::vector<int> row_first_x;
  double area = 0.0;  ///< texels inside the outline
  int Width() const { return hi.x() - lo.x(); }
  int Height() const { return hi.y() - lo.y(); }
};

/// The texel columns [first, last] of [0, width) whose centres x + 0.5 lie in `span`.
std::pair<int, int> TexelColumns(const std::pair<double, double>& span, int width);

/// A chart's corners turned by `angle` (texels, chart frame) and its texel box
/// with the gutters (o.lo, o.hi); the outline's runs are left empty.
ChartOutline Box(const std::vector<ChartFace>& chart, double angle,
                 const std::vector<synth::TrianglePatch>& patches, double t, int gutter,
                 std::vector<std::array<Eigen::Vector2d, 3>>* corners);

ChartOutline Outline(const std::vector<ChartFace>& chart, double angle,
                     const std::vector<synth::TrianglePatch>& patches, double t, int gutter);

/// The same outline as Outline(chart, angle) from its faces' own outlines
/// (`face_outlines[i]` = Outline({chart[i]}, angle)): a packer that outlines many
/// pieces of one chart rasterises each face once.
ChartOutline UnionOutline(const std::vector<ChartFace>& chart,
                          const std::vector<const ChartOutline*>& face_outlines,
                          const std::vector<synth::TrianglePatch>& patches, double t, int gutter);

/// The turn that brings a chart's smallest bounding box upright (radians): the
/// smallest box has a side along an edge of the convex hull, so every hull
/// edge's turn is tried. Packing tries turns from it, so long thin charts
/// (the slivers of decimated meshes) lie along the atlas axes.
double UprightBoxAngle(const std::vector<ChartFace>& chart,
                       const std::vector<synth::TrianglePatch>& patches);

/// One atlas being packed: per texel, the length of the free (> 0) or used
/// (< 0) run of texels that starts there, to its right.
struct PackingBin {
  int size = 0;
  std::vector<std::int16_t> run;  // size x size, row-major (|run| <= 16384)
  std::vector<int> longest_free;  // per row: its longest free run
  int used_rows = 0;
  explicit PackingBin(int bin_size)
      : size(bin_size),
        run(static_cast<std::size_t>(bin_size) * bin_size),
        longest_free(static_cast<std::size_t>(bin_size), 0) {
    for (int y = 0; y < size; ++y) UpdateRow(y, nullptr);
  }
  int At(int x, int y) const {
    return run[static_cast<std::size_t>(y) * static_cast<std::size_t>(size) +
               static_cast<std::size_t>(x)];
  }
  /// Rebuilds row y's runs; `used` marks texels to take (nullptr: all free).
  void UpdateRow(int y, const std::vector<char>* used) {
    std::int16_t* r = &run[static_cast<std::size_t>(y) * static_cast<std::size_t>(size)];
    for (int x = size - 1; x >= 0; --x) {
      const bool taken = used ? (*used)[static_cast<std::size_t>(x)] != 0 : false;
      const int next = x + 1 < size ? r[x + 1] : 0;
      r[x] =
          static_cast<std::int16_t>(taken ? (next < 0 ? next - 1 : -1) : (next > 0 ? next + 1 : 1));
    }
    int longest = 0;
    for (int x = 0; x < size; ++x) longest = std::max(longest, static_cast<int>(r[x]));
    longest_free[static_cast<std::size_t>(y)] = longest;
  }
  /// 0 when the outline fits with its box's top-left at (x, y); otherwise how
  /// far right the next position that can fit on the blocking row is.
  int Skip(const ChartOutline& o, int x, int y) const {
    for (const ChartOutline::Run& r : o.runs) {
      const int v = At(x + r.x, y + r.row);
      if (v >= r.length) continue;
      if (v < 0) return -v;                   // blocked at the run's start: pass the used run
      if (x + r.x + v >= size) return size;   // free to the edge but too short
      return v - At(x + r.x + v, y + r.row);  // pass the free run and the used one after it
    }
    return 0;
  }
  /// The first position, by rows then columns, where the outline fits, with the
  /// outline's row `y + Height()` not above `max_bottom`; (-1, -1): none.
  std::pair<int, int> FirstFit(const ChartOutline& o, int max_bottom) const {
    for (int y = 0; y + o.Height() <= std::min(size, max_bottom); ++y) {
      // Rows where the longest run has no room are passed at once.
      if (!o.runs.empty() &&
          longest_free[static_cast<std::size_t>(y + o.runs[0].row)] < o.runs[0].length)
        continue;
      for (int x = 0; x + o.Width() <= size;) {
        const int skip = Skip(o, x, y);
        if (skip == 0) return {x, y};
        x += skip;
      }
    }
    return {-1, -1};
  }
  void Take(const ChartOutline& o, int x0, int y0) {
    std::vector<std::vector<char>> rows(static_cast<std::size_t>(o.Height()));
    for (const ChartOutline::Run& r : o.runs) {
      auto& row = rows[static_cast<std::size_t>(r.row)];
      if (row.empty()) {
        row.resize(static_cast<std::size_t>(size));
        const std::int16_t* cur =
            &run[static_cast<std::size_t>(y0 + r.row) * static_cast<std::size_t>(size)];
        for (int x = 0; x < size; ++x) row[static_cast<std::size_t>(x)] = cur[x] < 0;
      }
      std::fill(row.begin() + x0 + r.x, row.begin() + x0 + r.x + r.length, 1);
    }
    for (std::size_t i = 0; i < rows.size(); ++i)
      if (!rows[i].empty()) UpdateRow(y0 + static_cast<int>(i), &rows[i]);
    used_rows = std::max(used_rows, y0 + o.Height());
  }
};

/// Where PackOutlines drops a chart: with its outline at `rotation`, the
/// outline box's top-left at texel (x, y) of atlas `bin` (y down).
struct OutlineDrop {
  int bin = 0, rotation = 0, x = 0, y = 0;
};

struct OutlinePacking {
  std::vector<OutlineDrop> drops;  ///< per chart
  std::int64_t texels = 0;         ///< atlas texels used (the last atlas cropped)
};

/// Which position (and rotation) a chart takes.
enum class DropRule {
  kLowestBottom,    ///< the outline box's bottom row nearest the atlas top, then leftmost
  kLowestPosition,  ///< the outline box's top row nearest the atlas top, then leftmost
};

/// Bottom-left packing of outlines (texel-exact, so charts fill each other's
/// concavities and holes): charts go in `order`, each into the first atlas
/// where it fits, at the rotation and position `rule` prefers.
/// `placed` is called after each chart.
OutlinePacking PackOutlines(const std::vector<std::vector<ChartOutline>>& outlines,
                            const std::vector<std::size_t>& order, int bin_size, DropRule rule,
                            const std::function<void()>& placed);

/// Strip charts (bands of equal height, synth/charts.h) packed in rows: pieces
/// go tallest first, left to right, by best fit (each place in a row takes the
/// piece of the row's height, and its turn by 0 or 180 degrees, whose left end
/// slid against the row's texel-exact right edge leaves the least gap, so
/// slanted ends nest); a band that overruns the row is cut at a rung, and its rest starts
/// the next row, so rows end within a triangle of the atlas edge.
struct RowPacking {
  std::vector<std::vector<ChartFace>> pieces;
  std::vector<ChartOutline> outlines;     ///< per piece, at its turn
  std::vector<std::array<int, 3>> drops;  ///< per piece: atlas, x, y of the outline box
  std::int64_t texels = 0;                ///< atlas texels used (the last atlas cropped)
};

RowPacking PackStripsInRows(const std::vector<std::vector<ChartFace>>& charts,
                            const std::vector<synth::TrianglePatch>& patches, double t, int gutter,
                            int atlas_size, const ProgressCallback& progress);

}  // namespace texlume::atlas::chart_packing
