// Shared pieces of the membrane's checks against closed forms (membrane-slit, membrane-hole,
// membrane-edge): the one-bone skeleton their flat sheets are skinned to, the pinned border,
// the foundation's closed forms and the solver's block of summary.json.
#pragma once

#include <cstdint>
#include <vector>

#include "conform/membrane/skin_material.hpp"
#include "conform/membrane/solver.hpp"
#include "conform/skin/skeleton.hpp"
#include "kinds/run_output.hpp"

namespace conform::scenes {

/// One root joint and one bone, both identity: a flat sheet's targets are its rest positions.
skin::Skeleton one_bone();

/// The indices of the flagged vertices (e.g. a sheet's border, to pin).
std::vector<std::int32_t> flagged_vertices(const std::vector<std::uint8_t>& flags);

/// A membrane on an elastic foundation of stiffness k (Pa/m), plane stress. A straight
/// traction-free edge made in a sheet under the pre-stress sigma normal to it retracts by
///   u(d) = u0 exp(-d / l),  u0 = sigma l / E'',  l = sqrt(E'' t / k),  E'' = E / (1 - nu^2),
/// from E'' t u'' = k u (the strain across a straight edge is uniaxial: eps_yy = 0) with the
/// edge free, E'' u'(0) = -sigma, and u -> 0 far from it.
struct Foundation {
  double plane_modulus = 0;  // E'' = E / (1 - nu^2), Pa
  double decay_length = 0;   // l, m; 0 when k = 0 (no foundation)
  /// u0 = sigma l / E'' for a pre-stress sigma (Pa) normal to the edge, m.
  double retraction(double sigma) const { return sigma * decay_length / plane_modulus; }
};
Foundation foundation(const membrane::SkinMaterial& material);

/// The solver's figures at the run's end: residual, relative_residual, converged, settled_at
/// (the last step in which the solver moved the sheet) and settled (before the run's end).
Json solver_metrics(const membrane::SolveReport& last, double settled_at,
                    const CommonSettings& common);

}  // namespace conform::scenes
