#pragma once

// Private to the readers in src/core/io: the index of names a reader looks elements up by.

#include <cstdint>
#include <functional>
#include <string_view>
#include <vector>


namespace mobility_analysis {
namespace io_detail {

/**
 * @brief Index by name of names kept elsewhere (the reader's links or connections, in a vector): an open-
 *        addressing hash table of (hash, index) pairs, eight bytes a slot.
 *
 * A name is found with one probe into a flat array and one comparison with the name it points at; a
 * node-based std::unordered_map costs a bucket, a node and the key's text (three cache misses on 10^5 names).
 * The names are not copied: @p nameOf(index) returns the name of an index given so far.
 */
class NameIndex {
 public:
  /// Room for @p count names without growing.
  void reserve(size_t count) {
    size_t capacity = 16;
    while (capacity < 2 * count)
      capacity *= 2;
    if (capacity > slots_.size())
      rehash(capacity);
  }

  /// @return The index of @p name among @p items (each index given so far stands for items[index].name), or
  /// -1.
  template <class Item>
  int find(std::string_view name, const std::vector<Item>& items) const {
    if (slots_.empty())
      return -1;
    const uint32_t hash = hashOf(name);
    for (size_t s = hash & mask(); slots_[s].index >= 0; s = (s + 1) & mask()) {
      if (slots_[s].hash == hash && items[slots_[s].index].name == name)
        return slots_[s].index;
    }
    return -1;
  }

  /**
   * @brief The index of @p name among @p items, as find gives it; when it has none, @p name is given @p index
   *        and -1 returned: find and insert with one hash and one probe sequence.
   * @note @p index must stand for items[index] before the next find meets it (the caller appends it next).
   */
  template <class Item>
  int findOrInsert(std::string_view name, int index, const std::vector<Item>& items) {
    if (2 * (count_ + 1) > slots_.size())
      rehash(slots_.empty() ? 16 : 2 * slots_.size());
    const uint32_t hash = hashOf(name);
    size_t s = hash & mask();
    for (; slots_[s].index >= 0; s = (s + 1) & mask()) {
      if (slots_[s].hash == hash && items[slots_[s].index].name == name)
        return slots_[s].index;
    }
    slots_[s] = Slot{hash, index};
    ++count_;
    return -1;
  }

  /// Gives @p name the index @p index; @p name must not have one yet (find first).
  void insert(std::string_view name, int index) {
    if (2 * (count_ + 1) > slots_.size())
      rehash(slots_.empty() ? 16 : 2 * slots_.size());
    place(Slot{hashOf(name), index});
    ++count_;
  }

 private:
  struct Slot {
    uint32_t hash = 0;
    int index = -1;  ///< -1: empty
  };

  /// The hash of @p name without its last character, plus that character: names numbered in order
  /// ("link_17", "link_18") take neighbouring slots, so a file's names, given and looked up mostly in the
  /// order they are numbered, share cache lines instead of each probe missing the cache (the table is
  /// megabytes for 10^5 names). The slot's stored hash still tells such names apart.
  static uint32_t hashOf(std::string_view name) {
    if (name.empty())
      return 0;
    const std::string_view stem = name.substr(0, name.size() - 1);
    return static_cast<uint32_t>(std::hash<std::string_view>()(stem)) +
           static_cast<unsigned char>(name.back());
  }
  size_t mask() const { return slots_.size() - 1; }

  void place(const Slot& slot) {
    size_t s = slot.hash & mask();
    while (slots_[s].index >= 0)
      s = (s + 1) & mask();
    slots_[s] = slot;
  }

  void rehash(size_t capacity) {
    std::vector<Slot> old(capacity);
    old.swap(slots_);
    for (const Slot& slot : old) {
      if (slot.index >= 0)
        place(slot);
    }
  }

  std::vector<Slot> slots_;  ///< Capacity a power of two, at most half full.
  size_t count_ = 0;
};

}  // namespace io_detail
}  // namespace mobility_analysis
