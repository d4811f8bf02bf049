// The pieces' handles (piece_handles.hpp) on live Bullet bodies, through a run of edits: every
// id the body lists is valid and names a live body; the events an edit delivers are exactly the
// change of the listed ids (created: new ones, removed: gone ones); an id once removed never
// becomes valid again, and no slot has two valid generations.
#include <BulletSoftBody/btSoftBody.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>
#include <vector>

#include "conform/bullet/plugin.hpp"
#include "plugin_world.hpp"

using namespace conform;
using bullet::PieceEvent;
using bullet::PieceId;
using conform::test::SoftWorld;

namespace {

std::set<std::pair<std::int32_t, std::uint32_t>> keys(const std::vector<PieceId>& ids) {
  std::set<std::pair<std::int32_t, std::uint32_t>> out;
  for (const PieceId& id : ids) out.insert({id.index, id.generation});
  return out;
}

}  // namespace

TEST(PluginPieceHandles, EventsAreTheChangeOfTheIdsAndRemovedIdsStayStale) {
  std::vector<PieceEvent> events;  // outlives the plugin: the listener runs in its destructor
  SoftWorld world;
  bullet::Plugin plugin(world.world);
  auto& body =
      plugin.add_skinned_body(test::one_bone_sheet(12, 4, 1.2, 0.4), test::one_bone_skeleton());
  body.on_piece_event([&](const PieceEvent& e) { events.push_back(e); });
  std::vector<PieceId> removed;
  for (const double x : {0.3, -0.2, 0.05, 0.45}) {
    world.step(1);
    const auto before = keys(body.piece_ids());
    events.clear();
    body.cut(cga::Plane<double>::from_normal_point({1, 0, 0}, {x, 0, 0}));
    const std::vector<PieceId> listed = body.piece_ids();
    const auto after = keys(listed);
    std::set<std::pair<std::int32_t, std::uint32_t>> created, gone;
    for (const PieceEvent& e : events) {
      if (e.kind == PieceEvent::Kind::created) created.insert({e.piece.index, e.piece.generation});
      if (e.kind == PieceEvent::Kind::removed) {
        gone.insert({e.piece.index, e.piece.generation});
        removed.push_back(e.piece);
      }
    }
    for (const auto& k : after) {
      if (!before.contains(k)) {
        EXPECT_TRUE(created.contains(k)) << "x " << x;
      }
    }
    for (const auto& k : before) {
      if (!after.contains(k)) {
        EXPECT_TRUE(gone.contains(k)) << "x " << x;
      }
    }
    std::map<std::int32_t, int> per_slot;
    for (const PieceId& id : listed) {
      EXPECT_TRUE(body.piece_valid(id));
      EXPECT_NE(body.piece_body(id), nullptr);
      EXPECT_EQ(++per_slot[id.index], 1);
    }
    EXPECT_EQ(std::int32_t(listed.size()), body.piece_count());
    for (const PieceId& id : removed) {
      EXPECT_FALSE(body.piece_valid(id));
      EXPECT_EQ(body.piece_body(id), nullptr);
    }
  }
  EXPECT_GE(body.piece_count(), 4);
}

TEST(PluginPieceHandles, ABodyDeletedByTheApplicationStalesItsIdAndRefusesEdits) {
  SoftWorld world;
  bullet::Plugin plugin(world.world);
  auto& body =
      plugin.add_skinned_body(test::one_bone_sheet(8, 4, 1.0, 0.5), test::one_bone_skeleton());
  body.cut(cga::Plane<double>::from_normal_point({1, 0, 0}, {0.3, 0, 0}));
  const std::vector<PieceId> ids = body.piece_ids();
  ASSERT_EQ(ids.size(), 2u);
  btSoftBody* doomed = body.piece_body(ids[1]);
  world.world.removeSoftBody(doomed);
  delete doomed;  // as Bullet's standard teardown does
  EXPECT_FALSE(body.piece_valid(ids[1]));
  EXPECT_TRUE(body.piece_valid(ids[0]));
  EXPECT_EQ(body.piece_ids().size(), 1u);
  EXPECT_THROW(body.cut(cga::Plane<double>::from_normal_point({1, 0, 0}, {-0.2, 0, 0})),
               std::logic_error);
}
