// Reference skinning for the mesh tests: linear-blend skinning written directly from the
// definition, x = Σ_k w_k · V_{b_k} x_rest V_{b_k}⁻¹, one versor per bone (independent of the
// library's SoA kernels, so a re-deformation test compares against something else).
#pragma once

#include <Eigen/Core>
#include <vector>

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

}  // namespace conform::test
