// The small keys every part of the plugin uses: an undirected edge as the books key it, and the
// third vertex of a face.
#pragma once

#include <cstdint>
#include <utility>

#include "conform/mesh/skinned_mesh.hpp"

namespace conform::bullet {

/// An undirected edge as the books key it: (min, max).
inline std::pair<std::int32_t, std::int32_t> edge_key(std::int32_t a, std::int32_t b) {
  return a < b ? std::pair{a, b} : std::pair{b, a};
}

/// The vertex of `f` that is neither a nor b (−1 if none).
inline std::int32_t third_vertex(const mesh::Face& f, std::int32_t a, std::int32_t b) {
  for (const auto v : f)
    if (v != a && v != b) return v;
  return -1;
}

}  // namespace conform::bullet
