#include "conform/membrane/model.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <stdexcept>
#include <string>

#include "conform/membrane/detail/cst_kernel.hpp"

namespace conform::membrane {
namespace {

// The element's rest frame: e1 along the first edge, e2 = n x e1 in the face's plane.
struct RestFrame {
  Eigen::Vector3d e1, e2, normal;
  Eigen::Matrix2d dm;  // [X1 - X0, X2 - X0] in (e1, e2)
  double area = 0;
};

RestFrame rest_frame(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1,
                     const Eigen::Vector3d& x2) {
  RestFrame f;
  const Eigen::Vector3d a = x1 - x0, b = x2 - x0, n = a.cross(b);
  f.area = 0.5 * n.norm();
  f.normal = n.normalized();
  f.e1 = a.normalized();
  f.e2 = f.normal.cross(f.e1);
  f.dm << a.dot(f.e1), b.dot(f.e1), a.dot(f.e2), b.dot(f.e2);
  return f;
}

// The face's pre-stress direction (face_prestress_tangent) in the frame.
Eigen::Vector2d axis_in_frame(const SkinMaterial& m, const RestFrame& f,
                              const Eigen::Vector3d& limb_axis) {
  const Eigen::Vector3d t = face_prestress_tangent(m, f.normal, limb_axis);
  return {t.dot(f.e1), t.dot(f.e2)};
}

// v1 a a^T + v2 b b^T in the frame, a the face's tangent of the axis and b = n x a: the
// pre-stress S0 (v = the pre-stress), or the neo-Hookean pre-stretch G (v = its principal
// stretches).
Eigen::Matrix2d principal_in_frame(const SkinMaterial& m, const std::array<double, 2>& v,
                                   const RestFrame& f, const Eigen::Vector3d& limb_axis) {
  if (v[0] == v[1])  // isotropic: no direction needed
    return v[0] * Eigen::Matrix2d::Identity();
  const Eigen::Vector2d a = axis_in_frame(m, f, limb_axis);
  const Eigen::Vector2d b(-a.y(), a.x());
  return v[0] * a * a.transpose() + v[1] * b * b.transpose();
}

}  // namespace

Eigen::Vector3d prestress_tangent(const Eigen::Vector3d& axis, const Eigen::Vector3d& normal) {
  const Eigen::Vector3d a = axis.normalized(), n = normal.normalized();
  Eigen::Vector3d t = a - a.dot(n) * n;
  if (t.norm() > kNormalAxis) return t.normalized();
  // The axis is the face's normal: the world axis least aligned with it, projected instead.
  int k = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(a[i]) < std::abs(a[k])) k = i;
  const Eigen::Vector3d e = Eigen::Vector3d::Unit(k);
  t = e - e.dot(n) * n;
  return t.normalized();
}

Eigen::Vector3d face_prestress_tangent(const SkinMaterial& material, const Eigen::Vector3d& normal,
                                       const Eigen::Vector3d& limb_axis) {
  using Field = SkinMaterial::DirectionField;
  if (material.prestress_field != Field::axis) {
    const Eigen::Vector3d n = normal.normalized();
    const Eigen::Vector3d t = limb_axis - limb_axis.dot(n) * n;
    if (t.norm() > kNormalAxis * limb_axis.norm() && t.norm() > 0)
      return material.prestress_field == Field::along_bones
                 ? Eigen::Vector3d(t.normalized())
                 : Eigen::Vector3d(n.cross(t).normalized());
  }
  return prestress_tangent(material.prestress_axis, normal);
}

Eigen::Vector3d face_limb_axis(const Eigen::Ref<const Eigen::Matrix3Xd>& vertex_axes,
                               const mesh::Face& face) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const std::int32_t v : face) {
    const Eigen::Vector3d a = vertex_axes.col(v);
    sum += sum.dot(a) < 0 ? Eigen::Vector3d(-a) : a;
  }
  return sum;
}

