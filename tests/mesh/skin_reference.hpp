// Reference skinning for the mesh tests: linear-blend skinning written directly from the
// definition, x = Σ_k w_k · V_{b_k} x_rest V_{b_k}⁻¹, one versor per bone (independent of the
// library's SoA kernels, so a re-deformation test compares against something else).
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "conform/cga/motor.hpp"
#include "conform/cga/versor.hpp"
#include "conform/mesh/skinned_mesh.hpp"

namespace conform::test {

inline Eigen::Matrix3Xd reference_lbs(const mesh::SkinnedMesh& m,
                                      const std::vector<cga::Versor<double>>& pose) {
  Eigen::Matrix3Xd out(3, m.rest.cols());
  for (Eigen::Index v = 0; v < m.rest.cols(); ++v) {
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (int k = 0; k < mesh::kMaxInfluences; ++k)
      if (m.weights(k, v) != 0)
        x += m.weights(k, v) * pose[static_cast<std::size_t>(m.bones(k, v))].apply(m.rest.col(v));
    out.col(v) = x;
  }
  return out;
}

/// Two poses of the procedural arm's three bones for the re-deformation tests: the first to
/// pose the arm before a change, the second to re-skin after it (rotations about several axes,
/// a translation, and dilations 1.1 and 0.8, so that every part of the versor counts).
inline std::array<std::vector<cga::Versor<double>>, 2> arm_test_poses() {
  using V = cga::Versor<double>;
  using M = cga::Motor<double>;
  return {{{V::identity(), V::from_motor(M::from_axis_angle({1, 0, 0}, 0.4)),
            V{M::from_axis_angle({0, 1, 0}, 0.3), 1.1}},
           {V::from_motor(M::from_translation({0.1, 0, 0})),
            V::from_motor(M::from_axis_angle({1, 1, 0}, -0.7)),
            V{M::from_axis_angle({0, 0, 1}, 0.5), 0.8}}}};
}

}  // namespace conform::test
