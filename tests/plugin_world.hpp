// A real Bullet soft-rigid world for the plugin tests (no gravity unless asked).
#pragma once

#include <BulletSoftBody/btDefaultSoftBodySolver.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>

namespace conform::test {

struct SoftWorld {
  btSoftBodyRigidBodyCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDefaultSoftBodySolver soft_solver;
  btSoftRigidDynamicsWorld world{&dispatcher, &broadphase, &solver, &config, &soft_solver};
  explicit SoftWorld(double gravity = 0) {
    world.setGravity(btVector3(0, 0, btScalar(-gravity)));
    world.getWorldInfo().m_gravity = btVector3(0, 0, btScalar(-gravity));
    world.getWorldInfo().m_sparsesdf.Initialize();
  }
  void step(int n = 1, double dt = 1.0 / 60) {
    for (int i = 0; i < n; ++i) world.stepSimulation(btScalar(dt), 1, btScalar(dt));
  }
};

}  // namespace conform::test
