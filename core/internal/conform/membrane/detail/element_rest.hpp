// A membrane element's constant data (the rest triangle's shape-function gradients, its
// pre-stress and its law), apart from the kernels that use it (cst_kernel.hpp), so that what
// only stores elements (model.hpp) does not compile the kernels.
#pragma once

#include <Eigen/Core>

#include "conform/membrane/skin_material.hpp"

namespace conform::membrane::detail {

using Mat32 = Eigen::Matrix<double, 3, 2>;

/// Constant per-element data, from the rest configuration and the material.
struct ElementRest {
  Eigen::Matrix2d beta;   // columns beta_1, beta_2 (beta_0 = -beta_1 - beta_2), 1/m
  Eigen::Matrix2d s0;     // pre-stress in the element's frame, Pa (the bind state's stress)
  double area_thickness;  // A t, m^3
  // The neo-Hookean law's pre-stretch G in the element's frame (symmetric, principal stretches
  // along the pre-stress axes); the identity, and unused, for stvk.
  Eigen::Matrix2d g = Eigen::Matrix2d::Identity();
  SkinMaterial::Law law = SkinMaterial::Law::stvk;
  // The fibre-reinforced law's fibres q = G a in the element's frame (a the unit pre-stress
  // axis), and its k1 (Pa) and k2; q = 0 (no fibres) for the other laws.
  Eigen::Vector2d fibre = Eigen::Vector2d::Zero();
  double fibre_k1 = 0, fibre_k2 = 1;
};

}  // namespace conform::membrane::detail
