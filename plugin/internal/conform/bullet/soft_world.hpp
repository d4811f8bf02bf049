// A Bullet soft-rigid dynamics world that owns its collision configuration, dispatcher,
// broadphase and solvers: the world the plugin's tests, benchmarks and scenes run in.
#pragma once

#include "conform/bullet/precision.hpp"  // the package's Bullet precision, checked

#include <BulletSoftBody/btDefaultSoftBodySolver.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>

namespace conform::bullet {

struct SoftWorld {
  btSoftBodyRigidBodyCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDefaultSoftBodySolver soft_solver;
  btSoftRigidDynamicsWorld world{&dispatcher, &broadphase, &solver, &config, &soft_solver};

  /// `gravity` (m/s²) for rigid and soft bodies alike; the soft bodies' sparse SDF is ready.
  explicit SoftWorld(const btVector3& gravity = btVector3(0, 0, 0)) {
    world.setGravity(gravity);
    world.getWorldInfo().m_gravity = gravity;
    world.getWorldInfo().m_sparsesdf.Initialize();
  }
  SoftWorld(const SoftWorld&) = delete;
  SoftWorld& operator=(const SoftWorld&) = delete;

  /// One step of `substeps` fixed substeps of `dt` seconds each.
  void step(double dt, int substeps = 1) {
    world.stepSimulation(btScalar(dt * substeps), substeps, btScalar(dt));
  }
};

}  // namespace conform::bullet
