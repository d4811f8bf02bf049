// Griffith's growth on a flat sheet in core (crack_growth.hpp, crack_extension.hpp): a pinned
// slit sheet pre-stressed across its slit grows at both tips above Griffith's stress
// sqrt(E G_c / (pi a)) and not below it, straight ahead in mode I; one extension is a valid
// topology change that opens the old tip.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "conform/membrane/crack_extension.hpp"
#include "conform/membrane/crack_growth.hpp"
#include "conform/membrane/slit_sheet.hpp"

namespace conform::membrane {
namespace {

constexpr double kA = 0.025, kToughness = 0.1;

std::int32_t nearest(const mesh::SkinnedMesh& m, const Eigen::Vector3d& p) {
  std::int32_t best = 0;
  for (std::int32_t v = 1; v < m.vertex_count(); ++v)
    if ((m.rest.col(v) - p).norm() < (m.rest.col(best) - p).norm()) best = v;
  return best;
}

// A slit of half-length kA along x, pre-stressed by sigma_yy = factor x Griffith's stress.
CrackedSheet sheet(double factor) {
  SlitSheetOptions o;
  o.width = 0.8;
  o.slit_length = 2 * kA;
  SlitSheet s = make_slit_sheet(o);
  mesh::apply(s.mesh, s.slit);
  SkinMaterial m;
  m.toughness = kToughness;
  m.attachment_stiffness = 0;
  m.attachment_normal_stiffness = 0;
  m.wrinkling = false;
  m.prestress_axis = Eigen::Vector3d::UnitX();
  const double griffith = std::sqrt(m.youngs_modulus * kToughness / (std::numbers::pi * kA));
  m.prestress = {0, factor * griffith};
  SolverSettings solver;
  solver.relative_tolerance = 1e-5;
  solver.max_cg_iterations = 20000;
  std::vector<std::uint8_t> fixed(s.border);
  fixed.resize(std::size_t(s.mesh.vertex_count()), 0);
  const std::vector<CrackTip> tips = {
      {nearest(s.mesh, Eigen::Vector3d(kA, 0, 0)), Eigen::Vector3d::UnitX()},
      {nearest(s.mesh, Eigen::Vector3d(-kA, 0, 0)), -Eigen::Vector3d::UnitX()}};
  return {std::move(s.mesh), std::move(fixed), tips, m, solver};
}

GrowthSettings settings(double step_length) {
  GrowthSettings g;
  g.domain.domain_radius = 0.5 * kA;
  g.step_length = step_length;
  return g;
}

TEST(MembraneCrackGrowth, BelowGriffithNothingGrows) {
  CrackedSheet s = sheet(0.95);
  EXPECT_TRUE(s.solve().converged);
  const GrowthReport r = s.grow(settings(0.005));
  ASSERT_EQ(r.first.size(), 2u);
  EXPECT_LT(r.first[0].fracture.energy_release_rate, kToughness);
  EXPECT_TRUE(r.extensions.empty());
}

TEST(MembraneCrackGrowth, AboveGriffithBothTipsGrowStraightAhead) {
  CrackedSheet s = sheet(1.05);
  EXPECT_TRUE(s.solve().converged);
  const GrowthReport r = s.grow(settings(0.003));
  ASSERT_FALSE(r.extensions.empty());
  EXPECT_GE(r.grown, 0.003);
  EXPECT_TRUE(r.solve.converged);
  for (const GrowingTip& t : s.tips()) {
    EXPECT_GT(t.grown, 0);
    // Mode I: straight ahead along the slit's line.
    for (const Eigen::Vector3d& p : t.path) EXPECT_LT(std::abs(p.y()), 1e-9) << p.transpose();
    EXPECT_GT(std::abs(t.path.back().x()), kA);
  }
  for (const TipEvaluation& e : r.extensions) EXPECT_NEAR(e.kink, 0, 1e-3);
}

TEST(MembraneCrackGrowth, AnExtensionOpensTheOldTip) {
  SlitSheetOptions o;
  o.width = 0.8;
  o.slit_length = 2 * kA;
  SlitSheet s = make_slit_sheet(o);
  mesh::apply(s.mesh, s.slit);
  std::vector<std::uint8_t> fixed(s.border);
  fixed.resize(std::size_t(s.mesh.vertex_count()), 0);
  const std::int32_t tip = nearest(s.mesh, Eigen::Vector3d(kA, 0, 0));
  // 30 degrees off the slit: the ray crosses a face's far edge, which is split.
  const double angle = std::numbers::pi / 6;
  const CrackExtension e =
      crack_extension(s.mesh, fixed, tip, Eigen::Vector3d(std::cos(angle), std::sin(angle), 0));
  ASSERT_FALSE(e.change.empty()) << e.message;
  EXPECT_EQ(e.change.validate(), "");
  const Eigen::Vector3d at = s.mesh.rest.col(tip);
  mesh::apply(s.mesh, e.change);
  // The old tip has a duplicate now, and the new tip lies ahead of it.
  int copies = 0;
  for (std::int32_t v = 0; v < s.mesh.vertex_count(); ++v)
    copies += (s.mesh.rest.col(v) - at).norm() == 0;
  EXPECT_EQ(copies, 2);
  EXPECT_GT((s.mesh.rest.col(e.new_tip) - at).x(), 0);
}

}  // namespace
}  // namespace conform::membrane
