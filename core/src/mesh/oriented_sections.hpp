// The cut's caps from its section's loops, with every loop running as its nesting says.
//
// A cap triangle of the section (counter-clockwise about the plane's normal) caps both sides,
// reversed for the positive one. That is oriented against the pieces' faces only when every
// loop runs as the positive side's boundary of a closed, outward-oriented surface does: at an
// even nesting depth counter-clockwise, at an odd depth (a hole) clockwise. In a running
// simulation pieces overlap, so one piece's loop can lie inside another's and be taken for its
// hole: capped as one section, such a loop would get cap faces oriented like their neighbours
// (edges used twice in one direction). So the loops are triangulated in groups: the loops
// against their nesting are set aside and the others triangulated again until every loop of
// the group agrees, and the loops set aside make the next group (where the overlapping piece's
// loop is an outer loop of its own). A group all of whose loops run against their nesting (an
// inside-out surface: outer loops clockwise, holes counter-clockwise) is triangulated as it
// nests and its triangles reversed, so that its caps are oriented like its own faces.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "conform/mesh/cap.hpp"

namespace conform::mesh::detail {

struct OrientedSections {
  /// Triangles counter-clockwise, clockwise in an inside-out group (the caps' orientation on the
  /// negative side); indices into the loops' vertices concatenated in order.
  std::vector<std::array<std::int32_t, 3>> triangles;
  std::int32_t capped_loops = 0;
  std::int32_t nested_loops = 0;      // capped loops inside another loop of their group
  std::int32_t inside_out_loops = 0;  // capped loops of groups running against their nesting
  std::string problem;                // a triangulation's problem; then no triangles at all
};

OrientedSections oriented_sections(const std::vector<std::vector<Eigen::Vector2d>>& loops,
                                   SectionTriangulator method, const ForbiddenDiagonals& forbidden);

}  // namespace conform::mesh::detail
