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
#include "conform/mesh/adjacency.hpp"
#include "conform/mesh/primitives.hpp"
#include "conform/mesh/tear.hpp"

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
  EXPECT_EQ((s.mesh.rest.col(e.duplicate) - at).norm(), 0);
  EXPECT_NE(e.duplicate, tip);
}

// A blade's tear takes a grown segment at either end: its borders run on to the new tip, each
// on its own side, and the blade cuts on from there.
TEST(MembraneCrackGrowth, ATearAdoptsGrowthAtEitherEnd) {
  mesh::SkinnedMesh sheet = mesh::make_sheet(40, 40, 0.4, 0.4);
  mesh::Adjacency adjacency(sheet);
  mesh::Tear tear(sheet, adjacency);
  const double y = 0.00123;
  for (int i = 0; i < 11; ++i) {
    const double x = -0.05 + 0.01 * i;
    tear.advance({double(i), {x, y, -0.1}, {x, y, 0.1}});
  }
  ASSERT_GT(tear.path_length(), 3) << tear.message();
  const std::int32_t points = tear.path_length();
  for (const bool at_tip : {true, false}) {
    const std::vector<std::int32_t> border = tear.right_border();
    const std::int32_t end = at_tip ? border.back() : border.front();
    const Eigen::Vector3d ahead(at_tip ? 1 : -1, 0, 0);
    const std::vector<std::uint8_t> none(std::size_t(sheet.vertex_count()), 0);
    const CrackExtension e = crack_extension(sheet, none, end, ahead);
    ASSERT_FALSE(e.change.empty()) << e.message;
    mesh::apply(sheet, e.change, &adjacency);
    tear.adopt_growth(end, e.duplicate, e.new_tip);
    const std::vector<std::int32_t> right = tear.right_border(), left = tear.left_border();
    EXPECT_EQ(at_tip ? right.back() : right.front(), e.new_tip);
    EXPECT_EQ(at_tip ? left.back() : left.front(), e.new_tip);
    // The right copies lie in the faces on one side of the path, the left ones on the other.
    const auto face_y = [&](std::int32_t v) {
      double y = 0;
      int n = 0;
      for (const mesh::Face& f : sheet.faces)
        if (f[0] == v || f[1] == v || f[2] == v)
          y += sheet.rest(1, f[0]) + sheet.rest(1, f[1]) + sheet.rest(1, f[2]), n += 3;
      return y / n;
    };
    const double side = face_y(left[1]) - face_y(right[1]);
    for (std::size_t i = 1; i + 1 < right.size(); ++i) {
      EXPECT_NE(left[i], right[i]) << i;
      EXPECT_GT(side * (face_y(left[i]) - face_y(right[i])), 0) << i;
    }
  }
  EXPECT_EQ(tear.path_length(), points + 2);
  EXPECT_THROW(tear.adopt_growth(tear.right_border()[2], 0, 1), std::invalid_argument);
  // The blade cuts on from the grown tip.
  const double from = sheet.rest(0, tear.right_border().back());
  for (int i = 1; i <= 3; ++i) {
    const double x = from + 0.01 * i;
    tear.advance({double(20 + i), {x, y, -0.1}, {x, y, 0.1}});
  }
  EXPECT_GT(tear.path_length(), points + 2) << tear.message();
  EXPECT_GT(sheet.rest(0, tear.right_border().back()), from);
}

}  // namespace
}  // namespace conform::membrane
