// A body's tear that grows by itself (SkinnedSoftBody::grow_tear): on a pre-stressed sheet pinned
// far from a scalpel's straight tear, the energy release rate at both tips is Griffith's
// sigma^2 pi a / E (plane stress), the tips extend where it reaches the toughness and not below
// it, straight ahead (pure mode I), through the body's own edits (mass and momentum kept).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

#include "conform/bullet/plugin.hpp"
#include "conform/mesh/primitives.hpp"
#include "plugin_world.hpp"

using namespace conform;
using conform::test::SoftWorld;

namespace {

constexpr double kHalf = 0.4;       // the sheet spans [-0.4, 0.4]^2: 20 half-tears
constexpr double kTearHalf = 0.02;  // the blade runs from x = -0.02 to 0.02
constexpr double kTearY = 0.00123;  // off the grid lines
constexpr double kSigma = 4200;     // Pa: sigma / E = 1 %, LEFM's small strain
constexpr double kRadius = 0.012;   // the domain of G, m

bullet::Material sheet_material(double toughness) {
  bullet::Material m;  // the membrane
  m.skin.prestress = {kSigma, kSigma};
  m.skin.attachment_stiffness = 0;  // a free membrane held by its pinned border
  m.skin.attachment_normal_stiffness = 0;
  m.skin.wrinkling = false;  // LEFM's sheet carries compression (plugin_membrane_test.cpp)
  m.skin.toughness = toughness;
  m.solver.relative_tolerance = 1e-5;
  m.solver.max_cg_iterations = 4000;
  m.growth.enabled = true;
  m.growth.domain_radius = kRadius;
  return m;
}

// Griffith's energy release rate of a slit of half-length a, plane stress, J/m^2.
double griffith_g(const bullet::Material& m, double a) {
  return kSigma * kSigma * std::numbers::pi * a / m.skin.youngs_modulus;
}

struct Torn {
  SoftWorld w;
  bullet::Plugin plugin{w.world};
  bullet::SkinnedSoftBody* body = nullptr;
  double half_length = 0;  // the tear's, rest space, m
};

// Grid lines: every h within 3 cm of the centre, then 15 % wider each out to kHalf.
std::vector<double> graded_lines(double h) {
  std::vector<double> half;
  double x = 0;
  for (; x < 0.03 - 1e-12; x += h) half.push_back(x);
  for (; x < kHalf; x += h, h *= 1.15) half.push_back(x);
  half.push_back(kHalf);
  std::vector<double> lines;
  for (auto it = half.rbegin(); it != half.rend(); ++it)
    if (*it > 0) lines.push_back(-*it);
  lines.insert(lines.end(), half.begin(), half.end());
  return lines;
}

// The sheet pinned at its border, torn along y = kTearY and settled. `mesh_space`: its points
// stored that many times smaller than its bind pose, the bone's offset bringing them to it.
void tear_sheet(Torn& t, const bullet::Material& material, double h = 0.002,
                double mesh_space = 1) {
  const std::vector<double> lines = graded_lines(h);
  mesh::SkinnedMesh sheet = mesh::make_grid_sheet(lines, lines, Eigen::Vector3d::UnitX(),
                                                  Eigen::Vector3d::UnitY(), 2 * kHalf);
  std::vector<std::int32_t> border;
  for (std::int32_t v = 0; v < sheet.vertex_count(); ++v)
    if (std::abs(sheet.rest(0, v)) > kHalf - 1e-9 || std::abs(sheet.rest(1, v)) > kHalf - 1e-9)
      border.push_back(v);
  skin::Skeleton skeleton = test::one_bone_skeleton();
  if (mesh_space != 1) {
    sheet.rest = sheet.rest / mesh_space;
    skeleton.bones[0].offset = skeleton.bones[0].offset * skin::Versor{{}, mesh_space};
  }
  t.body = &t.plugin.add_skinned_body(sheet, skeleton, material);
  t.body->set_pinned(border);
  t.w.step(5);
  t.body->begin_tear();
  const int samples = 32;
  for (int i = 0; i < samples; ++i) {
    const double x = -kTearHalf + 2 * kTearHalf * i / (samples - 1);
    t.body->tear_advance({double(i), {x, kTearY, -0.1}, {x, kTearY, 0.1}});
  }
  ASSERT_GT(t.body->tear()->path_length(), 4) << t.body->tear()->message();
  t.w.step(60);  // 1 s: the damped membrane settles
  const auto border_chain = t.body->tear()->right_border();
  t.half_length = 0.5 * (t.body->mesh().rest.col(border_chain.back()) -
                         t.body->mesh().rest.col(border_chain[0]))
                            .norm();
}

TEST(PluginTearGrowth, OffByDefault) {
  Torn t;
  bullet::Material m = sheet_material(1e-3);
  m.growth = {};
  tear_sheet(t, m);
  const auto version = t.body->topology_version();
  const bullet::TearGrowthReport report = t.body->grow_tear();
  EXPECT_TRUE(report.tips.empty());
  EXPECT_EQ(report.grown, 0);
  EXPECT_EQ(t.body->topology_version(), version);
}

// G at both tips of a blade's tear settled in the body, against Griffith; at elements of h.
double griffith_ratio(double h) {
  Torn t;
  const bullet::Material m = sheet_material(1e6);  // judged, never grown
  tear_sheet(t, m, h);
  const double reference = griffith_g(m, t.half_length);
  const bullet::TearGrowthReport report = t.body->grow_tear();
  EXPECT_EQ(report.tips.size(), 2u);
  double ratio = 0;
  for (const bullet::TipGrowth& tip : report.tips) {
    std::printf(
        "h %.3g m, tip %d: G %.6g J/m^2, Griffith %.6g (a %.4g m), ratio %.4f, "
        "K_II/K_I %.3g, R %.4g m, kink %.3g deg\n",
        h, tip.vertex, tip.energy_release_rate, reference, t.half_length,
        tip.energy_release_rate / reference, tip.k2 / tip.k1, tip.domain_radius,
        tip.kink * 180 / std::numbers::pi);
    EXPECT_LT(std::abs(tip.k2 / tip.k1), 0.1);
    EXPECT_LT(std::abs(tip.kink), 5 * std::numbers::pi / 180);
    EXPECT_EQ(tip.extended, 0);
    ratio += tip.energy_release_rate / reference / 2;
  }
  EXPECT_EQ(report.grown, 0);
  EXPECT_EQ(t.body->tear_grown_length(), 0);
  return ratio;
}

TEST(PluginTearGrowth, EnergyReleaseRateAtBothTipsIsGriffithsAndConvergesToIt) {
  // The blade's path through the elements opens the slit a little less than LEFM's ellipse
  // (0.95 of its width at 2 mm elements, 0.966 at 1 mm): G follows, and converges.
  const double coarse = griffith_ratio(0.002), fine = griffith_ratio(0.001);
  EXPECT_NEAR(coarse, 1.0, 0.07);
  EXPECT_NEAR(fine, 1.0, 0.05);
  EXPECT_GT(fine, coarse);
}

TEST(PluginTearGrowth, TipsGrowStraightAheadWhereGReachesToughnessKeepingMassAndMomentum) {
  Torn probe;
  tear_sheet(probe, sheet_material(1e6));
  const double g = probe.body->grow_tear().tips.at(0).energy_release_rate;

  Torn t;
  tear_sheet(t, sheet_material(0.8 * g));
  bullet::SkinnedSoftBody& body = *t.body;
  const double mass = body.total_mass();
  const Eigen::Vector3d momentum = body.momentum();
  const std::int32_t vertices = body.vertex_count();
  const bullet::TearGrowthReport report = body.grow_tear();
  ASSERT_EQ(report.tips.size(), 2u);
  double sum = 0;
  for (const bullet::TipGrowth& tip : report.tips) {
    EXPECT_GT(tip.extended, 0) << tip.message;
    EXPECT_LT(std::abs(tip.kink), 5 * std::numbers::pi / 180);
    sum += tip.extended;
  }
  EXPECT_NEAR(report.grown, sum, 1e-15);
  EXPECT_NEAR(body.tear_grown_length(), sum, 1e-15);
  EXPECT_GT(body.vertex_count(), vertices);
  EXPECT_LT(std::abs(body.total_mass() - mass) / mass, 1e-9);
  EXPECT_LT((body.momentum() - momentum).norm() / std::max(body.momentum_scale(), 1e-30), 1e-9);
  // The grown tips lie ahead of the blade's tear, on its line.
  const bullet::TearGrowthReport next = body.grow_tear();
  ASSERT_EQ(next.tips.size(), 2u);
  for (const bullet::TipGrowth& tip : next.tips) {
    const Eigen::Vector3d at = body.mesh().rest.col(tip.vertex);
    EXPECT_GT(std::abs(at.x()), t.half_length) << at.transpose();
    EXPECT_LT(std::abs(at.y() - kTearY), 0.01) << at.transpose();
  }
  t.w.step(30);
  for (std::int32_t v = 0; v < body.vertex_count(); ++v)
    ASSERT_TRUE(body.position(v).allFinite()) << v;
}

TEST(PluginTearGrowth, BladeAndGrowthActOnOneTear) {
  Torn t;
  tear_sheet(t, sheet_material(1e-3));  // every judgement grows
  bullet::SkinnedSoftBody& body = *t.body;
  const double mass = body.total_mass();
  const std::int32_t points = body.tear()->path_length();
  const bullet::TearGrowthReport grown = body.grow_tear();
  ASSERT_GT(grown.grown, 0);
  // The tear takes the grown segments: its ends are the grown tips.
  EXPECT_EQ(body.tear()->path_length(), points + 2);
  const std::int32_t tip = body.tear()->right_border().back();
  EXPECT_EQ(body.tear()->left_border().back(), tip);
  EXPECT_GT(body.mesh().rest(0, tip), t.half_length);
  t.w.step(2);
  // The blade cuts on from the grown tip; the growth then judges the blade's new tip.
  const double from = body.mesh().rest(0, tip);
  for (int i = 0; i < 6; ++i) {
    const double x = from + 0.002 * (i + 1);
    body.tear_advance({double(20 + i), {x, kTearY, -0.1}, {x, kTearY, 0.1}});
  }
  EXPECT_GT(body.tear()->path_length(), points + 2) << body.tear()->message();
  EXPECT_GT(body.mesh().rest(0, body.tear()->right_border().back()), from + 0.008);
  const bullet::TearGrowthReport after = body.grow_tear();
  ASSERT_EQ(after.tips.size(), 2u);
  EXPECT_EQ(after.tips[1].vertex, body.tear()->right_border().back());
  EXPECT_GT(after.grown, 0);
  t.w.step(10);
  EXPECT_LT(std::abs(body.total_mass() - mass) / mass, 1e-9);
  for (std::int32_t v = 0; v < body.vertex_count(); ++v)
    ASSERT_TRUE(body.position(v).allFinite()) << v;
  // Both borders stay chains of distinct copies between the shared ends, each on its own side.
  const auto left = body.tear()->left_border(), right = body.tear()->right_border();
  ASSERT_EQ(left.size(), right.size());
  const double side = body.position(left[1]).y() - body.position(right[1]).y();
  for (std::size_t i = 1; i + 1 < left.size(); ++i) {
    EXPECT_NE(left[i], right[i]) << i;
    EXPECT_GT(side * (body.position(left[i]).y() - body.position(right[i]).y()), 0) << i;
  }
}

TEST(PluginTearGrowth, GrowsInAMeshSpaceOfAnotherScaleAsInItsBindPose) {
  // The growth works on the skin's rest state (the bind pose), not the stored points.
  Torn plain, scaled;
  tear_sheet(plain, sheet_material(1e-3));  // every judgement grows
  tear_sheet(scaled, sheet_material(1e-3), 0.002, 100);
  for (int call = 0; call < 2; ++call) {
    const bullet::TearGrowthReport a = plain.body->grow_tear(), b = scaled.body->grow_tear();
    ASSERT_EQ(a.tips.size(), b.tips.size());
    EXPECT_GT(a.grown, 0);
    EXPECT_NEAR(b.grown, a.grown, 1e-9);
    for (std::size_t i = 0; i < a.tips.size(); ++i) {
      EXPECT_EQ(b.tips[i].vertex, a.tips[i].vertex);
      EXPECT_NEAR(b.tips[i].energy_release_rate, a.tips[i].energy_release_rate,
                  1e-6 * a.tips[i].energy_release_rate);
    }
    ASSERT_EQ(scaled.body->vertex_count(), plain.body->vertex_count());
  }
  EXPECT_NEAR(scaled.body->tear_grown_length(), plain.body->tear_grown_length(), 1e-9);
}

TEST(PluginTearGrowth, NoGrowthBelowToughness) {
  Torn t;
  tear_sheet(t, sheet_material(1e6));
  const double g = t.body->grow_tear().tips.at(0).energy_release_rate;
  Torn tough;
  tear_sheet(tough, sheet_material(1.25 * g));
  const auto version = tough.body->topology_version();
  const bullet::TearGrowthReport report = tough.body->grow_tear();
  EXPECT_EQ(report.tips.size(), 2u);
  EXPECT_EQ(report.grown, 0);
  EXPECT_EQ(tough.body->topology_version(), version);
}

TEST(PluginTearGrowth, RefusesSettingsOutOfRangeByName) {
  SoftWorld w;
  bullet::Plugin plugin(w.world);
  bullet::Material m = sheet_material(1);
  m.growth.domain_radius = -1;
  try {
    plugin.add_skinned_body(test::one_bone_sheet(4, 4, 1, 1), test::one_bone_skeleton(), m);
    FAIL() << "accepted a negative domain radius";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("growth.domain_radius = -1"), std::string::npos)
        << e.what();
  }
}

}  // namespace
