#include "conform/membrane/energy_release.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "conform/membrane/model.hpp"
#include "range_error.hpp"

namespace conform::membrane {
namespace {

// q(X): 1 within r_in of the tip, linear to 0 at R.
std::vector<double> domain_weights(const mesh::SkinnedMesh& mesh, const Eigen::Vector3d& at,
                                   const EnergyReleaseOptions& o) {
  const double r_out = o.domain_radius, r_in = o.inner_fraction * r_out;
  std::vector<double> q(static_cast<std::size_t>(mesh.vertex_count()), 0.0);
  for (std::int32_t v = 0; v < mesh.vertex_count(); ++v) {
    const double r = (mesh.rest.col(v) - at).norm();
    q[std::size_t(v)] = std::clamp((r_out - r) / (r_out - r_in), 0.0, 1.0);
  }
  return q;
}

// dU/d(delta) by a central difference over the faces where q varies (the others move rigidly).
double energy_derivative(const mesh::SkinnedMesh& mesh, const SkinMaterial& material,
                         const Eigen::Ref<const Eigen::Matrix3Xd>& x, const std::vector<double>& q,
                         const Eigen::Vector3d& e, double delta) {
  std::vector<mesh::Face> ring;
  for (const mesh::Face& f : mesh.faces) {
    const double q0 = q[std::size_t(f[0])], q1 = q[std::size_t(f[1])], q2 = q[std::size_t(f[2])];
    if (q0 != q1 || q1 != q2) ring.push_back(f);
  }
  const auto shifted_energy = [&](double d) {
    Eigen::Matrix3Xd rest = mesh.rest, moved = x;
    for (std::int32_t v = 0; v < mesh.vertex_count(); ++v) {
      const double s = d * q[std::size_t(v)];
      if (s == 0) continue;
      rest.col(v) += s * e;
      moved.col(v) += s * e;
    }
    Model ring_model;
    ring_model.build(rest, ring, material);
    return ring_model.energy(moved);
  };
  return (shifted_energy(delta) - shifted_energy(-delta)) / (2 * delta);
}

// K(r) = E / 8 sqrt(2 pi / r) delta over the lip pairs behind the tip in [inner, radius],
// fitted by a line in r and taken at r = 0.
struct Correlation {
  double k1 = 0, k2 = 0;
  int pairs = 0;
};
Correlation displacement_correlation(const mesh::SkinnedMesh& mesh,
                                     const Eigen::Ref<const Eigen::Matrix3Xd>& x, double modulus,
                                     const Eigen::Vector3d& at, const Eigen::Vector3d& e,
                                     const Eigen::Vector3d& n, double inner, double radius) {
  // The lips' copies share their rest position: group the vertices within R by it.
  std::map<std::array<double, 3>, std::vector<std::int32_t>> by_place;
  for (std::int32_t v = 0; v < mesh.vertex_count(); ++v) {
    const Eigen::Vector3d d = mesh.rest.col(v) - at;
    if (d.norm() <= radius && d.norm() >= inner && d.norm() > 0 && d.dot(e) < 0)
      by_place[{mesh.rest(0, v), mesh.rest(1, v), mesh.rest(2, v)}].push_back(v);
  }
  // A copy is the upper one when its faces lie on the +n side of it.
  std::vector<Eigen::Vector3d> side(static_cast<std::size_t>(mesh.vertex_count()),
                                    Eigen::Vector3d::Zero());
  for (const mesh::Face& f : mesh.faces) {
    const Eigen::Vector3d c = (mesh.rest.col(f[0]) + mesh.rest.col(f[1]) + mesh.rest.col(f[2])) / 3;
    for (const std::int32_t v : f) side[std::size_t(v)] += c - mesh.rest.col(v);
  }
  // Least squares of K = k0 + k1 r for both modes.
  double s1 = 0, sr = 0, srr = 0, sI = 0, srI = 0, sII = 0, srII = 0;
  Correlation out;
  for (const auto& [place, copies] : by_place) {
    if (copies.size() != 2) continue;
    std::int32_t up = copies[0], low = copies[1];
    if (side[std::size_t(up)].dot(n) < side[std::size_t(low)].dot(n)) std::swap(up, low);
    const Eigen::Vector3d jump =
        (x.col(up) - mesh.rest.col(up)) - (x.col(low) - mesh.rest.col(low));
    const double r = (mesh.rest.col(up) - at).norm();
    const double scale = modulus / 8 * std::sqrt(2 * std::numbers::pi / r);
    const double kI = scale * jump.dot(n), kII = scale * jump.dot(e);
    s1 += 1, sr += r, srr += r * r, sI += kI, srI += r * kI, sII += kII, srII += r * kII;
    ++out.pairs;
  }
  const double det = s1 * srr - sr * sr;
  if (out.pairs >= 2 && det > 0) {
    out.k1 = (srr * sI - sr * srI) / det;
    out.k2 = (srr * sII - sr * srII) / det;
  } else if (out.pairs == 1) {
    out.k1 = sI, out.k2 = sII;
  }
  return out;
}

}  // namespace

void EnergyReleaseOptions::validate() const {
  const RangeCheck check("energy release");
  check(std::isfinite(domain_radius) && domain_radius > 0, "domain_radius", domain_radius, "> 0 m");
  check(inner_fraction >= 0 && inner_fraction < 1, "inner_fraction", inner_fraction, "[0, 1)");
  check(extension_fraction > 0 && extension_fraction <= 1e-2, "extension_fraction",
        extension_fraction, "(0, 1e-2]");
}

TipFracture energy_release(const mesh::SkinnedMesh& mesh, const SkinMaterial& material,
                           const Eigen::Ref<const Eigen::Matrix3Xd>& x, const CrackTip& tip,
                           const EnergyReleaseOptions& options) {
  options.validate();
  material.validate();
  if (tip.vertex < 0 || tip.vertex >= mesh.vertex_count() || x.cols() != mesh.vertex_count())
    throw std::invalid_argument("energy_release: tip vertex " + std::to_string(tip.vertex) +
                                " or positions (" + std::to_string(x.cols()) +
                                " columns) do not fit the mesh of " +
                                std::to_string(mesh.vertex_count()) + " vertices");
  const Eigen::Vector3d at = mesh.rest.col(tip.vertex);
  const Eigen::Vector3d normal = sheet_normal(mesh, tip.vertex);
  const Eigen::Vector3d e = (tip.direction - tip.direction.dot(normal) * normal).normalized();
  const Eigen::Vector3d n = normal.cross(e);
  const std::vector<double> q = domain_weights(mesh, at, options);
  const double delta = options.extension_fraction * options.domain_radius;
  TipFracture out;
  out.energy_release_rate = -energy_derivative(mesh, material, x, q, e, delta) / material.thickness;
  const double modulus = material.youngs_modulus;
  const Correlation c = displacement_correlation(mesh, x, modulus, at, e, n,
                                                 options.inner_fraction * options.domain_radius,
                                                 options.domain_radius);
  out.k1_correlation = c.k1;
  out.k2_correlation = c.k2;
  out.lip_pairs = c.pairs;
  out.mode_phase = c.pairs > 0 ? std::atan2(c.k2, c.k1) : 0.0;
  const double k = std::sqrt(modulus * std::max(0.0, out.energy_release_rate));
  out.k1 = k * std::cos(out.mode_phase);
  out.k2 = k * std::sin(out.mode_phase);
  return out;
}

Eigen::Vector3d sheet_normal(const mesh::SkinnedMesh& mesh, std::int32_t vertex) {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  for (const mesh::Face& f : mesh.faces)
    if (f[0] == vertex || f[1] == vertex || f[2] == vertex)
      n += (mesh.rest.col(f[1]) - mesh.rest.col(f[0]))
               .cross(mesh.rest.col(f[2]) - mesh.rest.col(f[0]));
  if (!(n.norm() > 0))
    throw std::invalid_argument("sheet_normal: vertex " + std::to_string(vertex) + " has no faces");
  return n.normalized();
}

double mts_kink_angle(double k1, double k2) {
  if (k2 == 0) return 0;
  return 2 * std::atan((k1 - std::sqrt(k1 * k1 + 8 * k2 * k2)) / (4 * k2));
}

}  // namespace conform::membrane
