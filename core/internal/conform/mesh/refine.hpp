// Edge splitting without T-junctions: every face that has one, two or three of the given
// edges split is re-triangulated (1-to-2, 1-to-3 along the shorter diagonal, or 1-to-4), so
// that neighbours stay conforming. (The drill refines its own copy of the patch by longest-edge
// bisection and emits one change; see drill.hpp.)
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "conform/mesh/adjacency.hpp"
#include "conform/mesh/topology_change.hpp"

namespace conform::mesh {

struct EdgeSplit {
  std::int32_t a = 0, b = 0;  // the edge (either direction)
  double t = 0.5;             // the new vertex at (1 − t) a + t b, t in (0, 1)
};

/// The change splitting the given edges (duplicates, by either direction, are split once,
/// at the first given parameter). Edges that are not edges of the mesh are ignored. O(edges).
TopologyChange split_edges(const SkinnedMesh& mesh, const Adjacency& adjacency,
                           std::span<const EdgeSplit> edges);

/// The index each added face of `change` gets once applied (filled slots, then appended).
std::vector<std::int32_t> added_face_indices(const TopologyChange& change);

}  // namespace conform::mesh
