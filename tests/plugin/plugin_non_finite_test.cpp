// The per-substep finiteness check (conform/bullet/non_finite_state.hpp): a NaN or infinity in a
// node stops stepSimulation with a NonFiniteState naming the substep, the skinned body, the
// piece, the node and its vertex; a healthy run never trips it.
#include <BulletSoftBody/btSoftBody.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "conform/bullet/plugin.hpp"
#include "conform/skin/procedural_arm.hpp"
#include "plugin_world.hpp"

using namespace conform;
using conform::test::SoftWorld;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The first vertex whose kinematic flag is `kinematic`.
std::int32_t vertex_where(const bullet::SkinnedSoftBody& body, bool kinematic) {
  for (std::int32_t v = 0; v < body.vertex_count(); ++v)
    if (body.kinematic(v) == kinematic) return v;
  return -1;
}

// Steps until the plugin throws; the exception (or a failure when none came within `steps`).
bullet::NonFiniteState step_until_thrown(SoftWorld& w, int steps) {
  for (int i = 0; i < steps; ++i) {
    try {
      w.step();
    } catch (const bullet::NonFiniteState& e) {
      return e;
    }
  }
  ADD_FAILURE() << "no NonFiniteState within " << steps << " steps";
  return bullet::NonFiniteState(-1, 0, 0, {});
}

struct TwoArms : ::testing::Test {
  SoftWorld w;
  bullet::Plugin plugin{w.world};
  skin::Arm arm = skin::make_arm(1);
  bullet::SkinnedSoftBody* first = nullptr;
  bullet::SkinnedSoftBody* second = nullptr;
  void SetUp() override {
    // bullet_links: kinematic nodes (weight ≥ kinematic_weight) and pulled free ones.
    const bullet::Material links{.model = bullet::MaterialModel::bullet_links};
    first = &plugin.add_skinned_body(arm.mesh, arm.skeleton, links);
    second = &plugin.add_skinned_body(arm.mesh, arm.skeleton, links);
    w.step(3);
    ASSERT_FALSE(first->first_non_finite_node());
    ASSERT_FALSE(second->first_non_finite_node());
  }
};

TEST_F(TwoArms, ANaNPositionOfAFreeNodeNamesSubstepBodyPieceNodeAndVertex) {
  const std::int32_t v = vertex_where(*second, false);
  ASSERT_GE(v, 0);
  const int node = second->node_of(v);
  btSoftBody* body = second->body_of(v);
  body->m_nodes[node].m_x.setX(btScalar(kNaN));
  const bullet::NonFiniteState e = step_until_thrown(w, 1);
  EXPECT_EQ(e.substep(), 4);
  EXPECT_NEAR(e.time(), 4.0 / 60, 1e-6);  // btScalar may be float
  EXPECT_EQ(e.body(), 1u);                // the second body added
  EXPECT_EQ(e.node().piece, second->piece_of(v).index);
  EXPECT_EQ(e.node().node, node);
  EXPECT_EQ(e.node().vertex, v);
  EXPECT_TRUE(e.node().position);
  EXPECT_TRUE(std::isnan(e.node().value.x()));
  const std::string what = e.what();
  EXPECT_NE(what.find("substep 4 "), std::string::npos) << what;
  EXPECT_NE(what.find("skinned body 1, piece 0, node " + std::to_string(node) + " (mesh vertex " +
                      std::to_string(v) + ") has position (nan"),
            std::string::npos)
      << what;
  EXPECT_EQ(plugin.substeps(), 4);  // it stopped in that substep
  // The body itself reports the same node between steps.
  const auto bad = second->first_non_finite_node();
  ASSERT_TRUE(bad);
  EXPECT_EQ(bad->vertex, v);
}

