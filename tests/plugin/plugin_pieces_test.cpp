// Piece handles and events on live Bullet bodies: a split announces its new piece with its
// parent; an edit that empties a piece announces its removal, and an id kept across it is
// detected as stale (piece_body null), never resolved to freed memory; per-piece settings
// (user pointer, collision group and mask, btSoftBody::Config) are inherited by split pieces.
#include <BulletSoftBody/btSoftBody.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>
#include <vector>

#include "conform/bullet/plugin.hpp"
#include "conform/skin/procedural_arm.hpp"
#include "plugin_world.hpp"

using namespace conform;
using bullet::PieceEvent;
using bullet::PieceId;
using conform::test::SoftWorld;

namespace {

const cga::Plane<double> kCut = cga::Plane<double>::from_normal_point({0, 0, 1}, {0, 0, 0.42});

skin::Arm small_arm() {
  return skin::make_arm({.segments = 12, .rings = 24});
}

// The two vertices of an edge used by one face only, in piece `p`, nearest to x = `at`.
std::pair<std::int32_t, std::int32_t> boundary_edge(const bullet::SkinnedSoftBody& body, PieceId p,
                                                    double at) {
  std::map<std::pair<std::int32_t, std::int32_t>, int> uses;
  for (const auto& f : body.mesh().faces)
    for (int k = 0; k < 3; ++k) ++uses[std::minmax(f[std::size_t(k)], f[std::size_t((k + 1) % 3)])];
  std::pair<std::int32_t, std::int32_t> best{-1, -1};
  double best_d = 1e9;
  for (const auto& [e, n] : uses) {
    if (n != 1 || !(body.piece_of(e.first) == p)) continue;
    const double d =
        std::abs(body.position(e.first).x() - at) + std::abs(body.position(e.second).x() - at);
    if (d < best_d) best_d = d, best = e;
  }
  return best;
}

}  // namespace

TEST(PluginPieces, SplitAnnouncesTheNewPieceWithItsParent) {
  std::vector<PieceEvent> events;  // outlives the plugin: the listener runs in its destructor
  SoftWorld world;
  bullet::Plugin plugin(world.world);
  const skin::Arm arm = small_arm();
  auto& body = plugin.add_skinned_body(arm.mesh, arm.skeleton);
  const std::vector<PieceId> before = body.piece_ids();
  ASSERT_EQ(before.size(), 1u);
  body.on_piece_event([&](const PieceEvent& e) {
    events.push_back(e);
    // Every query is valid inside the listener (the edit is mirrored completely).
    if (e.kind == PieceEvent::Kind::created) {
      EXPECT_NE(body.piece_body(e.piece), nullptr);
    }
  });
  world.step(2);
  ASSERT_EQ(body.cut(kCut).status, mesh::CutStatus::Cut);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, PieceEvent::Kind::created);
  EXPECT_EQ(events[0].parent, before[0]);
  EXPECT_TRUE(body.piece_valid(before[0]));
  EXPECT_TRUE(body.piece_valid(events[0].piece));
  // The new piece holds the vertices beyond the cut, the parent those before it (vertices
  // within 5 mm may be snapped onto the plane by the sliver floor and duplicated).
  int beyond = 0, wrong = 0;
  for (std::int32_t v = 0; v < body.vertex_count(); ++v) {
    if (body.detached(v)) continue;
    const bool far = body.position(v).z() > 0.425, near = body.position(v).z() < 0.415;
    const PieceId p = body.piece_of(v);
    beyond += far;
    const bool bad = (far && !(p == events[0].piece)) || (near && !(p == before[0]));
    wrong += bad;
    EXPECT_EQ(body.piece_body(p), body.body_of(v));
  }
  EXPECT_GT(beyond, 0);
  EXPECT_EQ(wrong, 0);
}

