#include "kinds/membrane_stress.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include "conform/membrane/detail/cst_kernel.hpp"
#include "conform/membrane/model.hpp"
#include "conform/skin/limb_axes.hpp"

namespace conform::scenes {

Eigen::Vector2d principal_cauchy_stresses(const Eigen::Matrix<double, 3, 2>& f,
                                          const Eigen::Matrix2d& pk2) {
  const Eigen::Matrix3d cauchy = f * pk2 * f.transpose();
  // An orthonormal basis of the deformed face's plane (F's columns span it): the stress has no
  // component along the normal, whose eigenvalue 0 is not a principal stress of the sheet.
  const Eigen::Matrix<double, 3, 2> plane =
      f.householderQr().householderQ() * Eigen::Matrix<double, 3, 2>::Identity();
  const Eigen::Matrix2d in_plane = plane.transpose() * cauchy * plane;
  const Eigen::Vector2d ascending =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(in_plane, Eigen::EigenvaluesOnly)
          .eigenvalues();
  return {ascending(1), ascending(0)};
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
