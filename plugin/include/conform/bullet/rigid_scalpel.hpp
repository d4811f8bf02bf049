// A scalpel held by a Bullet rigid body: its blade (a segment fixed in the body's local
// frame) becomes tear samples of one SkinnedSoftBody, with the spacing handled here. update(),
// called between steps, sub-samples the blade's motion since the previous call so that every
// face it sweeps is reached, and submits a sample only once the blade has left the tip's fan of
// thin faces (where the tear would refuse it): the same tear with far fewer samples and path
// points. Lifetime: the skinned body and the rigid body must outlive the scalpel; it begins its
// own tear at the first update. Threading: as every edit. A usage example, update()'s rules
// and why the spacing matters: docs/notes/plugin.md, "Using the rigid scalpel
// (rigid_scalpel.hpp)".
#pragma once

#include <LinearMath/btVector3.h>

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "conform/bullet/skinned_soft_body.hpp"
#include "conform/mesh/tear.hpp"

class btRigidBody;

namespace conform::bullet {

class RigidScalpel {
 public:
  struct Options {
    double min_advance = 0.5;     // × h: how far the blade must be from the tip to submit, > 0
    double max_advance = 1.0;     // × h: the longest blade move of one sample, ≥ min_advance
    mesh::TearOptions tear = {};  // for the tear this scalpel begins
  };

  /// Throws std::invalid_argument on a degenerate blade (a == b, non-finite) or options out
  /// of range, naming the value.
  RigidScalpel(SkinnedSoftBody& body, const btRigidBody& blade, const btVector3& a_local,
               const btVector3& b_local, const Options& options);
  RigidScalpel(SkinnedSoftBody& body, const btRigidBody& blade, const btVector3& a_local,
               const btVector3& b_local);

  struct Update {
    int samples = 0;   // submitted to tear_advance
    int extended = 0;  // of which extended the tear
    int held = 0;      // sub-samples held back (the blade too close to the tip)
  };
  /// Reads the blade's world transform and tears along its motion since the previous call.
  /// `time` stamps the samples (e.g. Plugin::time()); sub-samples are interpolated in time.
  /// Between stepSimulation calls only.
  Update update(double time);

  /// Totals over every update.
  const Update& totals() const { return totals_; }
  /// The blade's world end points at the last update.
  const Eigen::Vector3d& a() const { return a_; }
  const Eigen::Vector3d& b() const { return b_; }
  /// h: the mean edge length at the tip (of the mesh before the tear starts), m.
  double edge_length() const { return edge_length_; }

 private:
  void submit(const mesh::ScalpelSample& sample, Update& update);
  bool ready(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const;
  void measure_edges();

  SkinnedSoftBody& body_;
  const btRigidBody& blade_;
  Eigen::Vector3d a_local_, b_local_;
  Options options_;
  bool first_ = true;
  Eigen::Vector3d a_ = Eigen::Vector3d::Zero(), b_ = Eigen::Vector3d::Zero();
  double time_ = 0;
  double edge_length_ = 0;
  std::int32_t tip_ = -1;
  std::vector<mesh::Face> fan_;  // the faces around the tip
  Update totals_;
};

}  // namespace conform::bullet
