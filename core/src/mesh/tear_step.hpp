// A tear's step after the start (Tear::advance, tear.hpp), split by concept over layered
// classes: StepPlane (step 1, the plane Π and the queries on it), TearWalk (step 2,
// tear_walk.hpp), PathSplit (step 3's face splits, tear_face_split.hpp), TipPlacement (the
// lips' tip, tear_tip_placement.hpp), TearOpening (step 3's second change, tear_opening.hpp)
// and TearAdvance (the order of the steps, tear_advance.hpp). Each layer reads the state of
// the ones below it. Internal to core.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "conform/cga/plane.hpp"
#include "conform/mesh/analysis.hpp"
#include "conform/mesh/tear.hpp"

namespace conform::mesh {

// What a step reads and writes of its Tear (the only friend of Tear): references named as
// the Tear's own members.
struct TearState {
  explicit TearState(Tear& tear)
      : mesh_(tear.mesh_),
        adjacency_(tear.adjacency_),
        options_(tear.options_),
        path_(tear.path_),
        tip_(tear.tip_),
        first_new_vertex_(tear.first_new_vertex_),
        tip_neighbor_(tear.tip_neighbor_),
        tip_target_(tear.tip_target_),
        tip_off_track_(tear.tip_off_track_),
        previous_(tear.previous_),
        steps_(tear.steps_),
        message_(tear.message_),
        tear_(tear) {}
  void commit(TopologyChange&& change, TearStep& step) { tear_.commit(std::move(change), step); }

  SkinnedMesh& mesh_;
  Adjacency& adjacency_;
  const TearOptions& options_;
  std::vector<Tear::PathVertex>& path_;
  std::int32_t& tip_;
  const std::int32_t& first_new_vertex_;
  std::int32_t& tip_neighbor_;
  Eigen::Vector3d& tip_target_;
  bool& tip_off_track_;
  ScalpelSample& previous_;
  int& steps_;
  std::string& message_;

 private:
  Tear& tear_;
};

namespace tearing {

// A point of the tear's path: a vertex, a point on an edge, or a point inside a face.
struct PathPoint {
  enum Kind { Vertex, Edge, Inside } kind = Vertex;
  std::int32_t v = -1;          // Vertex
  std::int32_t a = -1, b = -1;  // Edge: (1 − t) a + t b
  double t = 0;
  std::array<double, 3> bary{0, 0, 0};  // Inside: barycentric in the crossing's face
};

struct Crossing {
  std::int32_t face;
  PathPoint in, out;
};

// Segment p→q against triangle (a, b, c); on a hit, the barycentric coordinates of the hit.
inline bool segment_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                             const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                             const Eigen::Vector3d& c, std::array<double, 3>& bary) {
  double t = 0;
  return conform::mesh::segment_triangle(p, q, a, b, c, t, bary);
}

// Step 1 of a sample after the start: the plane Π through the tip and the blade, and the
// geometric queries the walk and the splits make against it and the blade.
class StepPlane {
 public:
  StepPlane(Tear& tear, const ScalpelSample& s, TearStep& step)
      : tear_(tear),
        mesh_(tear_.mesh_),
        adjacency_(tear_.adjacency_),
        s_(s),
        step_(step),
        snap_(tear_.options_.snap_fraction) {}

 protected:
  // Step 1: the plane Π through the tip and the blade, and the direction to walk in (toward
  // the blade's point nearest the tip).
  bool make_plane();
  double delta(std::int32_t v) const {
    const double d = plane_.signed_distance(mesh_.current.col(v));
    return std::abs(d) <= zero_ ? 0.0 : d;
  }
  Eigen::Vector3d pos(const PathPoint& p, std::int32_t face) const;
  // Where the blade crosses `face`, as barycentrics each at least `floor` (then normalized);
  // false when it does not cross it.
  bool blade_barycentrics(const Face& f, double floor, std::array<double, 3>& bary) const;
  // The blade crosses `face`: `out` is the hit, kept snap_fraction inside the face.
  bool blade_hit(std::int32_t face, PathPoint& out) const;
  // A crossing of edge (x, y) at t from x, off Π if need be, into the range where it makes no
  // sliver on either side.
  PathPoint edge_point(std::int32_t x, std::int32_t y, double t) const;
  // Where Π leaves face `face` through the edge opposite its corner `corner` (x = next,
  // y = after): a vertex, or a point on the edge; false when Π does not cross that edge.
  bool exit_opposite(std::int32_t face, int corner, PathPoint& out) const;
  std::int32_t corner_of(std::int32_t face, std::int32_t v) const {
    const Face& f = mesh_.faces[static_cast<std::size_t>(face)];
    return f[0] == v ? 0 : (f[1] == v ? 1 : 2);
  }
  // Corner k of `face` is on a border of the mesh (the tear's slit or a boundary): a face
  // around it has an edge without a twin.
  bool on_border(std::int32_t face, int k) const;
  static bool on_edge(const PathPoint& p, std::int32_t u, std::int32_t w) {
    return p.kind == PathPoint::Edge && ((p.a == u && p.b == w) || (p.b == u && p.a == w));
  }
  double mean_edge(std::int32_t face) const;
  // A face whose corners, split once more, keep the sliver floor (smallest angle ≥ 2 min_angle):
  // in a thinner face (a real model's) the halves would be split again below the bound of the
  // face they lie in.
  bool roomy(std::int32_t face) const {
    const Face& f = mesh_.faces[static_cast<std::size_t>(face)];
    return smallest_angle(mesh_.current.col(f[0]), mesh_.current.col(f[1]),
                          mesh_.current.col(f[2])) >= 2 * tear_.options_.min_angle;
  }
  // Where Π leaves the blade's face (crossing c) ahead of the hit (or behind it by at most
  // `slack`, m), on an edge other than the one it came in by: false if there is none, or if Π
  // leaves it through a vertex and `through_vertex` is false.
  bool exit_ahead(const Crossing& c, const Eigen::Vector3d& hit, PathPoint& out, double slack = 0,
                  bool through_vertex = false) const;

  TearState tear_;
  SkinnedMesh& mesh_;
  Adjacency& adjacency_;
  const ScalpelSample& s_;
  TearStep& step_;
  const double snap_;
  Eigen::Vector3d tip_, n_, toward_;
  cga::Plane<double> plane_;
  double zero_ = 0;                       // |distance to Π| taken as on it
  std::array<Eigen::Vector3d, 5> sweep_;  // the tip and both blades: their hull is the sweep
};

}  // namespace tearing
}  // namespace conform::mesh
