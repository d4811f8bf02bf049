// Triangulation of a planar cross-section bounded by closed loops: the caps of a cut.
//
// The section is the set of points of odd nesting depth among the loops — inside an outer
// loop but not inside one of its holes, inside an island within a hole, and so on — so a
// hollow tube cut across gives a ring, and loops side by side give separate discs. Loops are
// polygons in the plane, each vertex listed once, in any orientation; they must not cross or
// touch one another or themselves.
//
// Two triangulators:
//   ConstrainedDelaunay  CGAL's 2D constrained Delaunay triangulation of every loop edge
//                        (exact predicates), faces kept by nesting parity (a walk from the
//                        infinite face that flips parity across each loop edge). Available
//                        when Conform was built with CGAL (libcgal-dev; an optional
//                        dependency, see has_cgal_triangulator()). CGAL gets the loops'
//                        corners, centred and sheared by 2^-32 (orientations kept, exact
//                        cocircular ties broken): flat vertices (collinear with their
//                        neighbours, every other vertex of a cut across split quads) and
//                        symmetric sections otherwise send its filters to exact arithmetic.
//                        The flat vertices are put back by splitting the triangle on their
//                        edge, then Lawson's flips (as below) restore constrained Delaunay.
//   EarClipping          nesting depths by point-in-polygon tests, each hole joined to the
//                        loop around it by a bridge to a vertex it sees; a convex polygon is
//                        triangulated as a strip taking the Delaunay diagonal at each step,
//                        any other by ear clipping (a linked list, only reflex vertices
//                        tested); then Lawson's flips of the inner edges to the constrained
//                        Delaunay triangulation (floating-point predicates with a tolerance).
//                        Always available; the fallback, and faster than CGAL's on the cut's
//                        small sections.
// Neither adds vertices: every triangle joins three loop vertices.
//
// Forbidden diagonals: pairs of loop vertices that the triangulation must not join (a cut
// passes them in: an edge of the mesh that lies in the plane between two loop vertices, with
// its faces on one side, is a diagonal of the section, and a cap triangle on it would give that
// edge a third and fourth face). When the first triangulation uses one, the section is
// triangulated again by ear clipping that clips no ear whose diagonal is forbidden and flips
// no edge into one; if that fails too, a problem is reported.
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