TEST(PluginPieces, AHandleKeptAcrossTheEditThatEmptiesItsPieceIsDetected) {
  // Two pieces (a sheet cut in two); a face bridging them merges them: the smaller piece's
  // nodes move into the larger one's body and its own body is emptied and deleted.
  std::vector<PieceEvent> events;
  SoftWorld world;
  bullet::Plugin plugin(world.world);
  auto& body =
      plugin.add_skinned_body(test::one_bone_sheet(8, 4, 1.0, 0.5), test::one_bone_skeleton());
  body.cut(cga::Plane<double>::from_normal_point({1, 0, 0}, {0.3, 0, 0}));
  ASSERT_EQ(body.piece_count(), 2);
  const std::vector<PieceId> ids = body.piece_ids();
  const PieceId big = ids[0], small = ids[1];
  btSoftBody* small_body = body.piece_body(small);
  ASSERT_NE(small_body, nullptr);
  ASSERT_LT(small_body->m_nodes.size(), body.piece_body(big)->m_nodes.size());
  body.on_piece_event([&](const PieceEvent& e) { events.push_back(e); });
  world.step(1);

  const auto [a, b] = boundary_edge(body, small, 0.3);
  std::int32_t c = -1;  // the nearest vertex of the big piece across the cut
  double best = 1e9;
  for (std::int32_t v = 0; v < body.vertex_count(); ++v)
    if (body.piece_of(v) == big && (body.position(v) - body.position(a)).norm() < best &&
        (body.position(v) - body.position(a)).norm() > 1e-6)
      best = (body.position(v) - body.position(a)).norm(), c = v;
  ASSERT_GE(a, 0);
  ASSERT_GE(c, 0);
  body.sync_mesh();
  mesh::TopologyChange bridge;
  bridge.base_vertex_count = body.vertex_count();
  bridge.base_face_count = std::int32_t(body.mesh().faces.size());
  bridge.added_faces.push_back({b, a, c});
  body.apply(bridge);

  EXPECT_EQ(body.piece_count(), 1);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, PieceEvent::Kind::removed);
  EXPECT_EQ(events[0].piece, small);
  EXPECT_FALSE(body.piece_valid(small));
  EXPECT_EQ(body.piece_body(small), nullptr);  // not the freed small_body
  EXPECT_TRUE(body.piece_valid(big));
  EXPECT_THROW(body.set_piece_user(small, nullptr), std::invalid_argument);
  const auto pieces = body.pieces();
  EXPECT_EQ(std::count(pieces.begin(), pieces.end(), small_body), 0);
  world.step(2);
  EXPECT_EQ(test::bullet_internals_problem(body), "");
}

TEST(PluginPieces, SplitPiecesInheritUserCollisionFilterAndConfig) {
  int tag = 0, other = 0;
  PieceId child{};
  SoftWorld world;
  bullet::Plugin plugin(world.world);
  const skin::Arm arm = small_arm();
  // btSoftBody::Config leaves its fields uninitialized: a template starts from a body's.
  btSoftBody probe(&world.world.getWorldInfo(), 0, nullptr, nullptr);
  btSoftBody::Config config = probe.m_cfg;
  config.kCHR = btScalar(0.25);
  config.kDF = btScalar(0.7);
  config.collisions = btSoftBody::fCollision::SDF_RS | btSoftBody::fCollision::VF_SS;
  bullet::PieceSettings settings{};
  settings.user = &tag;
  settings.collision_group = 2;
  settings.collision_mask = 5;
  settings.config = config;
  bullet::Material material{};
  material.position_iterations = 7;
  auto& body = plugin.add_skinned_body(arm.mesh, arm.skeleton, material, settings);
  const PieceId root = body.piece_ids().at(0);
  btSoftBody* sb = body.piece_body(root);
  EXPECT_EQ(sb->getBroadphaseHandle()->m_collisionFilterGroup, 2);
  EXPECT_EQ(sb->getBroadphaseHandle()->m_collisionFilterMask, 5);
  EXPECT_EQ(sb->getUserPointer(), &tag);
  EXPECT_EQ(sb->m_cfg.kCHR, btScalar(0.25));
  EXPECT_EQ(sb->m_cfg.piterations, 7);  // the material's, over the template's

  // The application changes the root piece: the split copies what it has now.
  body.set_piece_user(root, &other);
  body.set_piece_collision(root, 4, 9);
  sb->m_cfg.kDF = btScalar(0.3);
  body.on_piece_event([&](const PieceEvent& e) {
    if (e.kind == PieceEvent::Kind::created) child = e.piece;
  });
  world.step(1);
  body.cut(kCut);
  ASSERT_TRUE(body.piece_valid(child));
  btSoftBody* cb = body.piece_body(child);
  EXPECT_EQ(cb->getBroadphaseHandle()->m_collisionFilterGroup, 4);  // was 1 before
  EXPECT_EQ(cb->getBroadphaseHandle()->m_collisionFilterMask, 9);   // was -1
  EXPECT_EQ(cb->getUserPointer(), &other);
  EXPECT_EQ(body.piece_settings(child).user, &other);
  EXPECT_EQ(cb->m_cfg.kDF, btScalar(0.3));
  EXPECT_EQ(cb->m_cfg.kCHR, btScalar(0.25));
  EXPECT_EQ(cb->m_cfg.collisions, sb->m_cfg.collisions);
  EXPECT_EQ(cb->m_cfg.piterations, 7);
  EXPECT_EQ(cb->getCollisionShape()->getMargin(), sb->getCollisionShape()->getMargin());
  // Both still in the world once each.
  EXPECT_EQ(world.world.getSoftBodyArray().size(), 2);
  world.step(2);
  EXPECT_EQ(test::bullet_internals_problem(body), "");
}
