// Each library's one-include header (conform/bullet.hpp, mesh.hpp, skin.hpp, ik.hpp, io.hpp,
// membrane.hpp, cga.hpp) compiles on its own and brings what an application uses from it. The
// installed copies are compiled by the install test's consumer (tests/consumer/application.cpp).
#include <gtest/gtest.h>

#include <type_traits>

#include "conform/bullet.hpp"
#include "conform/cga.hpp"
#include "conform/ik.hpp"
#include "conform/io.hpp"
#include "conform/membrane.hpp"
#include "conform/mesh.hpp"
#include "conform/skin.hpp"

namespace {

using namespace conform;

// The edits, the skinning, the IK and the import, each named through its library's header.
TEST(UmbrellaHeaders, EachLibraryHeaderBringsWhatAnApplicationUses) {
  static_assert(std::is_class_v<bullet::SkinnedSoftBody>);
  static_assert(std::is_class_v<bullet::Material>);
  static_assert(std::is_class_v<bullet::RigidScalpel>);
  static_assert(std::is_class_v<mesh::SkinnedMesh>);
  static_assert(std::is_class_v<mesh::TopologyChange>);
  static_assert(std::is_class_v<mesh::Tear>);
  static_assert(std::is_class_v<skin::Skeleton>);
  static_assert(std::is_class_v<skin::Pose>);
  static_assert(std::is_class_v<io::SkinnedModel>);
  static_assert(std::is_class_v<io::ImportOptions>);
  static_assert(std::is_class_v<membrane::SkinMaterial>);
  static_assert(std::is_class_v<cga::Motor<double>>);
  // Calls through them: the procedural arm is built, and the IK's solution reaches its target
  // by forward kinematics.
  const skin::Arm arm = skin::make_arm(1);
  EXPECT_GT(arm.mesh.vertex_count(), 0);
  EXPECT_EQ(arm.skeleton.joint_count(), 3);
  const ik::Arm<double> limb;
  const ik::Vec3<double> target(0.1, 0.2, 0.3);
  const ik::Solution<double> s = ik::solve(limb, target, 0.3);
  EXPECT_LT((ik::forward_kinematics(limb, s.qs, s.qe).wrist - target).norm(), 1e-9);
}

}  // namespace
