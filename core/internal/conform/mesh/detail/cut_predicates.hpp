// The cut's benchmark hooks (the paper's Table 1 compares the conformal predicates with plain
// Euclidean ones): not part of the product API, for tests and benchmarks only.
#pragma once

#include <vector>

#include "conform/cga/plane.hpp"
#include "conform/mesh/cut.hpp"
#include "conform/mesh/skinned_mesh.hpp"

namespace conform::mesh::detail {

/// Which predicates classify vertices and intersect edges: the conformal inner product
/// X·Π with X = up(x) (what compute_cut uses), or the plain Euclidean n·x − d.
enum class Predicates { Cga, Euclidean };

/// Step 1 alone: signed distances of the current positions.
void classify_vertices(const SkinnedMesh& mesh, const cga::Plane<double>& plane,
                       Predicates predicates, std::vector<double>& distance);

/// compute_cut with the given predicates.
CutResult compute_cut(const SkinnedMesh& mesh, const cga::Plane<double>& plane,
                      const CutOptions& options, Predicates predicates);

}  // namespace conform::mesh::detail
