// Planar cut (Algorithm 1 of the second paper), on the current positions.
//
//   1. classify every vertex once by X·Π (conformal point against the plane Π = n + d e∞);
//      vertices within plane_tolerance × (bounding diagonal) are on the plane;
//   2. snap (no slivers): every crossed face is split in thought; if a triangle of its split
//      would have its smallest angle below min(min_angle, half the smallest angle of the face)
//      — or a crossing lies within snap_fraction of an edge's end — the fewest of its vertices,
//      nearest the plane, are taken as on the plane instead (the nearest alone if that makes
//      the split acceptable, else the second nearest, else both, which uncrosses the face),
//      until no face needs it. Vertices are never moved: a snapped vertex stays where it is, at
//      most about its face's size off the plane (in the property tests: ≤ 0.4 of the mean edge
//      on the arm, ≤ 1.1 at the cylinder's thin cap fans);
//   3. one new vertex per crossed edge (edge parameter t from the lower vertex index), shared
//      by the faces on both sides; split triangles stay triangles (a quad is split along the
//      diagonal that gives the larger smallest angle);
//   4. separate the sides: the positive side keeps the original vertices, every fan of faces
//      around a loop vertex beyond the first gets a duplicate (normally: the negative side);
//      faces lying in the plane go to the side opposite their normal;
//   5. optionally cap the cross-section, both sides: every closed cut loop goes into one
//      triangulation of the section (cap.hpp: CGAL's constrained Delaunay triangulation when
//      built with CGAL, else ear clipping with holes bridged), filled by nesting parity, so
//      loops inside loops (a hollow tube, a torus cut through its hole) give rings. A group
//      of loops all running against their nesting (an inside-out surface) is capped with its
//      triangles reversed, oriented like its own faces (oriented_sections.hpp). A loop that
//      meets itself at a vertex step 2 snapped (near a saddle, the surface then touches the
//      plane in two fans there) cannot be capped: such vertices are kept off the plane and
//      the cut computed again, while that caps more loops (CutResult::unsnapped_vertices;
//      4 of 191 capped cuts of real models in the property test). A vertex on the plane by
//      itself with several fans, or loops that cross (intersecting shells), stay uncapped,
//      with the reason in the message.
// Pieces are then the connected components (label_pieces), so one plane may give many.
//
// Regional cuts: with options.region (cut_region.hpp), step 2's result is grouped into
// sections (the crossed and touching faces, connected through shared vertices) and only the
// sections the region keeps go on to steps 3–5; the rest of the mesh is untouched. A section
// is kept or dropped whole, so a kept loop separates and caps as an unbounded cut's would.
//
// Sliver guarantee: every face the cut adds inside an original face (caps excluded: their
// constrained Delaunay triangulation is bounded by the cut loop's own geometry) has smallest
// angle ≥ min(min_angle, half the smallest angle of that original face), except a face whose
// only snappable vertices were kept off the plane by step 5's rounds. The default floor,
// kCutMinAngle = 5°, was chosen by measurement over the property tests (1,550 random planes on
// the arm, a sphere, a cylinder and a sheet): floors of 1°, 2°, 5° and 10° snap about 2.5, 5, 12
// and 23 vertices per cut of the arm and move the cut off the plane by at most 0.18, 0.29, 0.37
// and 0.37 mean edges on the arm (0.28, 0.51, 1.05, 1.13 on the cylinder, whose cap fans have
// 11° corners); 5° keeps the deviation under half an edge on well-shaped meshes. Without the
// angle rule (1 % snapping alone) the smallest added angle was 0.10°.
//
// Degenerate input: a non-finite or zero-normal plane, non-finite positions or an invalid
// region (CutRegion::validate) throw std::invalid_argument; a plane that misses or only touches
// the mesh, or crosses it only in sections the region drops, returns status Missed with an
// empty change (a documented no-op).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "conform/cga/plane.hpp"
#include "conform/mesh/analysis.hpp"
#include "conform/mesh/cap.hpp"
#include "conform/mesh/cut_region.hpp"
#include "conform/mesh/topology_change.hpp"

namespace conform::mesh {

/// The cut's sliver floor θ_floor (radians): see CutOptions::min_angle.
inline constexpr double kCutMinAngle = 5.0 * 3.14159265358979323846 / 180;

struct CutOptions {
  double plane_tolerance = 1e-9;    // × bounding diagonal
  double snap_fraction = 0.01;      // of an edge's length
  double min_angle = kCutMinAngle;  // sliver floor θ_floor, radians, in [0, 0.5); 0: off
  bool cap = false;
  SectionTriangulator cap_triangulator = SectionTriangulator::Best;
  CutRegion region = {};  // default: everywhere (the unbounded plane)
};

enum class CutStatus { Cut, Missed };

struct CutResult {
  CutStatus status = CutStatus::Missed;
  TopologyChange change;
  std::vector<std::int8_t> added_side;  // +1 / −1 for each added face (caps included)
  std::int32_t crossed_edges = 0;
  std::int32_t snapped_vertices = 0;  // vertices taken as on the plane by step 2 (snaps)
  std::int32_t loops = 0;             // closed cut loops found (when capping)
  std::int32_t capped_loops = 0;
  std::int32_t nested_loops = 0;        // capped loops inside another loop (holes, islands)
  std::int32_t inside_out_loops = 0;    // capped loops of an inside-out surface (caps reversed)
  std::int32_t unsnapped_vertices = 0;  // kept off the plane: snapped, they pinched a loop
  std::int32_t cap_faces = 0;           // per side
  std::int32_t sections = 0;            // with a region: the sections the plane crosses
  std::int32_t kept_sections = 0;       // with a region: those it kept (cut)
  std::string message;                  // why a loop was not capped, or why the cut missed
};

/// Computes the change without touching the mesh. O(V + F) for the classification, then
/// proportional to the faces near the plane; the working arrays are kept per thread between
/// calls (no allocation but for the result).
CutResult compute_cut(const SkinnedMesh& mesh, const cga::Plane<double>& plane,
                      const CutOptions& options = {});

struct CutOutcome {
  CutResult result;
  Pieces pieces;
};

/// compute_cut, apply (keeping `adjacency` up to date), then label the pieces.
CutOutcome cut(SkinnedMesh& mesh, Adjacency& adjacency, const cga::Plane<double>& plane,
               const CutOptions& options = {});

}  // namespace conform::mesh
