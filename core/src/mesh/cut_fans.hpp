// Step 4 of the planar cut (cut.hpp): the two sides separated, at the vertices on the plane
// (one copy per fan beyond the first) and at the crossing vertices. Internal to core.
#pragma once

#include "cut_split.hpp"

namespace conform::mesh::cutting {

class CutFans : public CutSplit {
 public:
  using CutSplit::CutSplit;

 protected:
  const Pending& pending_at(std::size_t on_plane_index) const {
    return sc_.pending[static_cast<std::size_t>(sc_.on_plane[on_plane_index].second)];
  }
  // Step 4 at the vertices on the plane: faces on one side sharing an edge through the vertex
  // form a fan; the first positive fan keeps the vertex, every other fan gets a copy.
  void separate_fans();
  // The fans of the vertex of on_plane[i, j).
  void separate_fans_at(std::size_t i, std::size_t j);
  // Step 4 at the crossing vertices: the negative side uses a copy.
  void separate_crossings();

  std::int32_t nx_ = 0;  // crossing vertices
};

}  // namespace conform::mesh::cutting
