#pragma once

// Private to src/core: the local eliminations (LocalStressFinder.hpp, ContractEchelon.cpp) put the rows and
// columns of every ball in order, tens of thousands of balls of a few hundred each.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace mobility_analysis {
namespace core_detail {

/**
 * Sorts lists of ints in increasing order. Where the values span at most kSpanPerValue times as many integers
 * as there are values, each is marked in a bitmap over that span and read back in order; a value met twice,
 * a wider span or a short list is left to std::sort. Ints in increasing order are one list whatever sorts
 * them, so the result is std::sort's to the bit.
 *
 * Why: the sweep sorts each ball's rows by sweep position and its columns by priority, about 190 of each on a
 * braced lattice, and std::sort of them was a fifth of the sweep's instructions (callgrind, 100 x 100 cells,
 * one thread). A ball's rows and columns lie close together in those orders, so the bitmap is a few hundred
 * words. The bitmap is kept from call to call (and left all zero).
 */
class IntSorter {
 public:
  /// Below this many values std::sort (its insertion sort) costs about as little.
  static constexpr size_t kSmall = 32;
  /// The bitmap is used while the span is at most this many times the number of values (then reading it
  /// back costs at most a word per value).
  static constexpr size_t kSpanPerValue = 64;

  void sort(std::vector<int>& values) {
    const size_t n = values.size();
    if (n < kSmall) {
      std::sort(values.begin(), values.end());
      return;
    }
    const auto [lowest, highest] = std::minmax_element(values.begin(), values.end());
    const int64_t low = *lowest;
    const size_t span = static_cast<size_t>(static_cast<int64_t>(*highest) - low) + 1;
    if (span > kSpanPerValue * n) {
      std::sort(values.begin(), values.end());
      return;
    }
    const size_t words = (span + 63) / 64;
    if (bits_.size() < words)
      bits_.resize(words, 0);
    bool repeated = false;
    for (int v : values) {
      const size_t offset = static_cast<size_t>(static_cast<int64_t>(v) - low);
      const uint64_t bit = uint64_t{1} << (offset & 63);
      repeated = repeated || (bits_[offset >> 6] & bit) != 0;
      bits_[offset >> 6] |= bit;
    }
    if (repeated) {
      std::fill(bits_.begin(), bits_.begin() + static_cast<std::ptrdiff_t>(words), 0);
      std::sort(values.begin(), values.end());
      return;
    }
    size_t k = 0;
    for (size_t w = 0; w < words; ++w) {
      uint64_t word = bits_[w];
      bits_[w] = 0;
      while (word != 0) {
        values[k++] =
            static_cast<int>(low + static_cast<int64_t>(w * 64 + static_cast<size_t>(__builtin_ctzll(word))));
        word &= word - 1;
      }
    }
  }

 private:
  std::vector<uint64_t> bits_;
};

}  // namespace core_detail
}  // namespace mobility_analysis
