// The skinned soft body in a real btSoftRigidDynamicsWorld: validation, kinematic nodes on
// their CGA-skinned targets, free nodes converging, masses, pretension kept across edits.
#include <BulletSoftBody/btSoftBody.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "conform/bullet/plugin.hpp"
#include "conform/io/import.hpp"
#include "conform/mesh/analysis.hpp"
#include "conform/mesh/primitives.hpp"
#include "conform/skin/procedural_arm.hpp"
#include "conform/skin/skinner.hpp"
#include "plugin_world.hpp"

using namespace conform;
using conform::test::SoftWorld;

namespace {

// Elbow bent by `angle` about the local x axis, shoulder swung about z.
skin::Pose arm_pose(const skin::Skeleton& skeleton, double elbow, double shoulder) {
  skin::Pose pose = skin::Pose::rest(skeleton);
  pose.apply_local(1,
                   skin::Versor::from_trs(
                       cga::Vec3<double>(0, 0, 0),
                       cga::Quat<double>(Eigen::AngleAxisd(elbow, Eigen::Vector3d::UnitX())), 1.0));
  pose.apply_local(
      0, skin::Versor::from_trs(
             cga::Vec3<double>(0, 0, 0),
             cga::Quat<double>(Eigen::AngleAxisd(shoulder, Eigen::Vector3d::UnitZ())), 1.0));
  return pose;
}

skin::PoseTrack bending_track(const skin::Skeleton& skeleton) {
  skin::PoseTrack track;
  track.set_key(0, skin::Pose::rest(skeleton));
  track.set_key(0.5, arm_pose(skeleton, 1.0, 0.4));
  track.set_key(1.0, arm_pose(skeleton, 0.3, -0.2));
  return track;
}

// Independent reference: the library's Skinner (CGA mode) on the same pose.
Eigen::Matrix3Xd reference_skin(const mesh::SkinnedMesh& m, const skin::Skeleton& skeleton,
                                const skin::Pose& pose) {
  skin::Skinner<double> skinner(skeleton, m.rest, skin::InfluenceLists::from_mesh(m));
  skinner.skin(pose, skin::SkinMode::cga);
  Eigen::Matrix3Xd out;
  skinner.write(out);
  return out;
}

bool all_finite(const bullet::SkinnedSoftBody& body) {
  for (std::int32_t v = 0; v < body.vertex_count(); ++v)
    if (!body.position(v).allFinite() || !body.velocity(v).allFinite()) return false;
  return true;
}

}  // namespace

TEST(PluginSkinnedBody, ValidatesWorldAndInput) {
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher(&config);
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld rigid(&dispatcher, &broadphase, &solver, &config);
  bullet::Plugin plain(rigid);
  const auto arm = skin::make_arm({.segments = 8, .rings = 10});
  EXPECT_THROW(plain.add_skinned_body(arm.mesh, arm.skeleton), std::logic_error);

  SoftWorld w;
  bullet::Plugin plugin(w.world);
  auto bad = arm.mesh;
  bad.faces[3][1] = bad.vertex_count();
  EXPECT_THROW(plugin.add_skinned_body(bad, arm.skeleton), std::invalid_argument);
  bad = arm.mesh;
  bad.bones(0, 5) = 7;
  EXPECT_THROW(plugin.add_skinned_body(bad, arm.skeleton), std::invalid_argument);
  EXPECT_THROW(
      plugin.add_skinned_body(arm.mesh, arm.skeleton,
                              {.model = bullet::MaterialModel::bullet_links, .pretension = 1.0}),
      std::invalid_argument);
  EXPECT_EQ(plugin.skinned_body_count(), 0u);
  auto& body = plugin.add_skinned_body(arm.mesh, arm.skeleton,
                                       {.model = bullet::MaterialModel::bullet_links});
  EXPECT_EQ(plugin.skinned_body_count(), 1u);
  EXPECT_EQ(body.piece_count(), 1);
  EXPECT_EQ(w.world.getSoftBodyArray().size(), 1);
  plugin.remove_skinned_body(body);
  EXPECT_EQ(w.world.getSoftBodyArray().size(), 0);
}

// A triangle that repeats a vertex (assimp makes them from coincident corners) overflowed a
// heap buffer in Bullet's face set-up; it is refused, naming the face, before Bullet sees it.
TEST(PluginSkinnedBody, RefusesAFaceThatRepeatsAVertex) {
  SoftWorld w;
  bullet::Plugin plugin(w.world);
  const auto arm = skin::make_arm({.segments = 8, .rings = 10});
  auto bad = arm.mesh;
  bad.faces[7][2] = bad.faces[7][0];
  try {
    plugin.add_skinned_body(bad, arm.skeleton);
    ADD_FAILURE() << "a face repeating a vertex was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("face 7 repeats vertex"), std::string::npos) << e.what();
  }
  EXPECT_EQ(plugin.skinned_body_count(), 0u);
  EXPECT_EQ(w.world.getSoftBodyArray().size(), 0);
}

