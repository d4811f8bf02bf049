// The skin membrane's in-plane principal Cauchy stresses at a body's simulated positions, per
// vertex, for the ParaView series (vertex_fields.hpp).
//
// Each face is the membrane's own element (membrane::Model, built from the rest mesh and the
// material as the plugin builds it, with the limbs' axes when the pre-stress follows the bones),
// evaluated by the membrane's kernel (detail/cst_kernel.hpp, relaxed where wrinkled): the Cauchy
// stress F S F^T of an incompressible sheet (the membrane's tests' definition), restricted to the
// deformed face's plane, and its two eigenvalues. A vertex takes the rest-area-weighted mean of
// its faces' (sigma_1, sigma_2).
#pragma once

#include <Eigen/Core>

#include "conform/membrane/skin_material.hpp"
#include "conform/mesh/skinned_mesh.hpp"
#include "conform/skin/skeleton.hpp"

namespace conform::scenes {

/// 2 x #V: (sigma_1, sigma_2), sigma_1 >= sigma_2, Pa, at mesh.current (0 for a vertex on no
/// face that carries material).
Eigen::Matrix2Xd vertex_principal_stresses(const mesh::SkinnedMesh& mesh,
                                           const membrane::SkinMaterial& material,
                                           const skin::Skeleton& skeleton);

/// The principal Cauchy stresses (sigma_1 >= sigma_2, Pa) of a face whose deformation gradient
/// is `f` (3 x 2, rest frame to space) and whose second Piola-Kirchhoff stress is `pk2`.
Eigen::Vector2d principal_cauchy_stresses(const Eigen::Matrix<double, 3, 2>& f,
                                          const Eigen::Matrix2d& pk2);

}  // namespace conform::scenes
