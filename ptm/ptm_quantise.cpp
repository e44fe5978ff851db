#include "ptm/ptm_quantise.h"

#include <omp.h>

#include <cmath>
#include <cstring>
#include <exception>
#include <limits>
#include <vector>

#include "core/first_exception.h"

namespace texlume::ptm {
namespace {

// A float's bits as an unsigned key in the float's order (IEEE 754: the sign bit
// flipped for a positive value, every bit for a negative one).
std::uint32_t OrderedKey(float v) {
  std::uint32_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  // Every bit flipped for a negative value, the sign bit for a positive one (C++20:
  // >> of a signed value is arithmetic); branch-free so that key loops vectorise.
  return bits ^ (static_cast<std::uint32_t>(static_cast<std::int32_t>(bits) >> 31) | 0x80000000u);
}

// The float whose OrderedKey is `key`.
float FromOrderedKey(std::uint32_t key) {
  const std::uint32_t bits = (key & 0x80000000u) ? (key & 0x7fffffffu) : ~key;
  float v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

// The values 255 a_i of each coefficient index i over every texel and polynomial
// (a: 6 floats per texel and polynomial), and of each the values of two ranks,
// found exactly in two passes over the coefficients without a copy of them (a
// radix select): a histogram of the keys' high 16 bits finds each rank's bin,
// then a histogram of the low 16 bits of the keys in that bin finds the key.
class CoefficientRanks {
 public:
  static constexpr std::size_t kBins = std::size_t{1} << 16;

  CoefficientRanks(const float* a, std::size_t values, std::array<std::size_t, 2> ranks)
      : a_(a), ranks_(ranks), count_(values / 6) {}

  // The value of rank ranks[r] among index i's values, for every i and r.
  std::array<std::array<float, 2>, 6> Values() {
    const std::vector<std::size_t> high = Count(false);
    for (std::size_t i = 0; i < 6; ++i)
      for (std::size_t r = 0; r < 2; ++r) high_[i][r] = Find(high, i * 2, ranks_[r], below_[i][r]);
    const std::vector<std::size_t> low = Count(true);
    std::array<std::array<float, 2>, 6> values;
    for (std::size_t i = 0; i < 6; ++i) {
      for (std::size_t r = 0; r < 2; ++r) {
        std::size_t below = below_[i][r];
        const std::uint32_t digit = Find(low, i * 2 + r, ranks_[r], below);
        values[i][r] = FromOrderedKey(high_[i][r] << 16 | digit);
      }
    }
    return values;
  }

 private:
  std::uint32_t Key(std::size_t j, std::size_t i) const {
    return OrderedKey(255.0f * a_[j * 6 + i]);
  }

  // Histogram h = i * 2 + r of the keys' high digits (r = 0: one per index), or of
  // the low digits of the keys whose high digit is high_[i][r].
  std::vector<std::size_t> Count(bool low_digits) const {
    std::vector<std::size_t> bins(12 * kBins, 0);
#pragma omp parallel
    {
      std::vector<std::uint32_t> local(12 * kBins, 0);  // < 2^32 values per thread
#pragma omp for schedule(static) nowait
      for (std::size_t j = 0; j < count_; ++j) {
        for (std::size_t i = 0; i < 6; ++i) {
          const std::uint32_t key = Key(j, i);
          if (!low_digits) {
            ++local[i * 2 * kBins + (key >> 16)];
            continue;
          }
          for (std::size_t r = 0; r < 2; ++r)
            if ((key >> 16) == high_[i][r]) ++local[(i * 2 + r) * kBins + (key & 0xffffu)];
        }
      }
#pragma omp critical
      for (std::size_t b = 0; b < bins.size(); ++b) bins[b] += local[b];
    }
    return bins;
  }

  // The digit whose bin in histogram h holds rank `rank`; `below` (values before
  // the histogram's first bin) becomes the values before that digit's bin.
  static std::uint32_t Find(const std::vector<std::size_t>& bins, std::size_t h, std::size_t rank,
                            std::size_t& below) {
    std::uint32_t digit = 0;
    while (below + bins[h * kBins + digit] <= rank) below += bins[h * kBins + digit++];
    return digit;
  }

  const float* a_;  // 6 per texel and polynomial
  std::array<std::size_t, 2> ranks_;
  std::size_t count_;
  std::array<std::array<std::uint32_t, 2>, 6> high_{};
  std::array<std::array<std::size_t, 2>, 6> below_{};
};

// CoefficientRanks' values in one pass over the coefficients, when a strided
// sample brackets each rank: every step-th texel's keys give, per index and rank,
// a key range holding the rank with a margin of 8 standard deviations of a sample
// quantile's rank; the pass counts the keys below each range and collects those
// inside it, among which the rank's key is selected. Exact like CoefficientRanks;
// Values() returns false (and the caller falls back to it) when a rank falls
// outside its range or a range holds too many keys (many equal values).
class BracketedRanks {
 public:
  BracketedRanks(const float* a, std::size_t values, std::array<std::size_t, 2> ranks)
      : a_(a), ranks_(ranks), count_(values / 6) {}

  bool Values(std::array<std::array<float, 2>, 6>& values) {
    const std::size_t step = std::max<std::size_t>(1, count_ / kSampleTarget);
    std::array<std::vector<std::uint32_t>, 6> samples;
    for (auto& sample : samples) sample.reserve((count_ + step - 1) / step);
#pragma omp parallel for schedule(dynamic, 1)
    for (std::size_t i = 0; i < 6; ++i) Bracket(i, step, samples[i]);
    limit_ = *std::max_element(limits_.begin(), limits_.end());
    if (!CountAndCollect()) return false;
    for (std::size_t i = 0; i < 6; ++i)
      for (std::size_t r = 0; r < 2; ++r) {
        std::vector<std::uint32_t>& inside = inside_[i][r];
        if (ranks_[r] < below_[i][r] || ranks_[r] - below_[i][r] >= inside.size()) return false;
        const auto nth = inside.begin() + static_cast<std::ptrdiff_t>(ranks_[r] - below_[i][r]);
        std::nth_element(inside.begin(), nth, inside.end());
        values[i][r] = FromOrderedKey(*nth);
      }
    return true;
  }

 private:
  static constexpr std::size_t kSampleTarget = std::size_t{1} << 18;

  std::uint32_t Key(std::size_t j, std::size_t i) const {
    return OrderedKey(255.0f * a_[j * 6 + i]);
  }

  // Index i's key range around each rank, from every step-th texel's keys, in
  // `sample` (its memory reserved by the caller: no allocation on the threads).
  void Bracket(std::size_t i, std::size_t step, std::vector<std::uint32_t>& sample) {
    for (std::size_t j = 0; j < count_; j += step) sample.push_back(Key(j, i));
    const double m = static_cast<double>(sample.size());
    for (std::size_t r = 0; r < 2; ++r) {
      const double p = static_cast<double>(ranks_[r]) / static_cast<double>(count_);
      const double at = p * m, margin = 8.0 * std::sqrt(m * p * (1.0 - p)) + 16.0;
      const auto nth = [&](double rank, std::uint32_t beyond) {
        if (rank < 0.0 || rank > m - 1.0) return beyond;
        const auto it = sample.begin() + static_cast<std::ptrdiff_t>(rank);
        std::nth_element(sample.begin(), it, sample.end());
        return *it;
      };
      low_[i][r] = nth(std::floor(at - margin), 0u);
      high_[i][r] = nth(std::ceil(at + margin), std::numeric_limits<std::uint32_t>::max());
      // At most 4 times the keys a range of this width should hold, and 2^16.
      limits_[i] = std::max<std::size_t>(
          limits_[i], static_cast<std::size_t>(4.0 * 2.0 * margin * static_cast<double>(step)) +
                          (std::size_t{1} << 16));
    }
  }

  // Counts each index's keys below its ranges and collects those inside; false
  // when a range holds more than limit_ keys. Two texels at a time, in fixed-length
  // loops over their keys that the compiler vectorises; a pair with a key inside a
  // range, rare, is collected one key at a time.
  bool CountAndCollect() {
    for (std::size_t e = 0; e < kPair; ++e)
      for (std::size_t r = 0; r < 2; ++r) {
        low_of_lane_[r][e] = low_[e % 6][r];
        width_of_lane_[r][e] = high_[e % 6][r] - low_[e % 6][r];
      }
    bool overflow = false;
    FirstException error;  // from a thread's allocation: rethrown, not terminate()
    const std::size_t blocks = (count_ + kBlock - 1) / kBlock;
#pragma omp parallel
    {
      Counts counts;
#pragma omp for schedule(static) nowait
      for (std::size_t b = 0; b < blocks; ++b) {
        error.Run([&] { CountBlock(b * kBlock, std::min(count_, (b + 1) * kBlock), counts); });
      }
#pragma omp critical
      for (std::size_t i = 0; i < 6; ++i)
        for (std::size_t r = 0; r < 2; ++r) {
          below_[i][r] += counts.below[i][r];
          overflow = overflow || counts.inside[i][r].size() >= limit_;
          inside_[i][r].insert(inside_[i][r].end(), counts.inside[i][r].begin(),
                               counts.inside[i][r].end());
        }
    }
    error.Rethrow();
    return !overflow;
  }

  struct Counts {
    std::array<std::array<std::size_t, 2>, 6> below{};
    std::array<std::array<std::vector<std::uint32_t>, 2>, 6> inside;
  };

  // Texels [begin, end): a pair at a time, the last odd one on its own. A key is
  // inside its range when key - low <= high - low (unsigned: a key below wraps).
  void CountBlock(std::size_t begin, std::size_t end, Counts& counts) const {
    std::uint32_t below[2][kPair] = {};
    std::size_t j = begin;
    for (; j + 2 <= end; j += 2) {
      std::uint32_t key[kPair];
      for (std::size_t e = 0; e < kPair; ++e) key[e] = OrderedKey(255.0f * a_[j * 6 + e]);
      std::uint32_t inside[kPair];
      for (std::size_t e = 0; e < kPair; ++e) {
        below[0][e] += key[e] < low_of_lane_[0][e] ? 1u : 0u;
        below[1][e] += key[e] < low_of_lane_[1][e] ? 1u : 0u;
        inside[e] = (key[e] - low_of_lane_[0][e] <= width_of_lane_[0][e] ? 1u : 0u) |
                    (key[e] - low_of_lane_[1][e] <= width_of_lane_[1][e] ? 1u : 0u);
      }
      std::uint32_t any = 0;
      for (std::size_t e = 0; e < kPair; ++e) any |= inside[e];
      if (any) [[unlikely]]
        for (std::size_t t = j; t < j + 2; ++t) Collect(t, counts, nullptr);
    }
    for (std::size_t r = 0; r < 2; ++r)
      for (std::size_t e = 0; e < kPair; ++e) counts.below[e % 6][r] += below[r][e];
    if (j < end) Collect(j, counts, &counts.below);
  }

  // Texel j's keys inside their ranges into `counts`, and those below into `below`
  // when given.
  void Collect(std::size_t j, Counts& counts,
               std::array<std::array<std::size_t, 2>, 6>* below) const {
    for (std::size_t i = 0; i < 6; ++i)
      for (std::size_t r = 0; r < 2; ++r) {
        const std::uint32_t key = Key(j, i);
        if (below && key < low_[i][r]) ++(*below)[i][r];
        std::vector<std::uint32_t>& inside = counts.inside[i][r];
        if (key >= low_[i][r] && key <= high_[i][r] && inside.size() < limit_)
          inside.push_back(key);
      }
  }

  static constexpr std::size_t kPair = 12;      // two texels' coefficients
  static constexpr std::size_t kBlock = 65536;  // texels counted in 32-bit lanes at once

  const float* a_;  // 6 per texel and polynomial
  std::array<std::size_t, 2> ranks_;
  std::size_t count_;
  std::size_t limit_ = 0;
  std::array<std::size_t, 6> limits_{};  // limit_ of each index
  std::array<std::array<std::uint32_t, 2>, 6> low_{}, high_{};
  // Each lane's range of a pair of texels: its low key and its width.
  std::uint32_t low_of_lane_[2][kPair] = {}, width_of_lane_[2][kPair] = {};
  std::array<std::array<std::size_t, 2>, 6> below_{};
  std::array<std::array<std::vector<std::uint32_t>, 2>, 6> inside_;
};

}  // namespace

std::array<Quantiser, 6> Quantisers(const Ptm& ptm) {
  std::array<Quantiser, 6> q;
  const std::size_t count = ptm.coefficients.size() / 6;
  if (count == 0) return q;
  const std::array<std::size_t, 2> ranks{count / 1000, count - 1 - count / 1000};
  std::array<std::array<float, 2>, 6> values;
  const float* a = ptm.coefficients.data();
  if (!BracketedRanks(a, ptm.coefficients.size(), ranks).Values(values))
    values = CoefficientRanks(a, ptm.coefficients.size(), ranks).Values();
  for (std::size_t i = 0; i < 6; ++i) {
    const float lo = std::min(0.0f, values[i][0]);
    const float hi = std::max(0.0f, values[i][1]);
    q[i].scale = hi > lo ? (hi - lo) / 255.0f : 1.0f;
    q[i].bias = static_cast<int>(std::lround(-lo / q[i].scale));
  }
  return q;
}

void GroupEncoder::Encode(const float* a, std::size_t stride, std::size_t count,
                          std::uint8_t* out) const {
  for (std::size_t t = 0; t < count; t += kGroups) {
    const std::size_t n = std::min(kGroups, count - t);
    float v[kValues];
    for (std::size_t g = 0; g < kGroups; ++g)
      std::memcpy(v + g * 6, a + (t + std::min(g, n - 1)) * stride, 6 * sizeof(float));
    std::int32_t byte[kValues];
    for (std::size_t j = 0; j < kValues; ++j) {  // RoundToByte, lane by lane
      const float x = 255.0f * v[j] / scale_[j] + bias_[j];
      const float clamped = std::min(x > 0.0f ? x : 0.0f, 255.0f);
      const auto whole = static_cast<std::int32_t>(clamped);
      byte[j] = whole + (clamped - static_cast<float>(whole) >= 0.5f ? 1 : 0);
    }
    std::uint8_t bytes[kValues];
    for (std::size_t j = 0; j < kValues; ++j) bytes[j] = static_cast<std::uint8_t>(byte[j]);
    std::memcpy(out + t * 6, bytes, n * 6);
  }
}

}  // namespace texlume::ptm
