// What the plugin refuses, and with which message: an animation of another skeleton in play(),
// an edit from inside a step, every out-of-range Material field (naming field, value and
// range); and what it no longer refuses: target(v) and every other query right after an edit.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "conform/bullet/plugin.hpp"
#include "conform/skin/procedural_arm.hpp"
#include "conform/skin/skinner.hpp"
#include "plugin_world.hpp"

using namespace conform;
using conform::test::SoftWorld;

namespace {

const cga::Plane<double> kCut = cga::Plane<double>::from_normal_point({0, 0, 1}, {0, 0, 0.42});

skin::Arm small_arm() {
  return skin::make_arm({.segments = 12, .rings = 24});
}

template <class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no exception)";
}

}  // namespace

TEST(PluginValidation, PlayRefusesAnAnimationOfAnotherSkeleton) {
  SoftWorld world;
  bullet::Plugin plugin(world.world);
  const skin::Arm arm = small_arm();  // 3 joints
  auto& body = plugin.add_skinned_body(arm.mesh, arm.skeleton);
  skin::Animation animation;
  animation.name = "tail";
  animation.duration_ticks = 25;
  for (std::int32_t joint : {0, 1, 3}) {  // joint 3 does not exist
    skin::Channel channel;
    channel.joint = joint;
    channel.rotation.push_back({0.0, Eigen::Quaterniond::Identity()});
    animation.channels.push_back(channel);
  }
  const std::string message = message_of([&] { body.play(animation); });
  EXPECT_NE(message.find("play: animation 'tail' does not fit the skeleton"), std::string::npos)
      << message;
  EXPECT_NE(message.find("joint 3"), std::string::npos) << message;
  world.step(3);  // the earlier source stands: no heap corruption (ASan build)
  animation.channels.pop_back();
  EXPECT_NO_THROW(body.play(animation));
  world.step(3);
}

TEST(PluginValidation, APoseSourceOfAnotherSkeletonIsRefusedNamingTheCounts) {
  SoftWorld world;
  bullet::Plugin plugin(world.world);
  const skin::Arm arm = small_arm();
  auto& body = plugin.add_skinned_body(arm.mesh, arm.skeleton);
  body.set_pose_source([](double, skin::Pose& pose) { pose.local.resize(7); });
  const std::string message = message_of([&] { world.step(1); });
  EXPECT_NE(message.find("pose source gave 7 joints"), std::string::npos) << message;
}

TEST(PluginValidation, TargetsAndQueriesAreValidRightAfterAnEdit) {
  SoftWorld world;
  bullet::Plugin plugin(world.world);
  const skin::Arm arm = small_arm();
  auto& body = plugin.add_skinned_body(arm.mesh, arm.skeleton);
  const skin::Pose pose = test::bent_arm_pose(arm.skeleton, 0.3, 0.8);
  body.set_pose(pose);
  world.step(3);
  const std::int32_t before = body.vertex_count();
  ASSERT_EQ(body.cut(kCut).status, mesh::CutStatus::Cut);
  ASSERT_GT(body.vertex_count(), before);
  // Independently: core's skinning of the edited mesh's rest points at the same pose.
  const auto& m = body.mesh();
  skin::Skinner<double> skinner(arm.skeleton, m.rest, skin::Influences<double>::from_mesh(m));
  skinner.skin(pose, skin::SkinMode::cga);
  const auto& expected = skinner.output();
  double worst = 0;
  for (std::int32_t v = 0; v < body.vertex_count(); ++v) {
    const Eigen::Vector3d t = body.target(v);  // was out_of_range for new vertices
    const auto i = static_cast<std::size_t>(v);
    worst =
        std::max(worst, (t - Eigen::Vector3d(expected.x[i], expected.y[i], expected.z[i])).norm());
    EXPECT_TRUE(body.position(v).allFinite());
    EXPECT_TRUE(body.velocity(v).allFinite());
    EXPECT_GT(body.mass(v), 0);
    EXPECT_EQ(body.body_of(v) != nullptr, !body.detached(v));
    EXPECT_EQ(body.piece_body(body.piece_of(v)), body.body_of(v));
    if (!body.detached(v)) {
      EXPECT_EQ(body.vertex_of(body.body_of(v), body.node_of(v)), v);
    }
  }
  EXPECT_LT(worst, 1e-12);
  world.step(2);
  for (std::int32_t v = 0; v < body.vertex_count(); ++v) EXPECT_TRUE(body.target(v).allFinite());
}

