// The limbs' axes in the bind pose, from the skeleton: what a direction field that runs along or
// around each limb (membrane::SkinMaterial::prestress_field) is derived from.
//
// A bone's axis is the unit direction from its joint's bind position to its child bones'
// joints (the mean of their unit directions), or, for a bone without children, from its parent
// bone's joint to its own; a bone alone has none (zero). Bind positions are B_n^-1 (0), the
// origin of each bone's joint space mapped back to mesh space. A vertex's axis is the
// weight-blended sum of its influences' axes: along a chain the bones point the same way
// (proximal to distal), so the blend turns smoothly through a joint. New vertices of an edit
// carry interpolated weights, so their axes follow from the same rule.
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "conform/mesh/skinned_mesh.hpp"
#include "conform/skin/skeleton.hpp"

namespace conform::skin {

/// One unit (or zero) axis per bone of the skeleton, in mesh space. Throws
/// std::invalid_argument when a bone's bind versor is not invertible.
std::vector<Eigen::Vector3d> bone_axes(const Skeleton& skeleton);

/// The weight-blended axis of every vertex (3 x #V, not normalised; zero where the influences'
/// axes are). Throws std::invalid_argument when a vertex names a bone outside `axes`.
Eigen::Matrix3Xd vertex_limb_axes(const mesh::SkinnedMesh& mesh,
                                  std::span<const Eigen::Vector3d> axes);

}  // namespace conform::skin
