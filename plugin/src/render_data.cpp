// What an application reads to display a skinned body: current normals, the pose and joint
// transforms, and the debug drawing of what Bullet does not draw itself (the skeleton, the
// pull of every driven node toward its skinned target, the tear's path and its blade).
#include <LinearMath/btIDebugDraw.h>

#include <vector>

#include "skinned_soft_body_impl.hpp"

namespace conform::bullet {

Eigen::Matrix3Xd SkinnedSoftBody::Impl::normals() const {
  const std::int32_t n = vertex_count();
  Eigen::Matrix3Xd x(3, n), out = Eigen::Matrix3Xd::Zero(3, n);
  for (std::int32_t v = 0; v < n; ++v) x.col(v) = position(v);
  for (const auto& f : mesh_.faces) {
    // The cross product's length is twice the area: an area-weighted sum.
    const Eigen::Vector3d c = (x.col(f[1]) - x.col(f[0])).cross(x.col(f[2]) - x.col(f[0]));
    for (const auto v : f) out.col(v) += c;
  }
  for (std::int32_t v = 0; v < n; ++v) {
    const double length = out.col(v).norm();
    if (length > 0) out.col(v) /= length;
  }
  return out;
}

std::vector<skin::Versor> SkinnedSoftBody::Impl::joint_transforms() const {
  std::vector<skin::Versor> global(skeleton_.joints.size());
  skin::global_versors(skeleton_, drive_.pose(), global);
  return global;
}

void SkinnedSoftBody::Impl::debug_draw(btIDebugDraw& drawer) const {
  const std::vector<skin::Versor> global = joint_transforms();
  const btVector3 yellow(1, 1, 0), cyan(0, 1, 1);
  const auto origin = [](const skin::Versor& m) {
    return to_bt(Eigen::Vector3d(m.apply(cga::Vec3<double>::Zero())));
  };
  for (std::size_t j = 0; j < skeleton_.joints.size(); ++j) {
    const std::int32_t parent = skeleton_.joints[j].parent;
    if (parent >= 0)
      drawer.drawLine(origin(global[static_cast<std::size_t>(parent)]), origin(global[j]), yellow);
  }
  if (tear_ && tear_->started()) {
    // Both borders of the tear (they share its start and tip), at the simulated positions.
    const btVector3 orange(1, 0.5, 0);
    for (const auto& border : {tear_->left_border(), tear_->right_border()})
      for (std::size_t i = 1; i < border.size(); ++i)
        drawer.drawLine(to_bt(position(border[i - 1])), to_bt(position(border[i])), orange);
  }
  if (blade_) drawer.drawLine(to_bt(blade_->a), to_bt(blade_->b), btVector3(1, 0, 1));
  for (const auto& piece : pieces_) {
    if (!piece || !piece->body || piece->released) continue;
    const btSoftBody& body = *piece->body;
    for (int i = 0; i < body.m_nodes.size(); ++i) {
      const std::int32_t v = piece->node_vertex[static_cast<std::size_t>(i)];
      drawer.drawLine(body.m_nodes[i].m_x, to_bt(drive_.target(v)), cyan);
    }
  }
}

}  // namespace conform::bullet
