// The tension-field (wrinkling) relaxation of the membrane element: the relaxed energy is the
// minimum of the plain energy over every wrinkle strain D >= 0 (checked by sampling D, not by
// the closed form), its stress is never compressive, and the element's gradient and Hessian are
// the derivatives of the relaxed energy in each of the three regimes (finite differences).
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <array>
#include <random>

#include "conform/membrane/detail/cst_kernel.hpp"
#include "conform/membrane/model.hpp"

namespace conform::membrane {
namespace {

using detail::Regime;

// The StVK law's tension field (detail/tension_field.hpp), which these tests check; the
// neo-Hookean relaxation's derivatives are checked in membrane_law_test.
SkinMaterial anisotropic() {
  SkinMaterial m;
  m.law = SkinMaterial::Law::stvk;
  m.prestress = {60e3, 20e3};
  m.prestress_axis = Eigen::Vector3d(0.3, 1, 0.2);
  return m;
}

struct Triangle {
  Eigen::Matrix3Xd rest{3, 3}, x{3, 3};
  std::vector<mesh::Face> faces{{0, 1, 2}};
};

// A rest triangle and a deformation: stretch `along` its first edge's direction, `across` in
// the plane, then a random rotation and a small random perturbation.
Triangle deformed_triangle(std::mt19937& rng, double along, double across) {
  std::uniform_real_distribution<double> u(-1, 1);
  Triangle t;
  t.rest << 0, 0.01, 0.003, 0, 0.001, 0.011, 0, 0.0005, -0.001;
  for (int i = 0; i < 9; ++i) t.rest(i % 3, i / 3) += 0.001 * u(rng);
  const Eigen::Vector3d e1 = (t.rest.col(1) - t.rest.col(0)).normalized();
  const Eigen::Vector3d n = e1.cross(t.rest.col(2) - t.rest.col(0)).normalized();
  const Eigen::Vector3d e2 = n.cross(e1);
  const Eigen::Matrix3d stretch =
      along * e1 * e1.transpose() + across * e2 * e2.transpose() + n * n.transpose();
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(u(rng) * 3, Eigen::Vector3d(u(rng), u(rng), 1).normalized())
          .toRotationMatrix();
  t.x = r * stretch * t.rest;
  for (int i = 0; i < 9; ++i) t.x(i % 3, i / 3) += 2e-5 * u(rng);
  return t;
}

detail::ElementState state_of(const Model& model, const Triangle& t) {
  return detail::element_state(model.elements()[0], t.x.col(0), t.x.col(1), t.x.col(2),
                               model.lambda(), model.mu(), true);
}

// The deformations of the three regimes under the anisotropic pre-stress.
constexpr std::array<std::array<double, 2>, 6> kCases = {
    {{1.04, 1.03}, {1.1, 0.98}, {1.05, 0.75}, {0.8, 1.02}, {0.7, 0.72}, {0.6, 0.8}}};

// Trial `trial`'s triangle (cycling through kCases), its element and its relaxed state.
struct Sample {
  Triangle t;
  Model model;
  detail::ElementState s;
  Sample(std::mt19937& rng, int trial) {
    const auto c = kCases[std::size_t(trial) % kCases.size()];
    t = deformed_triangle(rng, c[0], c[1]);
    model.build(t.rest, t.faces, anisotropic());
    s = state_of(model, t);
  }
};

TEST(MembraneWrinkling, RelaxedEnergyIsTheMinimumOverWrinkleStrains) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  int seen[3] = {0, 0, 0};
  for (int trial = 0; trial < 60; ++trial) {
    const Sample sample(rng, trial);
    const Model& model = sample.model;
    const detail::ElementRest& e = model.elements()[0];
    const detail::ElementState& s = sample.s;
    ++seen[int(s.regime)];
    const Eigen::Matrix2d strain = detail::green_strain(s.f);
    const double plain = detail::energy_density(e, strain, model.lambda(), model.mu());
    EXPECT_LE(s.psi, plain + 1e-9 * std::abs(plain));
    // No compression: S* is positive semi-definite.
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(s.stress);
    EXPECT_GE(eig.eigenvalues().minCoeff(), -1e-9 * s.stress.norm() - 1e-9);
    // psi(E + D) >= psi* for sampled D >= 0 ...
    for (int k = 0; k < 500; ++k) {
      Eigen::Matrix2d l;
      l << u(rng), 0, u(rng), u(rng);
      const Eigen::Matrix2d d = 0.4 * std::abs(u(rng)) * l * l.transpose();
      const double psi = detail::energy_density(e, strain + d, model.lambda(), model.mu());
      EXPECT_GE(psi, s.psi - 1e-9 * std::abs(plain) - 1e-9) << trial;
    }
    // ... and projected gradient descent over D >= 0 (an independent minimiser) reaches psi*.
    Eigen::Matrix2d d = Eigen::Matrix2d::Zero();
    const double rate = 1 / (2 * (model.lambda() + model.mu()));  // 1 / C's largest eigenvalue
    for (int k = 0; k < 2000; ++k) {
      d -= rate * detail::pk2_stress(e, strain + d, model.lambda(), model.mu());
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> de(0.5 * (d + d.transpose()));
      d = de.eigenvectors() * de.eigenvalues().cwiseMax(0).asDiagonal() *
          de.eigenvectors().transpose();
    }
    const double descent = detail::energy_density(e, strain + d, model.lambda(), model.mu());
    EXPECT_NEAR(descent, s.psi, 1e-7 * std::abs(plain) + 1e-9) << trial;
  }
  EXPECT_GT(seen[int(Regime::taut)], 5);
  EXPECT_GT(seen[int(Regime::wrinkled)], 5);
  EXPECT_GT(seen[int(Regime::slack)], 5);
}

TEST(MembraneWrinkling, GradientAndHessianAreTheDerivativesInEveryRegime) {
  std::mt19937 rng(9);
  int seen[3] = {0, 0, 0};
  for (int trial = 0; trial < 60; ++trial) {
    const Sample sample(rng, trial);
    const Triangle& t = sample.t;
    const Model& model = sample.model;
    const detail::ElementRest& e = model.elements()[0];
    const detail::ElementState& s = sample.s;
    ++seen[int(s.regime)];
    Eigen::Matrix3Xd g(3, 3);
    model.gradient(t.x, g);
    const double h = 1e-8, scale = g.cwiseAbs().maxCoeff();
    for (int i = 0; i < 9; ++i) {
      Eigen::Matrix3Xd plus = t.x, minus = t.x;
      plus(i % 3, i / 3) += h;
      minus(i % 3, i / 3) -= h;
      const double fd = (model.energy(plus) - model.energy(minus)) / (2 * h);
      EXPECT_NEAR(g(i % 3, i / 3), fd, 1e-5 * scale + 1e-9) << trial << " " << i;
    }
    // The Hessian action against differences of the gradient, and its blocks against it.
    const Eigen::Matrix3Xd d = Eigen::Matrix3Xd::Random(3, 3);
    Eigen::Vector3d o[3];
    detail::hessian_apply(e, s, model.lambda(), model.mu(), d.col(0), d.col(1), d.col(2), o[0],
                          o[1], o[2]);
    const double step = 1e-8;
    Eigen::Matrix3Xd gp(3, 3), gm(3, 3);
    model.gradient(t.x + step * d, gp);
    model.gradient(t.x - step * d, gm);
    const Eigen::Matrix3Xd fd = (gp - gm) / (2 * step);
    Eigen::Matrix3Xd out(3, 3);
    out << o[0], o[1], o[2];
    EXPECT_LT((out - fd).norm(), 1e-4 * fd.norm() + 1e-6) << trial << " regime " << int(s.regime);
    Eigen::Matrix3d upper[6];
    detail::hessian_upper_blocks(e, s, model.lambda(), model.mu(), upper);
    Eigen::Vector3d sum[3] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                              Eigen::Vector3d::Zero()};
    constexpr int kPair[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
    for (int k = 0; k < 6; ++k) {
      const int a = kPair[k][0], b = kPair[k][1];
      sum[a] += upper[k] * d.col(b);
      if (a != b) sum[b] += upper[k].transpose() * d.col(a);
    }
    for (int a = 0; a < 3; ++a) EXPECT_LT((sum[a] - o[a]).norm(), 1e-9 * out.norm() + 1e-12);
  }
  EXPECT_GT(seen[int(Regime::wrinkled)], 5);
  EXPECT_GT(seen[int(Regime::slack)], 5);
}

TEST(MembraneWrinkling, OffKeepsTheCompressionAndTheSameTautElement) {
  std::mt19937 rng(13);
  const Triangle t = deformed_triangle(rng, 1.05, 0.75);
  SkinMaterial plain = anisotropic();
  plain.wrinkling = false;
  Model relaxed, compressive;
  relaxed.build(t.rest, t.faces, anisotropic());
  compressive.build(t.rest, t.faces, plain);
  EXPECT_LT(relaxed.energy(t.x), compressive.energy(t.x));
  const Triangle taut = deformed_triangle(rng, 1.04, 1.03);
  EXPECT_DOUBLE_EQ(relaxed.energy(taut.x), compressive.energy(taut.x));
}

}  // namespace
}  // namespace conform::membrane
