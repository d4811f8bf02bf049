// Ownership and teardown with a real Bullet world: the application's natural teardown orders
// (Bullet's standard removeSoftBody + delete of every soft body, or of every collision object,
// then the plugin; the world destroyed before the plugin) are safe, and a skinned body whose
// piece the application deleted refuses to step or edit with a message saying why. Run under
// ASan (-DCONFORM_SANITIZE=ON), these were a double free and a SEGV before.
#include <BulletSoftBody/btSoftBody.h>
#include <gtest/gtest.h>

#include <memory>
#include <stdexcept>
#include <string>

#include "conform/bullet/plugin.hpp"
#include "conform/skin/procedural_arm.hpp"
#include "plugin_world.hpp"

using namespace conform;
using conform::test::SoftWorld;

namespace {

// A world with the arm cut in two (two pieces, so that a split's body is in the teardown too).
struct Scene {
  std::unique_ptr<SoftWorld> world = std::make_unique<SoftWorld>(9.81);
  std::unique_ptr<bullet::Plugin> plugin = std::make_unique<bullet::Plugin>(world->world);
  bullet::SkinnedSoftBody* body = nullptr;
  int destroyed = 0;  // body_destroyed events seen
  Scene() {
    const skin::Arm arm = skin::make_arm({.segments = 12, .rings = 24});
    body = &plugin->add_skinned_body(arm.mesh, arm.skeleton);
    body->on_piece_event([this](const bullet::PieceEvent& e) {
      destroyed += e.kind == bullet::PieceEvent::Kind::body_destroyed;
    });
    world->step(2);
    body->cut(cga::Plane<double>::from_normal_point({0, 0, 1}, {0, 0, 0.42}));
    world->step(2);
  }
};

}  // namespace

TEST(PluginLifetime, PluginBeforeWorldLeavesTheWorldEmpty) {
  Scene s;
  ASSERT_EQ(s.body->piece_count(), 2);
  EXPECT_EQ(s.world->world.getSoftBodyArray().size(), 2);
  EXPECT_EQ(s.world->world.getNumCollisionObjects(), 3);  // 2 pieces and the plugin's guard
  s.plugin.reset();
  EXPECT_EQ(s.destroyed, 1);
  EXPECT_EQ(s.world->world.getSoftBodyArray().size(), 0);
  EXPECT_EQ(s.world->world.getNumCollisionObjects(), 0);
  s.world->step(3);  // the action is gone too: stepping touches nothing of the plugin's
}

TEST(PluginLifetime, BulletStandardTeardownThenPlugin) {
  // (a) The app removes and deletes every soft body of the world, then destroys the plugin.
  Scene s;
  btSoftBodyArray& bodies = s.world->world.getSoftBodyArray();
  ASSERT_EQ(bodies.size(), 2);
  for (int i = bodies.size() - 1; i >= 0; --i) {
    btSoftBody* sb = bodies[i];
    s.world->world.removeSoftBody(sb);
    delete sb;
  }
  EXPECT_TRUE(s.body->pieces().empty());  // the books know
  EXPECT_TRUE(s.body->piece_ids().empty());
  s.plugin.reset();  // was a double free
  EXPECT_EQ(s.destroyed, 1);
  EXPECT_EQ(s.world->world.getNumCollisionObjects(), 0);
  s.world.reset();
}

TEST(PluginLifetime, DeletingEveryCollisionObjectThenPlugin) {
  // The demos' exitPhysics: remove and delete every collision object (the guard included).
  Scene s;
  auto& world = s.world->world;
  for (int i = world.getNumCollisionObjects() - 1; i >= 0; --i) {
    btCollisionObject* object = world.getCollisionObjectArray()[i];
    if (btSoftBody* sb = btSoftBody::upcast(object))
      world.removeSoftBody(sb);
    else
      world.removeCollisionObject(object);
    delete object;
  }
  s.plugin.reset();
  EXPECT_EQ(s.destroyed, 1);
  s.world->step(2);  // the action left the world
}

TEST(PluginLifetime, WorldBeforePlugin) {
  // (b) The world (and its dispatcher, broadphase, solvers) goes first: was a SEGV.
  Scene s;
  s.world.reset();
  s.plugin.reset();
  EXPECT_EQ(s.destroyed, 1);
}

TEST(PluginLifetime, AfterTheAppDeletedAPieceStepsAndEditsAreRefused) {
  Scene s;
  btSoftBody* sb = s.body->pieces().back();
  s.world->world.removeSoftBody(sb);
  delete sb;
  try {
    s.world->step(1);
    FAIL() << "a step with a deleted piece must be refused";
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("deleted by the application"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(s.body->cut(cga::Plane<double>::from_normal_point({0, 0, 1}, {0, 0, 0.2})),
               std::logic_error);
  EXPECT_EQ(s.body->pieces().size(), 1u);
  s.plugin->remove_skinned_body(*s.body);  // the remaining piece leaves the world
  EXPECT_EQ(s.destroyed, 1);
  EXPECT_EQ(s.world->world.getSoftBodyArray().size(), 0);
  s.world->step(1);
}
