// The membrane drive: each substep (in the plugin's action, after Bullet's motion prediction
// and before its constraint solve), the skin membrane (core/membrane) takes one backward-Euler
// step of the free nodes toward the equilibrium of membrane, attachment to the skinned targets,
// inertia and damping, solved to a residual; the nodes then carry the result (position and
// velocity), so Bullet's contacts and collisions act on it as before.
//
// The membrane's elements are rebuilt from the skin's REST configuration (the bind pose) after a
// topology change (O(#F) once per change, paid at the next substep), never from the current shape.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "conform/membrane/model.hpp"
#include "conform/membrane/solver.hpp"
#include "conform/mesh/skinned_mesh.hpp"

class btSoftBody;

namespace conform::bullet {

class MembraneDrive {
 public:
  /// The mesh's faces or rest positions changed: the model is rebuilt at the next step.
  void invalidate() { stale_ = true; }
  /// The skeleton's bone axes (skin::bone_axes), which the along_bones and around_bones
  /// pre-stress fields follow through each vertex's weights.
  void set_bone_axes(std::vector<Eigen::Vector3d> axes) { bone_axes_ = std::move(axes); }
  /// One substep. `rest`: the skin's rest state per vertex (the bind pose, SkinDrive::bind_pose),
  /// read when the model is rebuilt. `nodes` per vertex (null for a vertex outside Bullet); `fixed`
  /// per vertex (kinematic or pinned: left where Bullet put them); masses, targets and previous
  /// targets per vertex.
  membrane::SolveReport step(const mesh::SkinnedMesh& mesh,
                             const Eigen::Ref<const Eigen::Matrix3Xd>& rest,
                             const membrane::SkinMaterial& material,
                             const membrane::SolverSettings& settings, std::span<void* const> nodes,
                             std::span<const std::uint8_t> fixed, std::span<const double> masses,
                             const Eigen::Ref<const Eigen::Matrix3Xd>& targets,
                             const Eigen::Ref<const Eigen::Matrix3Xd>& previous_targets, double dt);
  const membrane::Model& model() const { return model_; }
  const membrane::SolveReport& last_report() const { return report_; }

 private:
  void target_normals(const mesh::SkinnedMesh& mesh, const Eigen::Ref<const Eigen::Matrix3Xd>& t);

  membrane::Model model_;
  membrane::Solver solver_;
  membrane::SolveReport report_;
  bool stale_ = true;
  std::vector<Eigen::Vector3d> bone_axes_;
  Eigen::Matrix3Xd limb_axes_;  // per vertex, at the last rebuild
  Eigen::Matrix3Xd x_, start_, predicted_, carried_, velocity_, normals_;
  Eigen::Matrix3Xd solution_;  // the last solve's result, unrounded (empty after a change)
  // Its velocity (solution - start) / dt unrounded, and the one Bullet will leave in its nodes.
  Eigen::Matrix3Xd solution_velocity_, bullet_velocity_;
  std::vector<std::uint8_t> fixed_;
};

}  // namespace conform::bullet
