// Physical opening: a straight tear in a uniformly pre-tensioned flat patch pinned at its
// border opens by itself with the elliptical profile of a slit in a stretched membrane,
// w(x) = w_max·sqrt(1 − (2x/L)²); without pretension it stays closed.
#include <BulletSoftBody/btSoftBody.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "conform/bullet/plugin.hpp"
#include "conform/mesh/primitives.hpp"
#include "plugin_world.hpp"

using namespace conform;
using conform::test::SoftWorld;

namespace {

constexpr double kHalf = 0.5;       // the patch spans [−0.5, 0.5]²
constexpr double kTearHalf = 0.25;  // the tear runs from x = −0.25 to 0.25
constexpr double kTearY = 0.0123;   // off the grid lines

struct Profile {
  std::vector<double> x, w;  // position along the tear (rest space), gap width
  double w_max = 0, r2 = 0, length = 0;
};

// Least-squares fit of w = w_max·sqrt(1 − (2(x − c)/L)²) with c, L from the tear's ends.
void fit_ellipse(Profile& p) {
  const double x0 = p.x.front(), x1 = p.x.back();
  p.length = x1 - x0;
  const double c = 0.5 * (x0 + x1);
  std::vector<double> f(p.x.size());
  double fw = 0, ff = 0, mean = 0;
  for (std::size_t i = 0; i < p.x.size(); ++i) {
    const double u = 2 * (p.x[i] - c) / p.length;
    f[i] = std::sqrt(std::max(0.0, 1 - u * u));
    fw += f[i] * p.w[i];
    ff += f[i] * f[i];
    mean += p.w[i];
  }
  mean /= double(p.w.size());
  p.w_max = fw / ff;
  double res = 0, tot = 0;
  for (std::size_t i = 0; i < p.x.size(); ++i) {
    res += std::pow(p.w[i] - p.w_max * f[i], 2);
    tot += std::pow(p.w[i] - mean, 2);
  }
  p.r2 = tot > 0 ? 1 - res / tot : 0;
}

mesh::SkinnedMesh patch() {
  return test::one_bone_sheet(40, 40, 2 * kHalf, 2 * kHalf);
}

// Tears the patch along y = kTearY, lets it settle, and returns the opening profile.
Profile tear_and_settle(double pretension, SoftWorld& w, bullet::Plugin& plugin) {
  const mesh::SkinnedMesh m = patch();
  bullet::Material material;
  material.model = bullet::MaterialModel::bullet_links;  // the links' pretension opens it
  material.pretension = pretension;
  material.kinematic_weight = 2;  // nothing kinematic by weight: only the pinned border
  material.target_stiffness = 0;  // a free membrane
  material.target_damping = 0;
  material.damping = 0.05;
  material.position_iterations = 10;
  auto& body = plugin.add_skinned_body(m, test::one_bone_skeleton(), material);
  std::vector<std::int32_t> border;
  for (std::int32_t v = 0; v < m.vertex_count(); ++v)
    if (std::abs(m.rest(0, v)) > kHalf - 1e-9 || std::abs(m.rest(1, v)) > kHalf - 1e-9)
      border.push_back(v);
  body.set_pinned(border);
  w.step(30);  // the pinned, uniformly pre-tensioned patch is in equilibrium
  body.begin_tear();
  const int samples = 60;
  for (int i = 0; i < samples; ++i) {
    const double x = -kTearHalf + 2 * kTearHalf * i / (samples - 1);
    body.tear_advance({double(i), {x, kTearY, -0.1}, {x, kTearY, 0.1}});
  }
  EXPECT_GT(body.tear()->path_length(), 15) << body.tear()->message();
  w.step(240);
  Profile p;
  const auto left = body.tear()->left_border(), right = body.tear()->right_border();
  EXPECT_EQ(left.size(), right.size());
  for (std::size_t i = 0; i < left.size(); ++i) {
    p.x.push_back(body.mesh().rest(0, right[i]));
    p.w.push_back((body.position(left[i]) - body.position(right[i])).norm());
  }
  for (std::int32_t v = 0; v < body.vertex_count(); ++v) EXPECT_TRUE(body.position(v).allFinite());
  return p;
}

}  // namespace

TEST(PluginOpening, PretensionedPatchOpensElliptically) {
  SoftWorld w;
  bullet::Plugin plugin(w.world);
  Profile p = tear_and_settle(0.1, w, plugin);
  fit_ellipse(p);
  std::printf("physical opening (s = 0.1): %zu points, L = %.3f m, w_max = %.4f m, R² = %.4f\n",
              p.x.size(), p.length, p.w_max, p.r2);
  RecordProperty("r2", std::to_string(p.r2));
  EXPECT_NEAR(p.length, 2 * kTearHalf, 0.05);
  EXPECT_GT(p.w_max, 0.01);  // it opened, by itself
  EXPECT_GE(p.r2, 0.9);
  // Widest in the middle, closed at the ends.
  EXPECT_LT(p.w.front(), 1e-9);
  EXPECT_LT(p.w.back(), 1e-9);
}

TEST(PluginOpening, WithoutPretensionTheTearStaysClosed) {
  SoftWorld w;
  bullet::Plugin plugin(w.world);
  const Profile p = tear_and_settle(0.0, w, plugin);
  double widest = 0;
  for (const double x : p.w) widest = std::max(widest, x);
  EXPECT_LT(widest, 1e-4);
}

TEST(PluginOpening, TheGeometricOpeningIsAPrescribedProfile) {
  // For comparison: Algorithm 2 step 6 moves the borders by a sine taper, not by physics.
  mesh::SkinnedMesh m = patch();
  mesh::Adjacency adjacency(m);
  mesh::Tear tear(m, adjacency);
  for (int i = 0; i < 60; ++i) {
    const double x = -kTearHalf + 2 * kTearHalf * i / 59;
    tear.advance({double(i), {x, kTearY, -0.1}, {x, kTearY, 0.1}});
  }
  tear.open(0.05);
  Profile p;
  const auto left = tear.left_border(), right = tear.right_border();
  for (std::size_t i = 0; i < left.size(); ++i) {
    p.x.push_back(m.rest(0, right[i]));
    p.w.push_back((m.current.col(left[i]) - m.current.col(right[i])).norm());
  }
  fit_ellipse(p);
  std::printf("geometric opening (step 6): w_max = %.4f m, R² against the ellipse = %.4f\n",
              p.w_max, p.r2);
  EXPECT_GT(p.w_max, 0.03);
}
