// A real Bullet soft-rigid world for the plugin tests (no gravity unless asked).
#pragma once

#include <BulletSoftBody/btDefaultSoftBodySolver.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <map>
#include <utility>
#include <vector>

#include "conform/bullet/skinned_soft_body.hpp"
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

/// Bending links of a skinned body against its mesh, counted independently of the plugin's
/// own bookkeeping: a correct link joins the two vertices opposite an edge that exactly two
/// faces of the mesh use; `expected` counts such edges (with distinct opposite vertices).
struct BendingCheck {
  int links = 0;     // Bullet links of material 1 over all pieces
  int wrong = 0;     // of which no edge of the mesh explains
  int expected = 0;  // edges shared by exactly two faces
};

inline BendingCheck check_bending(const bullet::SkinnedSoftBody& body) {
  const auto& m = body.mesh();
  std::map<std::pair<std::int32_t, std::int32_t>, std::vector<std::int32_t>> opposite;
  for (const auto& f : m.faces)
    for (int k = 0; k < 3; ++k)
      opposite[std::minmax(f[std::size_t(k)], f[std::size_t((k + 1) % 3)])].push_back(
          f[std::size_t((k + 2) % 3)]);
  std::map<std::pair<std::int32_t, std::int32_t>, int> pairs;  // opposite pair → edges
  BendingCheck out;
  for (const auto& [edge, far] : opposite)
    if (far.size() == 2 && far[0] != far[1]) {
      ++out.expected;
      ++pairs[std::minmax(far[0], far[1])];
    }
  for (btSoftBody* sb : body.pieces())
    for (int i = 0; i < sb->m_links.size(); ++i) {
      const auto& l = sb->m_links[i];
      if (l.m_material == sb->m_materials[0]) continue;
      ++out.links;
      const std::int32_t c = body.vertex_of(sb, int(l.m_n[0] - &sb->m_nodes[0])),
                         d = body.vertex_of(sb, int(l.m_n[1] - &sb->m_nodes[0]));
      auto it = pairs.find(std::minmax(c, d));
      if (it == pairs.end() || it->second == 0)
        ++out.wrong;
      else
        --it->second;
    }
  return out;
}

}  // namespace conform::test
