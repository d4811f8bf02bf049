// Tension-field relaxation (wrinkling) of the pre-stressed St Venant-Kirchhoff membrane.
//
// A membrane as thin as skin buckles out of its plane at almost no cost instead of carrying
// compression, so its energy is the relaxed one (Pipkin, "The relaxed energy density for
// isotropic elastic membranes", IMA J Appl Math 36:85-99, 1986):
//   psi*(E) = min over D >= 0 (positive semi-definite) of psi(E + D),
// the wrinkles taking up the strain D. psi is a convex quadratic in E, so psi* is convex, and by
// the envelope theorem dpsi*/dE = S(E + D*) =: S*, which is positive semi-definite: no
// compression is ever carried. With S = S(E) = s1 p p^T + s2 m m^T (s1 >= s2) and k = lambda + 2
// mu:
//   taut      s2 >= 0                          D = 0            S* = S        psi* = psi
//   wrinkled  s2 < 0 <= sigma = s1 - lambda s2 / k
//                                              D = -s2/k m m^T  S* = sigma p p^T
//                                                               psi* = psi - s2^2 / (2 k)
//   slack     sigma < 0                        D = -C^-1 S      S* = 0
//                                                               psi* = psi - S : C^-1 S / 2,
//   with C^-1 S = (S - lambda tr(S) I / (2 (lambda + mu))) / (2 mu).
// Material tangent dS*/dE while wrinkled (exact and positive semi-definite):
//   dS* = (k - lambda^2 / k) dE_pp p p^T + 2 mu r dE_pm (p m^T + m p^T),  r = sigma / (s1 - s2),
// the second term from p turning with S; r lies in [0, 1] because s2 < 0. Slack: dS* = 0.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>

namespace conform::membrane::detail {

enum class Regime : std::uint8_t { taut, wrinkled, slack };

struct Relaxation {
  Regime regime = Regime::taut;
  Eigen::Matrix2d stress;  // S*, Pa
  double energy_drop = 0;  // psi - psi*, J/m^2 (>= 0)
  Eigen::Vector2d p, m;    // S's tension and compression directions (wrinkled only)
  double turn_ratio = 0;   // r = sigma / (s1 - s2) (wrinkled only)
};

/// The relaxed stress and energy of a plane-stress StVK stress S (symmetric 2 x 2).
inline Relaxation relax_compression(const Eigen::Matrix2d& s, double lambda, double mu) {
  const double a = s(0, 0), b = 0.5 * (s(0, 1) + s(1, 0)), c = s(1, 1);
  Relaxation r;
  r.stress = s;
  if (a >= 0 && c >= 0 && a * c >= b * b) return r;  // positive semi-definite: taut
  const double mean = 0.5 * (a + c), radius = std::sqrt(0.25 * (a - c) * (a - c) + b * b);
  const double s1 = mean + radius, s2 = mean - radius;
  if (s2 >= 0) return r;
  const double k = lambda + 2 * mu, sigma = s1 - lambda * s2 / k;
  if (sigma < 0) {
    const double tr = a + c, s_s = a * a + 2 * b * b + c * c;
    r.regime = Regime::slack;
    r.stress.setZero();
    r.energy_drop = 0.5 * (s_s - lambda * tr * tr / (2 * (lambda + mu))) / (2 * mu);
    return r;
  }
  // s1 > s2 strictly here (s1 >= lambda s2 / k > s2), so p is well defined.
  const Eigen::Vector2d u(b, s1 - a), v(s1 - c, b);
  r.regime = Regime::wrinkled;
  r.p = (u.squaredNorm() >= v.squaredNorm() ? u : v).normalized();
  r.m = Eigen::Vector2d(-r.p.y(), r.p.x());
  r.stress = sigma * r.p * r.p.transpose();
  r.energy_drop = s2 * s2 / (2 * k);
  r.turn_ratio = sigma / (s1 - s2);
  return r;
}

}  // namespace conform::membrane::detail
