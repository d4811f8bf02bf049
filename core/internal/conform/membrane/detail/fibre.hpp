// The fibre term of the fibre-reinforced law, in the bind (rest) frame of a constant-strain
// triangle: one family of collagen fibres (Holzapfel, Gasser & Ogden, J Elasticity 61:1-48,
// 2000; the dispersed form of Gasser, Ogden & Holzapfel 2006 with kappa = 0), added to the
// neo-Hookean matrix of neo_hookean.hpp.
//
// The fibres lie along the first principal axis of the pre-stretch G (the pre-stress axis), so
// with a their unit direction on the stress-free state, G a = l1 a = q, and
//   I4 = a^T Ch a = q^T C q,   e = <I4 - 1>   (fibres carry no compression),
//   psi_f = k1 / (2 k2) (exp(k2 e^2) - 1)                       per unit volume (incompressible)
//   S_f = 2 dpsi_f/dC = 2 psi_f'(e) q q^T,        psi_f' = k1 e exp(k2 e^2)
//   dS_f = 4 psi_f''(e) (q^T dE q) q q^T,         psi_f'' = k1 (1 + 2 k2 e^2) exp(k2 e^2)
// for e > 0 (all zero otherwise): the tangent is rank one and positive semi-definite. It does
// not depend on the matrix's regime (taut, wrinkled or slack): the fibres act on the mean
// stretch of a wrinkled element.
// Energy relative to the bind state (e_b = <q^T q - 1>), without cancellation at small strain:
// e - e_b = 2 q^T E q when both are positive, so
//   psi_f - psi_f(bind) = k1 / (2 k2) exp(k2 e_b^2) expm1(k2 (e - e_b)(e + e_b)).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace conform::membrane::detail {

struct FibreTerms {
  double stress = 0;     // 2 psi_f', Pa: S_f = stress q q^T
  double stiffness = 0;  // 4 psi_f'', Pa: dS_f = stiffness (q^T dE q) q q^T
  double energy = 0;     // psi_f - psi_f(bind), J/m^3
};

/// The fibre term at Green strain E (bind frame) for fibres q = G a, k1 in Pa, k2 > 0.
inline FibreTerms fibre_terms(const Eigen::Vector2d& q, const Eigen::Matrix2d& strain, double k1,
                              double k2) {
  FibreTerms t;
  const double bind = q.squaredNorm() - 1, extra = 2 * q.dot(strain * q);
  const double e = bind + extra;
  const auto potential = [&](double x) {  // k1 / (2 k2) (exp(k2 x^2) - 1), x >= 0
    return k1 / (2 * k2) * std::expm1(k2 * x * x);
  };
  if (e > 0 && bind > 0)
    t.energy = k1 / (2 * k2) * std::exp(k2 * bind * bind) * std::expm1(k2 * extra * (e + bind));
  else
    t.energy = potential(std::max(e, 0.0)) - potential(std::max(bind, 0.0));
  if (e <= 0) return t;
  const double growth = std::exp(k2 * e * e);
  t.stress = 2 * k1 * e * growth;
  t.stiffness = 4 * k1 * (1 + 2 * k2 * e * e) * growth;
  return t;
}

}  // namespace conform::membrane::detail
