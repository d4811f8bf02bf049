// A skin membrane's material in SI units: what `membrane::Model` is built from.
//
// Every nodal quantity (mass, attachment, damping) is a per-area property times the node's
// share of the rest area (a third of its faces' rest areas), and every element quantity is a
// per-area property times the element's rest area, so the material does not depend on the mesh.
//
// The defaults are human skin in vivo (forearm and upper arm). Their sources, and the
// derivations of the derived ones (pre-stress, attachment, damping, the fibres' k1 and k2,
// the toughness), are in docs/notes/membrane.md.
#pragma once

#include <Eigen/Core>
#include <array>

namespace conform::membrane {

struct SkinMaterial {
  /// The membrane's constitutive law (detail/cst_kernel.hpp, detail/neo_hookean.hpp).
  ///   stvk: pre-stressed St Venant-Kirchhoff, S = S0 + lambda tr(E) I + 2 mu E with the
  ///         plane-stress Lame constants of E and nu; a small-strain law (linear in E).
  ///   neo_hookean: incompressible neo-Hookean membrane, mu = E / 3 (nu is unused: the
  ///         thickness follows the area change), pre-stressed by a finite pre-stretch G solved
  ///         from `prestress` (neo_hookean_prestretch); stiffens with stretch.
  ///   fibre_reinforced: the neo-Hookean matrix plus one family of collagen fibres along the
  ///         first principal pre-stress direction (prestress_axis; detail/fibre.hpp):
  ///         psi_f = k1 / (2 k2) (exp(k2 (I4 - 1)^2) - 1) where the fibres are stretched
  ///         (I4 > 1), none where they are not; pre-stretched so that the bind state's stress is
  ///         still `prestress` (an isotropic pre-stress then needs less stretch along the fibres).
  enum class Law { stvk, neo_hookean, fibre_reinforced };
  /// Default neo_hookean: skin runs at 10-20 % pre-strain, outside stvk's small-strain range.
  Law law = Law::neo_hookean;
  /// Young's modulus E, Pa, > 0 (skin in vivo: 0.1-1 MPa; default 0.42 MPa).
  double youngs_modulus = 0.42e6;
  /// The fibres' stiffness k1 of Law::fibre_reinforced, Pa, finite and >= 0 (default 79.8 kPa,
  /// 0.19 x the default E; docs/notes/membrane.md). Unused by the other laws.
  double fibre_stiffness = 79.8e3;
  /// The fibres' stiffening exponent k2 of Law::fibre_reinforced, dimensionless, in (0, 100]
  /// (default 1.285; docs/notes/membrane.md). Unused by the other laws.
  double fibre_nonlinearity = 1.285;
  /// Poisson's ratio nu of the membrane (plane stress), in [0, 0.5) (default 0.48); the stvk
  /// law's only (the neo-Hookean laws are incompressible, nu = 1/2).
  double poisson_ratio = 0.48;
  /// Thickness t, m, > 0 (default 1.5 mm).
  double thickness = 1.5e-3;
  /// Areal mass density rho_A, kg/m^2, > 0 (default 1.65 kg/m^2).
  double areal_density = 1.65;
  /// In-plane pre-stress of the rest configuration, Pa: its two principal values, the first
  /// along `prestress_axis` projected onto each face, the second across it in the face's plane.
  /// Each in [0, E) for stvk, finite and >= 0 for neo_hookean (whose pre-stretch reaches any
  /// tension), Cauchy stress of the bind state (tension; default 80.8 kPa both, isotropic). Give
  /// two different values to model skin-tension (Langer's) lines.
  std::array<double, 2> prestress = {80.8e3, 80.8e3};
  /// Direction field of the first principal pre-stress, in the rest (bind) space of the mesh:
  /// a constant direction, projected onto each face's plane (so the principal axes always lie
  /// in the face). Only its direction matters; unused when the pre-stress is isotropic. Where
  /// it is normal to a face, the face takes a documented fallback tangent that does not depend
  /// on the triangulation (membrane::prestress_tangent in model.hpp).
  Eigen::Vector3d prestress_axis = Eigen::Vector3d::UnitZ();
  /// Where the first principal pre-stress (and the fibre-reinforced law's fibres) points:
  ///   axis:         prestress_axis, constant, projected onto each face (the flat sheets);
  ///   along_bones:  along each limb, the face's tangent of its vertices' weight-blended bone
  ///                 axes (skin/limb_axes.hpp);
  ///   around_bones: around each limb, n x that tangent: on the limbs Langer's lines, and skin's
  ///                 larger tension, run mostly around the limb (Langer 1861; Ridge & Wright,
  ///                 J Anat 100:297-306, 1966), so this is the field for a character's skin.
  /// The bone fields need the skeleton's axes (Model::build's limb_axes); where a face has
  /// none, or its limb axis is normal to it (a limb's end), it takes prestress_axis's tangent.
  enum class DirectionField { axis, along_bones, around_bones };
  /// Default axis.
  DirectionField prestress_field = DirectionField::axis;
  /// Tangential stiffness of the attachment to the skinned target (the subcutaneous layer in
  /// shear), Pa/m = N/m^3: force per unit area per metre of offset along the surface, >= 0
  /// (default 4e5 Pa/m).
  double attachment_stiffness = 4.0e5;
  /// Stiffness of the attachment along the target's normal (the body beneath resisting
  /// indentation), Pa/m, >= 0 (default 4e7 Pa/m).
  double attachment_normal_stiffness = 4.0e7;
  /// Viscous damping of the velocity relative to the target's, Pa s/m = N s/m^3, >= 0
  /// (default 1.6e3 Pa s/m).
  double attachment_damping = 1.6e3;
  /// Toughness G_c, J/m^2: the energy per unit area of new crack surface through the thickness
  /// (a crack of length a in a membrane of thickness t releases G t da), at which a tear grows
  /// (membrane/crack_growth.hpp). In (0, 1e6] (human skin about 1e3-3e4; default 2e3,
  /// docs/notes/membrane.md). Unused unless crack growth is asked for.
  double toughness = 2.0e3;
  /// Wrinkling: the membrane carries no compression (tension-field theory, Pipkin 1986): where
  /// a principal stress would go negative the skin buckles out of its plane instead, and the
  /// relaxed energy of detail/tension_field.hpp (stvk) or detail/neo_hookean.hpp (neo_hookean)
  /// is used (default true). false keeps the plain membrane, which carries compression like a plate
  /// in its plane (linear elasticity's assumption, e.g. for comparison with LEFM).
  bool wrinkling = true;

