#pragma once

// Private to src/core: the local stress searches (SelfStressBasis.cpp, ContractEchelon.cpp,
// analysis/Prestress.cpp) remember the results of their small eliminations through it.

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <memory>
#include <unordered_map>
#include <utility>
#include <vector>

#include "mobility_analysis/ConstraintJacobian.hpp"

namespace mobility_analysis {
namespace core_detail {

/**
 * Results of small local eliminations, looked up by everything the elimination reads, bit for bit.
 *
 * Why it is exact: a local elimination (SparseElimination on a local matrix, its rows in a given order,
 * with given scales) is a deterministic function of those inputs, so two local problems whose inputs are
 * equal to the last bit have equal results to the last bit, whatever part of the mechanism they come
 * from; the caller stores its result in local numbering and maps it to its own rows. A key is compared in
 * full (the hash only picks the bucket), never trusted by its hash. Why it pays: a regular structure (a
 * lattice, a mast of equal bays) asks the same local question at every cell, whose matrix is the same
 * where its coordinates differ by exactly representable steps (a 100 x 100 braced lattice: 1 500 distinct
 * balls around 20 000 cables). Irregular structures never hit: past kMissesAlone lookups without a hit
 * the memo stops keying, and it stores at most its byte budget.
 */
template <class Result>
class LocalMemo {
 public:
  /// Lookups without a single hit after which keying stops.
  static constexpr size_t kMissesAlone = 500;

  explicit LocalMemo(size_t byteBudget = size_t{64} << 20) : budget_(byteBudget) {}

  /// Whether keys are still worth building; once not, what was stored is released.
  bool active() {
    if (hits_ > 0 || lookups_ < kMissesAlone)
      return true;
    if (!table_.empty()) {
      table_ = {};
      stored_ = budget_;  // nothing more is stored
    }
    return false;
  }

  /// Starts a key; the caller then appends every input of its elimination.
  void clearKey() { key_.clear(); }
  void appendKey(uint64_t word) { *key_.extend(1) = word; }
  void appendKey(double value) { std::memcpy(key_.extend(1), &value, sizeof(uint64_t)); }
  /// @p count integers, two to a word (an odd count's last word padded with zero).
  void appendKey(const int* data, size_t count) {
    uint64_t* words = key_.extend((count + 1) / 2);
    if (count % 2 != 0)
      words[count / 2] = 0;
    std::memcpy(words, data, count * sizeof(int));
  }
  /// The matrix's shape, pattern and values (compressed storage, as copyRows writes it, copied in bulk:
  /// the key of a hit costs a small part of the elimination it saves).
  void appendKey(const SparseJacobian& local) {
    const Eigen::Index rows = local.rows();
    const Eigen::Index entries = local.outerIndexPtr()[rows] - local.outerIndexPtr()[0];
    appendKey(static_cast<uint64_t>(rows));
    appendKey(static_cast<uint64_t>(local.cols()));
    // Row starts and column indices two to a word (an odd count's last word padded with zero), then the
    // values' bits.
    const size_t indices = static_cast<size_t>(rows + 1 + entries);
    const size_t indexWords = (indices + 1) / 2;
    uint64_t* words = key_.extend(indexWords + static_cast<size_t>(entries));
    if (indices % 2 != 0)
      words[indexWords - 1] = 0;
    std::memcpy(words, local.outerIndexPtr(), static_cast<size_t>(rows + 1) * sizeof(int));
    std::memcpy(reinterpret_cast<int*>(words) + rows + 1, local.innerIndexPtr() + local.outerIndexPtr()[0],
                static_cast<size_t>(entries) * sizeof(int));
    std::memcpy(words + indexWords, local.valuePtr() + local.outerIndexPtr()[0],
                static_cast<size_t>(entries) * sizeof(double));
  }

  /// The result stored under the current key, if any (the caller may improve it in place).
  Result* find() {
    ++lookups_;
    hash_ = hashOf(key_.data(), key_.size());
    const auto bucket = table_.find(hash_);
    if (bucket == table_.end())
      return nullptr;
    for (Entry& entry : bucket->second) {
      if (entry.key.size() == key_.size() &&
          std::memcmp(entry.key.data(), key_.data(), key_.size() * sizeof(uint64_t)) == 0) {
        ++hits_;
        return &entry.result;
      }
    }
    return nullptr;
  }

  /// Stores @p result under the key of the last find (while within the byte budget).
  void insert(Result result, size_t resultBytes) {
    const size_t bytes = key_.size() * sizeof(uint64_t) + resultBytes;
    if (stored_ + bytes > budget_)
      return;
    stored_ += bytes;
    table_[hash_].push_back(
        Entry{std::vector<uint64_t>(key_.data(), key_.data() + key_.size()), std::move(result)});
  }

 private:
  struct Entry {
    std::vector<uint64_t> key;
    Result result;
  };

  /// The key being built: words appended without first being zeroed (a vector's resize writes every word
  /// twice; a ball's key is hundreds of words, a contract-order patch's thousands, once per lookup).
  class KeyWords {
   public:
    void clear() { size_ = 0; }
    size_t size() const { return size_; }
    const uint64_t* data() const { return words_.get(); }
    /// Room for @p count more words at the end, to be written by the caller.
    uint64_t* extend(size_t count) {
      if (size_ + count > capacity_) {
        const size_t capacity = std::max(size_ + count, 2 * capacity_);
        std::unique_ptr<uint64_t[]> grown(new uint64_t[capacity]);
        if (size_ > 0)
          std::memcpy(grown.get(), words_.get(), size_ * sizeof(uint64_t));
        words_ = std::move(grown);
        capacity_ = capacity;
      }
      uint64_t* end = words_.get() + size_;
      size_ += count;
      return end;
    }

   private:
    std::unique_ptr<uint64_t[]> words_;
    size_t size_ = 0, capacity_ = 0;
  };

  /// Picks the bucket only (keys are compared in full), so every fourth word and the length suffice.
  static uint64_t hashOf(const uint64_t* words, size_t size) {
    uint64_t h = 1469598103934665603ull ^ size;
    for (size_t i = 0; i < size; i += 4) {
      h ^= words[i] + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
      h *= 1099511628211ull;
    }
    return h;
  }

  size_t budget_;
  size_t stored_ = 0;
  size_t lookups_ = 0, hits_ = 0;
  uint64_t hash_ = 0;
  KeyWords key_;
  std::unordered_map<uint64_t, std::vector<Entry>> table_;
};

}  // namespace core_detail
}  // namespace mobility_analysis
