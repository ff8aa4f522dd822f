#pragma once

// Private to src/core: integers grouped by a key in one pooled array, for the per-link and per-joint lists of
// the sweep order (EliminationOrder.cpp) and the passive-freedom search (analysis/PassiveFreedoms.cpp), and
// the pivot rows by column (SparseElimination::nullSpace).

#include <cstddef>
#include <vector>

namespace mobility_analysis {
namespace core_detail {

/// A [begin, end) range of one bucket, for range-for and indexing.
struct BucketRange {
  const int* first;
  const int* last;
  const int* begin() const { return first; }
  const int* end() const { return last; }
  size_t size() const { return static_cast<size_t>(last - first); }
  bool empty() const { return first == last; }
  int operator[](size_t i) const { return first[i]; }
};

/// Integers grouped by a key in one pooled array (compressed rows): one allocation for all keys instead of a
/// vector per link and per joint (4 10^5 of them on a 10^5-link chain); each group keeps insertion order.
/// Filled in two passes over the same values: count() each, allocate(), then add() each in the same order.
class Buckets {
 public:
  explicit Buckets(int numKeys) : start_(static_cast<size_t>(numKeys) + 1, 0) {}
  /// First pass: one more value under @p key.
  void count(int key) { ++start_[static_cast<size_t>(key) + 1]; }
  /// After counting: room for every value counted.
  void allocate() {
    for (size_t k = 1; k < start_.size(); ++k)
      start_[k] += start_[k - 1];
    values_.resize(start_.back());
    fill_.assign(start_.begin(), start_.end() - 1);
  }
  /// Second pass, in the same order as counted: the value itself.
  void add(int key, int value) { values_[fill_[static_cast<size_t>(key)]++] = value; }
  BucketRange operator[](int key) const {
    return BucketRange{values_.data() + start_[static_cast<size_t>(key)],
                       values_.data() + start_[static_cast<size_t>(key) + 1]};
  }

 private:
  std::vector<size_t> start_, fill_;
  std::vector<int> values_;
};

}  // namespace core_detail
}  // namespace mobility_analysis
