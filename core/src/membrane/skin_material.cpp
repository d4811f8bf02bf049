#include "conform/membrane/skin_material.hpp"

#include <algorithm>
#include <cmath>

#include "range_error.hpp"

namespace conform::membrane {

double SkinMaterial::lame_lambda() const {
  return youngs_modulus * poisson_ratio / (1 - poisson_ratio * poisson_ratio);
}

double SkinMaterial::lame_mu() const {
  return youngs_modulus / (2 * (1 + poisson_ratio));
}

double SkinMaterial::stress_scale() const {
  const double prestressed = std::max(prestress[0], prestress[1]);
  return prestressed > 0 ? prestressed : youngs_modulus;
}

void SkinMaterial::validate() const {
  const auto finite = [](double v) { return std::isfinite(v); };
  const RangeCheck require("skin material");
  require(finite(youngs_modulus) && youngs_modulus > 0, "youngs_modulus", youngs_modulus, "> 0 Pa");
  require(finite(poisson_ratio) && poisson_ratio >= 0 && poisson_ratio < 0.5, "poisson_ratio",
          poisson_ratio, "[0, 0.5)");
  require(finite(thickness) && thickness > 0, "thickness", thickness, "> 0 m");
  require(finite(areal_density) && areal_density > 0, "areal_density", areal_density, "> 0 kg/m^2");
  require(law == Law::stvk || law == Law::neo_hookean || law == Law::fibre_reinforced,
          "law (enumerator)", double(law), "stvk, neo_hookean or fibre_reinforced");
  require(finite(fibre_stiffness) && fibre_stiffness >= 0, "fibre_stiffness", fibre_stiffness,
          ">= 0 Pa");
  require(finite(fibre_nonlinearity) && fibre_nonlinearity > 0 && fibre_nonlinearity <= 100,
          "fibre_nonlinearity", fibre_nonlinearity, "(0, 100]");
  // The StVK law is linear in E: a pre-stress near E would be a pre-strain of order 1, outside
  // its range. The neo-Hookean pre-stretch reaches any finite tension (prestretch.cpp).
  for (int i = 0; i < 2; ++i) {
    const char* field = i == 0 ? "prestress[0]" : "prestress[1]";
    if (law == Law::stvk)
      require(finite(prestress[i]) && prestress[i] >= 0 && prestress[i] < youngs_modulus, field,
              prestress[i], "[0, youngs_modulus) Pa");
    else
      require(finite(prestress[i]) && prestress[i] >= 0, field, prestress[i], "finite and >= 0 Pa");
  }
  require(
      prestress_field == DirectionField::axis || prestress_field == DirectionField::along_bones ||
          prestress_field == DirectionField::around_bones,
      "prestress_field (enumerator)", double(prestress_field), "axis, along_bones or around_bones");
  require(prestress_axis.allFinite() && prestress_axis.norm() > 0, "prestress_axis (norm)",
          prestress_axis.norm(), "a finite, non-zero direction");
  require(finite(attachment_stiffness) && attachment_stiffness >= 0, "attachment_stiffness",
          attachment_stiffness, ">= 0 Pa/m");
  require(finite(attachment_normal_stiffness) && attachment_normal_stiffness >= 0,
          "attachment_normal_stiffness", attachment_normal_stiffness, ">= 0 Pa/m");
  require(finite(toughness) && toughness > 0 && toughness <= 1e6, "toughness", toughness,
          "(0, 1e6] J/m^2");
  require(finite(attachment_damping) && attachment_damping >= 0, "attachment_damping",
          attachment_damping, ">= 0 Pa s/m");
}

bool PlaneModuli::isotropic() const {
  const double scale = std::max(std::abs(c11), std::abs(c22));
  return std::abs(c11 - c22) <= 1e-12 * scale && std::abs(c12 + 2 * c66 - c11) <= 1e-12 * scale;
}

double PlaneModuli::along(double cos_theta) const {
  const double c2 = cos_theta * cos_theta, s2 = 1 - c2;
  return c11 * c2 * c2 + 2 * (c12 + 2 * c66) * c2 * s2 + c22 * s2 * s2;
}

PlaneModuli small_strain_moduli(const SkinMaterial& material) {
  PlaneModuli m;
  if (!hyperelastic(material.law)) {
    const double e = material.youngs_modulus, nu = material.poisson_ratio;
    m.c11 = m.c22 = e / (1 - nu * nu);
    m.c12 = nu * m.c11;
    m.c66 = e / (2 * (1 + nu));
    return m;
  }
  const double mu = material.neo_hookean_mu();
  m.c11 = m.c22 = 4 * mu;
  m.c12 = 2 * mu;
  m.c66 = mu;
  if (material.law == SkinMaterial::Law::fibre_reinforced) m.c11 += 4 * material.fibre_stiffness;
  return m;
}

double equibiaxial_prestress(const SkinMaterial& material, double prestrain) {
  return material.youngs_modulus * prestrain / (1 - material.poisson_ratio);
}

}  // namespace conform::membrane
