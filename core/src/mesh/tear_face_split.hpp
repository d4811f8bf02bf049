// Step 3's first change for a tear's sample (tear_step.hpp): the faces the path crosses split
// along it, collected in one TopologyChange before it is applied. Internal to core.
#pragma once

#include <vector>

#include "change_flips.hpp"
#include "conform/mesh/edge_map.hpp"
#include "tear_walk.hpp"

namespace conform::mesh::tearing {

class PathSplit : public TearWalk {
 public:
  using TearWalk::TearWalk;

 protected:
  // The id of path point p of face `face` in the change: a vertex, the edge point's new
  // vertex (one per edge), or the new tip.
  std::int32_t id_of(const PathPoint& p, std::int32_t face);
  Eigen::Vector3d position_of(std::int32_t id) const;
  void restart_split();
  // Crossing c's face as a polygon with the path's edge points inserted, split along the
  // path: a fan around the new tip, or the two sides of the chord (quads along the diagonal
  // with the larger smallest angle); a face crossed along an existing edge stays.
  void split_face(const Crossing& c);
  // Face `face`, which holds edge point p's edge, split in two from its vertex opposite it.
  void split_from_opposite(std::int32_t face, const PathPoint& p);
  // Edge flips among the faces the split adds and those beside them, the path's edges kept.
  void flip_beside_path() {
    std::vector<std::array<std::int32_t, 2>> path_edges;
    for (std::size_t i = 0; i + 1 < points_.size(); ++i)
      path_edges.push_back({points_[i], points_[i + 1]});
    flip_for_angles(mesh_, adjacency_, split_, path_edges);
  }
  // The path goes through a vertex on a border (a boundary, a hole's rim, the tear's own lips):
  // whichever split made it, that vertex would stay joined across the opened path, a pinch (two
  // fans at one vertex). The walks stop at such a vertex; a path may still reach one.
  bool path_through_border_vertex() const {
    for (const Crossing& c : path_)
      if (c.out.kind == PathPoint::Vertex && on_border(c.face, corner_of(c.face, c.out.v)))
        return true;
    return false;
  }

  TopologyChange split_;
  std::int32_t nv0_ = 0;
  EdgeMap edge_ids_;  // edge → its new vertex
  std::int32_t tip_id_ = -1;
  std::vector<std::int32_t> points_;  // S_i, Q_1 … Q_m, S_i+1
  Eigen::Vector3d target_;            // the blade's hit the new tip stands for
  bool off_track_ = false;            // the new tip was moved off the blade's hit (its fan)
};

}  // namespace conform::mesh::tearing
