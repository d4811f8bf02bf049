// Union–find over a parent array (parent[r] == r at a root), for the mesh layer's groupings:
// the cut's fans around a vertex on the plane, check_mesh's fans around a vertex,
// label_pieces' pieces. Internal: not part of the installed API.
#pragma once

#include <cstdint>

namespace conform::mesh::detail {

/// The root of x's set, halving the path on the way (every other vertex on it is pointed at
/// its grandparent). A vertex whose parent is a root is not written, so that the usual
/// look-up of a settled set only loads.
inline std::int32_t find_root(std::int32_t* parent, std::int32_t x) {
  for (;;) {
    const std::int32_t p = parent[x];
    if (p == x) return x;
    const std::int32_t g = parent[p];
    if (g == p) return p;
    parent[x] = g;
    x = g;
  }
}

/// Joins the sets of a and b: a's root is hung under b's.
inline void unite(std::int32_t* parent, std::int32_t a, std::int32_t b) {
  const std::int32_t rb = find_root(parent, b);
  parent[find_root(parent, a)] = rb;
}

}  // namespace conform::mesh::detail