TEST(PluginSkinnedBody, BuildsNodesLinksFacesAndMasses) {
  SoftWorld w;
  bullet::Plugin plugin(w.world);
  const auto arm = skin::make_arm(1);
  const bullet::Material material{.model = bullet::MaterialModel::bullet_links, .density = 1.3};
  auto& body = plugin.add_skinned_body(arm.mesh, arm.skeleton, material);
  btSoftBody* sb = body.pieces().at(0);
  EXPECT_EQ(sb->m_nodes.size(), arm.mesh.vertex_count());
  EXPECT_EQ(sb->m_faces.size(), arm.mesh.face_count());
  // Closed genus-0 triangle mesh: E = 3F / 2.
  EXPECT_EQ(sb->m_links.size(), 3 * arm.mesh.face_count() / 2);
  const double area = mesh::surface_area(arm.mesh);
  EXPECT_NEAR(body.total_mass(), material.density * area, 1e-12 * material.density * area);
  int kinematic = 0;
  for (std::int32_t v = 0; v < body.vertex_count(); ++v) {
    const auto& node = sb->m_nodes[body.node_of(v)];
    EXPECT_EQ(body.kinematic(v), arm.mesh.weights(0, v) >= material.kinematic_weight);
    if (body.kinematic(v)) {
      ++kinematic;
      EXPECT_EQ(node.m_im, btScalar(0));
    } else {
      EXPECT_NEAR(1 / double(node.m_im), body.mass(v), 1e-6 * body.mass(v));
    }
  }
  EXPECT_GT(kinematic, 0);
  EXPECT_LT(kinematic, body.vertex_count());  // the joints' blend zones are free
}

TEST(PluginSkinnedBody, KinematicNodesTrackTheirCgaSkinnedTargetsExactly) {
  SoftWorld w(9.81);
  bullet::Plugin plugin(w.world);
  const auto arm = skin::make_arm(1);
  auto& body = plugin.add_skinned_body(arm.mesh, arm.skeleton,
                                       {.model = bullet::MaterialModel::bullet_links});
  const auto track = bending_track(arm.skeleton);
  body.set_keyframes(track);
  for (int step = 1; step <= 60; ++step) {
    w.step();
    if (step % 15) continue;
    skin::Pose pose = skin::Pose::rest(arm.skeleton);
    track.sample(plugin.time(), skin::Blend::linear, pose);
    const Eigen::Matrix3Xd expected = reference_skin(arm.mesh, arm.skeleton, pose);
    double target_error = 0, node_error = 0;
    for (std::int32_t v = 0; v < body.vertex_count(); ++v) {
      target_error = std::max(target_error, (body.target(v) - expected.col(v)).norm());
      if (body.kinematic(v))
        node_error = std::max(node_error, (body.position(v) - body.target(v)).norm());
    }
    EXPECT_LT(target_error, 1e-12) << "step " << step;
    // Exact up to storing the target in btScalar.
    EXPECT_LT(node_error, sizeof(btScalar) == 4 ? 1e-6 : 1e-14) << "step " << step;
  }
  EXPECT_TRUE(all_finite(body));
}

TEST(PluginSkinnedBody, FreeNodesConvergeToTheirTargets) {
  SoftWorld w;
  bullet::Plugin plugin(w.world);
  const auto arm = skin::make_arm(1);
  // Only the shoulder end is kinematic; everything else follows by the per-node pull.
  auto& body = plugin.add_skinned_body(
      arm.mesh, arm.skeleton,
      {.model = bullet::MaterialModel::bullet_links, .kinematic_weight = 2.0});
  std::vector<std::int32_t> pinned;
  for (std::int32_t v = 0; v < arm.mesh.vertex_count(); ++v)
    if (arm.mesh.rest(2, v) < 0.05) pinned.push_back(v);
  body.set_pinned(pinned);
  // A rigid swing of the whole arm: skinning keeps every length, so the links agree with the
  // targets and the free nodes can reach them exactly.
  skin::Pose pose = skin::Pose::rest(arm.skeleton);
  pose.apply_local(0, skin::Versor::from_trs(cga::Vec3<double>(0, 0, 0),
                                             cga::Quat<double>(Eigen::AngleAxisd(
                                                 0.7, Eigen::Vector3d(1, 1, 0).normalized())),
                                             1.0));
  // Set after a first substep in the bind pose: a body given its pose source before stepping
  // would start on that pose (no transient to converge from).
  w.step(1);
  body.set_pose(pose);
  w.step(10);
  double early = 0;
  for (std::int32_t v = 0; v < body.vertex_count(); ++v)
    early = std::max(early, (body.position(v) - body.target(v)).norm());
  EXPECT_GT(early, 1e-2);  // a real transient, not placed on the target
  w.step(170);
  double late = 0, speed = 0;
  for (std::int32_t v = 0; v < body.vertex_count(); ++v) {
    late = std::max(late, (body.position(v) - body.target(v)).norm());
    speed = std::max(speed, body.velocity(v).norm());
  }
  EXPECT_LT(late, 1e-3);
  EXPECT_LT(speed, 1e-2);
  EXPECT_TRUE(all_finite(body));
}

