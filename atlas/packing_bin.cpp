#include "atlas/packing_bin.h"

#include <algorithm>

namespace texlume::atlas::chart_packing {

template <typename Value>
RowMaxGrid<Value>::RowMaxGrid(int size) : size_(size) {
  while (blocks_ * kBlock < size_) blocks_ *= 2;
  values_.resize(Index(size_, size_));
  // Blocks past the row's end hold -1: no value reaches it.
  tree_.assign(Index(size_, 2 * blocks_), Value{-1});
}

template <typename Value>
void RowMaxGrid<Value>::Changed(int y, int x_lo, int x_hi) {
  if (x_lo >= x_hi) return;
  const Value* v = Row(y);
  Value* t = &tree_[Index(y, 2 * blocks_)];
  int lo = x_lo / kBlock, hi = (x_hi - 1) / kBlock;
  for (int b = lo; b <= hi; ++b) {
    const Value* first = v + b * kBlock;
    t[blocks_ + b] = *std::max_element(first, v + std::min(size_, (b + 1) * kBlock));
  }
  for (lo = (lo + blocks_) / 2, hi = (hi + blocks_) / 2; lo >= 1; lo /= 2, hi /= 2)
    for (int i = lo; i <= hi; ++i) t[i] = std::max(t[2 * i], t[2 * i + 1]);
}

template <typename Value>
int RowMaxGrid<Value>::FirstAtLeast(int y, int from, int value) const {
  if (from >= size_) return size_;
  const Value* v = Row(y);
  const int block_end = std::min(size_, (from / kBlock + 1) * kBlock);
  for (int x = from; x < block_end; ++x)
    if (v[x] >= value) return x;
  // The first later block holding such a value: climb while the node is a right
  // child, step to the right sibling, then descend to the leftmost such leaf.
  const Value* t = Tree(y);
  int i = blocks_ + from / kBlock;
  do {
    while (i & 1) i >>= 1;
    if (i == 0) return size_;
    ++i;
  } while (t[i] < value);
  while (i < blocks_) i = t[2 * i] >= value ? 2 * i : 2 * i + 1;
  for (int x = (i - blocks_) * kBlock;; ++x)
    if (v[x] >= value) return x;
}

template class RowMaxGrid<std::int16_t>;
template class RowMaxGrid<std::int8_t>;

PackingBin::PackingBin(int bin_size) : size_(bin_size), runs_(bin_size), squares_(bin_size) {
  for (int y = 0; y < size_; ++y) {
    std::int16_t* r = runs_.Row(y);
    for (int x = 0; x < size_; ++x) r[x] = static_cast<std::int16_t>(size_ - x);
    runs_.Changed(y, 0, size_);
  }
  UpdateSquares(0, size_, 0, size_);
}

void PackingBin::TakeRun(int y, int x_first, int x_end) {
  // Runs right of the taken texels stay; leftwards from the last taken texel each
  // run follows from the one to its right, until one comes out as it was.
  std::int16_t* r = runs_.Row(y);
  int x = x_end - 1;
  for (; x >= 0; --x) {
    const bool used = x >= x_first || r[x] < 0;
    const int next = x + 1 < size_ ? r[x + 1] : 0;
    const auto run =
        static_cast<std::int16_t>(used ? (next < 0 ? next - 1 : -1) : (next > 0 ? next + 1 : 1));
    if (x < x_first && run == r[x]) break;
    r[x] = run;
  }
  runs_.Changed(y, x + 1, x_end);
}

void PackingBin::UpdateSquares(int x_lo, int x_hi, int y_lo, int y_hi) {
  // side(x, y) = 1 + min(side right, below, right-below) on a free texel, 0 on a used
  // one or past the bin's edge, at most kMaxSquare; computed from the bottom-right.
  const auto side = [&](int x, int y) -> int {
    return x < size_ && y < size_ ? squares_.Row(y)[x] : 0;
  };
  for (int y = y_hi - 1; y >= y_lo; --y) {
    const std::int16_t* run = runs_.Row(y);
    std::int8_t* square = squares_.Row(y);
    for (int x = x_hi - 1; x >= x_lo; --x) {
      const int s = 1 + std::min({side(x + 1, y), side(x, y + 1), side(x + 1, y + 1)});
      square[x] = static_cast<std::int8_t>(run[x] > 0 ? std::min(s, kMaxSquare) : 0);
    }
    squares_.Changed(y, x_lo, x_hi);
  }
}

int PackingBin::NextCandidate(const ChartOutline& o, const OutlineSquare& core, int x,
                              int y) const {
  if (core.side > 0) {
    const int side = std::min(core.side, kMaxSquare);
    const int at = squares_.FirstAtLeast(y + core.row, x + core.x, side) - core.x;
    if (at > x) return at;
  }
  for (const ChartOutline::Run& run : o.runs) {
    if (runs_.Row(y + run.row)[x + run.x] >= run.length) continue;
    // Every position before the next column where this run finds room is blocked by it.
    return runs_.FirstAtLeast(y + run.row, x + run.x + 1, run.length) - run.x;
  }
  return x;
}

std::pair<int, int> PackingBin::FirstFit(const ChartOutline& o, const OutlineSquare& core,
                                         int max_bottom) const {
  const int side = std::min(core.side, kMaxSquare);
  for (int y = 0; y + o.Height() <= std::min(size_, max_bottom); ++y) {
    // Rows where the core square or the longest run has no room are passed at once.
    if (side > 0 && squares_.RowMax(y + core.row) < side) continue;
    if (!o.runs.empty() && runs_.RowMax(y + o.runs[0].row) < o.runs[0].length) continue;
    for (int x = 0; x + o.Width() <= size_;) {
      const int next = NextCandidate(o, core, x, y);
      if (next == x) return {x, y};
      x = next;
    }
  }
  return {-1, -1};
}

void PackingBin::Take(const ChartOutline& o, int x0, int y0) {
  for (const ChartOutline::Run& r : o.runs) TakeRun(y0 + r.row, x0 + r.x, x0 + r.x + r.length);
  // Squares up to kMaxSquare up and left of the taken texels may have shrunk.
  UpdateSquares(std::max(0, x0 - kMaxSquare + 1), std::min(size_, x0 + o.Width()),
                std::max(0, y0 - kMaxSquare + 1), std::min(size_, y0 + o.Height()));
  used_rows_ = std::max(used_rows_, y0 + o.Height());
}

}  // namespace texlume::atlas::chart_packing
