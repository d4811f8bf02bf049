// Steiner points beside the tear's path (the lips, issue 18): local refinement where flips
// cannot help.
//
// A mesh vertex a tenth of an edge off the blade's track, too far to put a path point on
// (the lip would leave the track) and too near to leave out of the path's faces, is the apex of
// the faces on the path's edges beside it: with path points a third of an edge apart, those
// reaching past its foot are caps thinner than 15°, and no flip removes them (the path's edges
// stay). A new vertex at the apex of the equilateral triangle on such a path edge, on the cap's
// side, gives that edge a roomy face; flips (change_flips.hpp) then re-triangulate around it.
// Likewise a face on a path vertex that is thin at a vertex off the path (its short side joins
// the path to a vertex just off the track) gets a Steiner point across that short side.
#pragma once

#include <cstdint>
#include <vector>

#include "conform/mesh/adjacency.hpp"
#include "conform/mesh/skinned_mesh.hpp"
#include "conform/mesh/topology_change.hpp"

namespace conform::mesh {

/// One Steiner point beside the path (consecutive vertices joined by mesh edges) where a face is
/// thinner than `thin` (radians), as above, with the flips that follow, the path's edges kept:
/// the first such change that removes that face, raises the smallest angle of the faces it
/// replaces and keeps every face it adds at or above `floor`; empty when there is none.
TopologyChange refine_beside_path(const SkinnedMesh& mesh, const Adjacency& adjacency,
                                  const std::vector<std::int32_t>& path, double thin, double floor);

}  // namespace conform::mesh
