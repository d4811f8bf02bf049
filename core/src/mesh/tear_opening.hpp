// Step 3's second change for a tear's sample (tear_step.hpp): the path's interior points
// duplicated for the faces on its left, so that the tear opens there. Internal to core.
#pragma once

#include <vector>

#include "tear_tip_placement.hpp"

namespace conform::mesh::tearing {

class TearOpening : public TipPlacement {
 public:
  using TipPlacement::TipPlacement;

 protected:
  // Step 3, second change: duplicate the interior points for the faces on the path's left,
  // found by turning counter-clockwise around each from the outgoing path edge to the
  // incoming one (or to the open slit, at the old tip).
  void open_left_side();
  // The faces counter-clockwise around path point p from the outgoing edge (p, next) to the
  // incoming one from `prev` (or a boundary); false when there is no incoming edge around.
  bool left_faces(std::int32_t p, std::int32_t next, std::int32_t prev,
                  std::vector<std::int32_t>& faces) const;

  std::vector<std::int32_t> dups_;  // per point, its copy for the left, or −1
  std::vector<Eigen::Vector3d> left_dir_;
};

// One sample of Tear::advance after the start: steps 1–3 of tear.hpp, in order (tear.cpp).
class TearAdvance : public TearOpening {
 public:
  using TearOpening::TearOpening;
  void run();

 private:
  // Step 3, first change: split the crossed faces along S_i, Q_1 … Q_m, S_i+1. False (and
  // the mesh unchanged) when the new tip would be in a face too thin for it.
  bool split_along_path();
  // The path recorded: the old tip becomes interior, then the Q_j, then the new tip.
  void record();
};

}  // namespace conform::mesh::tearing
