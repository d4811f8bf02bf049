#include "conform/mesh/adjacency.hpp"

namespace conform::mesh {

void Adjacency::build(const SkinnedMesh& mesh) {
  const std::int32_t nf = mesh.face_count();
  map_.clear();
  // Room for about 1/8 more half-edges (as ColumnArray leaves for vertices), so that the first
  // edits after a build do not rehash the whole table.
  const std::size_t half_edges = 3 * static_cast<std::size_t>(nf);
  map_.reserve(half_edges + half_edges / 8 + 64);
  twin_.assign(3 * static_cast<std::size_t>(nf), -1);
  nonmanifold_ = 0;
  for (std::int32_t f = 0; f < nf; ++f) {
    const Face& t = mesh.faces[static_cast<std::size_t>(f)];
    for (int k = 0; k < 3; ++k)
      if (!map_.insert(t[k], t[(k + 1) % 3], 3 * f + k)) ++nonmanifold_;
  }
  for (std::int32_t f = 0; f < nf; ++f) {
    const Face& t = mesh.faces[static_cast<std::size_t>(f)];
    for (int k = 0; k < 3; ++k) {
      const std::int32_t h = 3 * f + k;
      if (map_.find(t[k], t[(k + 1) % 3]) != h) continue;  // a duplicate: left as boundary
      const std::int32_t o = map_.find(t[(k + 1) % 3], t[k]);
      // Link only mutual pairs (o's own entry is o), so twin(twin(h)) == h always holds.
      twin_[static_cast<std::size_t>(h)] = o;
    }
  }
}

void Adjacency::remove_face(const SkinnedMesh& mesh, std::int32_t f) {
  const Face& t = mesh.faces[static_cast<std::size_t>(f)];
  for (int k = 0; k < 3; ++k) {
    const std::int32_t h = 3 * f + k;
    map_.erase(t[k], t[(k + 1) % 3], h);
    const std::int32_t o = twin_[static_cast<std::size_t>(h)];
    if (o >= 0 && twin_[static_cast<std::size_t>(o)] == h) twin_[static_cast<std::size_t>(o)] = -1;
    twin_[static_cast<std::size_t>(h)] = -1;
  }
}

void Adjacency::add_face(const SkinnedMesh& mesh, std::int32_t f) {
  if (3 * static_cast<std::size_t>(f) + 3 > twin_.size()) resize_faces(f + 1);
  const Face& t = mesh.faces[static_cast<std::size_t>(f)];
  for (int k = 0; k < 3; ++k) {
    const std::int32_t h = 3 * f + k;
    twin_[static_cast<std::size_t>(h)] = -1;
    if (!map_.insert(t[k], t[(k + 1) % 3], h)) {
      ++nonmanifold_;
      continue;
    }
    const std::int32_t o = map_.find(t[(k + 1) % 3], t[k]);
    if (o >= 0 && twin_[static_cast<std::size_t>(o)] < 0) {
      twin_[static_cast<std::size_t>(h)] = o;
      twin_[static_cast<std::size_t>(o)] = h;
    }
  }
}

void Adjacency::move_face(const SkinnedMesh& mesh, std::int32_t from, std::int32_t to) {
  const Face& t = mesh.faces[static_cast<std::size_t>(to)];
  for (int k = 0; k < 3; ++k) {
    const std::int32_t h = 3 * from + k, g = 3 * to + k;
    if (map_.find(t[k], t[(k + 1) % 3]) == h) map_.insert(t[k], t[(k + 1) % 3], g, true);
    const std::int32_t o = twin_[static_cast<std::size_t>(h)];
    twin_[static_cast<std::size_t>(g)] = o;
    if (o >= 0) twin_[static_cast<std::size_t>(o)] = g;
    twin_[static_cast<std::size_t>(h)] = -1;
  }
}

}  // namespace conform::mesh
