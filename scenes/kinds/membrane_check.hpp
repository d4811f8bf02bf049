// Shared pieces of the membrane's checks against closed forms (membrane-slit, membrane-hole,
// membrane-edge): the one-bone skeleton their flat sheets are skinned to, the pinned border,
// the foundation's closed forms and the solver's block of summary.json.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "conform/membrane/skin_material.hpp"
#include "conform/membrane/slit_sheet.hpp"
#include "conform/membrane/solver.hpp"
#include "conform/skin/skeleton.hpp"
#include "kinds/run_output.hpp"

namespace conform::scenes {

/// Blocks of the built-in scenes' text (join_scene_json, kinds/scene.hpp) that the checks share,
/// each default written once. The pinned sheet's skin of membrane-slit and membrane-hole: human
/// skin's modulus and thickness, an equibiaxial pre-stress, no foundation.
inline constexpr std::string_view kPinnedSheetMaterialJson = R"json(
  "material": { "prestress": [400, 400], "prestress_axis": [1, 0, 0], "youngs_modulus": 420000, "poisson_ratio": 0.48,
                "thickness": 0.0015, "attachment_stiffness": 0,
                "attachment_normal_stiffness": 0, "wrinkling": false, "relative_tolerance": 0.0001, "max_cg_iterations": 4000 },)json";
/// The step of membrane-slit, membrane-hole and membrane-edge: 1/60 s, one substep, no gravity
/// (the sheet settles under its pre-stress alone).
inline constexpr std::string_view kSheetCheckPhysicsJson = R"json(
  "physics": { "dt": 0.016666666666666666, "substeps": 1, "gravity": [0, 0, 0] },)json";

/// One root joint and one bone, both identity: a flat sheet's targets are its rest positions.
/// The "sheet" object of the slit scenes (membrane-slit, membrane-griffith): width, resolution
/// (the element size along the slit, m) and tip_refinement, into `options`.
void read_slit_sheet(Reader& root, membrane::SlitSheetOptions& options);
skin::Skeleton one_bone();

/// The indices of the flagged vertices (e.g. a sheet's border, to pin).
std::vector<std::int32_t> flagged_vertices(const std::vector<std::uint8_t>& flags);

/// A membrane on an elastic foundation of stiffness k (Pa/m), plane stress. A straight
/// traction-free edge made in a sheet under the pre-stress sigma normal to it retracts by
///   u(d) = u0 exp(-d / l),  u0 = sigma l / E'',  l = sqrt(E'' t / k),  E'' = E / (1 - nu^2)
///   (isotropic),
/// from E'' t u'' = k u (the strain across a straight edge is uniaxial: eps_yy = 0) with the
/// edge free, E'' u'(0) = -sigma, and u -> 0 far from it.
struct Foundation {
  double plane_modulus = 0;  // E'' = E / (1 - nu^2) isotropic; PlaneModuli::along(normal), Pa
  double decay_length = 0;   // l, m; 0 when k = 0 (no foundation)
  /// u0 = sigma l / E'' for a pre-stress sigma (Pa) normal to the edge, m.
  double retraction(double sigma) const { return sigma * decay_length / plane_modulus; }
};
/// The foundation across an edge of unit normal `normal` in the sheet (z = 0). E'' is the
/// law's modulus of a uniaxial strain along the normal; exact when the law is isotropic or the
/// normal lies along a material axis (aligned), where no shear couples in.
Foundation foundation(const membrane::SkinMaterial& material, const Eigen::Vector3d& normal);

/// The first principal pre-stress direction (and the fibres') in a flat sheet in z = 0: what
/// membrane::Model gives each of its faces (prestress_axis's tangent).
Eigen::Vector3d sheet_first_axis(const membrane::SkinMaterial& material);

/// The pre-stress normal to a line of unit normal n in the sheet: sigma_1 c^2 + sigma_2 s^2,
/// c = n . sheet_first_axis, Pa.
double prestress_across(const membrane::SkinMaterial& material, const Eigen::Vector3d& normal);

/// Whether the closed forms of an isotropic plate hold along `direction` in the sheet: the law
/// is isotropic at small strain, or the direction lies along a material axis (to 1e-9).
bool material_axes_aligned(const membrane::SkinMaterial& material,
                           const Eigen::Vector3d& direction);

/// H of LEFM for a straight crack along a material axis in an orthotropic plane-stress plate:
/// G = K_I^2 H and the Griffith crack opens as an ellipse of largest width 4 sigma_n a H.
/// Sih, Paris & Irwin, Int J Fract Mech 1:189-203 (1965), with the compliances a_ij of the
/// crack's axes (1 along the crack, 2 across it, a66 the shear compliance):
///   H = sqrt(a11 a22 / 2) sqrt(sqrt(a22 / a11) + (2 a12 + a66) / (2 a11));
/// H = 1 / E for an isotropic law. `crack_along_first_axis` says which material axis is 1.
double crack_compliance(const membrane::PlaneModuli& moduli, bool crack_along_first_axis);

/// The solver's figures at the run's end: residual, relative_residual, converged, settled_at
/// (the last step in which the solver moved the sheet) and settled (before the run's end).
Json solver_metrics(const membrane::SolveReport& last, double settled_at,
                    const CommonSettings& common);

}  // namespace conform::scenes
