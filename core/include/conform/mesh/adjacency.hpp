// Edge adjacency of a triangle mesh, built once and kept up to date by apply() (see
// topology_change.hpp) so that walks over the surface never scan all faces.
//
// Half-edge h = 3 f + k of face f runs from faces[f][k] to faces[f][(k + 1) % 3]. A hash map
// from each directed edge (u, v) to its half-edge gives the twin of h = (u, v) as the
// half-edge (v, u), or −1 on a boundary. Where the input is not manifold (an edge used twice
// in the same direction, or by more than two faces) the later half-edges are not in the map
// and such edges are treated as boundaries; nonmanifold_edges() counts them.
#pragma once

#include <cstdint>
#include <vector>

#include "conform/mesh/skinned_mesh.hpp"

namespace conform::mesh {

/// A map from a directed edge (u, v) to an int32: the adjacency's half-edges, the operations'
/// crossing tables, the plugin's per-edge books. Open addressing with linear probing, at most
/// half full, and deletion by shifting the following entries of the run back (no tombstones),
/// so that probe runs stay short however many edits come and go, and no edit ever pays for a
/// rehash that only sweeps tombstones (the table grows only when its live entries double).
class EdgeMap {
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
  /// The value of (u, v), made `initial` first if the edge is not in the map (one probe run:
  /// a count is bumped with one look-up). The reference holds until the next insertion.
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
  void clear();

 private:
  struct Slot {  // key and value side by side: one cache line per probe
    std::uint64_t key;
    std::int32_t value;
  };
  static constexpr std::uint64_t kEmpty = ~std::uint64_t(0);
  static std::uint64_t key(std::int32_t u, std::int32_t v) {
    return (std::uint64_t(std::uint32_t(u)) << 32) | std::uint32_t(v);
  }
  // Fibonacci hashing: the top bits of the product depend on every bit of both vertices (low
  // bits would see only v, so keys sharing it, such as a vertex's fan, would pile up).
  std::size_t home(std::uint64_t k) const {
    return std::size_t((k * 0x9E3779B97F4A7C15ull) >> shift_);
  }
  void rehash(std::size_t capacity);

  std::vector<Slot> slots_;
  std::size_t size_ = 0, mask_ = 0;
  int shift_ = 64;
};

class Adjacency {
 public:
  Adjacency() = default;
  explicit Adjacency(const SkinnedMesh& mesh) { build(mesh); }
  void build(const SkinnedMesh& mesh);

  /// The half-edge from u to v, or −1.
  std::int32_t find(std::int32_t u, std::int32_t v) const { return map_.find(u, v); }
  /// The opposite half-edge of h, or −1 on a boundary (or a non-manifold edge).
  std::int32_t twin(std::int32_t h) const { return twin_[static_cast<std::size_t>(h)]; }
  /// The face across edge k of face f, or −1.
  std::int32_t neighbor(std::int32_t f, int k) const {
    const std::int32_t t = twin_[static_cast<std::size_t>(3 * f + k)];
    return t < 0 ? -1 : t / 3;
  }
  std::int32_t face_count() const { return static_cast<std::int32_t>(twin_.size() / 3); }
  std::int32_t nonmanifold_edges() const { return nonmanifold_; }
  /// True when this adjacency describes `mesh` (face count matches); a cheap sanity check.
  bool matches(const SkinnedMesh& mesh) const { return face_count() == mesh.face_count(); }

  // Incremental updates, used by apply(). Faces are identified by their slot.
  void remove_face(const SkinnedMesh& mesh, std::int32_t f);  // before the slot is overwritten
  void add_face(const SkinnedMesh& mesh, std::int32_t f);     // after the slot is written
  /// Face `from` was moved into slot `to` (mesh already updated); `from` is then popped.
  void move_face(const SkinnedMesh& mesh, std::int32_t from, std::int32_t to);
  void resize_faces(std::int32_t face_count) {
    twin_.resize(3 * static_cast<std::size_t>(face_count), -1);
  }

 private:
  EdgeMap map_;
  std::vector<std::int32_t> twin_;
  std::int32_t nonmanifold_ = 0;
};

}  // namespace conform::mesh
