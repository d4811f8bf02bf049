// The membrane's constitutive laws: the incompressible neo-Hookean law against its closed
// forms (plane stress, det F_3D = 1, so the in-plane Cauchy stress is F S F^T), its small-strain
// limit (linear elasticity with nu = 1/2), its pre-stretch, and both laws' gradient and Hessian
// against finite differences of the energy. References are computed here from the settings.
#include <gtest/gtest.h>

#include <random>

#include "conform/membrane/detail/cst_kernel.hpp"
#include "conform/membrane/model.hpp"

namespace conform::membrane {
namespace {

using Law = SkinMaterial::Law;

struct Triangle {
  Eigen::Matrix3Xd rest{3, 3}, x{3, 3};
  std::vector<mesh::Face> faces{{0, 1, 2}};
};

// A right triangle in the xy plane: the element's frame is (x, y).
Triangle right_triangle() {
  Triangle t;
  t.rest << 0, 0.01, 0, 0, 0, 0.01, 0, 0, 0;
  t.x = t.rest;
  return t;
}

SkinMaterial unstressed(Law law) {
  SkinMaterial m;
  m.law = law;
  m.prestress = {0, 0};
  m.wrinkling = false;
  return m;
}

// The in-plane Cauchy stress (x, y block) of the element at positions x.
Eigen::Matrix2d cauchy(const Model& model, const Eigen::Matrix3Xd& x) {
  const detail::ElementState s =
      detail::element_forces(model.elements()[0], x.col(0), x.col(1), x.col(2), model.lambda(),
                             model.mu(), model.wrinkling());
  return (s.f * s.stress * s.f.transpose()).topLeftCorner<2, 2>();
}

Eigen::Matrix3Xd stretched(const Triangle& t, double sx, double sy) {
  Eigen::Matrix3Xd x = t.rest;
  x.row(0) *= sx;
  x.row(1) *= sy;
  return x;
}

TEST(MembraneLaw, NeoHookeanEquibiaxialStretchGivesTheClosedForm) {
  const Triangle t = right_triangle();
  Model model;
  model.build(t.rest, t.faces, unstressed(Law::neo_hookean));
  const double mu = model.material().youngs_modulus / 3;
  EXPECT_EQ(model.mu(), mu);
  for (const double l : {1.05, 1.2, 1.35, 1.5}) {
    const Eigen::Matrix2d s = cauchy(model, stretched(t, l, l));
    const double expected = mu * (l * l - std::pow(l, -4));  // sigma = mu (l^2 - l^-4)
    EXPECT_NEAR(s(0, 0), expected, 1e-6 * expected) << l;
    EXPECT_NEAR(s(1, 1), expected, 1e-6 * expected) << l;
    EXPECT_NEAR(s(0, 1), 0, 1e-9 * expected) << l;
  }
}

// Uniaxial stretch l along x (along_x) or y with a free width: the width w that makes the
// energy stationary in it (the other Cauchy stress 0, by bisection: it grows with the width),
// and the Cauchy stress along the stretch there.
struct Uniaxial {
  double width = 0, stress = 0;
};
Uniaxial uniaxial(const Model& model, const Triangle& t, double l, bool along_x) {
  const auto at = [&](double w) {
    return cauchy(model, along_x ? stretched(t, l, w) : stretched(t, w, l));
  };
  const int across = along_x ? 1 : 0, along = 1 - across;
  double lo = 0.3, hi = 1.0;
  for (int i = 0; i < 200 && hi - lo > 1e-15; ++i) {
    const double w = 0.5 * (lo + hi);
    (at(w)(across, across) > 0 ? hi : lo) = w;
  }
  const double w = 0.5 * (lo + hi);
  return {w, at(w)(along, along)};
}

TEST(MembraneLaw, NeoHookeanUniaxialStretchWithAFreeWidthGivesTheClosedForm) {
  const Triangle t = right_triangle();
  Model model;
  model.build(t.rest, t.faces, unstressed(Law::neo_hookean));
  const double mu = model.mu();
  for (const double l : {1.05, 1.2, 1.35, 1.5}) {
    const double w = uniaxial(model, t, l, true).width;
    EXPECT_NEAR(w, 1 / std::sqrt(l), 1e-9) << l;   // the natural width l^-1/2
    const double expected = mu * (l * l - 1 / l);  // sigma = mu (l^2 - 1/l)
    EXPECT_NEAR(cauchy(model, stretched(t, l, w))(0, 0), expected, 1e-6 * expected) << l;
  }
}

TEST(MembraneLaw, NeoHookeanIsLinearElasticityWithPoissonHalfAtSmallStrain) {
  const Triangle t = right_triangle();
  Model model;
  model.build(t.rest, t.faces, unstressed(Law::neo_hookean));
  const double young = model.material().youngs_modulus, nu = 0.5;
  for (const double eps : {1e-6, 1e-5, 1e-4})
    for (const double ratio : {0.3, -0.7, 1.0}) {
      const double ex = eps, ey = ratio * eps;
      const Eigen::Matrix2d s = cauchy(model, stretched(t, 1 + ex, 1 + ey));
      const double sx = young / (1 - nu * nu) * (ex + nu * ey),
                   sy = young / (1 - nu * nu) * (ey + nu * ex);
      // The law's departure from linearity is of order eps relative (tolerance 10 eps).
      const double tol = 10 * eps * std::max(std::abs(sx), std::abs(sy));
      EXPECT_NEAR(s(0, 0), sx, tol) << eps << " " << ratio;
      EXPECT_NEAR(s(1, 1), sy, tol) << eps << " " << ratio;
    }
}

// The pre-stresses the pre-stretch tests try, Pa.
constexpr std::array<std::array<double, 2>, 4> kPrestresses = {
    {{80.8e3, 80.8e3}, {60e3, 20e3}, {0, 150e3}, {840e3, 10e3}}};

// The law, unstressed but for `sigma`, with its axis at 45 degrees in the element's frame.
SkinMaterial prestressed_at_45(Law law, const std::array<double, 2>& sigma) {
  SkinMaterial m = unstressed(law);
  m.prestress = sigma;
  m.prestress_axis = Eigen::Vector3d(1, 1, 0);
  return m;
}

// Unloaded (x = rest, F = I) the Cauchy stress should be the pre-stress, s1 a a^T + s2 b b^T:
// the largest difference, Pa.
double bind_stress_error(const Triangle& t, const SkinMaterial& m) {
  Model model;
  model.build(t.rest, t.faces, m);
  const Eigen::Vector2d a = Eigen::Vector2d(1, 1).normalized(), b(-a.y(), a.x());
  const Eigen::Matrix2d expected =
      m.prestress[0] * a * a.transpose() + m.prestress[1] * b * b.transpose();
  return (cauchy(model, t.rest) - expected).cwiseAbs().maxCoeff();
}

TEST(MembraneLaw, PrestretchReproducesThePrestressOfTheBindState) {
  const Triangle t = right_triangle();
  for (const std::array<double, 2>& sigma : kPrestresses) {
    const SkinMaterial m = prestressed_at_45(Law::neo_hookean, sigma);
    const std::array<double, 2> l = neo_hookean_prestretch(m);
    const double mu = m.neo_hookean_mu(), c = 1 / std::pow(l[0] * l[1], 2);
    EXPECT_NEAR(mu * (l[0] * l[0] - c), sigma[0], 1e-12 * mu);
    EXPECT_NEAR(mu * (l[1] * l[1] - c), sigma[1], 1e-12 * mu);
    EXPECT_LT(bind_stress_error(t, m), 1e-12 * mu);
  }
  EXPECT_EQ(neo_hookean_prestretch(unstressed(Law::neo_hookean)), (std::array<double, 2>{1, 1}));
}

TEST(MembraneLaw, NeoHookeanIsTheDefaultAndTheRangesFollowTheLaw) {
  EXPECT_EQ(SkinMaterial{}.law, Law::neo_hookean);
  SkinMaterial m;
  m.law = Law::stvk;
  m.prestress = {2 * m.youngs_modulus, 0};
  EXPECT_THROW(m.validate(), std::invalid_argument);  // StVK: below E
  m.law = Law::neo_hookean;
  EXPECT_NO_THROW(m.validate());  // any finite tension is reachable
  m.prestress = {-1, 0};
  EXPECT_THROW(m.validate(), std::invalid_argument);
}

// ---- Gradient and Hessian against finite differences of the energy -------------------------

Triangle random_triangle(std::mt19937& rng, double sx, double sy) {
  std::uniform_real_distribution<double> u(-1, 1);
  Triangle t;
  t.rest << 0, 0.01, 0.002, 0, 0.001, 0.012, 0, 0.0005, -0.001;
  for (int i = 0; i < 9; ++i) t.rest(i % 3, i / 3) += 0.002 * u(rng);
  t.x = t.rest;
  t.x.row(0) *= sx;
  t.x.row(1) *= sy;
  for (int i = 0; i < 9; ++i) t.x(i % 3, i / 3) += 0.0005 * u(rng);
  return t;
}

SkinMaterial prestressed(Law law, bool wrinkling) {
  SkinMaterial m;
  m.law = law;
  m.prestress = {60e3, 20e3};
  m.prestress_axis = Eigen::Vector3d(0.3, 1, 0.2);
  m.wrinkling = wrinkling;
  return m;
}

// Checks one element's gradient against the energy and its Hessian (action, blocks, upper
// blocks) against the gradient, by central differences; returns the element's regime.
detail::Regime check_derivatives(const Triangle& t, const SkinMaterial& material) {
  Model model;
  model.build(t.rest, t.faces, material);
  Eigen::Matrix3Xd g(3, 3), gp(3, 3), gm(3, 3);
  model.gradient(t.x, g);
  const double h = 1e-8, scale = g.cwiseAbs().maxCoeff();
  for (int i = 0; i < 9; ++i) {
    Eigen::Matrix3Xd plus = t.x, minus = t.x;
    plus(i % 3, i / 3) += h;
    minus(i % 3, i / 3) -= h;
    const double fd = (model.energy(plus) - model.energy(minus)) / (2 * h);
    EXPECT_NEAR(g(i % 3, i / 3), fd, 1e-6 * scale) << i;
  }
  const detail::ElementRest& e = model.elements()[0];
  const detail::ElementState state = detail::element_state(
      e, t.x.col(0), t.x.col(1), t.x.col(2), model.lambda(), model.mu(), model.wrinkling());
  Eigen::Matrix3d upper[6];
  detail::hessian_upper_blocks(e, state, model.lambda(), model.mu(), upper);
  Eigen::Matrix<double, 9, 9> k_fd, k_apply, k_block;
  const double step = 1e-7;
  for (int j = 0; j < 9; ++j) {
    Eigen::Matrix3Xd plus = t.x, minus = t.x, unit = Eigen::Matrix3Xd::Zero(3, 3);
    plus(j % 3, j / 3) += step;
    minus(j % 3, j / 3) -= step;
    unit(j % 3, j / 3) = 1;
    model.gradient(plus, gp);
    model.gradient(minus, gm);
    const Eigen::Matrix3Xd column = (gp - gm) / (2 * step);
    k_fd.col(j) = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(column.data());
    Eigen::Vector3d o[3];
    detail::hessian_apply(e, state, model.lambda(), model.mu(), unit.col(0), unit.col(1),
                          unit.col(2), o[0], o[1], o[2]);
    for (int a = 0; a < 3; ++a) k_apply.block<3, 1>(3 * a, j) = o[a];
  }
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      k_block.block<3, 3>(3 * a, 3 * b) =
          detail::hessian_block(e, state, model.lambda(), model.mu(), a, b);
  int k = 0;
  for (int a = 0; a < 3; ++a)
    for (int b = a; b < 3; ++b, ++k)
      EXPECT_LE((upper[k] - k_block.block<3, 3>(3 * a, 3 * b)).norm(), 1e-12 * k_block.norm());
  const double kscale = k_fd.cwiseAbs().maxCoeff();
  EXPECT_LE((k_apply - k_fd).cwiseAbs().maxCoeff(), 1e-5 * kscale);
  EXPECT_LE((k_block - k_apply).cwiseAbs().maxCoeff(), 1e-12 * kscale);
  return state.regime;
}

TEST(MembraneLaw, BothLawsDerivativesMatchFiniteDifferencesWhenTaut) {
  std::mt19937 rng(5);
  for (const Law law : {Law::stvk, Law::neo_hookean, Law::fibre_reinforced})
    for (int trial = 0; trial < 10; ++trial) {
      const double s = 1.02 + 0.05 * trial;  // up to 47 % stretch
      const Triangle t = random_triangle(rng, s, s);
      for (const bool wrinkling : {false, true}) {
        SCOPED_TRACE(testing::Message()
                     << "law " << int(law) << " trial " << trial << " wrinkling " << wrinkling);
        EXPECT_EQ(check_derivatives(t, prestressed(law, wrinkling)), detail::Regime::taut);
      }
    }
}

TEST(MembraneLaw, NeoHookeanRelaxedDerivativesMatchFiniteDifferences) {
  std::mt19937 rng(9);
  int wrinkled = 0, slack = 0;
  for (int trial = 0; trial < 40; ++trial) {
    // Stretched along x, squeezed across: wrinkled; squeezed both ways: slack. The
    // fibre-reinforced law's fibres (along (0.3, 1, 0.2)) add their term in both regimes.
    const bool squeeze_both = trial % 2;
    const Law law = trial % 4 < 2 ? Law::neo_hookean : Law::fibre_reinforced;
    const Triangle t = random_triangle(rng, squeeze_both ? 0.8 : 1.3, 0.6);
    SCOPED_TRACE(testing::Message() << "trial " << trial << " law " << int(law));
    const detail::Regime r = check_derivatives(t, prestressed(law, true));
    wrinkled += r == detail::Regime::wrinkled;
    slack += r == detail::Regime::slack;
  }
  EXPECT_GE(wrinkled, 10);
  EXPECT_GE(slack, 10);
}

// ---- The fibre-reinforced law ----------------------------------------------------------------

SkinMaterial fibres_along_x() {
  SkinMaterial m = unstressed(Law::fibre_reinforced);
  m.prestress_axis = Eigen::Vector3d::UnitX();
  return m;
}

TEST(MembraneLaw, FibreReinforcedUniaxialStretchGivesTheClosedFormAlongAndAcross) {
  const Triangle t = right_triangle();
  Model model;
  const SkinMaterial m = fibres_along_x();
  model.build(t.rest, t.faces, m);
  const double mu = model.mu(), k1 = m.fibre_stiffness, k2 = m.fibre_nonlinearity;
  for (const double l : {1.05, 1.2, 1.35, 1.5}) {
    // Along the fibres: the matrix's mu (l^2 - 1/l) plus the fibres' 2 psi_f'(e) l^2,
    // e = l^2 - 1, psi_f' = k1 e exp(k2 e^2); the width is still l^-1/2 (the fibres carry no
    // stress across).
    const Uniaxial along = uniaxial(model, t, l, true);
    const double e = l * l - 1;
    const double expected = mu * (l * l - 1 / l) + 2 * k1 * e * std::exp(k2 * e * e) * l * l;
    EXPECT_NEAR(along.width, 1 / std::sqrt(l), 1e-9) << l;
    EXPECT_NEAR(along.stress, expected, 1e-6 * expected) << l;
    // Across: the fibres shorten (width < 1) and carry nothing: the matrix alone.
    const Uniaxial across = uniaxial(model, t, l, false);
    EXPECT_NEAR(across.stress, mu * (l * l - 1 / l), 1e-6 * mu * l * l) << l;
  }
}

TEST(MembraneLaw, FibreReinforcedDefaultsReproduceTheirTwoSourceRatios) {
  // skin_material.hpp: k1 makes the small-strain modulus along the fibres 1.76 x the modulus
  // across (112.5 / 63.8 MPa), k2 makes the nominal stress's tangent along the fibres at 54 %
  // strain 70.6 x its initial value (83.3 / 1.18 MPa). Measured on the element by uniaxial
  // stretches with a free width.
  const Triangle t = right_triangle();
  Model model;
  model.build(t.rest, t.faces, fibres_along_x());
  const auto nominal = [&](double l, bool along_x) {
    return uniaxial(model, t, l, along_x).stress / l;
  };
  const auto tangent = [&](double l, bool along_x) {
    const double h = 1e-5;
    return (nominal(l + h, along_x) - nominal(l - h, along_x)) / (2 * h);
  };
  EXPECT_NEAR(tangent(1 + 1e-5, true) / tangent(1 + 1e-5, false), 112.5 / 63.8, 0.01);
  EXPECT_NEAR(tangent(1.54, true) / tangent(1 + 1e-5, true) / (83.3 / 1.18), 1, 0.01);
}

TEST(MembraneLaw, FibreReinforcedPrestretchReproducesThePrestress) {
  const Triangle t = right_triangle();
  for (const std::array<double, 2>& sigma : kPrestresses) {
    const SkinMaterial m = prestressed_at_45(Law::fibre_reinforced, sigma);
    const std::array<double, 2> l = neo_hookean_prestretch(m);
    const double scale = m.neo_hookean_mu() + sigma[0] + sigma[1];
    EXPECT_LT(bind_stress_error(t, m), 1e-12 * scale);
    // The fibres take part of the tension along the axis: less stretch there than the
    // neo-Hookean matrix alone needs for the same pre-stress.
    SkinMaterial matrix = m;
    matrix.law = Law::neo_hookean;
    if (sigma[0] > 0) {
      EXPECT_LT(l[0], neo_hookean_prestretch(matrix)[0]);
    }
  }
}

TEST(MembraneLaw, FibreParametersAreValidated) {
  SkinMaterial m = fibres_along_x();
  EXPECT_NO_THROW(m.validate());
  m.fibre_stiffness = -1;
  EXPECT_THROW(m.validate(), std::invalid_argument);
  m = fibres_along_x();
  m.fibre_nonlinearity = 0;
  EXPECT_THROW(m.validate(), std::invalid_argument);
  m.fibre_nonlinearity = std::nan("");
  EXPECT_THROW(m.validate(), std::invalid_argument);
}

}  // namespace
}  // namespace conform::membrane
