// The membrane's benchmark against linear elastic fracture mechanics: a square sheet pinned at
// its border, pre-stressed, with a straight slit of length 2a through its centre. LEFM (plane
// stress) gives an elliptic opening w(s) = w_max sqrt(1 - (s/a)^2) with
//   w_max = 4 sigma_n a / E,
// sigma_n the pre-stress normal to the slit. The reference is the infinite sheet: a pinned
// border (displacement held, so Feddersen's sqrt(sec(pi a / W)) for a loaded border does not
// apply) lowers the opening, by about 1.1 % at W = 32 a and 0.5 % at W = 48 a (measured; it
// falls as (a / W)^2).
//
// The mesh is a graded tensor grid: elements of `element_size` h over a fine zone around the
// slit, h / tip_refinement at the slit's tips and along its line (the crack-tip singularity is
// what a constant-strain element resolves worst), growing geometrically toward the border. The slit
// lies on mesh edges; it is made by a TopologyChange that duplicates its interior vertices (the
// tips stay shared), so that the same change can be applied to a mesh and to a live soft body.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "conform/membrane/skin_material.hpp"
#include "conform/mesh/skinned_mesh.hpp"
#include "conform/mesh/topology_change.hpp"

namespace conform::membrane {

struct SlitSheetOptions {
  double width = 0.4;            // W, m: side of the square sheet (>= 8 slit lengths)
  double slit_length = 0.05;     // 2a, m
  double slit_angle = 0;         // rad, from the sheet's x axis
  double element_size = 2.5e-3;  // h, m: element size along the slit and in the fine zone
  double tip_refinement = 16;    // elements at the tips are h / this, growing by tip_grading
  double tip_grading = 1.3;      // growth ratio of the element size away from the tips
  double fine_zone = 1.0;        // half-width of the fine zone beyond the slit, in units of a
  double grading = 1.3;          // growth ratio of the element size outside the fine zone
  /// Throws std::invalid_argument naming a field out of range.
  void validate() const;
};

struct SlitSheet {
  mesh::SkinnedMesh mesh;               // the intact sheet in z = 0, one bone (weight 1 on 0)
  std::vector<std::uint8_t> border;     // per vertex: 1 on the sheet's border
  mesh::TopologyChange slit;            // duplicates the slit's interior vertices
  std::vector<std::int32_t> lip_upper;  // interior slit vertices, ordered along the slit
  std::vector<std::int32_t> lip_lower;  // their duplicates (indices after the slit change)
  std::vector<double> lip_s;            // their coordinate along the slit, m, in (-a, a)
  Eigen::Vector3d slit_direction, slit_normal;  // unit, in the sheet's plane
};

SlitSheet make_slit_sheet(const SlitSheetOptions& options);

/// sigma_n = n^T diag(sigma_xx, sigma_yy) n for the slit's normal n, Pa.
double normal_prestress(const SlitSheet& sheet, double sigma_xx, double sigma_yy);

/// The opening along the slit at positions x (3 x #V after the slit change): w_i =
/// (x_upper - x_lower) . n, one value per entry of lip_s, m.
std::vector<double> slit_opening(const SlitSheet& sheet,
                                 const Eigen::Ref<const Eigen::Matrix3Xd>& x);

struct EllipseFit {
  double w_max = 0;      // largest opening, m
  double amplitude = 0;  // least-squares A of w = A sqrt(1 - (s/a)^2), m
  double r2 = 0;         // its coefficient of determination
};
EllipseFit fit_ellipse(const std::vector<double>& s, const std::vector<double>& w, double a);

}  // namespace conform::membrane
