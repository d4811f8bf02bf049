// Step 6 of the drill (drill.hpp): tube walls joining an entry hole and the next exit hole
// along the axis, decided on the drill's change before it is applied. Internal to core.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <vector>

#include "drill_region.hpp"

namespace conform::mesh::drilling {

// The post-change mesh, seen from the drill's change before it is applied: positions of old and
// new vertices, and whether a directed edge between two rim vertices will exist.
struct Outcome {
  const SkinnedMesh& mesh;
  const Adjacency& adjacency;
  const TopologyChange& change;
  const std::vector<Eigen::Vector3d>& new_x;  // positions of change.new_vertices
  const EdgeMap& rim_edges;  // directed edges of the change's added faces between rim vertices
  Eigen::Vector3d pos(std::int32_t v) const {
    return v < change.base_vertex_count ? Eigen::Vector3d(mesh.current.col(v))
                                        : new_x[std::size_t(v - change.base_vertex_count)];
  }
  // x → y is a half-edge of the changed mesh: of an added face, or of an original face that
  // the change keeps.
  bool has(std::int32_t x, std::int32_t y) const {
    if (rim_edges.find(x, y) >= 0) return true;
    if (x >= change.base_vertex_count || y >= change.base_vertex_count) return false;
    const std::int32_t h = adjacency.find(x, y);
    return h >= 0 &&
           !std::binary_search(change.removed_faces.begin(), change.removed_faces.end(), h / 3);
  }
};

// Appends to `change` the tube walls joining consecutive holes along the axis, where the drill
// enters then leaves the surface: a strip of triangles between their rim loops, through
// intermediate rings of new vertices when ring_spacing > 0. Everything is decided on the change
// before it is applied (Outcome), so that the drill applies one change.
void add_tubes(const Outcome& out, const Axis& axis, const std::vector<Patch>& patches,
               double ring_spacing, TopologyChange& change, std::vector<Eigen::Vector3d>& new_x,
               EdgeMap& rim_edges, EdgeMap& in_a, DrillResult& result);

}  // namespace conform::mesh::drilling
