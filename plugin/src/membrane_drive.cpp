#include "membrane_drive.hpp"

#include <BulletSoftBody/btSoftBody.h>

#include "conform/bullet/convert.hpp"
#include "conform/skin/limb_axes.hpp"

namespace conform::bullet {

void MembraneDrive::target_normals(const mesh::SkinnedMesh& mesh,
                                   const Eigen::Ref<const Eigen::Matrix3Xd>& t) {
  normals_.setZero(3, t.cols());
  for (const mesh::Face& f : mesh.faces) {
    const Eigen::Vector3d n = (t.col(f[1]) - t.col(f[0])).cross(t.col(f[2]) - t.col(f[0]));
    for (const std::int32_t v : f) normals_.col(v) += n;  // area-weighted
  }
  for (Eigen::Index v = 0; v < normals_.cols(); ++v) {
    const double length = normals_.col(v).norm();
    if (length > 0) normals_.col(v) /= length;
  }
}

membrane::SolveReport MembraneDrive::step(
    const mesh::SkinnedMesh& mesh, const Eigen::Ref<const Eigen::Matrix3Xd>& rest,
    const membrane::SkinMaterial& material, const membrane::SolverSettings& settings,
    std::span<void* const> nodes, std::span<const std::uint8_t> fixed,
    std::span<const double> masses, const Eigen::Ref<const Eigen::Matrix3Xd>& targets,
    const Eigen::Ref<const Eigen::Matrix3Xd>& previous_targets, double dt) {
  const Eigen::Index nv = mesh.vertex_count();
  // The last solution in double precision carries over while the mesh is unchanged. Bullet
  // keeps btScalar positions, and in single precision their rounding alone (~1e-7 of the arm's
  // size) leaves a residual of 10-40 Pa, above the tolerance: a body at rest would be solved
  // again every substep. A node that Bullet left where it was written continues from the
  // unrounded value (its prediction shifted by the same amount); one that Bullet moved (a
  // contact) continues from Bullet's position.
  const bool carry = !stale_ && solution_.cols() == nv;
  if (stale_ || model_.vertex_count() != nv) {
    const bool by_bones = material.prestress_field != membrane::SkinMaterial::DirectionField::axis;
    if (by_bones) limb_axes_ = skin::vertex_limb_axes(mesh, bone_axes_);
    model_.build(rest, mesh.faces, material, by_bones ? &limb_axes_ : nullptr);
    stale_ = false;
  }
  x_.resize(3, nv);
  start_.resize(3, nv);
  predicted_.resize(3, nv);
  carried_.resize(3, nv);
  velocity_ = (targets - previous_targets) / dt;
  fixed_.assign(fixed.begin(), fixed.end());
  for (Eigen::Index v = 0; v < nv; ++v) {
    const auto* node = static_cast<const btSoftBody::Node*>(nodes[std::size_t(v)]);
    if (!node) {  // outside Bullet: rides its target
      x_.col(v) = start_.col(v) = predicted_.col(v) = carried_.col(v) = targets.col(v);
      fixed_[std::size_t(v)] = 1;
      continue;
    }
    predicted_.col(v) = from_bt(node->m_x);
    start_.col(v) = from_bt(node->m_q);
    if (carry && node->m_q == to_bt(solution_.col(v))) {
      // Bullet's prediction in float loses dt^2 g below a position's rounding (a 13 us step
      // at 5 cm); rebuild it in double: the last step's velocity, plus what Bullet's
      // prediction added to the velocity it left (gravity and forces, dt each).
      const Eigen::Vector3d kick = from_bt(node->m_v) - bullet_velocity_.col(v);
      predicted_.col(v) = solution_.col(v) + dt * (solution_velocity_.col(v) + kick);
      start_.col(v) = solution_.col(v);
    }
    // Initial guesses: Bullet's prediction (momentum and gravity), and the last solution
    // carried along by its target, which for a body at rest against gravity is the solution
    // already (the prediction is dt^2 g off there); the solver starts from the better one.
    x_.col(v) = predicted_.col(v);
    carried_.col(v) = fixed_[std::size_t(v)]
                          ? Eigen::Vector3d(predicted_.col(v))
                          : Eigen::Vector3d(start_.col(v) + dt * velocity_.col(v));
  }
  target_normals(mesh, targets);
  const membrane::StepInput input{targets, normals_,   start_, velocity_, fixed_,
                                  dt,      predicted_, masses, carried_};
  report_ = solver_.solve(model_, input, settings, x_);
  solution_ = x_;
  solution_velocity_ = (x_ - start_) / dt;
  bullet_velocity_.setZero(3, nv);
  for (Eigen::Index v = 0; v < nv; ++v) {
    if (fixed_[std::size_t(v)]) continue;
    auto* node = static_cast<btSoftBody::Node*>(nodes[std::size_t(v)]);
    node->m_x = to_bt(x_.col(v));
    node->m_v = (node->m_x - node->m_q) / btScalar(dt);
    // The velocity Bullet's constraint solve will leave (kDP = 0), as it computes it.
    bullet_velocity_.col(v) = from_bt((node->m_x - node->m_q) * (btScalar(1) / btScalar(dt)));
  }
  return report_;
}

}  // namespace conform::bullet
