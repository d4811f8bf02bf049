// Step 1 of the planar cut (cut.hpp): the input checked, the vertices' signed distances and
// sides, and the faces that need work. The base of the cut's layered classes: CutClassification
// (here), CutSnap (step 2, cut_snap.hpp), CutSections (the region, cut_sections.hpp), CutSplit
// (step 3, cut_split.hpp), CutFans (step 4, cut_fans.hpp), CutCaps (step 5, cut_caps.hpp) and
// CutComputation (their order, cut_computation.hpp); each layer reads the state of the ones
// below it. Internal to core.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "conform/cga/plane.hpp"
#include "conform/mesh/cut.hpp"
#include "conform/mesh/detail/cut_predicates.hpp"
#include "conform/mesh/edge_map.hpp"

namespace conform::mesh::cutting {

using detail::Predicates;

// The plane scaled to a unit normal; throws on a non-finite or zero normal.
cga::Plane<double> unit_plane(const cga::Plane<double>& plane);

struct Pending {
  Face v;    // after the separation remap
  Face pre;  // before it (original and crossing-vertex ids)
  std::int8_t side;
  std::int32_t original;  // the face it re-indexes, or −1 for a piece of a split face
  bool remapped = false;
};

// compute_cut's working arrays, kept per thread between calls so that a cut at haptic rates
// allocates only what it returns.
struct Scratch {
  std::vector<double> dist;
  std::vector<std::int8_t> side;
  std::vector<std::uint8_t> code;
  std::vector<std::int32_t> work, crossed, evaluate, again, snapped_now, parent, xcopy,
      plane_vertices, copy_plus, copy_minus, next, starts, ids, loop, section_parent, section_of;
  EdgeMap crossing;
  std::vector<Eigen::Vector3d> xpos;
  std::vector<Pending> pending;
  std::vector<std::pair<std::int32_t, std::int32_t>> on_plane;
  std::vector<std::array<std::int32_t, 3>> pending_local;
  std::vector<std::uint8_t> ambiguous, visited, diagonal;
  std::vector<std::uint64_t> plus_edges;
  std::vector<std::int32_t> unsnappable;  // sorted: vertices step 2 must not snap (pinches)
};
Scratch& scratch();

class CutClassification {
 public:
  CutClassification(const SkinnedMesh& mesh, const cga::Plane<double>& plane,
                    const CutOptions& options, Predicates predicates)
      : mesh_(mesh),
        plane_(unit_plane(plane)),
        options_(options),
        predicates_(predicates),
        sc_(scratch()),
        nv0_(mesh.vertex_count()),
        nf0_(mesh.face_count()),
        snap_(options.snap_fraction),
        floor_sin2_(std::sin(options.min_angle) * std::sin(options.min_angle)) {}

 protected:
  void check_input() const;
  // Step 1, in one pass over the positions: finite, their bounding box (the tolerance's
  // scale), the signed distances (the same predicates as classify_vertices) and the farthest
  // vertex on each side.
  void measure_distances();
  // Step 1's sides, and which vertices step 2 may snap. A vertex at distance d of the plane is
  // snapped only across an edge to a vertex at distance d' on the other side with
  // |d| < snap / (1 − snap) · |d'|, so only vertices nearer than that to the plane, measured
  // with the other side's reach, can be: "near". Per vertex code: 1 on the plane, 2 positive,
  // 8 negative, + 16 when near.
  void classify_sides();
  // One pass over the faces: index check, and the faces that need work — crossed, touching
  // the plane, or with a near vertex (which snapping may put on the plane) — in increasing
  // order. The rest only tell which sides have faces.
  void find_work_faces();
  Eigen::Map<const Eigen::Vector3d> point(std::int32_t v) const {
    return Eigen::Vector3d::Map(mesh_.current.data() + 3 * std::size_t(v));
  }
  double dist(std::int32_t v) const { return sc_.dist[static_cast<std::size_t>(v)]; }
  // Where the plane crosses edge (u, w), from its lower vertex.
  Eigen::Vector3d crossing_point(std::int32_t u, std::int32_t w) const {
    const std::int32_t a = std::min(u, w), b = std::max(u, w);
    const double da = dist(a), db = dist(b);
    const double t = da / (da - db);
    return (1 - t) * point(a) + t * point(b);
  }
  double crossing_t(std::int32_t from, std::int32_t to) const {  // from `from` along the edge
    const double df = dist(from), dt = dist(to);
    return df / (df - dt);
  }
  static bool is_crossed(const std::int8_t* s) {
    return s[0] * s[1] < 0 || s[1] * s[2] < 0 || s[2] * s[0] < 0;
  }

  const SkinnedMesh& mesh_;
  const cga::Plane<double> plane_;  // unit normal
  const CutOptions& options_;
  const Predicates predicates_;
  Scratch& sc_;
  const std::int32_t nv0_, nf0_;
  const double snap_, floor_sin2_;
  CutResult result_;
  double diagonal_ = 0, reach_pos_ = 0, reach_neg_ = 0, eps_ = 0;
  bool face_pos_ = false, face_neg_ = false;  // a face lies on that side
};

}  // namespace conform::mesh::cutting
