// Planar cut (Algorithm 1 of the second paper), on the current positions.
//
// Promises:
//   - the mesh is separated along the plane Π: the positive side keeps the original vertices,
//     every other fan of faces around a vertex on the plane gets a duplicate, faces lying in
//     the plane go to the side opposite their normal; pieces are then the connected components
//     (label_pieces), so one plane may give many;
//   - vertices never move: a vertex within plane_tolerance × (bounding diagonal) is on the
//     plane, and a vertex a split would make a sliver with is taken as on it ("snapped");
//   - no slivers: every face the cut adds inside an original face (caps excluded: their
//     triangulation is bounded by the loop's own geometry) has smallest angle ≥ min(min_angle,
//     half the smallest angle of that face), except a face whose only snappable vertices were
//     kept off the plane so that its loop could be capped;
//   - with options.cap, every closed, unambiguous loop is capped on both sides by one
//     triangulation of the section (cap.hpp), loops inside loops giving rings; a group of loops
//     running against their nesting (an inside-out surface) is capped oriented like its faces.
//     A vertex on the plane by itself with several fans, or loops that cross, stay uncapped,
//     with the reason in the message;
//   - with options.region (cut_region.hpp), only the sections the region keeps are cut, each
//     whole, so a kept loop separates and caps as an unbounded cut's would.
//
// How: (1) every vertex is classified once by X·Π (conformal point against Π = n + d e∞);
// (2) each crossed face is split in thought, and where a piece would be too thin (or a crossing
// lies within snap_fraction of an edge's end) the fewest of its vertices, nearest the plane,
// are snapped; (3) one new vertex per crossed edge, shared by both sides, quads split along the
// diagonal with the larger smallest angle; (4) the sides separated; (5) the caps. A loop that
// meets itself at a snapped vertex (near a saddle) cannot be capped, so such vertices are kept
// off the plane and the cut computed again while that caps more loops
// (CutResult::unsnapped_vertices). Measurements behind the defaults: docs/notes/mesh_edits.md.
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
