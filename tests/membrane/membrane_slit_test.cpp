// The membrane against linear elastic fracture mechanics: a pre-stressed, pinned sheet with a
// slit opens as an ellipse of maximum opening 4 sigma_n a / E (slit_sheet.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "conform/membrane/slit_sheet.hpp"
#include "conform/membrane/solver.hpp"

namespace conform::membrane {
namespace {

constexpr double kSigma = 400;  // Pa: strains of 1e-3, the linear regime

struct SlitResult {
  EllipseFit fit;
  double lefm = 0;
  SolveReport report;
};

// axis: the material's prestress_axis (its default is (0, 0, 1), the sheet's normal).
SlitResult solve_slit(const SlitSheetOptions& options, double sxx, double syy,
                      const Eigen::Vector3d& axis = Eigen::Vector3d::UnitX()) {
  SlitSheet sheet = make_slit_sheet(options);
  mesh::apply(sheet.mesh, sheet.slit);
  SkinMaterial material;
  material.prestress = {sxx, syy};
  material.prestress_axis = axis;
  material.attachment_stiffness = 0;
  material.attachment_normal_stiffness = 0;
  material.wrinkling = false;  // LEFM is linear elasticity: its sheet carries compression
  Model model;
  model.build(sheet.mesh.rest, sheet.mesh.faces, material);
  std::vector<std::uint8_t> fixed(sheet.border);
  fixed.resize(static_cast<std::size_t>(sheet.mesh.vertex_count()), 0);
  Eigen::Matrix3Xd x = sheet.mesh.rest;
  const Eigen::Matrix3Xd none(3, 0);
  StepInput input{sheet.mesh.rest, none, none, none, fixed, 0.0};
  SolverSettings settings;
  settings.relative_tolerance = 1e-3;
  settings.max_cg_iterations = 5000;
  Solver solver;
  SlitResult r;
  r.report = solver.solve(model, input, settings, x);
  const double a = 0.5 * options.slit_length;
  r.fit = fit_ellipse(sheet.lip_s, slit_opening(sheet, x), a);
  r.lefm = 4 * normal_prestress(sheet, sxx, syy) * a / material.youngs_modulus;
  std::printf(
      "h %.4g W %.3g: w_max %.6g lefm %.6g ratio %.5f amp %.6g r2 %.5f newton %d cg %d res %.3g\n",
      options.element_size, options.width, r.fit.w_max, r.lefm, r.fit.w_max / r.lefm,
      r.fit.amplitude / r.lefm, r.fit.r2, r.report.newton_iterations, r.report.cg_iterations,
      r.report.residual);
  return r;
}

// W = 16 x 2a: the pinned border's effect on the opening is below 1 %.
SlitSheetOptions options(double h = 2.5e-3, double angle = 0) {
  SlitSheetOptions o;
  o.width = 0.8;
  o.slit_length = 0.05;
  o.element_size = h;
  o.slit_angle = angle;
  return o;
}

// The reference solve (h = 2.5 mm, isotropic kSigma), shared by the tests below.
const SlitResult& reference() {
  static const SlitResult r = solve_slit(options(), kSigma, kSigma);
  return r;
}

TEST(MembraneSlit, OpensAsTheLefmEllipse) {
  const SlitResult& r = reference();
  EXPECT_TRUE(r.report.converged);
  EXPECT_NEAR(r.fit.w_max / r.lefm, 1.0, 0.03);
  EXPECT_GE(r.fit.r2, 0.99);
}

TEST(MembraneSlit, ConvergesWhenTheElementSizeIsHalved) {
  const SlitResult& coarse = reference();
  const SlitResult fine = solve_slit(options(1.25e-3), kSigma, kSigma);
  EXPECT_NEAR(fine.fit.w_max / coarse.fit.w_max, 1.0, 0.01);
}

TEST(MembraneSlit, OpeningIsLinearInThePrestress) {
  const SlitResult& one = reference();
  const SlitResult two = solve_slit(options(), 2 * kSigma, 2 * kSigma);
  EXPECT_NEAR(two.fit.w_max / one.fit.w_max, 2.0, 0.04);
}

TEST(MembraneSlit, OnlyTheStressNormalToTheSlitOpensIt) {
  // Pre-stress [2 sigma, sigma]: a slit across x (along y) feels 2 sigma, one along x sigma.
  const SlitResult across = solve_slit(options(2.5e-3, M_PI / 2), 2 * kSigma, kSigma);
  const SlitResult along = solve_slit(options(2.5e-3, 0), 2 * kSigma, kSigma);
  EXPECT_NEAR(across.fit.w_max / along.fit.w_max, 2.0, 0.1);
}

TEST(MembraneSlit, PrestressIsSigmaXxAndSigmaYyWithTheDefaultAxis) {
  // The default axis is normal to the sheet: every face takes the documented tangent (x here),
  // not its own first edge, so [2 sigma, sigma] is [sigma_xx, sigma_yy].
  const Eigen::Vector3d normal = SkinMaterial{}.prestress_axis;
  ASSERT_EQ(normal, Eigen::Vector3d::UnitZ());
  const SlitResult across = solve_slit(options(5e-3, M_PI / 2), 2 * kSigma, kSigma, normal);
  const SlitResult along = solve_slit(options(5e-3, 0), 2 * kSigma, kSigma, normal);
  EXPECT_NEAR(across.fit.w_max / along.fit.w_max, 2.0, 0.1);  // 2.0 +- 5 %
}

TEST(MembraneSlit, OpeningFollowsTheNormalPrestressAtEveryAngle) {
  // LEFM: sigma_n = sigma_xx sin^2 theta + sigma_yy cos^2 theta; the ratio to LEFM is the same
  // at every angle (the mesh turns with the slit; the pre-stress does not).
  const SlitResult zero = solve_slit(options(5e-3, 0), 2 * kSigma, kSigma);
  for (const double deg : {30.0, 60.0}) {
    const SlitResult r = solve_slit(options(5e-3, deg * M_PI / 180), 2 * kSigma, kSigma);
    const double s = std::sin(deg * M_PI / 180), c = std::cos(deg * M_PI / 180);
    EXPECT_NEAR(r.lefm, 4 * (2 * kSigma * s * s + kSigma * c * c) * 0.025 / 0.42e6, 1e-12);
    EXPECT_NEAR((r.fit.w_max / r.lefm) / (zero.fit.w_max / zero.lefm), 1.0, 0.02) << deg;
  }
}

TEST(MembraneSlit, TheRelativeToleranceMeansTheSameAtEveryStressLevel) {
  // The opening is linear in the pre-stress: with the same relative tolerance, the ratio to
  // LEFM is the same at 1/4 and 1x the stress (an absolute tolerance would be 4x looser, in
  // relative terms, at the lower one).
  const SlitResult low = solve_slit(options(5e-3), kSigma / 4, kSigma / 4);
  const SlitResult high = solve_slit(options(5e-3), kSigma, kSigma);
  EXPECT_LE(low.report.relative_residual, 1e-3);
  EXPECT_LE(high.report.relative_residual, 1e-3);
  EXPECT_NEAR(low.report.relative_residual, low.report.residual / (kSigma / 4), 1e-12);
  EXPECT_NEAR((high.fit.w_max / high.lefm) / (low.fit.w_max / low.lefm), 1.0, 0.01);
}

TEST(MembraneSlit, NoPrestressNoOpening) {
  const SlitResult r = solve_slit(options(5e-3), 0, 0);
  EXPECT_TRUE(r.report.converged);
  EXPECT_EQ(r.fit.w_max, 0.0);
  EXPECT_EQ(r.report.newton_iterations, 0);
}

TEST(MembraneSlit, SheetOptionsAreValidated) {
  SlitSheetOptions o = options();
  o.width = 0.3;  // < 8 slit lengths
  EXPECT_THROW(make_slit_sheet(o), std::invalid_argument);
  o = options();
  o.element_size = 0;
  EXPECT_THROW(make_slit_sheet(o), std::invalid_argument);
}

}  // namespace
}  // namespace conform::membrane
