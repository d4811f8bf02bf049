#include "conform/mesh/edge_map.hpp"

#include <bit>

namespace conform::mesh {

void EdgeMap::clear() {
  size_ = 0;
  if (++epoch_ == 0) {  // the stamps wrapped: sweep once
    for (Slot& s : slots_) s.epoch = 0;
    epoch_ = 1;
  }
}

void EdgeMap::rehash(std::size_t capacity) {
  std::vector<Slot> old = std::move(slots_);
  const std::uint32_t was = epoch_;
  slots_.assign(capacity, Slot{0, kNone, 0});
  epoch_ = 1;
  mask_ = capacity - 1;
  shift_ = 64 - std::countr_zero(capacity);
  size_ = 0;
  for (const Slot& o : old)
    if (o.epoch == was) {
      std::size_t s = home(o.key);
      while (live(s)) s = (s + 1) & mask_;
      slots_[s] = {o.key, o.value, epoch_};
      ++size_;
    }
}

void EdgeMap::reserve(std::size_t count) {
  std::size_t capacity = 16;
  while (capacity < 2 * count) capacity *= 2;
  if (capacity > slots_.size()) rehash(capacity);
}

void EdgeMap::erase(std::int32_t u, std::int32_t v, std::int32_t value) {
  if (slots_.empty()) return;
  const std::uint64_t k = key(u, v);
  std::size_t hole = home(k);
  while (slots_[hole].key != k || !live(hole)) {
    if (!live(hole)) return;
    hole = (hole + 1) & mask_;
  }
  if (slots_[hole].value != value) return;
  // Shift back every later entry of the run that may live in the hole: one whose home is not
  // cyclically within (hole, j] (its distance from home is at least the hole's distance).
  for (std::size_t j = (hole + 1) & mask_; live(j); j = (j + 1) & mask_) {
    const std::size_t h = home(slots_[j].key);
    if (((j - h) & mask_) >= ((j - hole) & mask_)) {
      slots_[hole] = slots_[j];
      hole = j;
    }
  }
  slots_[hole].epoch = 0;
  --size_;
}

}  // namespace conform::mesh
