// The constant-strain triangle of a pre-stressed St Venant-Kirchhoff membrane: energy,
// nodal gradient and the action of a positive semi-definite Hessian approximation.
//
// Rest triangle in its own 2D frame: Dm = [X1 - X0, X2 - X0] (2 x 2), B = Dm^-1, area A.
// Shape-function gradients beta_1 = B.row(0), beta_2 = B.row(1), beta_0 = -beta_1 - beta_2.
// Deformation gradient (3 x 2): F = sum_a x_a beta_a^T.
// Green strain E = (F^T F - I) / 2; second Piola-Kirchhoff stress (plane stress)
//   S = S0 + lambda tr(E) I + 2 mu E,
// with S0 the pre-stress of the rest configuration. Energy per unit rest area
//   psi = S0 : E + mu E : E + lambda tr(E)^2 / 2,     U = A t psi.
// Gradient: dU/dx_a = A t F S beta_a.
// Hessian action on dx: dF = sum_a dx_a beta_a^T, dE = sym(F^T dF), dS = lambda tr(dE) I +
//   2 mu dE, dP = dF S+ + F dS, d(dU/dx_a) = A t dP beta_a,
// where S+ is S with its negative eigenvalues set to 0: the material part dE : C : dE is
// positive semi-definite, and the geometric part tr(dF^T dF S+) is too, so Newton's steps are
// descent directions even where the membrane is in compression (the true Hessian is not PSD).
// Diagonal 3 x 3 block of node a:
//   K_aa = A t [ (beta_a^T S+ beta_a) I + mu |beta_a|^2 F F^T + (mu + lambda) (F beta_a)(F
//   beta_a)^T ].
// With wrinkling (tension_field.hpp) S is replaced by the relaxed S*, which is never
// compressive (S+ = S*), and psi by psi*. Where wrinkled, the material part of the blocks is
//   A t [ (k - lambda^2 / k) v_a v_b^T + 4 mu r u_a u_b^T ],
//   v_a = (beta_a . p) F p,  u_a = ((beta_a . m) F p + (beta_a . p) F m) / 2,
// from dE_pp = sum_b v_b . dx_b and dE_pm = sum_b u_b . dx_b; slack elements have none. The
// Hessian is then exact in all three regimes.
//
// The neo-Hookean law (ElementRest::law, detail/neo_hookean.hpp) replaces S, psi and dS by its
// own; F, P = F S, the gradient and the geometric part dF S+ are the same. Its taut material
// block, from dS = k [tr(Ci dE) Ci + Ci dE Ci], k = 2 mu / det Ch, Ci = C^-1, and
// dE = sym(F^T dx_b beta_b^T), with h_a = F Ci beta_a:
//   K_ab = A t [ (beta_a^T S+ beta_b) I + k h_a h_b^T + k/2 h_b h_a^T
//                + k/2 (beta_a^T Ci beta_b) F Ci F^T ];
// where wrinkled, the StVK blocks' v, u with p, m -> q, r (not unit) and the coefficients c1,
// 2 c2 in place of (k - lambda^2 / k), 4 mu r.
//
// The fibre-reinforced law adds its fibre term (detail/fibre.hpp) to the neo-Hookean element in
// every regime: S_f to S (so to P and S+), psi_f to psi, and to the material blocks, from
// q^T dE q = sum_b w_b . dx_b with w_b = (q . beta_b) F q,
//   K_ab += A t 4 psi_f'' w_a w_b^T.
#pragma once

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "conform/membrane/detail/element_rest.hpp"
#include "conform/membrane/detail/fibre.hpp"
#include "conform/membrane/detail/neo_hookean.hpp"
#include "conform/membrane/detail/tension_field.hpp"
#include "conform/membrane/skin_material.hpp"

