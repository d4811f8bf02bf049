// Step 5b of the drill (drill.hpp): no pinched rim. A vertex snapped onto the rim (side 0) is
// kept, and the hole may pass through it more than once: where the rim runs nearly along the
// surface (an axis close to a limb's own), the faces left around it are two fans that meet at
// one point, a non-manifold vertex. Such vertices are found in the change the clipping
// computed, before it is applied; drill.cpp then un-snaps them (each goes back to its own side
// of the cylinder, where the clipping keeps a manifold neighbourhood) and clips again.
// Internal to core.
#pragma once

#include <cstdint>
#include <vector>

#include "conform/mesh/adjacency.hpp"
#include "conform/mesh/topology_change.hpp"
#include "drill_region.hpp"

namespace conform::mesh::drilling {

/// The region's rim vertices (side 0, local ids, ascending) around which the faces that `ch`
/// leaves form more than one fan. `ch` is the clipping's change with its removed faces sorted
/// and every vertex of region.added given its mesh index; `mesh` and `adjacency` are as before
/// the change.
std::vector<std::int32_t> pinched_rim_vertices(const Region& region, const SkinnedMesh& mesh,
                                               const Adjacency& adjacency,
                                               const TopologyChange& ch);

}  // namespace conform::mesh::drilling
