// Progressive tearing (Algorithm 2 of the second paper), on the current positions.
//
// The scalpel is a blade segment (a, b) sampled at times t_i. The first sample that meets the
// surface starts the tear at its hit S_0 (nearest its end point a). Every later sample extends
// one continuous tear from the tip S_i to the blade's new hit S_i+1, or leaves the mesh
// unchanged and says why (message()).
//
// Promises:
//   - every step is one or two TopologyChanges (the split, then the separation), applied at
//     once and returned so that a soft body can mirror them; new vertices carry weights, UVs
//     and normals as topology_change.hpp describes;
//   - no slivers: every face the tear adds has smallest angle ≥ min(min_angle, half the
//     smallest angle of the input face it lies in). A sample whose blade lies in a face of the
//     tear's own too thin for a new tip waits for the blade to move on;
//   - the walk is local and bounded by the blade: a step adds only path points within
//     TearOptions::sweep_tolerance of the region the blade swept since the previous sample, so
//     a blade plane that would lead the walk around a limb waits instead;
//   - only the start queries the FaceIndex; given one, the tear refits it when marked moved,
//     updates it for every change and marks it moved when open() moves positions. Without one,
//     each start attempt scans every face once (keep an index for haptic rates).
//
// How, per sample: (1) the plane Π through the tip and the blade; (2) a walk across faces from
// S_i along Π ∩ M toward the blade, never scanning, its edge crossings Q_j kept where splitting
// the faces beside them makes no sliver; (3) the crossed faces split along S_i, Q_1 … Q_m,
// S_i+1 (the new tip inside its face, moved toward the incenter until its fan keeps the bound),
// then every interior point duplicated for the faces on the path's left, so the tear opens there.
// With TearOptions::smooth_lips the path's points are the blade's hits, on its track, and the
// faces beside them keep the floor by edge flips rather than by moving the points; open() then
// moves the lips along Π's normals smoothed along the path, so a bend does not fold a lip over
// itself. Measurements behind the defaults: docs/notes/mesh_edits.md.
//
// Degenerate input: non-finite samples throw std::invalid_argument; a blade outside the
// mesh, a blade that has not moved, a blade collinear with the tip, a blade in a face too thin
// for a new tip, or a walk that reaches a boundary, the step limit or the edge of the swept
// region leave the mesh unchanged for that sample (see message()).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "conform/mesh/adjacency.hpp"
#include "conform/mesh/face_index.hpp"
#include "conform/mesh/topology_change.hpp"

namespace conform::mesh {

struct ScalpelSample {
  double t = 0;
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();  // blade end points
};

/// The tear's sliver floor θ_floor (radians): see TearOptions::min_angle.
inline constexpr double kTearMinAngle = 5.0 * 3.14159265358979323846 / 180;

struct TearOptions {
  double snap_fraction = 0.05;       // of an edge (and barycentric margin of the tip in its face)
  double min_angle = kTearMinAngle;  // sliver floor θ_floor, radians, in [0, 0.5)
  int max_walk_faces = 100000;       // bound of one step's walk
  // How far a path point may lie outside the region the blade swept since the previous sample
  // (the convex hull of the tip and both samples' blades), in units of the longest edge of the
  // face the point is on; ≥ 0, infinity turns the bound off. The default leaves room for the
  // surface's curvature between tip and blade and for crossings kept off Π, and stops a walk
  // around a limb, which goes a diameter out.
  double sweep_tolerance = 8.0;
  // The lips' shape (see above): the path on the blade's track, the faces beside it flipped,
  // and open()'s directions smoothed along the path. Off by default; tear-opening turns it on.
  bool smooth_lips = false;
};

struct TearStep {
  std::vector<TopologyChange> changes;  // already applied, in order
  bool extended = false;                // the tear grew
};

class Tear {
 public:
  /// The mesh and adjacency must outlive the Tear; every change is applied to both.
  Tear(SkinnedMesh& mesh, Adjacency& adjacency, const TearOptions& options = {});
  /// Also keeps `index` (which must describe the mesh, and outlive the Tear) in sync.
  Tear(SkinnedMesh& mesh, Adjacency& adjacency, FaceIndex& index, const TearOptions& options = {});

  TearStep advance(const ScalpelSample& sample);
  /// Step 6: moves the two copies of each interior tear point apart along ± the normal of
  /// the plane Π that made it, by `amount` in total at the middle of the tear, tapering
  /// (sin) to zero at both ends. Changes current positions only; returns the displacements
  /// (vertex, offset) it applied.
  std::vector<std::pair<std::int32_t, Eigen::Vector3d>> open(double amount);

  /// The crack grew by itself from one of the tear's ends (a change applied to the mesh, its
  /// adjacency and index already): `end` was duplicated into `duplicate` and the crack runs on to
  /// `new_tip`. The path takes the grown segment, so the borders, open() and the blade's next
  /// step start from there. Throws std::invalid_argument when `end` is not an end of the tear.
  void adopt_growth(std::int32_t end, std::int32_t duplicate, std::int32_t new_tip);

  bool started() const { return tip_ >= 0; }
  int steps() const { return steps_; }
  /// Points of the tear (start, interior points, tip).
  std::int32_t path_length() const { return static_cast<std::int32_t>(path_.size()); }
  /// The tear's length along its path (current positions of the right border).
  double length() const;
  /// The two borders as vertex chains from the start to the tip (they share both ends).
  std::vector<std::int32_t> left_border() const;
  std::vector<std::int32_t> right_border() const;
  const std::string& message() const { return message_; }

 private:
  friend struct TearState;  // what the steps of advance() after the start use (tear_step.hpp)
  struct PathVertex {
    std::int32_t right = -1;  // the original vertex (faces right of the path)
    std::int32_t left = -1;   // its duplicate for the faces on the left, −1 at the ends
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // Π's unit normal of the step
  };
  bool start(const ScalpelSample& sample, TearStep& step);
  void commit(TopologyChange&& change, TearStep& step);  // apply, update adjacency and index

  SkinnedMesh& mesh_;
  Adjacency& adjacency_;
  FaceIndex* index_ = nullptr;
  TearOptions options_;
  std::vector<PathVertex> path_;
  std::int32_t tip_ = -1;
  std::int32_t first_new_vertex_ = 0;  // vertices from here on were added by this tear
  std::int32_t tip_neighbor_ = -1;     // a vertex sharing an edge with the tip
  Eigen::Vector3d tip_target_ = Eigen::Vector3d::Zero();  // the blade's hit the tip stands for
  bool tip_off_track_ = false;  // smooth_lips: the tip was moved off that hit, Π goes through it
  ScalpelSample previous_;      // the last sample seen: where the blade's sweep starts
  int steps_ = 0;
  std::string message_;
};

}  // namespace conform::mesh
