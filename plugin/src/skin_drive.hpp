// The skin drive's source side: the pose source gives a skeleton pose at the plugin's time, and
// CGA skinning (eq 17) of the rest points by core's skin::Skinner gives every vertex its target;
// the previous substep's targets are kept for target velocities. The Skinner reads the mesh's
// own influences as stored (Influences::from_mesh: no renormalization), so the targets are
// those of the mesh's weights bit for bit. No Bullet here: Impl::update (skin_drive.cpp), the
// one per-substep entry point, drives the nodes toward these targets.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "conform/mesh/skinned_mesh.hpp"
#include "conform/skin/animation.hpp"
#include "conform/skin/pose.hpp"
#include "conform/skin/skeleton.hpp"
#include "conform/skin/skinner.hpp"

namespace conform::bullet {

class SkinDrive {
 public:
  /// `skeleton` must outlive the drive.
  explicit SkinDrive(const skin::Skeleton& skeleton) : skeleton_(&skeleton) {}

  // Pose sources (the last one set wins). Time is the plugin's simulated time, s.
  void set_pose(const skin::Pose& pose);
  void play(const skin::Animation& animation, skin::Blend blend, bool loop);
  void set_keyframes(skin::PoseTrack track, skin::Blend blend);
  void set_pose_source(std::function<void(double time, skin::Pose& pose)> source);
  void set_threads(int threads);

  /// The rest pose, the mesh's skinning inputs and its targets at time 0 (previous = target).
  void start(const mesh::SkinnedMesh& mesh);
  /// Skins the rest points at `time` into the targets (re-reading the mesh's rest points and
  /// influences once vertices were added).
  void skin(const mesh::SkinnedMesh& mesh, double time);
  /// A substep's start: the targets become the previous ones, then skin(time); a vertex added
  /// since gets its target as its previous one (zero target velocity).
  void advance(const mesh::SkinnedMesh& mesh, double time);
  /// After an edit added vertices: their targets now (the last pose, the source not asked
  /// again), their previous targets equal to them, so that target(v) is valid at once.
  void extend(const mesh::SkinnedMesh& mesh);
  /// The bind pose: the rest points skinned at the skeleton's rest pose, model space (no world
  /// transform), 3 x #V. An imported mesh's rest points are in its mesh space, which need not
  /// be the bind pose's (huesitos.fbx: 100 times smaller); the skin's rest state is the bind
  /// pose. Empty where the two agree to 1e-9 of the mesh's size: the rest points are it.
  Eigen::Matrix3Xd bind_pose(const mesh::SkinnedMesh& mesh) const;
  /// The targets at `time` become the previous ones too (zero target velocity).
  void settle(const mesh::SkinnedMesh& mesh, double time) {
    skin(mesh, time);
    previous_ = target_;
  }

  const skin::SoaPoints<double>& targets() const { return target_; }
  /// Where the skinned (model-space) targets are placed in the world.
  void set_transform(const Eigen::Isometry3d& transform) { transform_ = transform; }
  const Eigen::Isometry3d& transform() const { return transform_; }
  /// The pose of the last skinning (the rest pose before the first).
  const skin::Pose& pose() const { return pose_; }
  const skin::SoaPoints<double>& previous_targets() const { return previous_; }
  Eigen::Vector3d target(std::int32_t v) const {
    const auto i = static_cast<std::size_t>(v);
    return {target_.x.at(i), target_.y.at(i), target_.z.at(i)};
  }
  Eigen::Vector3d previous_target(std::size_t v) const {
    return {previous_.x[v], previous_.y[v], previous_.z[v]};
  }

 private:
  void rebuild_inputs(const mesh::SkinnedMesh& mesh);

  const skin::Skeleton* skeleton_;
  std::function<void(double, skin::Pose&)> source_;
  skin::Pose pose_;
  std::optional<skin::Skinner<double>> skinner_;  // made by start(), on the validated mesh
  // The skinned targets, SoA (see skinning.hpp): the Skinner writes into target_, and a
  // substep's start swaps the two buffers.
  skin::SoaPoints<double> target_, previous_;
  bool fill_previous_ = false;  // vertices were added: their previous targets are NaN
  Eigen::Isometry3d transform_ = Eigen::Isometry3d::Identity();
  void place();  // transform_ applied to the targets just skinned
  int threads_ = 1;
};

}  // namespace conform::bullet
