#include "kinds/membrane_check.hpp"

#include <cmath>
#include <utility>

#include "conform/membrane/model.hpp"

namespace conform::scenes {

void read_slit_sheet(Reader& root, membrane::SlitSheetOptions& options) {
  Reader sheet = root.object("sheet");
  options.width = sheet.number("width", 1.2, 1e-3, 100);
  options.element_size = sheet.number("resolution", 2.5e-3, 1e-5, 1);
  options.tip_refinement = sheet.number("tip_refinement", 16, 1, 64);
  sheet.finish();
}

skin::Skeleton one_bone() {
  skin::Skeleton s;
  s.joints.push_back({"root", -1, skin::Versor::identity()});
  s.bones.push_back({"root", 0, skin::Versor::identity()});
  return s;
}

std::vector<std::int32_t> flagged_vertices(const std::vector<std::uint8_t>& flags) {
  std::vector<std::int32_t> out;
  for (std::size_t v = 0; v < flags.size(); ++v)
    if (flags[v]) out.push_back(std::int32_t(v));
  return out;
}

Eigen::Vector3d sheet_first_axis(const membrane::SkinMaterial& material) {
  return membrane::prestress_tangent(material.prestress_axis, Eigen::Vector3d::UnitZ());
}

double prestress_across(const membrane::SkinMaterial& material, const Eigen::Vector3d& normal) {
  const double c = normal.dot(sheet_first_axis(material));
  return material.prestress[0] * c * c + material.prestress[1] * (1 - c * c);
}

bool material_axes_aligned(const membrane::SkinMaterial& material,
                           const Eigen::Vector3d& direction) {
  const double c = std::abs(direction.normalized().dot(sheet_first_axis(material)));
  return membrane::small_strain_moduli(material).isotropic() || c < 1e-9 || c > 1 - 1e-9;
}

double crack_compliance(const membrane::PlaneModuli& m, bool crack_along_first_axis) {
  // Compliances of the material axes: the inverse of [[c11, c12], [c12, c22]], and 1 / c66.
  const double det = m.c11 * m.c22 - m.c12 * m.c12;
  double a11 = m.c22 / det, a22 = m.c11 / det;
  const double a12 = -m.c12 / det, a66 = 1 / m.c66;
  if (!crack_along_first_axis) std::swap(a11, a22);
  return std::sqrt(a11 * a22 / 2) * std::sqrt(std::sqrt(a22 / a11) + (2 * a12 + a66) / (2 * a11));
}

Foundation foundation(const membrane::SkinMaterial& m, const Eigen::Vector3d& normal) {
  Foundation f;
  f.plane_modulus =
      membrane::small_strain_moduli(m).along(normal.normalized().dot(sheet_first_axis(m)));
  const double k = m.attachment_stiffness;
  f.decay_length = k > 0 ? std::sqrt(f.plane_modulus * m.thickness / k) : 0.0;
  return f;
}

Json solver_metrics(const membrane::SolveReport& last, double settled_at, const CommonSettings& c) {
  return {{"residual", last.residual},
          {"relative_residual", last.relative_residual},
          {"converged", last.converged},
          {"settled_at", settled_at},
          {"settled", settled_at < c.steps * c.dt - 0.5 * c.dt}};
}

}  // namespace conform::scenes
