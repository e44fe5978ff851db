#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "atlas/chart_parts.h"
#include "atlas/charts.h"
#include "core/progress.h"
#include "synth/triangle_parts.h"

// Packing charts into atlases (synth/atlas.cpp's LayoutAtlases): chart
// outlines at turns, free-run bins, first-fit outline packing, and strip
// charts packed row by row by best fit.
namespace texlume::atlas::chart_packing {

using chart_parts::kPi;

/// Turns tried for every chart when packing (every 360/16 = 22.5 degrees).
inline constexpr int kPackingRotations = 16;

/// Charts whose upright box is this many times longer than wide are turned by
/// quarter turns only.
inline constexpr int kThinChartAspect = 4;

/// An atlas that has refused this many charts in a row is passed over by
/// PackOutlines until the charts are half as large (the largest come first).
inline constexpr int kBinRefusalsToClose = 256;

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

/// The largest square of texels inside an outline: its top-left (x, row) in the
/// outline's box and its side (0 for an empty outline). Packing tests it first:
/// a fragmented atlas has few free squares as large.
struct OutlineSquare {
  int row = 0, x = 0, side = 0;
};
OutlineSquare LargestSquare(const ChartOutline& o);
/// LargestSquare of every turn of every chart.
std::vector<std::vector<OutlineSquare>> LargestSquares(
    const std::vector<std::vector<ChartOutline>>& outlines);

/// Where PackOutlines drops a chart: with its outline at `rotation`, the
/// outline box's top-left at texel (x, y) of atlas `bin` (y down).
struct OutlineDrop {
  int bin = 0, rotation = 0, x = 0, y = 0;
};

struct OutlinePacking {
  std::vector<OutlineDrop> drops;     ///< per chart
  std::int64_t texels = 0;            ///< atlas texels used (the last atlas cropped)
  std::int64_t bins_passed_over = 0;  ///< atlases a chart skipped (kBinRefusalsToClose)
};

/// Which position (and rotation) a chart takes.
enum class DropRule {
  kLowestBottom,    ///< the outline box's bottom row nearest the atlas top, then leftmost
  kLowestPosition,  ///< the outline box's top row nearest the atlas top, then leftmost
};

/// Bottom-left packing of outlines (texel-exact, so charts fill each other's
/// concavities and holes): charts go in `order`, each into the first atlas
/// where it fits, at the rotation and position `rule` prefers; an atlas that
/// refused kBinRefusalsToClose charts in a row waits for charts half as large.
/// `cores`: LargestSquares(outlines), made once for every layout of the same
/// outlines. `placed` is called after each chart.
OutlinePacking PackOutlines(const std::vector<std::vector<ChartOutline>>& outlines,
                            const std::vector<std::vector<OutlineSquare>>& cores,
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
