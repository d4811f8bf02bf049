// A map from an edge (a pair of vertex ids) to an int32, for the plugin's per-edge books (face
// counts, link indices). Open addressing with linear probing, at most half full, and deletion
// by shifting the following entries back (no tombstones), so that probe runs stay short however
// many edits come and go; at() finds or makes an entry in one probe run (a count is bumped with
// one look-up, not a find and an insert).
#pragma once

#include <bit>
#include <cstdint>
#include <vector>

namespace conform::bullet {

class EdgeTable {
 public:
  static constexpr std::int32_t kNone = -1;

  std::int32_t find(std::int32_t u, std::int32_t v) const {
    if (slots_.empty()) return kNone;
    const std::uint64_t k = key(u, v);
    for (std::size_t s = home(k);; s = (s + 1) & mask_) {
      if (slots_[s].key == k) return slots_[s].value;
      if (slots_[s].key == kEmpty) return kNone;
    }
  }

  /// The value of (u, v), made `initial` first if the edge is not in the table. The reference
  /// holds until the next insertion.
  std::int32_t& at(std::int32_t u, std::int32_t v, std::int32_t initial) {
    if (2 * (size_ + 1) > slots_.size()) rehash(slots_.empty() ? 16 : 2 * slots_.size());
    const std::uint64_t k = key(u, v);
    std::size_t s = home(k);
    while (slots_[s].key != k && slots_[s].key != kEmpty) s = (s + 1) & mask_;
    if (slots_[s].key == kEmpty) {
      slots_[s] = {k, initial};
      ++size_;
    }
    return slots_[s].value;
  }

  /// Inserts or (when `overwrite`) overwrites; false if the key exists and is kept.
  bool insert(std::int32_t u, std::int32_t v, std::int32_t value, bool overwrite = false) {
    const std::size_t before = size_;
    std::int32_t& slot = at(u, v, value);
    if (size_ != before) return true;
    if (!overwrite) return false;
    slot = value;
    return true;
  }

  /// Removes the key if it maps to `value` (a stale removal never drops a newer entry).
  void erase(std::int32_t u, std::int32_t v, std::int32_t value) {
    if (slots_.empty()) return;
    const std::uint64_t k = key(u, v);
    std::size_t hole = home(k);
    while (slots_[hole].key != k) {
      if (slots_[hole].key == kEmpty) return;
      hole = (hole + 1) & mask_;
    }
    if (slots_[hole].value != value) return;
    // Shift back every later entry of the run that may live in the hole: one whose home is not
    // cyclically within (hole, j].
    for (std::size_t j = (hole + 1) & mask_; slots_[j].key != kEmpty; j = (j + 1) & mask_) {
      const std::size_t h = home(slots_[j].key);
      if (((j - h) & mask_) >= ((j - hole) & mask_)) {
        slots_[hole] = slots_[j];
        hole = j;
      }
    }
    slots_[hole] = {kEmpty, kNone};
    --size_;
  }

  void reserve(std::size_t count) {
    std::size_t capacity = 16;
    while (capacity < 2 * count) capacity *= 2;
    if (capacity > slots_.size()) rehash(capacity);
  }
  std::size_t size() const { return size_; }
  void clear() {
    slots_.clear();
    size_ = 0;
  }

 private:
  struct Slot {
    std::uint64_t key;
    std::int32_t value;
  };
  static constexpr std::uint64_t kEmpty = ~std::uint64_t(0);
  static std::uint64_t key(std::int32_t u, std::int32_t v) {
    return (std::uint64_t(std::uint32_t(u)) << 32) | std::uint32_t(v);
  }
  // Fibonacci hashing: the top bits of the product depend on every bit of both vertex ids.
  std::size_t home(std::uint64_t k) const {
    return std::size_t((k * 0x9E3779B97F4A7C15ull) >> shift_);
  }
  void rehash(std::size_t capacity) {
    std::vector<Slot> old = std::move(slots_);
    slots_.assign(capacity, Slot{kEmpty, kNone});
    mask_ = capacity - 1;
    shift_ = 64 - std::countr_zero(capacity);
    size_ = 0;
    for (const Slot& o : old)
      if (o.key != kEmpty) {
        std::size_t s = home(o.key);
        while (slots_[s].key != kEmpty) s = (s + 1) & mask_;
        slots_[s] = o;
        ++size_;
      }
  }

  std::vector<Slot> slots_;
  std::size_t size_ = 0, mask_ = 0;
  int shift_ = 64;
};

}  // namespace conform::bullet
