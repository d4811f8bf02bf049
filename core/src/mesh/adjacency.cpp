#include "conform/mesh/adjacency.hpp"

namespace conform::mesh {

void EdgeMap::clear() {
  slots_.clear();
  size_ = used_ = 0;
}

void EdgeMap::rehash(std::size_t capacity) {
  std::vector<Slot> old = std::move(slots_);
  slots_.assign(capacity, Slot{kEmpty, kNone});
  size_ = used_ = 0;
  for (const Slot& o : old)
    if (o.key != kEmpty && o.key != kTomb) {
      slots_[slot(o.key)] = o;
      ++size_, ++used_;
    }
}

void EdgeMap::reserve(std::size_t count) {
  std::size_t cap = 16;
  while (cap < 2 * count) cap *= 2;
  if (cap > slots_.size()) rehash(cap);
}

void EdgeMap::grow() {
  // Double when live entries fill half the table, else only drop the tombstones.
  if (slots_.empty()) return rehash(16);
  rehash(2 * size_ + 2 > slots_.size() / 2 ? 2 * slots_.size() : slots_.size());
}

// Home slots take bits 32 and up of the multiplicative hash: they depend on both vertices of
// the key (bits below 32 would see only the second one, so that keys sharing it — (v, 0) in
// the cut's loop maps, or a vertex's fan here — would pile up in one probe run).
//
// The slot holding k, or the first empty slot of its probe sequence.
std::size_t EdgeMap::slot(std::uint64_t k) const {
  const std::size_t mask = slots_.size() - 1;
  std::size_t s = std::size_t(k * 0x9E3779B97F4A7C15ull >> 32) & mask;
  while (slots_[s].key != kEmpty && slots_[s].key != k) s = (s + 1) & mask;
  return s;
}

std::int32_t EdgeMap::find(std::int32_t u, std::int32_t v) const {
  if (slots_.empty()) return kNone;
  const Slot& s = slots_[slot(key(u, v))];
  return s.key == kEmpty ? kNone : s.value;
}

bool EdgeMap::insert(std::int32_t u, std::int32_t v, std::int32_t value, bool overwrite) {
  if (slots_.empty() || 4 * (used_ + 1) > 3 * slots_.size()) grow();
  const std::uint64_t k = key(u, v);
  const std::size_t mask = slots_.size() - 1;
  std::size_t s = std::size_t(k * 0x9E3779B97F4A7C15ull >> 32) & mask;
  std::size_t tomb = slots_.size();
  while (slots_[s].key != kEmpty && slots_[s].key != k) {
    if (slots_[s].key == kTomb && tomb == slots_.size()) tomb = s;
    s = (s + 1) & mask;
  }
  if (slots_[s].key == k) {
    if (!overwrite) return false;
    slots_[s].value = value;
    return true;
  }
  if (tomb != slots_.size()) {
    s = tomb;
  } else {
    ++used_;
  }
  slots_[s] = {k, value};
  ++size_;
  return true;
}

void EdgeMap::erase(std::int32_t u, std::int32_t v, std::int32_t value) {
  if (slots_.empty()) return;
  Slot& s = slots_[slot(key(u, v))];
  if (s.key == kEmpty || s.value != value) return;
  s = {kTomb, kNone};
  --size_;
}

void Adjacency::build(const SkinnedMesh& mesh) {
  const std::int32_t nf = mesh.face_count();
  map_.clear();
  map_.reserve(3 * static_cast<std::size_t>(nf));
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
