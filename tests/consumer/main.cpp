// A stand-alone Bullet application that uses an installed Conform (find_package): it adds a
// CGA-skinned procedural arm to its own btSoftRigidDynamicsWorld, poses it with keyframes,
// tears and cuts it between steps, keeps stepping, and checks the result.
#include <BulletSoftBody/btDefaultSoftBodySolver.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>

#include <cmath>
#include <cstdio>

#include "conform/bullet/convert.hpp"
#include "conform/bullet/plugin.hpp"
#include "conform/skin/procedural_arm.hpp"

int main() {
  // The application's own world.
  btSoftBodyRigidBodyCollisionConfiguration config;
  btCollisionDispatcher dispatcher(&config);
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDefaultSoftBodySolver soft_solver;
  btSoftRigidDynamicsWorld world(&dispatcher, &broadphase, &solver, &config, &soft_solver);
  world.setGravity(btVector3(0, 0, -9.81));
  world.getWorldInfo().m_gravity = btVector3(0, 0, -9.81);

  // Conform attaches through addAction; the arm is skinned by CGA motors every substep.
  conform::bullet::Plugin plugin(world);
  const conform::skin::Arm arm = conform::skin::make_arm(1);  // 2562 vertices, 3 bones
  conform::bullet::Material material;
  material.skin.prestress = {80.8e3, 80.8e3};  // Pa: wounds open by themselves
  auto& skin = plugin.add_skinned_body(arm.mesh, arm.skeleton, material);

  // Keyframes made on the fly: bend the elbow by 1 rad over one second.
  conform::skin::PoseTrack track;
  conform::skin::Pose bent = conform::skin::Pose::rest(arm.skeleton);
  bent.apply_local(
      1, conform::skin::Versor::from_trs(
             {0, 0, 0},
             conform::cga::Quat<double>(Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitX())), 1.0));
  track.set_key(0, conform::skin::Pose::rest(arm.skeleton));
  track.set_key(1, bent);
  skin.set_keyframes(track);
  const double mass = skin.total_mass();
  for (int i = 0; i < 30; ++i) world.stepSimulation(btScalar(1.0 / 60), 1, btScalar(1.0 / 60));

  // Between steps: a tear along the upper arm, then a cut through the forearm.
  skin.begin_tear();
  int grew = 0;
  for (int i = 0; i < 12; ++i) {
    const double z = 0.08 + 0.006 * i;
    grew += skin.tear_advance({double(i), {0, 0, z}, {0.15, 0, z}}).extended;
  }
  const auto cut =
      skin.cut(conform::cga::Plane<double>::from_normal_point({0, 0, 1}, {0, 0, 0.45}));
  for (int i = 0; i < 30; ++i) world.stepSimulation(btScalar(1.0 / 60), 1, btScalar(1.0 / 60));

  // Kinematic nodes sit on their skinned targets; nothing blew up; mass is conserved.
  double on_target = 0;
  bool finite = true;
  for (std::int32_t v = 0; v < skin.vertex_count(); ++v) {
    finite = finite && std::isfinite(skin.position(v).norm());
    if (skin.kinematic(v))
      on_target = std::max(on_target, (skin.position(v) - skin.target(v)).norm());
  }
  const double mass_error = std::abs(skin.total_mass() - mass) / mass;
  std::printf(
      "consumer: Bullet %s, %lld substeps, tear grew %d steps, cut %s, %d pieces, %d vertices, "
      "kinematic nodes within %.1e m of their targets, mass error %.1e\n",
      conform::bullet::bullet_precision(), plugin.substeps(), grew,
      cut.status == conform::mesh::CutStatus::Cut ? "made" : "missed", skin.piece_count(),
      skin.vertex_count(), on_target, mass_error);
  const bool ok = finite && plugin.substeps() == 60 && grew > 5 &&
                  cut.status == conform::mesh::CutStatus::Cut && skin.piece_count() == 2 &&
                  on_target < 1e-5 && mass_error < 1e-9 && world.getSoftBodyArray().size() == 2;
  return ok ? 0 : 1;
}
