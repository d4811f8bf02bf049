// A scalpel held by a Bullet rigid body: its blade (a segment fixed in the body's local
// frame) becomes tear samples of one SkinnedSoftBody, with the spacing handled here.
//
//   btRigidBody blade_body(...);                       // kinematic or dynamic, in the world
//   conform::bullet::RigidScalpel scalpel(skin, blade_body, {0, 0, 0.02}, {0, 0, -0.02});
//   for (;;) {
//     world.stepSimulation(1.0 / 60);
//     scalpel.update(plugin.time());                   // between steps, like every edit
//   }
//
// Why the spacing matters. Every tear sample puts the tear's tip where the blade crosses the
// surface (tear.hpp). A sample whose blade is still in the old tip's fan of thin faces is
// refused (the tip would halve a thin corner) and waits for the blade to move on, so a blade
// that moves a small fraction of the local edge per frame extends the tear only in some
// samples and, when it does, by a step much shorter than the faces it cuts; one that jumps
// several edges per frame leaves the faces in between to one long step (bounded by the
// region the blade swept). Spacing the samples as below gives the same tear with far fewer
// samples and path points (figures: docs/notes/plugin.md).
//
// What update() does with the blade's motion since the previous call (taken as linear: the
// end points move on straight lines):
//   - sub-samples it so that no sample moves the blade more than max_advance × h from the
//     previous sample, h being the mean length of the edges at the tear's tip (before the
//     tear starts, of the mesh), so every face the blade sweeps is reached;
//   - submits a sample only once the blade is at least min_advance × h from the tip and no
//     longer crosses a face around the tip (accumulating the motion until then), so the new
//     tip lands outside the old tip's fan of thin faces. The tip thus lags the blade by at
//     most about one face; a blade that stops inside the tip's faces leaves the tear there.
// Until the tear has started, every sub-sample is submitted (the first that meets the
// surface starts it). The blade's end points are in the rigid body's local frame; samples
// are in world space (as SkinnedSoftBody's tear_advance takes them).
//
// Lifetime: the scalpel refers to the skinned body and the rigid body, which must outlive
// it; it begins its own tear (begin_tear) at the first update. Threading: as every edit.
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
