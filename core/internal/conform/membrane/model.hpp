// The membrane of a triangle mesh: one constant-strain, pre-stressed element per face, St
// Venant-Kirchhoff or incompressible neo-Hookean (SkinMaterial::law; detail/cst_kernel.hpp and
// detail/neo_hookean.hpp have the formulas), built from the REST configuration
// and the material only. Material that a topology change makes (new faces over new vertices,
// whose rest positions are interpolated from their parents) therefore continues the material it
// replaces: its rest state is never the current, stretched shape, and its pre-stress comes from
// the same field.
//
// Shapes (#V vertices, #F faces): rest 3 x #V, faces #F counter-clockwise triangles.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "conform/membrane/detail/element_rest.hpp"
#include "conform/membrane/skin_material.hpp"
#include "conform/mesh/skinned_mesh.hpp"

namespace conform::membrane {

/// Below this length of the unit axis projected onto a face's plane (the axis within about
/// 0.06 degrees of the face's normal) the face takes prestress_tangent's fallback.
inline constexpr double kNormalAxis = 1e-3;

/// The first principal pre-stress direction of a face of unit normal n: the axis projected
/// onto the face's plane, normalised; where the axis is the face's normal (a constant field on
/// a closed surface must be so somewhere, e.g. at the arm's poles), the projection of the world
/// axis (x, y, z, the first on a tie) least aligned with the axis. It depends on the axis and
/// the normal only, never on how the face is triangulated. Unit, and normal to n.
Eigen::Vector3d prestress_tangent(const Eigen::Vector3d& axis, const Eigen::Vector3d& normal);

/// The first principal pre-stress direction of a face of unit normal n under the material's
/// prestress_field, given the face's limb axis (face_limb_axis; zero without one): unit,
/// normal to n, and independent of how the face is triangulated.
Eigen::Vector3d face_prestress_tangent(const SkinMaterial& material, const Eigen::Vector3d& normal,
                                       const Eigen::Vector3d& limb_axis);

/// The face's limb axis: the sum of its vertices' axes (3 x #V, skin::vertex_limb_axes), each
/// turned to agree in sign with the first non-zero one (an axis is a line, not an arrow).
Eigen::Vector3d face_limb_axis(const Eigen::Ref<const Eigen::Matrix3Xd>& vertex_axes,
                               const mesh::Face& face);

class Model {
 public:
  /// Builds the elements and the nodal areas. Faces whose rest area is below 1e-12 of the
  /// squared longest edge carry no material (counted in degenerate_faces()); the material is
  /// validated (SkinMaterial::validate throws on a bad field). `limb_axes` (3 x #V, per
  /// vertex; skin::vertex_limb_axes) is what the along_bones and around_bones fields follow;
  /// those fields without it throw std::invalid_argument.
  void build(const Eigen::Ref<const Eigen::Matrix3Xd>& rest, std::span<const mesh::Face> faces,
             const SkinMaterial& material, const Eigen::Matrix3Xd* limb_axes = nullptr);

  std::int32_t vertex_count() const { return static_cast<std::int32_t>(node_area_.size()); }
  std::int32_t element_count() const { return static_cast<std::int32_t>(elements_.size()); }
  std::int32_t degenerate_faces() const { return degenerate_; }
  /// Distinct for every build() in the process (0 before the first): a model with the same id
  /// has the same elements, so what a solver computed of them may be reused.
  std::uint64_t build_id() const { return build_id_; }
  const SkinMaterial& material() const { return material_; }
  /// The law's parameters, as the kernel (detail/cst_kernel.hpp) takes them, Pa: stvk the
  /// plane-stress Lame constants; neo_hookean mu = E / 3 and lambda 0 (unused).
  double lambda() const { return lambda_; }
  double mu() const { return mu_; }
  bool wrinkling() const { return material_.wrinkling; }

  /// A third of the rest area of the vertex's faces, m^2 (0 for a vertex without faces).
  double node_area(std::int32_t v) const { return node_area_[static_cast<std::size_t>(v)]; }
  /// rho_A times node_area, kg.
  double node_mass(std::int32_t v) const { return material_.areal_density * node_area(v); }

  /// Membrane energy at positions x (3 x #V), J.
  double energy(const Eigen::Ref<const Eigen::Matrix3Xd>& x) const;
  /// Membrane energy gradient (= minus the elastic nodal forces), N, written to g (3 x #V).
  void gradient(const Eigen::Ref<const Eigen::Matrix3Xd>& x, Eigen::Ref<Eigen::Matrix3Xd> g) const;

  // The solver's access to the elements (solver.cpp).
  const std::vector<detail::ElementRest>& elements() const { return elements_; }
  const std::vector<mesh::Face>& element_faces() const { return faces_; }
  /// Incidence, CSR: the (element, corner) pairs of vertex v are
  /// incidence()[incidence_start()[v] .. incidence_start()[v + 1]).
  const std::vector<std::int32_t>& incidence_start() const { return incidence_start_; }
  const std::vector<std::int32_t>& incidence() const { return incidence_; }  // 3 e + corner
  /// The Hessian's 3 x 3 block pattern, CSR by vertex: row v's blocks are
  /// [block_start()[v], block_start()[v + 1]) with columns block_column(); element e's block
  /// (a, b) is block element_block()[9 e + 3 a + b]; row v's diagonal block is diagonal_block()[v].
  const std::vector<std::int32_t>& block_start() const { return block_start_; }
  const std::vector<std::int32_t>& block_column() const { return block_column_; }
  const std::vector<std::int32_t>& element_block() const { return element_block_; }
  const std::vector<std::int32_t>& diagonal_block() const { return diagonal_block_; }

 private:
  SkinMaterial material_;
  double lambda_ = 0, mu_ = 0;
  std::vector<detail::ElementRest> elements_;
  std::vector<mesh::Face> faces_;
  std::vector<double> node_area_;
  std::vector<std::int32_t> incidence_start_, incidence_;
  std::vector<std::int32_t> block_start_, block_column_, element_block_, diagonal_block_;
  void build_block_pattern();
  std::int32_t degenerate_ = 0;
  std::uint64_t build_id_ = 0;
};

}  // namespace conform::membrane
