// A skin membrane's material in SI units: what `membrane::Model` is built from.
//
// Every nodal quantity (mass, attachment, damping) is a per-area property times the node's
// share of the rest area (a third of its faces' rest areas), and every element quantity is a
// per-area property times the element's rest area, so the material does not depend on the mesh.
//
// Sources for the defaults (human skin in vivo, forearm and upper arm):
//   - Young's modulus 0.42 MPa: Agache, Monneur, Leveque & De Rigal, "Mechanical properties and
//     Young's modulus of human skin in vivo", Arch Dermatol Res 269:221-232 (1980), torsion
//     tests, 0.42 MPa under 30 years, 0.85 MPa over 30.
//   - Poisson's ratio 0.48 (nearly incompressible tissue) and thickness 1.5 mm (dermis and
//     epidermis of the arm, 1-2 mm by ultrasound): Joodaki & Panzer, "Skin mechanical properties
//     and modeling: a review", Proc IMechE H 232(4):323-343 (2018), its tables 1 and 3.
//   - Pre-strain of 10-20 % in vivo (Joodaki & Panzer 2018, section "Pre-stress"); the default
//     pre-stress is an equibiaxial pre-strain of 10 %: sigma = E eps / (1 - nu) = 80.8 kPa.
//   - Density 1.1e3 kg/m^3 x 1.5 mm = 1.65 kg/m^2.
//   - Attachment: the hypodermis as a shear layer, k = G / h with G about 2 kPa (adipose
//     tissue at low rates, Geerligs et al., Biorheology 45:677-688, 2008) and h about 5 mm:
//     4e5 Pa/m. Its decay length sqrt(E t / k) is then about 4 cm.
//   - Normal support: the body beneath resists indentation far more than shear; 100 x the
//     tangential stiffness keeps the skin from sinking under its own curvature load sigma t / R.
//   - Neo-Hookean law: skin is nearly incompressible (nu 0.48 above), and an incompressible
//     solid's shear modulus is linear elasticity's mu = E / (2 (1 + nu)) at nu = 1/2, E / 3;
//     with it the law's small-strain limit is linear elasticity with nu = 1/2, the same E.
//     Skin's stress-strain curve is J-shaped (stiffens with stretch; Joodaki & Panzer 2018);
//     neo-Hookean is the simplest hyperelastic law that stays valid at 10-20 % pre-strain
//     (it stiffens mildly, far less than skin past the toe region).
//   - Damping: not measured in these units; the default is about critical for the attachment,
//     2 sqrt(k rho_A) = 1.6e3 Pa s/m, so that secondary motion settles in tens of milliseconds.
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
  enum class Law { stvk, neo_hookean };
  /// Default stvk.
  Law law = Law::stvk;
  /// Young's modulus E, Pa, > 0 (skin in vivo: 0.1-1 MPa; default 0.42 MPa).
  double youngs_modulus = 0.42e6;
  /// Poisson's ratio nu of the membrane (plane stress), in [0, 0.5) (default 0.48).
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

/// The pre-stress of an equibiaxial pre-strain eps: sigma = E eps / (1 - nu), Pa (the StVK
/// law's small-strain relation).
double equibiaxial_prestress(const SkinMaterial& material, double prestrain);

/// The neo-Hookean law's principal pre-stretches [l1, l2] (along the pre-stress axis and across
/// it) whose plane-stress Cauchy stress mu (l_i^2 - 1 / (l1 l2)^2) is the material's
/// `prestress` (to 1e-13 relative); [1, 1] without pre-stress. Depends on the material only.
std::array<double, 2> neo_hookean_prestretch(const SkinMaterial& material);

}  // namespace conform::membrane