TEST_F(TwoArms, ANaNTargetIsCaughtAtTheNextSubstep) {
  // A pose source that returns NaN: the drive of substep 4 moves the nodes toward NaN targets,
  // the pass at the start of substep 5 sees them.
  first->set_pose_source([&](double, skin::Pose& pose) {
    pose = skin::Pose::rest(arm.skeleton);
    pose.local[0].motor.e1inf = kNaN;
  });
  const bullet::NonFiniteState e = step_until_thrown(w, 2);
  EXPECT_EQ(e.substep(), 5);
  EXPECT_EQ(e.body(), 0u);
  EXPECT_EQ(e.node().node, 0);  // every node is driven to NaN: the first one is named
  EXPECT_NE(std::string(e.what()).find("at the start of that substep"), std::string::npos)
      << e.what();
}

TEST_F(TwoArms, AVelocityAloneIsCaught) {
  // Bullet's prediction moves nodes by m_v dt; an infinite velocity of a kinematic node is
  // overwritten by the drive, a NaN one of a node at rest shows in its position first.
  const std::int32_t v = vertex_where(*first, false);
  first->body_of(v)->m_nodes[first->node_of(v)].m_v.setZ(btScalar(kNaN));
  const bullet::NonFiniteState e = step_until_thrown(w, 1);
  EXPECT_EQ(e.node().vertex, v);
  EXPECT_NE(std::string(e.what()).find("mesh vertex " + std::to_string(v) + ")"), std::string::npos)
      << e.what();
}

TEST_F(TwoArms, AnInfiniteVelocityIsCaughtInTheNextSubstep) {
  const std::int32_t v = vertex_where(*first, false);
  first->body_of(v)->m_nodes[first->node_of(v)].m_v.setY(
      btScalar(std::numeric_limits<double>::infinity()));
  const bullet::NonFiniteState e = step_until_thrown(w, 1);
  EXPECT_EQ(e.substep(), 4);
  EXPECT_EQ(e.node().vertex, v);
  // Bullet's prediction moved the node by v·dt: its position is the first non-finite value.
  EXPECT_TRUE(e.node().position);
  EXPECT_FALSE(e.node().value.allFinite());
}

TEST(PluginNonFinite, ARunawayNodeStopsTheStepBeforeItOverflows) {
  // A finite but unphysical velocity (an unstable integration grows like this for many steps
  // before it overflows): above Material::max_speed it stops the step. The library's default
  // is no bound (it does not know the world's unit); this world is in metres.
  SoftWorld w;
  bullet::Plugin plugin{w.world};
  const skin::Arm arm = skin::make_arm(1);
  bullet::Material links{.model = bullet::MaterialModel::bullet_links};
  EXPECT_TRUE(std::isinf(links.max_speed));
  links.max_speed = 100;
  bullet::SkinnedSoftBody& body = plugin.add_skinned_body(arm.mesh, arm.skeleton, links);
  w.step(1);
  const std::int32_t v = vertex_where(body, false);
  body.body_of(v)->m_nodes[body.node_of(v)].m_v.setX(btScalar(1e4));
  const bullet::NonFiniteState e = step_until_thrown(w, 1);
  EXPECT_EQ(e.node().vertex, v);
  EXPECT_TRUE(e.node().runaway);
  EXPECT_TRUE(e.node().value.allFinite());
  const std::string what = e.what();
  EXPECT_NE(what.find("ran away"), std::string::npos) << what;
  EXPECT_NE(what.find("moves at 10000 m/s"), std::string::npos) << what;
}

