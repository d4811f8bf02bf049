// The vertices that left Bullet (detached_vertices.hpp): the part's own rules, and on a live
// sheet whose every face around two vertices is removed: each is held once, keeps the position
// it left Bullet at until the skin drive runs, then rides its skinned target.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "conform/bullet/plugin.hpp"
#include "detached_vertices.hpp"
#include "plugin_world.hpp"

using namespace conform;
using conform::test::SoftWorld;

TEST(PluginDetachedVertices, EachHeldVertexNamesItsSlotBack) {
  bullet::DetachedVertices d;
  d.reset(5);
  d.add(3, {1, 2, 3}, {0, 0, 1});
  d.grow(7);
  d.add(6, {4, 5, 6}, {0, 0, 0});
  EXPECT_EQ(d.count(), 2);
  for (std::int32_t v = 0; v < 7; ++v) EXPECT_EQ(d.held(v), v == 3 || v == 6) << v;
  EXPECT_EQ(d.vertex(0), 3);
  EXPECT_EQ(d.vertex(1), 6);
  EXPECT_EQ(d.position(3), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(d.velocity(3), Eigen::Vector3d(0, 0, 1));
  d.set(1, {7, 8, 9}, {1, 0, 0});
  EXPECT_EQ(d.position(6), Eigen::Vector3d(7, 8, 9));
  EXPECT_EQ(d.velocity(6), Eigen::Vector3d(1, 0, 0));
}

TEST(PluginDetachedVertices, AVertexWithoutFacesLeavesBulletAndRidesItsTarget) {
  SoftWorld world;
  bullet::Plugin plugin(world.world);
  auto& body =
      plugin.add_skinned_body(test::one_bone_sheet(8, 8, 0.8, 0.8), test::one_bone_skeleton());
  world.step(2);
  const std::int32_t a = 4 * 9 + 2, b = 4 * 9 + 6;  // two interior vertices apart
  std::vector<std::int32_t> removed;
  for (std::int32_t f = 0; f < std::int32_t(body.mesh().faces.size()); ++f)
    for (const auto v : body.mesh().faces[std::size_t(f)])
      if (v == a || v == b) {
        removed.push_back(f);
        break;
      }
  const Eigen::Vector3d xa = body.position(a), xb = body.position(b);
  const std::int32_t links = body.link_count();
  body.sync_mesh();
  mesh::TopologyChange change;
  change.base_vertex_count = body.vertex_count();
  change.base_face_count = std::int32_t(body.mesh().faces.size());
  change.removed_faces = removed;
  body.apply(change);
  std::vector<std::uint8_t> used(std::size_t(body.vertex_count()), 0);
  for (const auto& f : body.mesh().faces)
    for (const auto v : f) used[std::size_t(v)] = 1;
  EXPECT_EQ(body.detached_count(), 2);
  for (std::int32_t v = 0; v < body.vertex_count(); ++v)
    EXPECT_EQ(body.detached(v), !used[std::size_t(v)]) << v;
  EXPECT_TRUE(body.detached(a) && body.detached(b));
  EXPECT_EQ(body.body_of(a), nullptr);
  EXPECT_EQ(body.position(a), xa);  // where it left Bullet
  EXPECT_EQ(body.position(b), xb);
  EXPECT_LT(body.link_count(), links);
  world.step(3);
  EXPECT_EQ(body.detached_count(), 2);  // for good
  EXPECT_EQ(body.position(a), body.target(a));
  EXPECT_EQ(body.position(b), body.target(b));
  EXPECT_TRUE(body.velocity(a).allFinite());
}
