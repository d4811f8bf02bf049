// Step 5 of the drill (drill.hpp): the classification of the patch's vertices against the
// cylinder, with the snapping and bisection that keep the angle guarantee. Internal to core.
#pragma once

#include <vector>

#include "drill_region.hpp"

namespace conform::mesh::drilling {

/// Classifies region's vertices (+1 outside, −1 inside, 0 on the cylinder: snapped), snapping
/// vertices near the rim and mending sharp pieces of clipped faces (by more snaps, else by
/// bisection and a fresh classification); sets result.snapped_rim_vertices and
/// result.refinements.
void classify_rim(Region& region, const std::vector<Patch>& patches, const SkinnedMesh& mesh,
                  const Axis& axis, const DrillOptions& options, DrillResult& result);

/// The rim's crossing of edge (a, b) of the region, from a: the first root, else 0.5.
inline double rim_crossing_t(const Region& region, const Axis& axis, std::int32_t a,
                             std::int32_t b) {
  double roots[2];
  const int n =
      edge_roots(region.verts[std::size_t(a)].q, region.verts[std::size_t(b)].q, axis.r2, roots);
  return n > 0 ? roots[0] : 0.5;
}

}  // namespace conform::mesh::drilling
