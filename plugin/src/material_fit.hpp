// What does not fit between a body's Material and its mesh, said once when the body is made
// (SkinnedSoftBody::material_warnings): fields the chosen model ignores, set away from their
// defaults, and a skin whose attachment acts over less than an element.
#pragma once

#include <Eigen/Core>
#include <span>
#include <string>
#include <vector>

#include "conform/bullet/skinned_soft_body.hpp"

namespace conform::bullet {

/// `rest`: the skin's rest state (the bind pose), 3 x #V; `faces` the mesh's. Each warning names
/// the field and the figure.
std::vector<std::string> material_fit_warnings(const Material& material,
                                               const Eigen::Ref<const Eigen::Matrix3Xd>& rest,
                                               std::span<const mesh::Face> faces);

}  // namespace conform::bullet
