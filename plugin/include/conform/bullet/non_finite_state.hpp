// What the plugin throws when a simulation goes non-finite. Every substep, before its drive, the
// plugin's action passes once over the nodes of every skinned body's pieces (released ones
// too) and stops the step at the first node whose position or velocity is NaN or infinite: an
// exploded run must not go on writing garbage (or summaries of it) as if it had succeeded.
// The pass sees what happened since the previous one: the previous substep's drive and
// Bullet's solve, and this substep's motion prediction (so the drive never reads a NaN). What
// the last substep of a stepSimulation leaves is seen at the start of the next one;
// SkinnedSoftBody::first_non_finite_node() asks at any time. The same pass stops a runaway: a
// node moving faster than the body's Material::max_speed past its skinned target (its own
// velocity less the target's over the last substep; a released piece's whole velocity): finite
// but unphysical. A skin the animation itself sweeps fast is not a runaway.
// The exception leaves stepSimulation mid-step; the world's state is then only fit for
// inspection and teardown.
#pragma once

#include "conform/bullet/precision.hpp"  // the package's Bullet precision, checked

#include <Eigen/Core>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace conform::bullet {

/// The first bad node of a skinned body (SkinnedSoftBody::first_non_finite_node).
struct NonFiniteNode {
  std::int32_t piece = -1;   // the piece's slot (PieceId::index)
  int node = -1;             // the node's index in the piece's btSoftBody
  std::int32_t vertex = -1;  // the mesh vertex it mirrors
  bool position = true;      // position (m_x) non-finite, else velocity (m_v)
  bool runaway = false;      // finite, but faster than Material::max_speed past its target
  Eigen::Vector3d value = Eigen::Vector3d::Zero();
};

class NonFiniteState : public std::runtime_error {
 public:
  /// `substep`: the plugin's substep count (Plugin::substeps()) at the failure, `time` its
  /// simulated time, `body` the skinned body's index in the order the plugin added them.
  NonFiniteState(long long substep, double time, std::size_t body, const NonFiniteNode& node);
  long long substep() const { return substep_; }
  double time() const { return time_; }
  std::size_t body() const { return body_; }
  const NonFiniteNode& node() const { return node_; }

 private:
  long long substep_;
  double time_;
  std::size_t body_;
  NonFiniteNode node_;
};

}  // namespace conform::bullet
