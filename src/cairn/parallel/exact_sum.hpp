// Exact floating-point sums, so that a global sum does not depend on the order of its terms:
// the same for any thread count, any number of MPI ranks and any partition of the particles
// (docs/parallel.md, "Determinism").
//
// ExactSum is a fixed-point superaccumulator: every finite double is an integer multiple of
// 2^-1074 below 2^1024, so it is added exactly into 68 limbs of 32 bits each (held in int64 so
// that carries can wait). Integer addition is associative, hence the accumulated value is the
// exact sum whatever the order of add() and merge() calls; value() rounds it once, by a fixed
// rule, to a double (within about one unit in the last place of the exact sum). Infinities and
// NaNs are counted and give inf/NaN as a plain sum would.
//
// Cost: a few integer operations per term (no division, no branch on the magnitude), about the
// price of the memory read of the term in a particle loop.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "cairn/parallel/comm.hpp"

namespace cairn {

class ExactSum {
 public:
  /// Limbs of 32 bits from 2^-1074; the top one also carries the sign.
  static constexpr int n_limbs = 68;
  /// Limbs plus the counts of NaN, +inf and -inf terms: the words summed across ranks.
  static constexpr int n_words = n_limbs + 3;

  void add(double x) {
    const auto bits = std::bit_cast<std::uint64_t>(x);
    const int exponent = static_cast<int>((bits >> 52) & 0x7ffu);
    std::uint64_t mantissa = bits & ((std::uint64_t{1} << 52) - 1);
    const bool negative = (bits >> 63) != 0;
    if (exponent == 0x7ff) {
      if (mantissa != 0) ++word_[n_limbs];
      else ++word_[negative ? n_limbs + 2 : n_limbs + 1];
      return;
    }
    // x = mantissa * 2^(shift - 1074), shift >= 0 (subnormals: exponent 0, no hidden bit).
    int shift = 0;
    if (exponent != 0) {
      mantissa |= std::uint64_t{1} << 52;
      shift = exponent - 1;
    }
    const int limb = shift >> 5;
    const unsigned __int128 m = static_cast<unsigned __int128>(mantissa) << (shift & 31);
    const auto lo = static_cast<std::int64_t>(static_cast<std::uint64_t>(m) & 0xffffffffu);
    const auto mid = static_cast<std::int64_t>(static_cast<std::uint64_t>(m >> 32) & 0xffffffffu);
    const auto hi = static_cast<std::int64_t>(static_cast<std::uint64_t>(m >> 64));
    if (negative) {
      word_[limb] -= lo;
      word_[limb + 1] -= mid;
      word_[limb + 2] -= hi;
    } else {
      word_[limb] += lo;
      word_[limb + 1] += mid;
      word_[limb + 2] += hi;
    }
    // Each add moves a limb by less than 2^32: carry long before an int64 can overflow.
    if (++pending_ == (1 << 30)) normalise();
  }

  ExactSum& operator+=(double x) {
    add(x);
    return *this;
  }

  /// Add another accumulator (exact).
  ExactSum& operator+=(const ExactSum& other) {
    ExactSum o = other;
    o.normalise();
    normalise();
    for (int k = 0; k < n_words; ++k) word_[k] += o.word_[k];
    pending_ = 1;
    return *this;
  }

  /// Propagate carries: limbs 0..n-2 in [0, 2^32), the top limb signed.
  void normalise() {
    for (int k = 0; k < n_limbs - 1; ++k) {
      const std::int64_t carry = word_[k] >> 32;  // floor division by 2^32
      word_[k] -= carry * (std::int64_t{1} << 32);
      word_[k + 1] += carry;
    }
    pending_ = 0;
  }

  /// The sum, rounded to a double by a rule that depends only on the exact value.
  [[nodiscard]] double value() const {
    const std::int64_t nan = word_[n_limbs], pos_inf = word_[n_limbs + 1], neg_inf = word_[n_limbs + 2];
    if (nan > 0 || (pos_inf > 0 && neg_inf > 0)) return std::numeric_limits<double>::quiet_NaN();
    if (pos_inf > 0) return std::numeric_limits<double>::infinity();
    if (neg_inf > 0) return -std::numeric_limits<double>::infinity();
    ExactSum s = *this;
    s.normalise();
    double sign = 1.0;
    if (s.word_[n_limbs - 1] < 0) {
      sign = -1.0;
      for (int k = 0; k < n_limbs; ++k) s.word_[k] = -s.word_[k];
      s.normalise();
    }
    int top = n_limbs - 1;
    while (top >= 0 && s.word_[top] == 0) --top;
    if (top < 0) return 0.0;
    // The three highest limbs hold at least 65 significant bits; the rest is below the last
    // place of a double.
    double v = 0.0;
    const int low = top >= 2 ? top - 2 : 0;
    for (int k = top; k >= low; --k) v = v * 4294967296.0 + static_cast<double>(s.word_[k]);
    return sign * std::ldexp(v, 32 * low - 1074);
  }

  /// The words to sum across ranks (normalise() first), and their count n_words.
  [[nodiscard]] std::int64_t* words() { return word_.data(); }
  [[nodiscard]] const std::int64_t* words() const { return word_.data(); }

 private:
  std::array<std::int64_t, n_words> word_{};
  int pending_ = 0;
};

/// Sum n accumulators across the ranks of `comm` (exactly: the result does not depend on how the
/// terms were spread over the ranks). Every rank gets the totals.
inline void sum_across(const Comm& comm, ExactSum* sums, int n) {
  if (!comm.parallel()) return;
  std::vector<std::int64_t> words(static_cast<std::size_t>(n) * ExactSum::n_words);
  for (int k = 0; k < n; ++k) {
    sums[k].normalise();
    std::copy(sums[k].words(), sums[k].words() + ExactSum::n_words, words.begin() + k * ExactSum::n_words);
  }
  comm.sum(words.data(), static_cast<int>(words.size()));
  for (int k = 0; k < n; ++k) {
    std::copy(words.begin() + k * ExactSum::n_words, words.begin() + (k + 1) * ExactSum::n_words, sums[k].words());
    sums[k].normalise();
  }
}

/// Exact sums of N terms over p in [0, n): term(p, out) sets out[0..N), every thread adds into
/// its own accumulators, merged exactly, so the result does not depend on the thread count or,
/// summed across ranks (sum_across), on the partition.
template <int N, class Fn>
std::array<ExactSum, N> exact_sums(std::int64_t n, Fn&& term) {
  std::array<ExactSum, N> total;
#pragma omp parallel
  {
    std::array<ExactSum, N> local;
    std::array<double, N> values{};
#pragma omp for schedule(static)
    for (std::int64_t p = 0; p < n; ++p) {
      term(p, values);
      for (int k = 0; k < N; ++k) local[k].add(values[k]);
    }
#pragma omp critical(cairn_exact_sums)
    for (int k = 0; k < N; ++k) total[k] += local[k];
  }
  return total;
}

}  // namespace cairn