TEST(PluginSkinnedBody, PretensionSurvivesBulletsRestLengthReset) {
  SoftWorld w;
  bullet::Plugin plugin(w.world);
  const auto arm = skin::make_arm({.segments = 16, .rings = 40});
  const double s = 0.2;
  auto& body = plugin.add_skinned_body(
      arm.mesh, arm.skeleton, {.model = bullet::MaterialModel::bullet_links, .pretension = s});
  auto check = [&](const char* when) {
    for (btSoftBody* sb : body.pieces()) {
      sb->m_bUpdateRtCst = true;  // as after any edit: Bullet resets rest lengths next step
    }
    w.step();
    int checked = 0;
    int stretched = 0;
    for (btSoftBody* sb : body.pieces())
      for (int i = 0; i < sb->m_links.size(); ++i) {
        const auto& l = sb->m_links[i];
        const std::int32_t a = body.vertex_of(sb, int(l.m_n[0] - &sb->m_nodes[0])),
                           b = body.vertex_of(sb, int(l.m_n[1] - &sb->m_nodes[0]));
        // Ours, not Bullet's reset value (the current length).
        ASSERT_NEAR(double(l.m_rl), body.rest_length(a, b), 1e-6 * body.rest_length(a, b)) << when;
        ASSERT_NEAR(double(l.m_c1), double(l.m_rl) * double(l.m_rl), 1e-6 * double(l.m_c1));
        const double current = double((l.m_n[0]->m_x - l.m_n[1]->m_x).length());
        if (body.kinematic(a) && body.kinematic(b)) {
          // Held apart by the skeleton: tension stays.
          ASSERT_LT(double(l.m_rl), 0.9 * current) << when;
          ++stretched;
        }
        ++checked;
      }
    EXPECT_GT(checked, 0);
    EXPECT_GT(stretched, checked / 2);
  };
  check("after build");
  // Original links keep (1 − s) × their initial length.
  const auto& f = arm.mesh.faces[100];
  EXPECT_NEAR(body.rest_length(f[0], f[1]),
              (1 - s) * (arm.mesh.rest.col(f[0]) - arm.mesh.rest.col(f[1])).norm(), 1e-12);
  body.cut(cga::Plane<double>::from_normal_point({0, 0, 1}, {0, 0, 0.42}));
  EXPECT_EQ(body.piece_count(), 2);
  check("after a cut");
}

TEST(PluginSkinnedBody, AnimatedModelFromAFile) {
  const auto model = io::import_model(std::string(CONFORM_ASSIMP_MODELS) + "/X/anim_test.x");
  ASSERT_FALSE(model.animations.empty());
  SoftWorld w;
  bullet::Plugin plugin(w.world);
  auto& body = plugin.add_skinned_body(
      model, {.model = bullet::MaterialModel::bullet_links, .kinematic_weight = 0.5});
  body.play(model.animations[0]);
  w.step(20);
  skin::Pose pose = skin::Pose::rest(model.skeleton);
  const double d = model.animations[0].duration();
  model.animations[0].sample(model.skeleton, d > 0 ? std::fmod(plugin.time(), d) : plugin.time(),
                             skin::Blend::linear, pose);
  const Eigen::Matrix3Xd expected = reference_skin(model.mesh, model.skeleton, pose);
  double scale = (expected.rowwise().maxCoeff() - expected.rowwise().minCoeff()).norm();
  for (std::int32_t v = 0; v < body.vertex_count(); ++v) {
    ASSERT_LT((body.target(v) - expected.col(v)).norm(), 1e-9 * scale);
    if (body.kinematic(v)) {
      ASSERT_LT((body.position(v) - expected.col(v)).norm(), 1e-5 * scale);
    }
  }
  EXPECT_TRUE(all_finite(body));
}
