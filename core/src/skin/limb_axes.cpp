#include "conform/skin/limb_axes.hpp"

#include <stdexcept>
#include <string>

namespace conform::skin {
namespace {

// The bone whose joint is the nearest strict ancestor of bone b's joint that drives a bone, or -1.
std::int32_t parent_bone(const Skeleton& skeleton, const std::vector<std::int32_t>& bone_of_joint,
                         std::int32_t b) {
  std::int32_t j = skeleton.joints[std::size_t(skeleton.bones[std::size_t(b)].joint)].parent;
  while (j >= 0 && bone_of_joint[std::size_t(j)] < 0) j = skeleton.joints[std::size_t(j)].parent;
  return j < 0 ? -1 : bone_of_joint[std::size_t(j)];
}

}  // namespace

std::vector<Eigen::Vector3d> bone_axes(const Skeleton& skeleton) {
  const std::size_t nb = skeleton.bones.size();
  std::vector<Eigen::Vector3d> position(nb);
  std::vector<std::int32_t> bone_of_joint(skeleton.joints.size(), -1);
  for (std::size_t b = 0; b < nb; ++b) {
    const std::optional<Versor> inverse = skeleton.bones[b].offset.inverse();
    if (!inverse)
      throw std::invalid_argument("bone_axes: bone '" + skeleton.bones[b].name +
                                  "' has a bind versor that is not invertible");
    position[b] = inverse->apply(Eigen::Vector3d::Zero());
    bone_of_joint[std::size_t(skeleton.bones[b].joint)] = std::int32_t(b);
  }
  std::vector<Eigen::Vector3d> to_children(nb, Eigen::Vector3d::Zero()), axes(nb);
  std::vector<std::int32_t> parent(nb);
  for (std::size_t b = 0; b < nb; ++b) {
    parent[b] = parent_bone(skeleton, bone_of_joint, std::int32_t(b));
    if (parent[b] < 0) continue;
    const Eigen::Vector3d d = position[b] - position[std::size_t(parent[b])];
    if (d.norm() > 0) to_children[std::size_t(parent[b])] += d.normalized();
  }
  for (std::size_t b = 0; b < nb; ++b) {
    Eigen::Vector3d d = to_children[b];
    if (!(d.norm() > 0) && parent[b] >= 0) d = position[b] - position[std::size_t(parent[b])];
    axes[b] = d.norm() > 0 ? Eigen::Vector3d(d.normalized()) : Eigen::Vector3d::Zero();
  }
  return axes;
}

Eigen::Matrix3Xd vertex_limb_axes(const mesh::SkinnedMesh& mesh,
                                  std::span<const Eigen::Vector3d> axes) {
  Eigen::Matrix3Xd out = Eigen::Matrix3Xd::Zero(3, mesh.vertex_count());
  for (std::int32_t v = 0; v < mesh.vertex_count(); ++v)
    for (int k = 0; k < mesh::kMaxInfluences; ++k) {
      const double w = mesh.weights(k, v);
      if (w == 0) continue;
      const std::int32_t b = mesh.bones(k, v);
      if (b < 0 || std::size_t(b) >= axes.size())
        throw std::invalid_argument("vertex_limb_axes: vertex " + std::to_string(v) +
                                    " names bone " + std::to_string(b) + " of " +
                                    std::to_string(axes.size()));
      out.col(v) += w * axes[std::size_t(b)];
    }
  return out;
}

}  // namespace conform::skin
