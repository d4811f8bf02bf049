#include "conform/mesh/adjacency.hpp"

namespace conform::mesh {

void EdgeMap::clear() {
  keys_.clear();
  values_.clear();
  size_ = used_ = 0;
}

void EdgeMap::rehash(std::size_t capacity) {
  std::vector<std::uint64_t> old_keys = std::move(keys_);
  std::vector<std::int32_t> old_values = std::move(values_);
  keys_.assign(capacity, kEmpty);
  values_.assign(capacity, kNone);
  size_ = used_ = 0;
  for (std::size_t i = 0; i < old_keys.size(); ++i)
    if (old_keys[i] != kEmpty && old_keys[i] != kTomb) {
      const std::size_t s = slot(old_keys[i]);
      keys_[s] = old_keys[i];
      values_[s] = old_values[i];
      ++size_, ++used_;
    }
}

void EdgeMap::reserve(std::size_t count) {
  std::size_t cap = 16;
  while (cap < 2 * count) cap *= 2;
  if (cap > keys_.size()) rehash(cap);
}

void EdgeMap::grow() {
  // Double when live entries fill half the table, else only drop the tombstones.
  if (keys_.empty()) return rehash(16);
  rehash(2 * size_ + 2 > keys_.size() / 2 ? 2 * keys_.size() : keys_.size());
}

// The slot holding k, or the first empty slot of its probe sequence.
std::size_t EdgeMap::slot(std::uint64_t k) const {
  const std::size_t mask = keys_.size() - 1;
  std::size_t s = std::size_t(k * 0x9E3779B97F4A7C15ull >> 17) & mask;
  while (keys_[s] != kEmpty && keys_[s] != k) s = (s + 1) & mask;
  return s;
}

std::int32_t EdgeMap::find(std::int32_t u, std::int32_t v) const {
  if (keys_.empty()) return kNone;
  const std::size_t s = slot(key(u, v));
  return keys_[s] == kEmpty ? kNone : values_[s];
}

bool EdgeMap::insert(std::int32_t u, std::int32_t v, std::int32_t value, bool overwrite) {
  if (keys_.empty() || 4 * (used_ + 1) > 3 * keys_.size()) grow();
  const std::uint64_t k = key(u, v);
  const std::size_t mask = keys_.size() - 1;
  std::size_t s = std::size_t(k * 0x9E3779B97F4A7C15ull >> 17) & mask;
  std::size_t tomb = keys_.size();
  while (keys_[s] != kEmpty && keys_[s] != k) {
    if (keys_[s] == kTomb && tomb == keys_.size()) tomb = s;
    s = (s + 1) & mask;
  }
  if (keys_[s] == k) {
    if (!overwrite) return false;
    values_[s] = value;
    return true;
  }
  if (tomb != keys_.size()) {
    s = tomb;
  } else {
    ++used_;
  }
  keys_[s] = k;
  values_[s] = value;
  ++size_;
  return true;
}

void EdgeMap::erase(std::int32_t u, std::int32_t v, std::int32_t value) {
  if (keys_.empty()) return;
  const std::size_t s = slot(key(u, v));
  if (keys_[s] == kEmpty || values_[s] != value) return;
  keys_[s] = kTomb;
  values_[s] = kNone;
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
