// Step 5 of the planar cut (cut.hpp): the section's closed loops found and triangulated, one cap
// on each side. Internal to core.
#pragma once

#include <string>
#include <vector>

#include "cut_fans.hpp"
#include "oriented_sections.hpp"

namespace conform::mesh::cutting {

class CutCaps : public CutFans {
 public:
  using CutFans::CutFans;
  // The snapped vertices where a loop met itself: compute_cut bars them in its next round.
  const std::vector<std::int32_t>& pinched_snaps() const { return pinched_snaps_; }

 protected:
  // Step 5: caps. Every closed, unambiguous loop goes into one triangulation of the section,
  // in the plane's frame, so that loops inside loops make holes and islands.
  void cap();
  // A loop vertex where the surface meets the plane in several fans: when it is an original
  // vertex that step 2 snapped (not on the plane by itself), compute_cut tries again without
  // snapping it.
  void note_pinch(std::int32_t l) {
    if (l < nx_) return;
    const std::int32_t v = global(l);
    if (std::abs(sc_.dist[static_cast<std::size_t>(v)]) > eps_) pinched_snaps_.push_back(v);
  }
  // Loop vertices (crossing vertices, and original vertices on the plane) get compact local
  // ids — crossing vertex nv0 + k is k, the i-th vertex of `plane_vertices` is nx + i — so
  // that the loop bookkeeping is flat arrays rather than hash maps.
  std::int32_t local(std::int32_t v) const {  // −1 when v is not a loop vertex
    if (v >= nv0_) return v < nv0_ + nx_ ? v - nv0_ : -1;
    if (sc_.side[static_cast<std::size_t>(v)] != 0) return -1;
    const auto& pv = sc_.plane_vertices;
    return nx_ + static_cast<std::int32_t>(std::lower_bound(pv.begin(), pv.end(), v) - pv.begin());
  }
  std::int32_t global(std::int32_t l) const {
    return l < nx_ ? nv0_ + l : sc_.plane_vertices[static_cast<std::size_t>(l - nx_)];
  }
  // The local ids of the pending faces' vertices, and the id each side uses for a loop vertex
  // (conflicting entries make a loop ambiguous).
  void index_loop_vertices();
  // The boundary of the positive side created by the cut: directed edges of positive faces
  // between loop vertices whose reverse no positive face has, as next[u] (and their starts).
  void chain_boundary();
  // Edges of the mesh in the plane whose faces are on one side (a crease of that side touching
  // the plane): they join two loop vertices through the section, and a cap triangle on one
  // would be a third face of that edge. As indices into sc_.ids, for the triangulation to avoid.
  ForbiddenDiagonals forbidden_diagonals() const;
  // The closed, unambiguous loops, projected on the plane's frame (e1, e2, n); their local
  // ids concatenated in sc_.ids.
  std::vector<std::vector<Eigen::Vector2d>> closed_loops(std::vector<std::string>& problems);
  // The triangulation of the section (in groups whose loops run as their nesting says,
  // oriented_sections.hpp); each triangle caps both sides. Section triangles turn
  // counter-clockwise about n (clockwise where the surface is inside out): the negative piece's
  // cap faces +n as they are, the positive piece's is reversed.
  void add_cap_faces(const std::vector<std::vector<Eigen::Vector2d>>& loops2,
                     const ForbiddenDiagonals& forbidden, std::vector<std::string>& problems);

  std::size_t nloop_ = 0;                    // loop vertices (local ids)
  bool branching_ = false;                   // a loop vertex with two boundary edges out
  std::vector<std::int32_t> pinched_snaps_;  // snapped vertices where a loop meets itself
};

}  // namespace conform::mesh::cutting