  /// Plane-stress Lame constants: lambda = E nu / (1 - nu^2), mu = E / (2 (1 + nu)), Pa.
  double lame_lambda() const;
  double lame_mu() const;
  /// The neo-Hookean law's shear modulus E / 3, Pa.
  double neo_hookean_mu() const { return youngs_modulus / 3; }
  /// The stress scale S of the solver's relative tolerance, Pa: the larger principal
  /// pre-stress, or Young's modulus when there is none.
  double stress_scale() const;
  /// Throws std::invalid_argument naming the first field out of its range, with its value.
  void validate() const;
};

/// Whether the law is neo-Hookean or built on it (the fibre-reinforced law's matrix).
inline bool hyperelastic(SkinMaterial::Law law) {
  return law != SkinMaterial::Law::stvk;
}

/// The law's plane-stress moduli at small strain about the unstrained state, Pa, in the axes
/// of the pre-stress (1: along the first principal pre-stress, where the fibres lie; 2: across
/// it, in the face): sigma_11 = c11 e_11 + c12 e_22, sigma_22 = c12 e_11 + c22 e_22,
/// sigma_12 = c66 gamma_12 (gamma_12 = 2 e_12).
///   stvk:             c11 = c22 = E / (1 - nu^2), c12 = nu c11, c66 = E / (2 (1 + nu));
///   neo_hookean:      incompressible plane stress (nu = 1/2, mu = E / 3): 4 mu, 4 mu, 2 mu, mu;
///   fibre_reinforced: the same with 4 k1 more on c11 (psi_f = 2 k1 e_11^2 to second order, for
///                     fibres in tension, e_11 > 0), so that the uniaxial modulus along the
///                     fibres is E + 4 k1.
/// The pre-stress's own (geometric) stiffness, O(sigma / E), is left out: these are the moduli
/// of the closed forms that the membrane checks compare with at sigma / E ~ 1e-3.
struct PlaneModuli {
  double c11 = 0, c22 = 0, c12 = 0, c66 = 0;
  /// The same moduli in every direction of the plane (c11 = c22 = c12 + 2 c66).
  bool isotropic() const;
  /// The modulus of a uniaxial strain along a direction at angle theta (cos c, sin s) to axis 1:
  /// c11 c^4 + 2 (c12 + 2 c66) c^2 s^2 + c22 s^4, Pa (E'' along an axis, e.g. across an edge).
  double along(double cos_theta) const;
};
PlaneModuli small_strain_moduli(const SkinMaterial& material);

/// The pre-stress of an equibiaxial pre-strain eps: sigma = E eps / (1 - nu), Pa (the StVK
/// law's small-strain relation).
double equibiaxial_prestress(const SkinMaterial& material, double prestrain);

/// The neo-Hookean law's principal pre-stretches [l1, l2] (along the pre-stress axis and across
/// it) whose plane-stress Cauchy stress mu (l_i^2 - 1 / (l1 l2)^2) (plus, for the
/// fibre-reinforced law, the fibres' 2 psi_f'(l1^2 - 1) l1^2 along the axis) is the material's
/// `prestress` (to 1e-13 relative); [1, 1] without pre-stress. Depends on the material only.
std::array<double, 2> neo_hookean_prestretch(const SkinMaterial& material);

}  // namespace conform::membrane
