// Optional bending links (Material::bending_stiffness): a patch pinned at its border sags less
// under gravity with them than without, and a tear removes every bending link across it.
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

constexpr double kHalf = 0.2;  // the patch spans [−0.2, 0.2]², flat in z = 0

mesh::SkinnedMesh patch(int cells) {
  return test::one_bone_sheet(cells, cells, 2 * kHalf, 2 * kHalf);
}

bullet::Material free_sheet(double bending) {
  bullet::Material material;
  material.model = bullet::MaterialModel::bullet_links;  // the links' pretension opens it
  material.kinematic_weight = 2;                         // only pinned vertices are kinematic
  material.target_stiffness = 0;  // no pull toward the (flat) skinned targets
  material.target_damping = 0;
  material.damping = 0.05;
  material.position_iterations = 10;
  material.bending_stiffness = bending;
  return material;
}

// Drop (−z) of the centre of a patch pinned along its whole border, after 3 s under gravity.
double centre_sag(double bending) {
  SoftWorld w(9.81);
  bullet::Plugin plugin(w.world);
  const mesh::SkinnedMesh m = patch(16);
  auto& body = plugin.add_skinned_body(m, test::one_bone_skeleton(), free_sheet(bending));
  std::vector<std::int32_t> border;
  std::int32_t centre = -1;
  for (std::int32_t v = 0; v < m.vertex_count(); ++v) {
    if (std::abs(m.rest(0, v)) > kHalf - 1e-9 || std::abs(m.rest(1, v)) > kHalf - 1e-9)
      border.push_back(v);
    if (m.rest.col(v).norm() < 1e-9) centre = v;
  }
  EXPECT_GE(centre, 0);
  body.set_pinned(border);
  EXPECT_EQ(body.bending_link_count() > 0, bending > 0);
  w.step(180);
  for (std::int32_t v = 0; v < m.vertex_count(); ++v) EXPECT_TRUE(body.position(v).allFinite());
  for (const auto v : border) EXPECT_NEAR(body.position(v).z(), 0, 1e-6);
  return -body.position(centre).z();
}

}  // namespace

TEST(PluginBending, APinnedPatchSagsLessWithBendingLinks) {
  const double plain = centre_sag(0), stiff = centre_sag(1.0);
  std::printf("pinned patch, centre drop: %.4f m without bending links, %.4f m with (kLST 1)\n",
              plain, stiff);
  EXPECT_GT(plain, 0.01);  // the membrane alone sags visibly
  EXPECT_GT(stiff, 0);     // and still does with bending links, less
  EXPECT_LT(stiff, 0.8 * plain);
}

TEST(PluginBending, NoBendingLinkCrossesATear) {
  SoftWorld w;
  bullet::Plugin plugin(w.world);
  const mesh::SkinnedMesh m = patch(20);
  bullet::Material material = free_sheet(0.5);
  material.pretension = 0.05;
  auto& body = plugin.add_skinned_body(m, test::one_bone_skeleton(), material);
  std::vector<std::int32_t> border;
  for (std::int32_t v = 0; v < m.vertex_count(); ++v)
    if (std::abs(m.rest(0, v)) > kHalf - 1e-9 || std::abs(m.rest(1, v)) > kHalf - 1e-9)
      border.push_back(v);
  body.set_pinned(border);
  w.step(10);
  // Bending links whose ends lie strictly on both sides of the line y = line (rest positions,
  // farther than 2 mm from it) and that cross it well inside [−half, half].
  const double y0 = 0.0101, half = 0.5 * kHalf, cell = 2 * kHalf / 20;
  auto crossing = [&](double line) {
    int n = 0;
    for (btSoftBody* sb : body.pieces())
      for (int i = 0; i < sb->m_links.size(); ++i) {
        const auto& l = sb->m_links[i];
        if (l.m_material == sb->m_materials[0]) continue;
        const Eigen::Vector3d a =
            body.mesh().rest.col(body.vertex_of(sb, int(l.m_n[0] - &sb->m_nodes[0])));
        const Eigen::Vector3d b =
            body.mesh().rest.col(body.vertex_of(sb, int(l.m_n[1] - &sb->m_nodes[0])));
        if (std::abs(a.y() - line) < 2e-3 || std::abs(b.y() - line) < 2e-3) continue;
        if ((a.y() - line) * (b.y() - line) > 0) continue;
        const double x = a.x() + (b.x() - a.x()) * (line - a.y()) / (b.y() - a.y());
        n += std::abs(x) < half - 2 * cell;
      }
    return n;
  };
  const int before = crossing(y0);
  EXPECT_GT(before, 10);
  body.begin_tear();
  for (int i = 0; i < 40; ++i) {
    const double x = -half + 2 * half * i / 39;
    body.tear_advance({double(i), {x, y0, -0.1}, {x, y0, 0.1}});
  }
  EXPECT_GT(body.tear()->path_length(), 10) << body.tear()->message();
  // The tear runs where the blade met the simulated (slightly contracted) patch: its line in
  // rest space is the mean rest y of its border vertices.
  double line = 0;
  const auto border_vertices = body.tear()->left_border();
  for (const auto v : border_vertices) line += body.mesh().rest(1, v);
  line /= double(border_vertices.size());
  EXPECT_NEAR(line, y0, 0.5 * cell);
  EXPECT_EQ(crossing(line), 0);
  const auto check = conform::test::check_bending(body);
  EXPECT_EQ(check.wrong, 0);
  EXPECT_EQ(check.links, check.expected);
  EXPECT_EQ(check.links, body.bending_link_count());
  w.step(60);  // the pre-tensioned patch opens; the bending links stay consistent
  for (std::int32_t v = 0; v < body.vertex_count(); ++v) ASSERT_TRUE(body.position(v).allFinite());
  EXPECT_EQ(crossing(line), 0);
}