void Model::build(const Eigen::Ref<const Eigen::Matrix3Xd>& rest, std::span<const mesh::Face> faces,
                  const SkinMaterial& material, const Eigen::Matrix3Xd* limb_axes) {
  material.validate();
  if (material.prestress_field != SkinMaterial::DirectionField::axis &&
      (!limb_axes || limb_axes->cols() != rest.cols()))
    throw std::invalid_argument(
        "membrane::Model: prestress_field along_bones or around_bones needs the limb axes of "
        "every vertex (skin::vertex_limb_axes; given " +
        std::to_string(limb_axes ? limb_axes->cols() : 0) + " for " + std::to_string(rest.cols()) +
        " vertices)");
  static std::atomic<std::uint64_t> builds{0};
  build_id_ = ++builds;
  material_ = material;
  const bool nh = hyperelastic(material.law);
  const bool fibres = material.law == SkinMaterial::Law::fibre_reinforced;
  lambda_ = nh ? 0.0 : material.lame_lambda();
  mu_ = nh ? material.neo_hookean_mu() : material.lame_mu();
  const std::array<double, 2> stretch =
      nh ? neo_hookean_prestretch(material) : std::array<double, 2>{1.0, 1.0};
  const auto nv = static_cast<std::size_t>(rest.cols());
  elements_.clear();
  faces_.clear();
  elements_.reserve(faces.size());
  faces_.reserve(faces.size());
  node_area_.assign(nv, 0.0);
  degenerate_ = 0;
  for (const mesh::Face& face : faces) {
    const Eigen::Vector3d x0 = rest.col(face[0]), x1 = rest.col(face[1]), x2 = rest.col(face[2]);
    const double longest =
        std::max({(x1 - x0).squaredNorm(), (x2 - x1).squaredNorm(), (x0 - x2).squaredNorm()});
    const RestFrame frame = rest_frame(x0, x1, x2);
    if (!(frame.area > 1e-12 * longest)) {
      ++degenerate_;
      continue;
    }
    const Eigen::Vector3d limb =
        limb_axes ? face_limb_axis(*limb_axes, face) : Eigen::Vector3d::Zero();
    detail::ElementRest e;
    e.beta = frame.dm.inverse().transpose();  // columns = rows of Dm^-1
    e.s0 = principal_in_frame(material, material.prestress, frame, limb);
    e.law = material.law;
    if (nh) e.g = principal_in_frame(material, stretch, frame, limb);
    if (fibres) {  // q = G a = l1 a
      e.fibre = stretch[0] * axis_in_frame(material, frame, limb);
      e.fibre_k1 = material.fibre_stiffness;
      e.fibre_k2 = material.fibre_nonlinearity;
    }
    e.area_thickness = frame.area * material.thickness;
    elements_.push_back(e);
    faces_.push_back(face);
    for (const std::int32_t v : face) node_area_[static_cast<std::size_t>(v)] += frame.area / 3;
  }
  // Vertex -> (element, corner) incidence, CSR.
  incidence_start_.assign(nv + 1, 0);
  for (const mesh::Face& face : faces_)
    for (const std::int32_t v : face) ++incidence_start_[static_cast<std::size_t>(v) + 1];
  for (std::size_t v = 0; v < nv; ++v) incidence_start_[v + 1] += incidence_start_[v];
  incidence_.resize(3 * faces_.size());
  std::vector<std::int32_t> fill(incidence_start_.begin(), incidence_start_.end() - 1);
  for (std::size_t e = 0; e < faces_.size(); ++e)
    for (int c = 0; c < 3; ++c)
      incidence_[static_cast<std::size_t>(fill[static_cast<std::size_t>(faces_[e][c])]++)] =
          static_cast<std::int32_t>(3 * e) + c;
  build_block_pattern();
}

void Model::build_block_pattern() {
  const std::size_t nv = node_area_.size();
  block_start_.assign(nv + 1, 0);
  block_column_.clear();
  diagonal_block_.assign(nv, -1);
  std::vector<std::int32_t> row;
  for (std::size_t v = 0; v < nv; ++v) {  // the vertex and its face neighbours, sorted
    row.clear();
    for (std::int32_t k = incidence_start_[v]; k < incidence_start_[v + 1]; ++k)
      for (const std::int32_t u : faces_[std::size_t(incidence_[std::size_t(k)] / 3)])
        row.push_back(u);
    if (row.empty()) row.push_back(std::int32_t(v));
    std::sort(row.begin(), row.end());
    row.erase(std::unique(row.begin(), row.end()), row.end());
    for (const std::int32_t u : row) {
      if (u == std::int32_t(v)) diagonal_block_[v] = std::int32_t(block_column_.size());
      block_column_.push_back(u);
    }
    block_start_[v + 1] = std::int32_t(block_column_.size());
  }
  element_block_.resize(9 * faces_.size());
  for (std::size_t e = 0; e < faces_.size(); ++e)
    for (int a = 0; a < 3; ++a) {
      const auto v = std::size_t(faces_[e][a]);
      const auto first = block_column_.begin() + block_start_[v],
                 last = block_column_.begin() + block_start_[v + 1];
      for (int b = 0; b < 3; ++b)
        element_block_[9 * e + 3 * std::size_t(a) + std::size_t(b)] =
            std::int32_t(std::lower_bound(first, last, faces_[e][b]) - block_column_.begin());
    }
}

double Model::energy(const Eigen::Ref<const Eigen::Matrix3Xd>& x) const {
  double total = 0;
  for (std::size_t e = 0; e < elements_.size(); ++e) {
    const mesh::Face& f = faces_[e];
    total +=
        elements_[e].area_thickness * detail::element_forces(elements_[e], x.col(f[0]), x.col(f[1]),
                                                             x.col(f[2]), lambda_, mu_, wrinkling())
                                          .psi;
  }
  return total;
}

void Model::gradient(const Eigen::Ref<const Eigen::Matrix3Xd>& x,
                     Eigen::Ref<Eigen::Matrix3Xd> g) const {
  g.setZero();
  for (std::size_t e = 0; e < elements_.size(); ++e) {
    const mesh::Face& f = faces_[e];
    const detail::ElementState s = detail::element_forces(elements_[e], x.col(f[0]), x.col(f[1]),
                                                          x.col(f[2]), lambda_, mu_, wrinkling());
    for (int c = 0; c < 3; ++c)
      g.col(f[c]) += elements_[e].area_thickness * s.p * detail::beta_of(elements_[e], c);
  }
}

}  // namespace conform::membrane
