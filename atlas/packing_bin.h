#pragma once

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "atlas/chart_packing.h"

namespace texlume::atlas::chart_packing {

/// A square grid of values and, per row, a max tree over blocks of kBlock
/// values: the first column from a given one on whose value is at least v is
/// found in O(kBlock + log(size)), however the row's values lie.
template <typename Value>
class RowMaxGrid {
 public:
  static constexpr int kBlock = 16;

  explicit RowMaxGrid(int size);
  Value* Row(int y) { return &values_[Index(y, size_)]; }
  const Value* Row(int y) const { return &values_[Index(y, size_)]; }
  /// The row's largest value.
  int RowMax(int y) const { return Tree(y)[1]; }
  /// Brings row y's tree up to date after its values in columns [x_lo, x_hi) changed.
  void Changed(int y, int x_lo, int x_hi);
  /// The first column x >= from of row y whose value is at least `value`; the
  /// grid's size when there is none.
  int FirstAtLeast(int y, int from, int value) const;

 private:
  static std::size_t Index(int y, int stride) {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(stride);
  }
  const Value* Tree(int y) const { return &tree_[Index(y, 2 * blocks_)]; }

  int size_ = 0;
  int blocks_ = 1;             // a power of two >= size_ / kBlock: the trees' leaves
  std::vector<Value> values_;  // size_ x size_, row-major
  std::vector<Value> tree_;    // per row 2 * blocks_: [1] the root, [blocks_ + b] block b
};

/// One atlas being packed by outlines (PackOutlines). Per texel, the length of
/// the free (> 0) or used (< 0) run of texels that starts there, to its right,
/// and the side of the largest free square whose top-left it is (up to
/// kMaxSquare). A position is tried only where the outline's core square and
/// its runs, longest first, find room, each jumping to the next such column.
class PackingBin {
 public:
  static constexpr int kMaxSquare = 64;

  explicit PackingBin(int bin_size);

  /// The first position, by rows then columns, where the outline fits (its
  /// box's top-left, y down), with the outline's bottom row `y + Height()` not
  /// below `max_bottom`; (-1, -1): none.
  std::pair<int, int> FirstFit(const ChartOutline& o, const OutlineSquare& core,
                               int max_bottom) const;
  /// Marks the outline's texels used, its box's top-left at (x0, y0).
  void Take(const ChartOutline& o, int x0, int y0);
  /// Rows from the top down to the lowest texel taken.
  int UsedRows() const { return used_rows_; }

 private:
  /// Marks texels [x_first, x_end) of row y used (they were free) and updates the
  /// runs that change: those taken and the ones left of them up to the first that stays.
  void TakeRun(int y, int x_first, int x_end);
  /// Recomputes the free squares whose top-left lies in [x_lo, x_hi) x [y_lo, y_hi).
  void UpdateSquares(int x_lo, int x_hi, int y_lo, int y_hi);
  /// The next column from x on (size_: none) where, the outline's top at row y,
  /// the blocking test passes: its core square's, then its runs'. x itself: it fits.
  int NextCandidate(const ChartOutline& o, const OutlineSquare& core, int x, int y) const;

  int size_ = 0;
  RowMaxGrid<std::int16_t> runs_;    // |run| <= 16384
  RowMaxGrid<std::int8_t> squares_;  // [0, kMaxSquare]
  int used_rows_ = 0;
};

}  // namespace texlume::atlas::chart_packing
