// Step 2 of the planar cut (cut.hpp): the vertices a face's split would make a sliver with
// taken as on the plane. Internal to core.
#pragma once

#include "cut_classify.hpp"

namespace conform::mesh::cutting {

class CutSnap : public CutClassification {
 public:
  using CutClassification::CutClassification;

 protected:
  // The split of face f with sides s (crossed): the quality (smallest angle's sin²) of its
  // worst triangle, or −1 when a crossing falls within `snap` of an edge's end; for a lone
  // vertex, `first_diagonal` tells how its quad is split (as step 3 will).
  double split_quality(const Face& f, const std::int8_t* s, bool* first_diagonal) const;
  // Step 2, snapping, face by face: a crossed face whose split (by the vertices' current
  // sides) would make a triangle with smallest angle below its bound — min(min_angle, half the
  // face's smallest angle) — or whose crossing lies within snap_fraction of an edge's end, has
  // one vertex taken as on the plane: of the vertices whose snapping makes this face
  // acceptable (the lone vertex always does), the nearest to the plane. Snapping only uncrosses
  // faces, so the faces a snap touched are evaluated again until none snaps. Vertices never
  // move.
  void snap();
  // Step 2 for the ci-th crossed face: records its quad's diagonal, and snaps the fewest of
  // its vertices, nearest the plane, that make it acceptable.
  void snap_face(std::int32_t ci);
  // Rare (a crossing far along its edge, in a poorly shaped face): a vertex step 1 did not flag
  // near was snapped; the faces around it, not in work, are found by one more pass.
  void add_faces_around_far_snaps();

  bool outside_work_ = false;  // a vertex not flagged near was snapped: its faces are not in work
};

}  // namespace conform::mesh::cutting
