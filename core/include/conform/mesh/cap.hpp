// Triangulation of a planar cross-section bounded by closed loops: the caps of a cut.
//
// The section is the set of points of odd nesting depth among the loops — inside an outer
// loop but not inside one of its holes, inside an island within a hole, and so on — so a
// hollow tube cut across gives a ring, and loops side by side give separate discs. Loops are
// polygons in the plane, each vertex listed once, in any orientation; they must not cross or
// touch one another or themselves. Neither triangulator adds vertices: every triangle joins
// three loop vertices, and the result is the constrained Delaunay triangulation.
//
// Two triangulators:
//   ConstrainedDelaunay  CGAL's, with exact predicates, faces kept by nesting parity; only when
//                        Conform was built with CGAL (has_cgal_triangulator()). The loops are
//                        sheared by 2^-32 first, so that flat vertices and symmetric sections do
//                        not send its filters to exact arithmetic; the flat vertices are then put
//                        back by splits and Lawson's flips.
//   EarClipping          holes bridged to the loop around them, then a Delaunay strip (convex
//                        polygons) or ear clipping, then Lawson's flips (floating-point
//                        predicates with a tolerance). Always available; the fallback, and
//                        faster than CGAL's on the cut's small sections.
//
// Forbidden diagonals: pairs of loop vertices that the triangulation must not join (an edge of
// the mesh lying in the plane with its faces on one side: a cap triangle on it would give that
// edge a third face). When the first triangulation uses one, the section is triangulated again
// by ear clipping that avoids them; if that fails too, a problem is reported.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace conform::mesh {

enum class SectionTriangulator { Best, ConstrainedDelaunay, EarClipping };

struct SectionTriangulation {
  /// Counter-clockwise triangles; indices into the loops' vertices concatenated in order.
  std::vector<std::array<std::int32_t, 3>> triangles;
  std::vector<std::int32_t> depth;  // nesting depth of each loop (0: outermost)
  std::string problem;              // empty on success; then `triangles` is empty
  bool ok() const { return problem.empty(); }
};

/// Pairs of loop vertices (indices into the loops' vertices concatenated) that no triangle
/// may join by a diagonal.
using ForbiddenDiagonals = std::vector<std::array<std::int32_t, 2>>;

/// Triangulates the section bounded by `loops` with `method` (Best: constrained Delaunay
/// when available, else ear clipping), using none of the `forbidden` diagonals (see above).
/// Requesting ConstrainedDelaunay without CGAL reports a problem.
SectionTriangulation triangulate_section(const std::vector<std::vector<Eigen::Vector2d>>& loops,
                                         SectionTriangulator method = SectionTriangulator::Best,
                                         const ForbiddenDiagonals& forbidden = {});

/// True when this build has CGAL's constrained Delaunay triangulation.
bool has_cgal_triangulator();

namespace detail {
// The CGAL path (cap_cgal.cpp); returns false with `problem` set when CGAL is not built in.
bool cdt_section(const std::vector<std::vector<Eigen::Vector2d>>& loops, SectionTriangulation& out);
bool cdt_available();
}  // namespace detail

}  // namespace conform::mesh