TEST(PluginValidation, AnEditInsideAStepHookIsRefusedSayingWhy) {
  SoftWorld world;
  bullet::Plugin plugin(world.world);
  const skin::Arm arm = small_arm();
  auto& body = plugin.add_skinned_body(arm.mesh, arm.skeleton);
  std::vector<std::string> messages;
  auto attempt = [&](const std::function<void()>& edit) { messages.push_back(message_of(edit)); };
  plugin.add_step_hook([&](double) {
    if (!messages.empty()) return;
    attempt([&] { body.cut(kCut); });
    attempt([&] { body.tear_advance({}); });
    attempt([&] { body.release_piece(body.piece_ids().at(0)); });
    attempt([&] { plugin.add_skinned_body(arm.mesh, arm.skeleton); });
  });
  const std::int32_t vertices = body.vertex_count();
  world.step(1);
  ASSERT_EQ(messages.size(), 4u);
  EXPECT_NE(messages[0].find("SkinnedSoftBody::cut: called inside stepSimulation"),
            std::string::npos)
      << messages[0];
  EXPECT_NE(messages[0].find("edit between stepSimulation calls"), std::string::npos);
  EXPECT_NE(messages[1].find("tear_advance: called inside stepSimulation"), std::string::npos);
  EXPECT_NE(messages[2].find("release_piece: called inside stepSimulation"), std::string::npos);
  EXPECT_NE(messages[3].find("add_skinned_body: called inside stepSimulation"), std::string::npos);
  EXPECT_EQ(body.vertex_count(), vertices);  // nothing happened
  EXPECT_EQ(plugin.skinned_body_count(), 1u);
  EXPECT_EQ(body.cut(kCut).status, mesh::CutStatus::Cut);  // between steps: fine
}

TEST(PluginValidation, EveryMaterialFieldIsRangeCheckedWithFieldValueAndRange) {
  SoftWorld world;
  bullet::Plugin plugin(world.world);
  const skin::Arm arm = small_arm();
  struct Case {
    std::function<void(bullet::Material&)> set;
    std::string expected;
  };
  const double nan = std::nan("");
  const std::vector<Case> cases = {
      {[](auto& m) { m.model = static_cast<bullet::MaterialModel>(7); },
       "material model = 7 is out of range (membrane (0) or bullet_links (1))"},
      {[](auto& m) { m.link_stiffness = 0; },
       "material link_stiffness = 0 is out of range ((0, 1])"},
      {[](auto& m) { m.link_stiffness = 1.5; }, "link_stiffness = 1.5 is out of range ((0, 1])"},
      {[](auto& m) { m.damping = -0.1; }, "material damping = -0.1 is out of range ([0, 1))"},
      {[](auto& m) { m.damping = 1; }, "damping = 1 is out of range ([0, 1))"},
      {[](auto& m) { m.pretension = 1; }, "material pretension = 1 is out of range ([0, 1))"},
      {[](auto& m) { m.density = 0; }, "material density = 0 is out of range (> 0 kg/m^2)"},
      {[](auto& m) { m.target_stiffness = -400; },
       "material target_stiffness = -400 is out of range (>= 0 1/s^2)"},
      {[](auto& m) { m.target_damping = -1; },
       "material target_damping = -1 is out of range (>= 0 1/s)"},
      {[nan](auto& m) { m.kinematic_weight = nan; }, "material kinematic_weight = nan"},
      {[](auto& m) { m.position_iterations = -3; },
       "material position_iterations = -3 is out of range ([1, 1000])"},
      {[](auto& m) { m.position_iterations = 0; }, "position_iterations = 0 is out of range"},
      {[](auto& m) { m.bending_stiffness = 2; },
       "material bending_stiffness = 2 is out of range ([0, 1])"},
      {[](auto& m) { m.margin = -0.005; }, "material margin = -0.005 is out of range ([0, 1] m)"},
      {[nan](auto& m) { m.margin = nan; }, "material margin = nan is out of range"},
      {[](auto& m) { m.skin.youngs_modulus = -1; }, "skin material: youngs_modulus = -1"},
      {[](auto& m) { m.solver.relative_tolerance = -1; },
       "membrane solver: relative_tolerance = -1"},
  };
  for (const Case& c : cases) {
    bullet::Material material{};
    c.set(material);
    const std::string message =
        message_of([&] { plugin.add_skinned_body(arm.mesh, arm.skeleton, material); });
    EXPECT_NE(message.find(c.expected), std::string::npos)
        << "expected '" << c.expected << "' in '" << message << "'";
  }
  EXPECT_EQ(plugin.skinned_body_count(), 0u);
  EXPECT_EQ(world.world.getSoftBodyArray().size(), 0);  // nothing half-built was left behind
}

TEST(PluginValidation, ReleaseOptionsAndStaleIdsAreRefusedWithTheirValues) {
  SoftWorld world;
  bullet::Plugin plugin(world.world);
  const skin::Arm arm = small_arm();
  auto& body = plugin.add_skinned_body(arm.mesh, arm.skeleton);
  const bullet::PieceId id = body.piece_ids().at(0);
  bullet::ReleaseOptions bad{};
  bad.volume_modulus = -2;
  EXPECT_NE(message_of([&] {
              body.release_piece(id, bad);
            }).find("release_piece: volume_modulus = -2 is out of range (>= 0 Pa)"),
            std::string::npos);
  EXPECT_FALSE(body.piece_released(id));
  const bullet::PieceId stale{id.index, id.generation + 1};
  EXPECT_NE(message_of([&] {
              body.release_piece(stale);
            }).find("release_piece: piece id (slot 0, generation 2) is stale or null"),
            std::string::npos);
  EXPECT_FALSE(body.piece_valid(bullet::PieceId{}));
  EXPECT_EQ(body.piece_body(bullet::PieceId{}), nullptr);
}
