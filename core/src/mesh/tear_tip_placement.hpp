// Where a tear's new tip goes (tear_step.hpp). With TearOptions::smooth_lips the lips follow
// the blade's track: an ordered list of placements is tried, the first that keeps every face
// it makes at or above min_angle wins. Otherwise, and after all of them fail, the tip goes
// inside the blade's face, moved toward its incenter until its fan keeps the sliver bound.
// Internal to core.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "tear_face_split.hpp"

namespace conform::mesh::tearing {

// A point inside the polygon `poly` (a face with at most one edge point) for the fan of
// triangles (poly[i], poly[i + 1], tip): the barycentric `bary` in the face (a, b, c) moved
// toward the face's incenter, by the first of a few steps that gives every fan triangle its
// smallest angle's sin² ≥ `target` (default: the face's sliver bound), else the step with the
// best fan; `achieved` gets that fan's quality.
std::array<double, 3> place_tip(const std::array<double, 3>& bary, const Eigen::Vector3d& a,
                                const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                                const std::vector<Eigen::Vector3d>& poly, double floor,
                                double* achieved = nullptr, double target = -1);

class TipPlacement : public PathSplit {
 public:
  using PathSplit::PathSplit;

 protected:
  // The lips (TearOptions::smooth_lips): the first placement of kOnTrack that keeps the new tip
  // on the blade's track and every face it makes at or above min_angle. Else the tip is moved
  // off the track toward its face's middle (place_new_tip) and the next step's Π passes
  // through the hit.
  bool split_on_track();
  // The new tip in crossing c's face, moved so that its fan makes no sliver.
  bool place_new_tip(Crossing& c);

  // The lips' spacing (TearOptions::smooth_lips): a blade hit just past the last edge crossing
  // (within `behind` of the face's mean edge, kLipBehind) leaves the new tip on that crossing,
  // and the blade's face is split from its vertex opposite that edge. A tip inside the face
  // would make a pair of path points that close, and a fan of thin triangles on the face's far
  // vertex; the tip lags the blade by at most that much. With `ahead`, a hit too far from the
  // crossing (or one in a face beside the tip) puts the tip where Π leaves the blade's face
  // instead, and splits the face beyond. False (nothing kept) when neither applies or the
  // faces it makes would be thinner than min_angle. `past_fan` (split_with_tip_past_fan) lets
  // the blade's face be thinner than roomy() asks, but then every face made must be roomy.
  static constexpr double kLipBehind = 0.4;
  bool split_with_tip_on_edge(double behind, bool ahead = false, bool past_fan = false);

  // Where the blade is in a face the tear made (the old tip's fan) too thin for a tip inside
  // it, the tip goes on an edge of the track instead: where Π leaves that face ahead of
  // the hit (the face beyond split from its vertex opposite; within a snap behind the hit, or
  // on the vertex where Π leaves through one), or else on the edge crossing behind the hit. Each face it makes keeps twice min_angle, so that a later split keeps the
  // floor; nothing moves off the track and nothing is flipped, so the area is the faces' own.
  // False (nothing kept) when neither fits.
  bool split_with_tip_past_fan();

 private:
  // One placement of the tip on the blade's track: true when it made the split.
  struct Strategy {
    const char* name;
    bool (TipPlacement::*split)();
  };
  static const std::array<Strategy, 6> kOnTrack;  // in the order they are tried

  bool tip_at_hit() { return split_with_recovered_edges(); }
  bool tip_on_edge_of_hit() { return split_with_recovered_edges(true); }
  bool tip_on_crossing_behind() { return split_with_tip_on_edge(kLipBehind); }

  // The lips evenly spaced on the blade's track (TearOptions::smooth_lips): the new tip exactly
  // at the blade's hit, joined to the old tip (through the vertices the walk went through) by
  // edges that flips make (change_flips.hpp) instead of a chain of edge crossings, which would
  // be moved off the track where they come near a vertex, to keep the sliver floor. Then flips
  // for the smallest angle, the path's edges kept. False (nothing kept) where an edge cannot be
  // made or a face would be thinner than min_angle. `lambda` > 0 moves the tip that far toward
  // its face's incenter.
  bool split_with_recovered_edges(bool on_edge = false, double lambda = 0);
  // The recovered tip's least barycentric coordinate in its face.
  static constexpr double kExactMargin = 0.01;
  // The recovered tip moved toward its face's incenter by the first of a few steps that keeps
  // the floor: off the track by less than place_tip's tip (whose step is coarser and whose faces
  // are not flipped); the next step's Π goes through the hit.
  bool split_with_recovered_shifted() {
    for (const double lambda : {0.1, 0.2, 0.35, 0.5})
      if (split_with_recovered_edges(false, lambda)) return true;
    return false;
  }

  // A blade hit within kEdgeTip (barycentric) of an edge of its face, where a tip inside the
  // face would make a sliver that no flip removes (the edge on a fold of the surface): the tip on
  // that edge, at the hit's projection, both faces of the edge split from their third vertex.
  static constexpr double kEdgeTip = 0.05;
  bool insert_tip_on_edge(std::int32_t face, const std::array<double, 3>& bary);

  // A blade hit within kLipSnapReach of its face's mean edge from a corner of the face that
  // lies within kLipSnap of Π (on the blade's track) puts the tip on that corner, where a tip at
  // the hit would make a sliver with it: the face is split along the chord from the path's last
  // crossing to it.
  static constexpr double kLipSnap = 0.05, kLipSnapReach = 0.3;
  bool split_with_tip_on_corner();

  // Where the tip cannot be at the blade's hit (its faces would be slivers however flipped),
  // it goes on the nearer of the edge crossings behind and ahead of the hit, within kLipReach of
  // that edge: an edge crossing lies on Π, so on the track.
  static constexpr double kLipReach = 0.6;
  bool split_with_nearer_crossing();

  // The polygon around a new tip in crossing c's face: its corners, with the path's edge point.
  std::vector<Eigen::Vector3d> tip_ring(const Crossing& c) const;
};

}  // namespace conform::mesh::tearing
