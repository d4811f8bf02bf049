// The neo-Hookean law's pre-stretch: the principal stretches l1, l2 of the stress-free state's
// map onto the bind state whose plane-stress Cauchy stress is the given pre-stress.
//
// With x_i = ln l_i the stresses are the gradient of a strictly convex function,
//   sigma_i(x) = mu (e^{2 x_i} - e^{-2 (x1 + x2)}) = dW/dx_i,
//   W = mu / 2 (e^{2 x1} + e^{2 x2} + e^{-2 (x1 + x2)}),
// so the stretches minimise Phi = W - sigma . x, which is coercive for any finite sigma: its
// Newton step is a descent direction of |dPhi/dx|^2 too, so Newton backtracking on the
// residual's norm (which, unlike Phi, does not stall in round-off near the root) converges
// from x = 0 (G = I). Hessian:
//   d2W/dx2 = 2 mu [[a + c, c], [c, b + c]],  a = l1^2, b = l2^2, c = 1 / (l1 l2)^2.
#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>
#include <string>

#include "conform/membrane/skin_material.hpp"

namespace conform::membrane {
namespace {

// The fibres' psi_f' and psi_f'' at e = a - 1 (zero for e <= 0 or without fibres).
struct FibreSlope {
  double first = 0, second = 0;
};
FibreSlope fibre_slope(const SkinMaterial& m, double a) {
  const double e = a - 1, k1 = m.fibre_stiffness, k2 = m.fibre_nonlinearity;
  if (m.law != SkinMaterial::Law::fibre_reinforced || e <= 0) return {};
  const double growth = std::exp(k2 * e * e);
  return {k1 * e * growth, k1 * (1 + 2 * k2 * e * e) * growth};
}

Eigen::Vector2d residual(const SkinMaterial& m, const Eigen::Vector2d& x,
                         const Eigen::Vector2d& sigma) {
  const double mu = m.neo_hookean_mu(), a = std::exp(2 * x[0]);
  const double c = std::exp(-2 * (x[0] + x[1]));
  return mu * Eigen::Vector2d(a - c, std::exp(2 * x[1]) - c) +
         Eigen::Vector2d(2 * a * fibre_slope(m, a).first, 0) - sigma;
}

}  // namespace

std::array<double, 2> neo_hookean_prestretch(const SkinMaterial& material) {
  const double mu = material.neo_hookean_mu();
  const Eigen::Vector2d sigma(material.prestress[0], material.prestress[1]);
  Eigen::Vector2d x = Eigen::Vector2d::Zero();
  const double tolerance = 1e-14 * (mu + material.fibre_stiffness + sigma.cwiseAbs().maxCoeff());
  for (int it = 0; it < 200; ++it) {
    const Eigen::Vector2d r = residual(material, x, sigma);
    if (r.cwiseAbs().maxCoeff() <= tolerance) return {std::exp(x[0]), std::exp(x[1])};
    const double a = std::exp(2 * x[0]), b = std::exp(2 * x[1]), c = std::exp(-2 * (x[0] + x[1]));
    Eigen::Matrix2d hessian;
    hessian << a + c, c, c, b + c;
    hessian *= 2 * mu;
    const FibreSlope f = fibre_slope(material, a);
    hessian(0, 0) += 4 * a * a * f.second + 4 * a * f.first;
    const Eigen::Vector2d step = -hessian.ldlt().solve(r);
    double t = 1;
    while (t > 1e-6 && residual(material, x + t * step, sigma).norm() >= r.norm()) t *= 0.5;
    x += t * step;
  }
  throw std::runtime_error("neo_hookean_prestretch: Newton did not converge for prestress [" +
                           std::to_string(sigma[0]) + ", " + std::to_string(sigma[1]) + "] Pa");
}

}  // namespace conform::membrane
