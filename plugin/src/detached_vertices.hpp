// The vertices that left Bullet (no face of theirs is left, or an edit made them without any):
// each keeps a position and velocity of its own, those it had when it left, then its skinned
// target's (the skin drive sets them each substep).
// Invariant: a vertex is held iff its slot is ≥ 0, and then the slot names it back
// (vertex(slot_of(v)) == v); a vertex is held at most once, for good (no edit re-attaches one),
// so count() only grows and equals the slots in use.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace conform::bullet {

class DetachedVertices {
 public:
  /// Room for `vertices` vertices without growing the per-vertex table.
  void reserve(std::size_t vertices) { slot_.reserve(vertices); }
  /// `vertices` vertices, none held (the books' build).
  void reset(std::size_t vertices) { slot_.assign(vertices, -1); }
  /// The per-vertex table covers `vertices` (an edit's new vertices, none held).
  void grow(std::size_t vertices) { slot_.resize(vertices, -1); }
  /// Holds `v` from now on, at x with velocity `velocity`.
  void add(std::int32_t v, const Eigen::Vector3d& x, const Eigen::Vector3d& velocity) {
    slot_[static_cast<std::size_t>(v)] = std::int32_t(state_.size());
    state_.emplace_back(x, velocity);
    vertex_.push_back(v);
  }
  bool held(std::int32_t v) const { return slot_[static_cast<std::size_t>(v)] >= 0; }
  const Eigen::Vector3d& position(std::int32_t v) const { return state(v).first; }
  const Eigen::Vector3d& velocity(std::int32_t v) const { return state(v).second; }
  std::int32_t count() const { return std::int32_t(vertex_.size()); }
  /// The held vertex of `slot` (0 ≤ slot < count()), and its state set.
  std::int32_t vertex(std::int32_t slot) const { return vertex_[static_cast<std::size_t>(slot)]; }
  void set(std::int32_t slot, const Eigen::Vector3d& x, const Eigen::Vector3d& velocity) {
    state_[static_cast<std::size_t>(slot)] = {x, velocity};
  }

 private:
  const std::pair<Eigen::Vector3d, Eigen::Vector3d>& state(std::int32_t v) const {
    return state_[static_cast<std::size_t>(slot_[static_cast<std::size_t>(v)])];
  }
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> state_;  // per slot
  std::vector<std::int32_t> slot_;                                  // per vertex, −1 unless held
  std::vector<std::int32_t> vertex_;                                // per slot
};

}  // namespace conform::bullet
