#include "kinds/membrane_stress.hpp"

#include <Eigen/Geometry>
#include <cmath>

#include "conform/membrane/detail/cst_kernel.hpp"
#include "conform/membrane/model.hpp"
#include "conform/skin/limb_axes.hpp"

namespace conform::scenes {

Eigen::Vector2d principal_cauchy_stresses(const Eigen::Matrix<double, 3, 2>& f,
                                          const Eigen::Matrix2d& pk2) {
  const Eigen::Matrix3d cauchy = f * pk2 * f.transpose();
  // An orthonormal basis (e1, e2) of the deformed face's plane, which F's columns span
  // (Gram-Schmidt from the longer one): the stress has no component along the normal, whose
  // eigenvalue 0 is not a principal stress of the sheet. A collapsed F spans less; any unit
  // vectors complete it, as its stress is 0 along them.
  const bool first_longer = f.col(0).squaredNorm() >= f.col(1).squaredNorm();
  const Eigen::Vector3d a = first_longer ? f.col(0) : f.col(1);
  const Eigen::Vector3d b = first_longer ? f.col(1) : f.col(0);
  const Eigen::Vector3d e1 =
      a.norm() > 0 ? Eigen::Vector3d(a.normalized()) : Eigen::Vector3d::UnitX();
  Eigen::Vector3d e2 = b - e1.dot(b) * e1;
  e2 = e2.norm() > 1e-12 * a.norm() ? Eigen::Vector3d(e2.normalized()) : e1.unitOrthogonal();
  // The eigenvalues of the symmetric [[p, q], [q, r]]: (p + r)/2 +- hypot((p - r)/2, q).
  const double p = e1.dot(cauchy * e1), q = e1.dot(cauchy * e2), r = e2.dot(cauchy * e2);
  const double mean = (p + r) / 2, radius = std::hypot((p - r) / 2, q);
  return {mean + radius, mean - radius};
}

Eigen::Matrix2Xd vertex_principal_stresses(const mesh::SkinnedMesh& mesh,
                                           const membrane::SkinMaterial& material,
                                           const skin::Skeleton& skeleton) {
  // The model the plugin solves (membrane_drive.cpp builds it the same way).
  membrane::Model model;
  Eigen::Matrix3Xd limb_axes;
  const bool by_bones = material.prestress_field != membrane::SkinMaterial::DirectionField::axis;
  if (by_bones) limb_axes = skin::vertex_limb_axes(mesh, skin::bone_axes(skeleton));
  model.build(mesh.rest, mesh.faces, material, by_bones ? &limb_axes : nullptr);
  const auto& x = mesh.current;
  Eigen::Matrix2Xd sum = Eigen::Matrix2Xd::Zero(2, mesh.vertex_count());
  Eigen::VectorXd weight = Eigen::VectorXd::Zero(mesh.vertex_count());
  for (std::size_t e = 0; e < model.elements().size(); ++e) {
    const auto& element = model.elements()[e];
    const mesh::Face& face = model.element_faces()[e];
    const membrane::detail::ElementState s =
        membrane::detail::element_forces(element, x.col(face[0]), x.col(face[1]), x.col(face[2]),
                                         model.lambda(), model.mu(), model.wrinkling());
    const Eigen::Vector2d sigma = principal_cauchy_stresses(s.f, s.stress);
    if (!sigma.allFinite()) continue;  // a collapsed face says nothing about its vertices
    for (const std::int32_t v : face) {
      sum.col(v) += element.area_thickness * sigma;
      weight(v) += element.area_thickness;
    }
  }
  for (Eigen::Index v = 0; v < sum.cols(); ++v)
    if (weight(v) > 0) sum.col(v) /= weight(v);
  return sum;
}

}  // namespace conform::scenes
