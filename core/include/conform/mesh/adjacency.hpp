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

#include "conform/mesh/edge_map.hpp"
#include "conform/mesh/skinned_mesh.hpp"

namespace conform::mesh {

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
