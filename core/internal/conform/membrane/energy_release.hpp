// The energy release rate G at a tear's tip, and its mode mix K_I, K_II, from a membrane at
// equilibrium. No stress threshold of an element: both come from fields integrated over a domain
// of a given physical size around the tip, so they do not depend on the element size.
//
// G by virtual crack extension (deLorenzi, Int J Fract 19:183-193, 1982; the finite element form
// of the domain J-integral): the nodes within R of the tip are shifted along the crack's
// direction e by delta q(X), q = 1 within r_in = inner_fraction R of the tip and falling linearly
// to 0 at R, their displacements held (rest and current positions move together), so the crack
// grows by delta with the material around the tip carried along. At equilibrium
//   G = -1/t dPi/da = -1/t dU/d(delta),
// U the membrane's energy (the free nodes' forces vanish, and q = 0 on the pinned ones, so the
// potential changes only through U). Only elements where q varies change: the derivative is a
// central difference over their energy, exact to O(delta^2). Valid at finite strain for any law.
// The domain must hold no other tip, no pinned node and no border but the crack's own lips.
//
// Mode mix by displacement correlation (plane stress, any nu): the lips' opening and sliding
// (upper minus lower, in the tip's frame e, n = N x e, N the sheet's normal) at a distance r
// behind the tip are
//   delta_n = 8 K_I / E sqrt(r / (2 pi)),   delta_t = 8 K_II / E sqrt(r / (2 pi)),
// so K(r) = E / 8 sqrt(2 pi / r) delta, fitted by a line over the lip pairs in the domain's ring
// r_in <= r <= R and taken at r = 0 (the constant-strain elements nearer the tip resolve the
// sqrt(r) field worst, so their pairs are left out; docs/notes/membrane.md). The fit's ratio
// gives the phase psi = atan2(K_II, K_I), and the energy gives the size: K_I = sqrt(E G) cos psi,
// K_II = sqrt(E G) sin psi (G = (K_I^2 + K_II^2) / E in plane stress). E is the law's small-strain
// Young's modulus (isotropic laws: the fibre-reinforced law's mix is not this closed form).
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "conform/membrane/skin_material.hpp"
#include "conform/mesh/skinned_mesh.hpp"

namespace conform::membrane {

struct CrackTip {
  std::int32_t vertex = -1;  // the tip: one vertex shared by both lips
  /// Unit, in the sheet's plane, in rest space: the way the crack runs at its tip (away from it).
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
};

struct EnergyReleaseOptions {
  double domain_radius = 0;      // R, m, > 0: smaller than the distance to a border or other tip
  double inner_fraction = 0.25;  // r_in / R, in [0, 1)
  /// The virtual extension delta, as a fraction of R, in (0, 1e-2].
  double extension_fraction = 1e-6;
  /// Throws std::invalid_argument naming a field out of its range.
  void validate() const;
};

struct TipFracture {
  double energy_release_rate = 0;  // G, J/m^2
  double k1 = 0, k2 = 0;           // K_I, K_II = sqrt(E G) (cos psi, sin psi), Pa m^1/2
  double mode_phase = 0;           // psi, rad
  /// K_I, K_II of the displacement correlation alone (their ratio gives psi), Pa m^1/2.
  double k1_correlation = 0, k2_correlation = 0;
  int lip_pairs = 0;  // lip pairs behind the tip in the ring [r_in, R] that the correlation used
};

/// G, K_I and K_II at `tip` of the membrane on `mesh` (its rest positions and faces) deformed
/// to x (3 x #V, at equilibrium), for `material`. Throws std::invalid_argument on a bad tip or
/// options.
TipFracture energy_release(const mesh::SkinnedMesh& mesh, const SkinMaterial& material,
                           const Eigen::Ref<const Eigen::Matrix3Xd>& x, const CrackTip& tip,
                           const EnergyReleaseOptions& options);

/// The sheet's unit normal N at a vertex: its faces' rest normals, summed (the faces' winding
/// sets its sign). Throws std::invalid_argument for a vertex without faces.
Eigen::Vector3d sheet_normal(const mesh::SkinnedMesh& mesh, std::int32_t vertex);

/// The kink angle of the maximum tangential (hoop) stress criterion (Erdogan & Sih, J Basic Eng
/// 85:519-525, 1963), from the crack's direction toward n = N x e, rad:
///   theta = 2 arctan[(K_I - sqrt(K_I^2 + 8 K_II^2)) / (4 K_II)],   0 when K_II = 0;
/// in [-70.5, 70.5] degrees for K_I >= 0 (pure mode II: -+ 70.53 degrees).
double mts_kink_angle(double k1, double k2);

}  // namespace conform::membrane
