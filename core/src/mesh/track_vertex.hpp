// A mesh vertex on the blade's track near the new tip (the tear's lips, issue 18).
//
// A path point put at the blade's hit beside a mesh vertex that lies on the track (within a
// tenth of an edge of it) joins that vertex by a short edge or caps it with a flat triangle, and
// the faces on that edge or cap are thin however the edges around are flipped: the fans of
// slivers on a vertex that the issue forbids. With the path points about a third of an edge
// apart, a path point on the vertex itself keeps the lip on the track and its spacing even.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "conform/mesh/skinned_mesh.hpp"

namespace conform::mesh {

struct TrackVertexQuery {
  Eigen::Vector3d hit;                   // the blade's hit, where the tip would go
  Eigen::Vector3d previous;              // the previous step's hit: hit − previous is one step
  std::array<Eigen::Vector3d, 4> sweep;  // the blade before and now: a, b, then a, b
  double edge = 0;                       // the local edge length
  double across = 0.09;                  // largest distance to the swept quad, in edges
  double behind = 0.36;  // largest shift back along the track from the hit, in steps (the
                         // next tip takes up half of it: tear.cpp's catch_up)
  double ahead = 0.3;    // largest shift forward, in steps
};

/// The candidate nearest the hit that lies within `across` edges of the swept quad and within
/// `behind` steps before and `ahead` steps past the hit along the step, or −1.
std::int32_t track_vertex(const SkinnedMesh& mesh, const std::vector<std::int32_t>& candidates,
                          const TrackVertexQuery& query);

}  // namespace conform::mesh
