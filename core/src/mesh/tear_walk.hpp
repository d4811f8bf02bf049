// Step 2 of a tear's sample (tear_step.hpp): the walk from the tip along Π ∩ M to the face the
// blade crosses, bounded by the region the blade swept. Internal to core.
#pragma once

#include <vector>

#include "tear_step.hpp"

namespace conform::mesh::tearing {

class TearWalk : public StepPlane {
 public:
  using StepPlane::StepPlane;

 protected:
  // Candidate first moves from a vertex: (face, exit, cosine).
  struct Move {
    std::int32_t face;
    PathPoint out;
    double cosine;
  };
  enum class WalkStep { Moved, Reached, Failed };

  // The walk's latest point lies within sweep_tolerance (in edge lengths of its face) of the
  // region the blade swept; else the first distance beyond it is kept for the message.
  bool within_sweep(const Crossing& c);
  // The moves out of vertex v across the faces around it (found from any neighbour), best
  // aligned with `dir` first; `fan_faces` gets those faces.
  std::vector<Move> moves_from(std::int32_t v, std::int32_t any_neighbor,
                               const Eigen::Vector3d& dir,
                               std::vector<std::int32_t>& fan_faces) const;
  // Step 2: walk from the tip along Π ∩ M; the first candidate direction that reaches the
  // blade gives the path.
  bool walk();
  // The blade meets a face around the tip: the path is that one face, unless the blade is
  // where it was (true: nothing to tear yet).
  bool blade_next_to_tip(const std::vector<std::int32_t>& fan_faces);
  // A tip put ahead of the blade's hit (on the edge crossing past it, TearOptions::smooth_lips)
  // and a blade still behind it: a walk toward the blade would turn the path back on itself.
  bool blade_behind_a_leading_tip() const {
    const auto& path = tear_.path_;
    if (!tear_.options_.smooth_lips || path.size() < 2) return false;
    const Eigen::Vector3d along = tip_ - mesh_.current.col(path[path.size() - 2].right);
    return (tear_.tip_target_ - tip_).dot(along) < 0 && toward_.dot(along) < 0;
  }
  // The walk that leaves the tip by move m; on reaching the blade it becomes the path.
  void walk_from(const Move& m);
  // With smooth_lips, a walk that reaches a vertex on a border (the tear's own lips, where a
  // stroke turns about) stops there like one that meets a boundary: a path through it would
  // pinch the border (two fans of faces on one vertex).
  bool at_border_vertex(const Crossing& c) const {
    return tear_.options_.smooth_lips && c.out.kind == PathPoint::Vertex &&
           on_border(c.face, corner_of(c.face, c.out.v));
  }
  // The walk is on an edge: into the face across it, which the blade crosses (reached) or
  // which Π leaves through an edge at its third vertex z (not back through the edge).
  WalkStep cross_edge(std::vector<Crossing>& trial, std::vector<std::int32_t>& visited) const;
  // The walk is at a vertex: the blade may be in a face around it, else it continues
  // straight on through the best aligned face not yet visited.
  WalkStep pass_vertex(std::vector<Crossing>& trial, std::vector<std::int32_t>& visited) const;

  std::vector<Crossing> path_;  // the walk that reached the blade
  double beyond_ = -1;          // how far a walk left the sweep (−1: none did)
};

}  // namespace conform::mesh::tearing
