// A real Bullet soft-rigid world for the plugin tests (no gravity unless asked).
#pragma once

#include <BulletSoftBody/btDefaultSoftBodySolver.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>

#include <Eigen/Geometry>

#include "conform/skin/pose.hpp"

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

/// The arm's rest pose with the shoulder turned about y and the elbow bent about x (radians).
inline skin::Pose bent_arm_pose(const skin::Skeleton& skeleton, double shoulder, double elbow) {
  skin::Pose pose = skin::Pose::rest(skeleton);
  const auto turn = [](double angle, const Eigen::Vector3d& axis) {
    return skin::Versor::from_trs(cga::Vec3<double>::Zero(),
                                  cga::Quat<double>(Eigen::AngleAxisd(angle, axis)), 1.0);
  };
  pose.apply_local(0, turn(shoulder, Eigen::Vector3d::UnitY()));
  pose.apply_local(1, turn(elbow, Eigen::Vector3d::UnitX()));
  return pose;
}

}  // namespace conform::test