TEST(PluginNonFinite, ASkinItsBodySweepsFasterThanTheBoundIsNoRunaway) {
  // The bound is on a node's speed past its skinned target: a body carried at 150 m/s (a long
  // chain turning full circles does this) runs on; a node kicked past its target stops it.
  SoftWorld w;
  bullet::Plugin plugin{w.world};
  const skin::Arm arm = skin::make_arm(1);
  bullet::Material skin;  // the membrane, the library's default
  skin.max_speed = 100;
  bullet::SkinnedSoftBody& body = plugin.add_skinned_body(arm.mesh, arm.skeleton, skin);
  const double acceleration = 300;  // m/s², so 150 m/s at 0.5 s
  const int frames = 30;
  for (int i = 1; i <= frames; ++i) {
    const double t = i / 60.0;
    body.set_world_transform(
        Eigen::Isometry3d(Eigen::Translation3d(0.5 * acceleration * t * t, 0, 0)));
    ASSERT_NO_THROW(w.step(1)) << "frame " << i;
  }
  const std::int32_t v = vertex_where(body, false);
  btSoftBody::Node& node = body.body_of(v)->m_nodes[body.node_of(v)];
  EXPECT_GT(double(node.m_v.x()), 0.9 * acceleration * (frames - 1) / 60.0);  // > 100 m/s
  node.m_v.setY(btScalar(1e4));
  const bullet::NonFiniteState e = step_until_thrown(w, 1);
  EXPECT_EQ(e.node().vertex, v);
  EXPECT_TRUE(e.node().runaway);
  EXPECT_NEAR(e.node().value.y(), 1e4, 1);  // past its target: the carried 145 m/s along x gone
  EXPECT_LT(std::abs(e.node().value.x()), 10);
}

TEST(PluginNonFinite, WithoutABoundAFastNodeGoesOnAndABadBoundIsRefused) {
  SoftWorld w;
  bullet::Plugin plugin{w.world};
  const skin::Arm arm = skin::make_arm(1);
  bullet::Material links{.model = bullet::MaterialModel::bullet_links};
  bullet::SkinnedSoftBody& body = plugin.add_skinned_body(arm.mesh, arm.skeleton, links);
  w.step(1);
  const std::int32_t v = vertex_where(body, false);
  body.body_of(v)->m_nodes[body.node_of(v)].m_v.setX(btScalar(1e4));
  EXPECT_NO_THROW(w.step(1));
  links.max_speed = 0;
  EXPECT_THROW(plugin.add_skinned_body(arm.mesh, arm.skeleton, links), std::invalid_argument);
}

TEST_F(TwoArms, AfterTheThrowThePluginStillEditsAndTearsDown) {
  const std::int32_t v = vertex_where(*first, false);
  first->body_of(v)->m_nodes[first->node_of(v)].m_x.setX(btScalar(kNaN));
  (void)step_until_thrown(w, 1);
  // Not inside a step any more: an edit is not refused as one made from a step hook.
  EXPECT_NO_THROW(plugin.remove_skinned_body(*first));
  EXPECT_EQ(plugin.skinned_body_count(), 1u);
}

TEST(PluginNonFinite, TheMembraneDriveStopsOnANaNNode) {
  SoftWorld w;
  bullet::Plugin plugin{w.world};
  const skin::Arm arm = skin::make_arm(1);
  auto& body = plugin.add_skinned_body(arm.mesh, arm.skeleton);  // the default membrane
  w.step(2);
  const std::int32_t v = arm.mesh.vertex_count() / 2;
  body.body_of(v)->m_nodes[body.node_of(v)].m_x.setY(btScalar(kNaN));
  bool thrown = false;
  try {
    w.step();
  } catch (const bullet::NonFiniteState& e) {
    thrown = true;
    EXPECT_EQ(e.substep(), 3);
    EXPECT_EQ(e.body(), 0u);
    EXPECT_GE(e.node().vertex, 0);
  } catch (const std::exception& e) {
    ADD_FAILURE() << "another error first: " << e.what();
  }
  EXPECT_TRUE(thrown);
}

TEST(PluginNonFinite, AHealthyRunNeverTripsTheCheck) {
  SoftWorld w(9.81);
  bullet::Plugin plugin{w.world};
  const skin::Arm arm = skin::make_arm(1);
  auto& body = plugin.add_skinned_body(arm.mesh, arm.skeleton);
  body.set_pose(conform::test::bent_arm_pose(arm.skeleton, 0.4, 1.0));
  EXPECT_NO_THROW(w.step(30));
  EXPECT_FALSE(body.first_non_finite_node());
}

}  // namespace
