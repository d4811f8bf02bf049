// Drilling (Algorithm 3 of the second paper), on the current positions.
//
// The drill is a cylinder of radius r about the axis from B (base) to A (tip). Every face the
// axis segment pierces, and the faces around it within r, make a patch; each patch becomes a
// hole whose rim lies on the cylinder (a closed mesh pierced through both walls gets both).
// Vertices closer to the cylinder than snap_fraction of an edge are taken as rim vertices and
// never moved; the computed rim points lie on the cylinder to rounding.
//
// Promises:
//   - one TopologyChange, applied once: refinement, holes and tube walls. Every new vertex is
//     a combination of the corners of the original face or edge it lies in (NewVertex::in_face
//     / on_edge), so rest positions, weights, UVs and normals follow in one step. New vertices
//     come in this order: refinement, rim, tube rings (whose parents may be rim vertices of
//     the same change); the tube walls' faces come last in added_faces;
//   - no slivers: every face the drill adds to the surface (tube walls excepted) has smallest
//     angle ≥ min(min_angle, half the smallest angle of the original face it lies in);
//   - a manifold surface stays manifold: a snapped vertex the hole would pass through twice is
//     given back to its side of the cylinder (DrillResult::unsnapped_rim_vertices);
//   - the rim polygon's chords, on the plane Π through B perpendicular to the axis, are at most
//     1.2 × the circumference / min_rim_points, with at least min_rim_points crossings per hole;
//   - with DrillOptions::tube, an entry hole and the next exit hole along the axis are joined
//     by a tube wall oriented as the surface, so that a closed input stays closed; a pair
//     whose rims are not two simple loops around the axis, share a vertex or would reuse an
//     edge is left open (see message). Tube faces are exempt from the angle bound: without
//     rings each spans the whole wall; with tube_ring_spacing > 0, rings of new vertices make
//     them about as long as wide.
//
// How: the pierced faces come from a FaceIndex segment query (or one scan of every face); a
// breadth-first walk from each marks its patch; each patch edge is intersected with the
// cylinder exactly on its projection on Π (eqs 18–20). Only faces the rim crosses with chords
// longer than the limit are refined, by Rivara's longest-edge bisection (neighbours stay
// conforming, angles stay at least half). The inside is removed and the rim re-triangulated;
// where a clipped piece would be sharper than the floor, one more vertex is snapped, or the face
// is bisected and the classification made again (four rounds at most, within max_refinements).
// Each thread keeps the drill's scratch tables between calls, so drilling at haptic rates
// allocates almost nothing. Measurements behind the defaults: docs/notes/mesh_edits.md.
//
// Given a FaceIndex, the drill refits it first if it was marked moved and updates it for every
// change it applies; without one it scans every face once (keep an index for haptic rates).
//
// Degenerate input — non-finite points or radius, r ≤ 0, A = B, non-finite positions of the
// faces the drill reaches — throws std::invalid_argument; a drill that pierces nothing returns
// holes = 0 and changes nothing.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "conform/mesh/adjacency.hpp"
#include "conform/mesh/face_index.hpp"
#include "conform/mesh/topology_change.hpp"

namespace conform::mesh {

struct DrillTool {
  Eigen::Vector3d tip;   // A
  Eigen::Vector3d base;  // B
  double radius = 0;
};

/// The drill's default sliver floor θ_floor (radians): 2° (the cut's and the tear's are 5°,
/// kCutMinAngle and kTearMinAngle).
inline constexpr double kDrillMinAngle = 2.0 * 3.14159265358979323846 / 180;

struct DrillOptions {
  int min_rim_points = 24;  // rim crossings per hole at least; keeps its area within 2 % of πr²
  int max_refinements = 6;  // at most 2 × this many bisections of an original face
  double snap_fraction = 0.01;
  double min_angle = kDrillMinAngle;  // sliver floor θ_floor, radians (see above); 0: none
  bool tube = false;  // join entry and exit holes of a closed surface with a tube wall
  // With the tube: intermediate rings at most this many times the rims' mean edge length
  // apart (0: none, one triangle spans the wall). Ring vertices are new vertices on the
  // segments between the two rims (NewVertex::on_edge of rim vertices).
  double tube_ring_spacing = 0;
};

struct DrillResult {
  // What the drill applied: one change (refinement, holes and tube walls), or none when it
  // pierces nothing or removes nothing.
  std::vector<TopologyChange> changes;
  std::int32_t holes = 0;
  std::int32_t rim_vertices = 0;          // new vertices on the cylinder
  std::int32_t snapped_rim_vertices = 0;  // existing vertices taken as rim vertices
  // Snapped vertices given back to their side of the cylinder: the hole would pinch there.
  std::int32_t unsnapped_rim_vertices = 0;
  std::int32_t removed_area_faces = 0;  // faces removed or clipped
  double removed_area = 0;
  int refinements = 0;     // refinement rounds: bisection depth / 2 (two bisections ≈ one 1-to-4)
  std::int32_t tubes = 0;  // hole pairs joined by a tube wall
  std::int32_t tube_faces = 0;  // faces of the tube walls
  std::string message;
};

/// Drills `mesh` (and keeps `adjacency` up to date), finding the pierced faces by one scan.
DrillResult drill(SkinnedMesh& mesh, Adjacency& adjacency, const DrillTool& tool,
                  const DrillOptions& options = {});
/// Drills `mesh`, keeping `adjacency` and `index` (which must describe the mesh) up to date.
DrillResult drill(SkinnedMesh& mesh, Adjacency& adjacency, FaceIndex& index, const DrillTool& tool,
                  const DrillOptions& options = {});

/// Radial distance squared of x from the drill's axis line.
double axis_distance_squared(const DrillTool& tool, const Eigen::Vector3d& x);

}  // namespace conform::mesh
