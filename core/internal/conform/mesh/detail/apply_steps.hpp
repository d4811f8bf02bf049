// The two halves of apply() (topology_change.hpp), without its validation, for timing them
// separately: not part of the product API, for tests and benchmarks only.
#pragma once

#include "conform/mesh/adjacency.hpp"
#include "conform/mesh/skinned_mesh.hpp"
#include "conform/mesh/topology_change.hpp"

namespace conform::mesh::detail {

/// Weights and attributes of the new vertices. Runs first.
void apply_vertices(SkinnedMesh& mesh, const TopologyChange& change);
/// The face slots (visit_face_slots), keeping `adjacency` up to date when given.
void apply_faces(SkinnedMesh& mesh, const TopologyChange& change, Adjacency* adjacency);

}  // namespace conform::mesh::detail