namespace conform::membrane::detail {

inline Eigen::Vector2d beta_of(const ElementRest& e, int corner) {
  if (corner == 0) return -e.beta.col(0) - e.beta.col(1);
  return e.beta.col(corner - 1);
}

inline Mat32 deformation_gradient(const ElementRest& e, const Eigen::Vector3d& x0,
                                  const Eigen::Vector3d& x1, const Eigen::Vector3d& x2) {
  Mat32 ds;
  ds.col(0) = x1 - x0;
  ds.col(1) = x2 - x0;
  return ds * e.beta.transpose();  // F = Ds B, with B's rows beta_1^T, beta_2^T
}

inline Eigen::Matrix2d green_strain(const Mat32& f) {
  return 0.5 * (f.transpose() * f - Eigen::Matrix2d::Identity());
}

inline Eigen::Matrix2d pk2_stress(const ElementRest& e, const Eigen::Matrix2d& strain,
                                  double lambda, double mu) {
  return e.s0 + lambda * strain.trace() * Eigen::Matrix2d::Identity() + 2 * mu * strain;
}

/// psi (J/m^2) of a strain.
inline double energy_density(const ElementRest& e, const Eigen::Matrix2d& strain, double lambda,
                             double mu) {
  const double tr = strain.trace();
  return (e.s0.cwiseProduct(strain)).sum() + mu * strain.squaredNorm() + 0.5 * lambda * tr * tr;
}

/// S with negative eigenvalues clamped to zero (2 x 2 symmetric, closed form).
inline Eigen::Matrix2d positive_part(const Eigen::Matrix2d& s) {
  const double a = s(0, 0), b = 0.5 * (s(0, 1) + s(1, 0)), c = s(1, 1);
  const double mean = 0.5 * (a + c), radius = std::sqrt(0.25 * (a - c) * (a - c) + b * b);
  const double l1 = mean + radius, l2 = mean - radius;
  if (l2 >= 0) return s;
  if (l1 <= 0) return Eigen::Matrix2d::Zero();
  // Projector onto l1's eigenvector: (S - l2 I) / (l1 - l2).
  Eigen::Matrix2d sym;
  sym << a, b, b, c;
  return l1 * (sym - l2 * Eigen::Matrix2d::Identity()) / (l1 - l2);
}

/// Per-iteration data of one element at the current positions.
struct ElementState {
  Mat32 f;                 // deformation gradient
  Mat32 p;                 // first Piola-Kirchhoff stress F S (for the gradient)
  Eigen::Matrix2d stress;  // second Piola-Kirchhoff stress S
  double psi = 0;          // energy density, J/m^2
  Regime regime = Regime::taut;
  Eigen::Vector2d dir_p, dir_m;  // wrinkled: tension and compression directions (rest frame)
  double turn_ratio = 0;         // wrinkled: r
  Eigen::Matrix2d s_pos;         // S+ (for the Hessian; add_hessian_terms)
  Eigen::Matrix3d ff;  // F F^T (stvk), F Ci F^T (neo-Hookean, taut): shared by the blocks; ditto
  Eigen::Vector3d fp, fm;  // wrinkled: F p, F m (neo-Hookean: F q, F r) (ditto)
  SkinMaterial::Law law = SkinMaterial::Law::stvk;
  NeoHookeanTerms nh;                     // neo-Hookean: Ci, det Ch (taut)
  double wrinkle_c1 = 0, wrinkle_c2 = 0;  // neo-Hookean, wrinkled: c1, c2
  double fibre_stiffness = 0;             // fibre-reinforced: 4 psi_f'' (0: no fibre term)
};

/// Adds the fibre term (fibre.hpp) to S and psi of an element of the fibre-reinforced law.
inline void add_fibre(const ElementRest& e, const Eigen::Matrix2d& c, ElementState& s) {
  if (e.fibre_k1 <= 0) return;
  const FibreTerms t =
      fibre_terms(e.fibre, 0.5 * (c - Eigen::Matrix2d::Identity()), e.fibre_k1, e.fibre_k2);
  s.stress += t.stress * e.fibre * e.fibre.transpose();
  s.psi += t.energy;
  s.fibre_stiffness = t.stiffness;
}

/// The neo-Hookean element_forces (see neo_hookean.hpp): the relaxed state first, so that a
/// collapsed element (det C = 0, infinite taut energy) that is wrinkled or slack stays finite.
inline void neo_hookean_forces(const ElementRest& e, const Mat32& f, double mu, bool wrinkling,
                               ElementState& s) {
  s.law = e.law;
  s.f = f;
  const Eigen::Matrix2d c = f.transpose() * f;
  if (wrinkling) {
    const NeoHookeanRelaxation r = neo_hookean_relax(e.g, c, mu);
    if (r.regime != Regime::taut) {
      s.regime = r.regime;
      s.stress = r.stress;
      s.psi = r.energy;
      s.dir_p = r.q;
      s.dir_m = r.r;
      s.wrinkle_c1 = r.c1;
      s.wrinkle_c2 = r.c2;
      add_fibre(e, c, s);
      s.p = s.f * s.stress;
      return;
    }
  }
  s.nh = neo_hookean_terms(e.g, c);
  s.stress = neo_hookean_stress(e.g, s.nh, mu);
  s.psi = neo_hookean_energy(e.g, 0.5 * (c - Eigen::Matrix2d::Identity()), s.nh, mu);
  add_fibre(e, c, s);
  s.p = s.f * s.stress;
}

/// F, S, P and psi: what the energy and the gradient need; relaxed when `wrinkling`.
inline ElementState element_forces(const ElementRest& e, const Eigen::Vector3d& x0,
                                   const Eigen::Vector3d& x1, const Eigen::Vector3d& x2,
                                   double lambda, double mu, bool wrinkling) {
  ElementState s;  // one object on every path (returned in place)
  if (hyperelastic(e.law)) {
    neo_hookean_forces(e, deformation_gradient(e, x0, x1, x2), mu, wrinkling, s);
    return s;
  }
  s.f = deformation_gradient(e, x0, x1, x2);
  const Eigen::Matrix2d strain = green_strain(s.f);
  s.stress = pk2_stress(e, strain, lambda, mu);
  s.psi = energy_density(e, strain, lambda, mu);
  if (wrinkling) {
    const Relaxation r = relax_compression(s.stress, lambda, mu);
    s.regime = r.regime;
    s.stress = r.stress;
    s.psi -= r.energy_drop;
    s.dir_p = r.p;
    s.dir_m = r.m;
    s.turn_ratio = r.turn_ratio;
  }
  s.p = s.f * s.stress;
  return s;
}

/// S+, F F^T (and F p, F m where wrinkled) from F and S: what the Hessian blocks need.
inline void add_hessian_terms(ElementState& s) {
  s.s_pos = positive_part(s.stress);
  if (hyperelastic(s.law) && s.regime == Regime::taut)
    s.ff = s.f * s.nh.c_inv * s.f.transpose();
  else
    s.ff = s.f * s.f.transpose();
  if (s.regime == Regime::wrinkled) {
    s.fp = s.f * s.dir_p;
    s.fm = s.f * s.dir_m;
  }
}

inline ElementState element_state(const ElementRest& e, const Eigen::Vector3d& x0,
                                  const Eigen::Vector3d& x1, const Eigen::Vector3d& x2,
                                  double lambda, double mu, bool wrinkling) {
  ElementState s = element_forces(e, x0, x1, x2, lambda, mu, wrinkling);
  add_hessian_terms(s);
  return s;
}

/// Wrinkled material terms of corner a: v_a, u_a (see the header), and the coefficients
/// (k - lambda^2 / k) and 4 mu r.
struct WrinkledCorner {
  Eigen::Vector3d v, u;
};
inline WrinkledCorner wrinkled_corner(const ElementState& s, const Eigen::Vector2d& beta) {
  const double bp = beta.dot(s.dir_p), bm = beta.dot(s.dir_m);
  return {bp * s.fp, 0.5 * (bm * s.fp + bp * s.fm)};
}
inline double uniaxial_modulus(double lambda, double mu) {
  const double k = lambda + 2 * mu;
  return k - lambda * lambda / k;
}

/// Adds dP beta_a to corner a's out (beta_0 = -beta_1 - beta_2).
inline void add_corner_forces(const ElementRest& e, const Mat32& dp, Eigen::Vector3d& out0,
                              Eigen::Vector3d& out1, Eigen::Vector3d& out2) {
  const Eigen::Vector3d g1 = dp * e.beta.col(0), g2 = dp * e.beta.col(1);
  out1 += g1;
  out2 += g2;
  out0 += -g1 - g2;
}

/// The fibre term's share of the Hessian action, written to out0..out2 (zero without fibres):
/// A t 4 psi_f'' (q^T dE q) w_a, q^T dE q = (F q) . (dF q), w_a = (q . beta_a) F q.
inline void fibre_action(const ElementRest& e, const ElementState& s, const Mat32& df,
                         Eigen::Vector3d& out0, Eigen::Vector3d& out1, Eigen::Vector3d& out2) {
  out0.setZero();
  out1.setZero();
  out2.setZero();
  if (s.fibre_stiffness <= 0) return;
  const Eigen::Vector3d fq = s.f * e.fibre;
  const double c = e.area_thickness * s.fibre_stiffness * fq.dot(df * e.fibre);
  out0 = c * e.fibre.dot(beta_of(e, 0)) * fq;
  out1 = c * e.fibre.dot(beta_of(e, 1)) * fq;
  out2 = c * e.fibre.dot(beta_of(e, 2)) * fq;
}

/// Hessian approximation times (dx0, dx1, dx2): the three 3-vectors written to out0..out2.
inline void hessian_apply(const ElementRest& e, const ElementState& s, double lambda, double mu,
                          const Eigen::Vector3d& d0, const Eigen::Vector3d& d1,
                          const Eigen::Vector3d& d2, Eigen::Vector3d& out0, Eigen::Vector3d& out1,
                          Eigen::Vector3d& out2) {
  Mat32 ds;
  ds.col(0) = d1 - d0;
  ds.col(1) = d2 - d0;
  const Mat32 df = ds * e.beta.transpose();
  const bool nh = hyperelastic(s.law);
  fibre_action(e, s, df, out0, out1, out2);  // zero without fibres
  if (nh && s.regime == Regime::taut) {
    const Eigen::Matrix2d m = s.f.transpose() * df;
    const Mat32 dp =
        e.area_thickness *
        (df * s.s_pos + s.f * neo_hookean_tangent(s.nh, mu, 0.5 * (m + m.transpose())));
    add_corner_forces(e, dp, out0, out1, out2);
    return;
  }
  if (s.regime == Regime::taut) {
    const Eigen::Matrix2d m = s.f.transpose() * df;
    const Eigen::Matrix2d de = 0.5 * (m + m.transpose());
    const Eigen::Matrix2d dstress = lambda * de.trace() * Eigen::Matrix2d::Identity() + 2 * mu * de;
    const Mat32 dp = e.area_thickness * (df * s.s_pos + s.f * dstress);
    out1 = dp * e.beta.col(0);
    out2 = dp * e.beta.col(1);
    out0 = -out1 - out2;
    return;
  }
  const Mat32 dp = e.area_thickness * df * s.s_pos;  // geometric part (S+ = S*)
  add_corner_forces(e, dp, out0, out1, out2);
  if (s.regime == Regime::slack) return;
  const WrinkledCorner w[3] = {wrinkled_corner(s, beta_of(e, 0)), wrinkled_corner(s, beta_of(e, 1)),
                               wrinkled_corner(s, beta_of(e, 2))};
  const double de_pp = w[0].v.dot(d0) + w[1].v.dot(d1) + w[2].v.dot(d2);
  const double de_pm = w[0].u.dot(d0) + w[1].u.dot(d1) + w[2].u.dot(d2);
  const double cv = nh ? e.area_thickness * s.wrinkle_c1 * de_pp
                       : e.area_thickness * uniaxial_modulus(lambda, mu) * de_pp,
               cu = nh ? e.area_thickness * 2 * s.wrinkle_c2 * de_pm
                       : e.area_thickness * 4 * mu * s.turn_ratio * de_pm;
  out0 += cv * w[0].v + cu * w[0].u;
  out1 += cv * w[1].v + cu * w[1].u;
  out2 += cv * w[2].v + cu * w[2].u;
}

/// The neo-Hookean taut material block over A t (see the header):
///   k (h_a h_b^T + h_b h_a^T / 2 + (beta_a^T Ci beta_b) F Ci F^T / 2), h_a = F Ci beta_a.
inline Eigen::Matrix3d neo_hookean_block(const ElementState& s, double mu,
                                         const Eigen::Vector2d& ba, const Eigen::Vector2d& bb) {
  const double k = 2 * mu / s.nh.det_hat;
  const Eigen::Vector2d ca = s.nh.c_inv * ba;
  const Eigen::Vector3d ha = s.f * ca, hb = s.f * (s.nh.c_inv * bb);
  return k * (ha * hb.transpose() + 0.5 * hb * ha.transpose() + 0.5 * ca.dot(bb) * s.ff);
}

/// Block (a, b) of the Hessian approximation without the fibre term.
inline Eigen::Matrix3d matrix_block(const ElementRest& e, const ElementState& s, double lambda,
                                    double mu, const Eigen::Vector2d& ba,
                                    const Eigen::Vector2d& bb) {
  const Eigen::Matrix3d geometric = ba.dot(s.s_pos * bb) * Eigen::Matrix3d::Identity();
  if (s.regime == Regime::slack) return e.area_thickness * geometric;
  const bool nh = hyperelastic(s.law);
  if (s.regime == Regime::wrinkled) {
    const WrinkledCorner wa = wrinkled_corner(s, ba), wb = wrinkled_corner(s, bb);
    if (nh)
      return e.area_thickness * (geometric + s.wrinkle_c1 * wa.v * wb.v.transpose() +
                                 2 * s.wrinkle_c2 * wa.u * wb.u.transpose());
    return e.area_thickness * (geometric + uniaxial_modulus(lambda, mu) * wa.v * wb.v.transpose() +
                               4 * mu * s.turn_ratio * wa.u * wb.u.transpose());
  }
  if (nh) return e.area_thickness * (geometric + neo_hookean_block(s, mu, ba, bb));
  const Eigen::Vector3d fa = s.f * ba, fb = s.f * bb;
  return e.area_thickness * (geometric + mu * ba.dot(bb) * s.ff + mu * fb * fa.transpose() +
                             lambda * fa * fb.transpose());
}

/// Block (a, b) of the Hessian approximation (corners a, b in 0..2).
inline Eigen::Matrix3d hessian_block(const ElementRest& e, const ElementState& s, double lambda,
                                     double mu, int a, int b) {
  const Eigen::Vector2d ba = beta_of(e, a), bb = beta_of(e, b);
  const Eigen::Matrix3d block = matrix_block(e, s, lambda, mu, ba, bb);
  if (s.fibre_stiffness <= 0) return block;
  // The fibres' rank-one block, in every regime: A t 4 psi_f'' w_a w_b^T.
  const Eigen::Vector3d fq = s.f * e.fibre;
  return block + e.area_thickness * s.fibre_stiffness * e.fibre.dot(ba) * e.fibre.dot(bb) * fq *
                     fq.transpose();
}

/// hessian_upper_blocks of a taut neo-Hookean element: hessian_block's operations in its order
/// (so the same blocks bit for bit), with each corner's S+ beta_b, Ci beta_b and h_b computed
/// once instead of in every block that uses them.
inline void neo_hookean_upper_blocks(const ElementRest& e, const ElementState& s, double mu,
                                     Eigen::Matrix3d* out) {
  const double k = 2 * mu / s.nh.det_hat;
  Eigen::Vector2d beta[3], sb[3], cb[3];
  Eigen::Vector3d h[3];
  for (int a = 0; a < 3; ++a) {
    beta[a] = beta_of(e, a);
    sb[a] = s.s_pos * beta[a];
    cb[a] = s.nh.c_inv * beta[a];
    h[a] = s.f * cb[a];
  }
  const bool fibres = !(s.fibre_stiffness <= 0);
  const Eigen::Vector3d fq = fibres ? Eigen::Vector3d(s.f * e.fibre) : Eigen::Vector3d::Zero();
  int n = 0;
  for (int a = 0; a < 3; ++a)
    for (int b = a; b < 3; ++b, ++n) {
      const Eigen::Matrix3d geometric = beta[a].dot(sb[b]) * Eigen::Matrix3d::Identity();
      const Eigen::Matrix3d material =
          k * (h[a] * h[b].transpose() + 0.5 * h[b] * h[a].transpose() +
               0.5 * cb[a].dot(beta[b]) * s.ff);
      out[n] = e.area_thickness * (geometric + material);
      if (fibres)
        out[n] = out[n] + e.area_thickness * s.fibre_stiffness * e.fibre.dot(beta[a]) *
                              e.fibre.dot(beta[b]) * fq * fq.transpose();
    }
}

/// The element's six distinct blocks K_ab, a <= b, in the order (0,0), (0,1), (0,2), (1,1),
/// (1,2), (2,2) (the formula of hessian_block, with each corner's terms computed once); the
/// others are K_ba = K_ab^T, since S+ and F F^T are symmetric.
inline void hessian_upper_blocks(const ElementRest& e, const ElementState& s, double lambda,
                                 double mu, Eigen::Matrix3d* out) {
  if (s.regime == Regime::taut && hyperelastic(s.law)) {
    neo_hookean_upper_blocks(e, s, mu, out);
    return;
  }
  // The rare relaxed elements: block by block.
  if (s.regime != Regime::taut) {
    int k = 0;
    for (int a = 0; a < 3; ++a)
      for (int b = a; b < 3; ++b, ++k) out[k] = hessian_block(e, s, lambda, mu, a, b);
    return;
  }
  Eigen::Vector2d beta[3];
  Eigen::Vector3d f[3];
  for (int a = 0; a < 3; ++a) {
    beta[a] = beta_of(e, a);
    f[a] = s.f * beta[a];
  }
  int k = 0;
  for (int a = 0; a < 3; ++a) {
    const Eigen::Vector2d sba = s.s_pos * beta[a];
    for (int b = a; b < 3; ++b, ++k)
      out[k].noalias() =
          e.area_thickness *
          ((sba.dot(beta[b])) * Eigen::Matrix3d::Identity() + mu * beta[a].dot(beta[b]) * s.ff +
           mu * f[b] * f[a].transpose() + lambda * f[a] * f[b].transpose());
  }
}

}  // namespace conform::membrane::detail
