// The planar cut's region (cut_region.hpp): the whole sections of the plane's intersection
// that the cut keeps, after step 2. Internal to core.
#pragma once

#include "cut_snap.hpp"

namespace conform::mesh::cutting {

class CutSections : public CutSnap {
 public:
  using CutSnap::CutSnap;

 protected:
  // A work face crossed by the plane or touching it (a section's face).
  bool in_section(const Face& f) const {
    const std::int8_t* const sd = sc_.side.data();
    const std::int8_t s[3] = {sd[f[0]], sd[f[1]], sd[f[2]]};
    return s[0] == 0 || s[1] == 0 || s[2] == 0 || is_crossed(s);
  }
  // The region's whole sections (cut_region.hpp), after step 2 so that snapped vertices count
  // as on the plane: the section faces grouped by shared vertices, each group's points (its
  // crossing points and vertices on the plane) measured against the region, and the work list
  // cut down to the kept groups' faces. Sharing any vertex is a coarser grouping than sharing a
  // crossed edge or a fan vertex, so no fan or crossing vertex is ever split between a kept and
  // a dropped face. False when no kept section crosses the plane.
  bool select_sections();
};

}  // namespace conform::mesh::cutting
