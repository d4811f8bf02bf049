// Links conform::core and conform::bullet from an install prefix, attaches the plugin to a real
// Bullet soft-rigid world, steps it, and checks a motor round trip through btTransform.
#include <BulletSoftBody/btDefaultSoftBodySolver.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>

#include <cmath>
#include <cstdio>

#include "conform/bullet/convert.hpp"
#include "conform/bullet/plugin.hpp"
#include "conform/cga.hpp"

int main() {
  btSoftBodyRigidBodyCollisionConfiguration config;
  btCollisionDispatcher dispatcher(&config);
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDefaultSoftBodySolver soft_solver;
  btSoftRigidDynamicsWorld world(&dispatcher, &broadphase, &solver, &config, &soft_solver);

  conform::bullet::Plugin plugin(world);
  double simulated = 0;
  plugin.add_step_hook([&](double dt) { simulated += dt; });
  for (int i = 0; i < 60; ++i) world.stepSimulation(btScalar(1.0 / 60), 1, btScalar(1.0 / 60));

  const auto motor = conform::cga::Motor<double>::from_axis_angle({0, 0, 1}, 0.5) *
                     conform::cga::Motor<double>::from_translation({1, 2, 3});
  const auto back = conform::bullet::to_motor(conform::bullet::to_transform(motor));
  const auto x = motor.apply({0.1, 0.2, 0.3}), y = back.apply({0.1, 0.2, 0.3});
  const double error = (x - y).norm();
  std::printf("consumer: %lld substeps, %.4f s simulated, Bullet %s, motor round trip %.2e\n",
              plugin.substeps(), simulated, conform::bullet::bullet_precision(), error);
  const bool ok = plugin.substeps() == 60 && std::abs(simulated - 1.0) < 1e-4 && error < 1e-5;
  return ok ? 0 : 1;
}
