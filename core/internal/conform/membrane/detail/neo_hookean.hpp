// The incompressible neo-Hookean membrane law, pre-stretched, in the bind (rest) frame of a
// constant-strain triangle: its stress, tangent and tension-field relaxation.
//
// Notation: Ch, Sh are quantities on the stress-free state ("C hat"); C = F^T F, E = (C - I) / 2
// and S on the bind frame; Ci = C^-1.
// Per unit volume of the stress-free state, with Ch the 2 x 2 right Cauchy-Green tensor in the
// membrane's plane (the thickness stretch is 1 / sqrt(det Ch): incompressibility),
//   psi = mu / 2 (tr Ch + 1 / det Ch - 3),   Sh = 2 dpsi/dCh = mu (I - Ch^-1 / det Ch).
// Pre-stress at finite strain: a symmetric pre-stretch G (principal stretches l1, l2) maps the
// stress-free state onto the bind state, so Ch = G C G. Volumes are conserved, so the energy
// per bind volume A t is psi too, and
//   dpsi = Sh : dCh / 2 = (G Sh G) : dE,  so  S = G Sh G = mu (G^2 - Ci / det Ch),
// since G Ch^-1 G = G (G C G)^-1 G = Ci. Tangent, from dCi = -Ci dC Ci and
// d(det Ch) = det Ch tr(Ci dC), dC = 2 dE:
//   dS = (2 mu / det Ch) [ tr(Ci dE) Ci + Ci dE Ci ],
//   dE : dS = (2 mu / det Ch) [ tr(Ci dE)^2 + |Ci^1/2 dE Ci^1/2|^2 ] >= 0: positive
//   semi-definite everywhere; G enters only through det Ch = det(G)^2 det C.
// Energy relative to the bind state (zero there, like the StVK law's), written so that it does
// not cancel at small strain (tr Ch - tr G^2 = 2 G^2 : E, 1 - det C = -2 tr E - 4 det E):
//   psi - psi(I) = mu [ G^2 : E - (tr E + 2 det E) / det Ch ].
// At small strain with G = I this is mu (tr E)^2 + mu E : E: plane-stress linear elasticity
// with lambda = 2 mu and mu = E_Young / 3, i.e. Poisson's ratio 1/2.
//
// Tension field (Pipkin 1986), with Ch's eigenvalues L1 >= L2 and l1 = sqrt(L1): the natural
// width of uniaxial tension l1 is l1^-1/2 (incompressible neo-Hookean), so
//   taut      L2 l1 >= 1 (Sh positive semi-definite)   psi* = psi
//   wrinkled  l1 > 1 and L2 l1 < 1                    psi* = mu/2 (L1 + 2/l1 - 3)
//   slack     l1 <= 1                                 psi* = 0
// Wrinkled: Sh* = mu (1 - l1^-3) ph ph^T (ph the unit eigenvector of L1, mh across it), so
//   S* = mu (1 - l1^-3) q q^T, q = G ph, r = G mh,
//   dS* = c1 dE_qq q q^T + c2 dE_qr (q r^T + r q^T), dE_qq = q^T dE q, dE_qr = q^T dE r,
//   c1 = 3 mu / l1^5 (from dl1 = dE_qq / l1), c2 = 2 mu (1 - l1^-3) / (L1 - L2) (ph turning),
// both positive (L1 > 1 > L2), so the relaxed tangent is positive semi-definite and exact.
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "conform/membrane/detail/tension_field.hpp"

namespace conform::membrane::detail {

/// Ci and det Ch of one element at one state: what the stress and the tangent share.
struct NeoHookeanTerms {
  Eigen::Matrix2d c_inv;  // Ci = (F^T F)^-1
  double det_hat = 1;     // det Ch = det(G)^2 det C
};

inline NeoHookeanTerms neo_hookean_terms(const Eigen::Matrix2d& g, const Eigen::Matrix2d& c) {
  const double det_c = c.determinant(), det_g = g.determinant();
  NeoHookeanTerms t;
  t.c_inv << c(1, 1), -c(0, 1), -c(1, 0), c(0, 0);
  t.c_inv /= det_c;
  t.det_hat = det_g * det_g * det_c;
  return t;
}

/// S = mu (G^2 - Ci / det Ch), Pa.
inline Eigen::Matrix2d neo_hookean_stress(const Eigen::Matrix2d& g, const NeoHookeanTerms& t,
                                          double mu) {
  return mu * (g * g - t.c_inv / t.det_hat);
}

/// psi - psi(bind) = mu [G^2 : E - (tr E + 2 det E) / det Ch], J/m^3.
inline double neo_hookean_energy(const Eigen::Matrix2d& g, const Eigen::Matrix2d& strain,
                                 const NeoHookeanTerms& t, double mu) {
  return mu * ((g * g).cwiseProduct(strain).sum() -
               (strain.trace() + 2 * strain.determinant()) / t.det_hat);
}

/// dS = (2 mu / det Ch) [tr(Ci dE) Ci + Ci dE Ci] of a symmetric dE.
inline Eigen::Matrix2d neo_hookean_tangent(const NeoHookeanTerms& t, double mu,
                                           const Eigen::Matrix2d& de) {
  const Eigen::Matrix2d cde = t.c_inv * de;
  return (2 * mu / t.det_hat) * (cde.trace() * t.c_inv + cde * t.c_inv);
}

/// The relaxed state of the law (tension field): regime, S*, psi*, and where wrinkled q, r and
/// the tangent's coefficients c1, c2 (see the header). Taut: only the regime is set.
struct NeoHookeanRelaxation {
  Regime regime = Regime::taut;
  Eigen::Matrix2d stress;  // S*, Pa
  double energy = 0;       // psi* - psi(bind), J/m^3, psi(bind) = mu/2 (tr G^2 + 1/det G^2 - 3)
  Eigen::Vector2d q, r;    // wrinkled: G ph, G mh
  double c1 = 0, c2 = 0;   // wrinkled: the tangent's coefficients, Pa
};

inline NeoHookeanRelaxation neo_hookean_relax(const Eigen::Matrix2d& g, const Eigen::Matrix2d& c,
                                              double mu) {
  NeoHookeanRelaxation out;
  const Eigen::Matrix2d ch = g * c * g;
  const double a = ch(0, 0), b = 0.5 * (ch(0, 1) + ch(1, 0)), d = ch(1, 1);
  const double mean = 0.5 * (a + d), radius = std::sqrt(0.25 * (a - d) * (a - d) + b * b);
  const double big = mean + radius, small = mean - radius, l1 = std::sqrt(big);
  if (small * l1 >= 1) return out;  // taut
  const double det_g = g.determinant();
  const double bind = 0.5 * mu * ((g * g).trace() + 1 / (det_g * det_g) - 3);
  if (l1 <= 1) {
    out.regime = Regime::slack;
    out.stress.setZero();
    out.energy = -bind;
    return out;
  }
  // big > 1 > small here, so the eigenvector of big is well defined.
  const Eigen::Vector2d u(b, big - a), v(big - d, b);
  const Eigen::Vector2d p = (u.squaredNorm() >= v.squaredNorm() ? u : v).normalized();
  const Eigen::Vector2d m(-p.y(), p.x());
  out.regime = Regime::wrinkled;
  out.q = g * p;
  out.r = g * m;
  const double tension = mu * (1 - 1 / (big * l1));
  out.stress = tension * out.q * out.q.transpose();
  out.energy = 0.5 * mu * (big + 2 / l1 - 3) - bind;
  out.c1 = 3 * mu / (big * big * l1);
  out.c2 = 2 * tension / (big - small);
  return out;
}

}  // namespace conform::membrane::detail
