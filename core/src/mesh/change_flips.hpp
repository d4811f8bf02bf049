// Edge flips beside a topology change (the tear's lips): Lawson's flips for the
// smallest angle among the faces a TopologyChange adds and the mesh faces next to them, made
// part of the change itself (flipped mesh faces become removed and added faces).
//
// A point put exactly where it belongs (the tear's tip on the blade's track) can be close to
// an edge of the face it splits, and the fan around it then holds a sliver. Moving the point
// off the track keeps the fan above the sliver floor but bends the lip; flipping the thin
// triangle's long edge (toward the vertex across it) keeps the point and the floor both.
//
// An edge is flipped when the two faces on it, turned to the other diagonal, have a larger
// smallest angle, the quad is convex (both new faces face the old faces' way) and nearly flat
// (the two diagonals within `max_bend` of the longer one: a flip across a fold would change the
// surface's shape). Edges in `fixed` (the tear's path) and edges with one face (borders, the
// tear's slit) stay. Each flip strictly raises the smaller of the two smallest angles it
// replaces, so no face the change makes is thinner than before and the flips end.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "conform/mesh/adjacency.hpp"
#include "conform/mesh/skinned_mesh.hpp"
#include "conform/mesh/topology_change.hpp"

namespace conform::mesh {

struct FlipOptions {
  double max_bend = 0.05;  // the diagonals' distance / the longer diagonal
  int max_flips = 64;      // bound of one change's flips
};

/// Flips edges among `change`'s added faces and the mesh faces across their edges (`change`
/// computed for `mesh` and not applied yet); returns the number of flips.
int flip_for_angles(const SkinnedMesh& mesh, const Adjacency& adjacency, TopologyChange& change,
                    const std::vector<std::array<std::int32_t, 2>>& fixed,
                    const FlipOptions& options = {});

/// Flips the edges that the segment from vertex t to vertex p crosses (sides taken across the
/// plane through t with unit normal `normal`, which holds p), among `change`'s added faces, the
/// mesh faces `slots` and those beside them, until (t, p) is an edge: the constrained edge of a
/// Delaunay insertion. False when a crossed edge cannot be flipped (a quad not convex, not flat,
/// or a boundary); `change` then holds the flips made until there.
bool flip_to_edge(const SkinnedMesh& mesh, const Adjacency& adjacency, TopologyChange& change,
                  std::int32_t t, std::int32_t p, const Eigen::Vector3d& normal,
                  const std::vector<std::int32_t>& slots, const FlipOptions& options = {});

}  // namespace conform::mesh
