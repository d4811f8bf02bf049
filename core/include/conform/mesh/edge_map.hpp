// The mesh layer's one open-addressing map, from a directed edge (u, v) to an int32: the
// adjacency's half-edges, the operations' crossing tables, the drill's scratch tables (keyed
// (0, x) for a single index x), the plugin's per-edge books.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace conform::mesh {

/// Open addressing with linear probing, at most half full, and deletion by shifting the
/// following entries of the run back (no tombstones), so that probe runs stay short however
/// many edits come and go, and no edit ever pays for a rehash that only sweeps tombstones (the
/// table grows only when its live entries double). clear() is O(1): a slot is live only when
/// stamped with the current epoch, so a table kept between operations (the drill's, the
/// cut's) is reused without being swept; it keeps its capacity.
class EdgeMap {
 public:
  static constexpr std::int32_t kNone = -1;

  EdgeMap() = default;
  /// Room for `count` entries from the start.
  explicit EdgeMap(std::size_t count) { reserve(count); }

  std::int32_t find(std::int32_t u, std::int32_t v) const {
    if (slots_.empty()) return kNone;
    const std::uint64_t k = key(u, v);
    for (std::size_t s = home(k);; s = (s + 1) & mask_) {
      if (slots_[s].epoch != epoch_) return kNone;
      if (slots_[s].key == k) return slots_[s].value;
    }
  }
  /// The value of (u, v), made `initial` first if the edge is not in the map (one probe run:
  /// a count is bumped with one look-up). The reference holds until the next insertion.
  std::int32_t& at(std::int32_t u, std::int32_t v, std::int32_t initial) {
    if (2 * (size_ + 1) > slots_.size()) rehash(slots_.empty() ? 16 : 2 * slots_.size());
    const std::uint64_t k = key(u, v);
    std::size_t s = home(k);
    while (slots_[s].epoch == epoch_ && slots_[s].key != k) s = (s + 1) & mask_;
    if (slots_[s].epoch != epoch_) {
      slots_[s] = {k, initial, epoch_};
      ++size_;
    }
    return slots_[s].value;
  }
  /// Inserts or (when `overwrite`) overwrites; returns false (and leaves the map unchanged) if
  /// the key exists and `overwrite` is false.
  bool insert(std::int32_t u, std::int32_t v, std::int32_t value, bool overwrite = false) {
    const std::size_t before = size_;
    std::int32_t& slot = at(u, v, value);
    if (size_ != before) return true;
    if (!overwrite) return false;
    slot = value;
    return true;
  }
  /// Removes the key if it maps to `value` (so that a stale removal never drops a newer entry).
  void erase(std::int32_t u, std::int32_t v, std::int32_t value);
  /// Room for `count` entries without growing.
  void reserve(std::size_t count);
  std::size_t size() const { return size_; }
  /// Empties the map in O(1), keeping its capacity.
  void clear();

 private:
  struct Slot {  // key, value and stamp side by side (16 bytes): one cache line per probe
    std::uint64_t key;
    std::int32_t value;
    std::uint32_t epoch;  // live when equal to epoch_
  };
  static std::uint64_t key(std::int32_t u, std::int32_t v) {
    return (std::uint64_t(std::uint32_t(u)) << 32) | std::uint32_t(v);
  }
  // Fibonacci hashing: the top bits of the product depend on every bit of both vertices (low
  // bits would see only v, so keys sharing it, such as a vertex's fan, would pile up).
  std::size_t home(std::uint64_t k) const {
    return std::size_t((k * 0x9E3779B97F4A7C15ull) >> shift_);
  }
  bool live(std::size_t s) const { return slots_[s].epoch == epoch_; }
  void rehash(std::size_t capacity);

  std::vector<Slot> slots_;
  std::size_t size_ = 0, mask_ = 0;
  std::uint32_t epoch_ = 1;
  int shift_ = 64;
};

}  // namespace conform::mesh
