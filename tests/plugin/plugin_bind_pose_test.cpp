// The skin's rest state is the bind pose, not the mesh's rest points: an imported mesh may keep
// its points in a mesh space of another scale (huesitos.fbx: 100 times smaller than its bind
// pose), its bones' offsets bringing them to the bind pose. The same arm described that way
// (points / 100, every offset dilated by 100: the same skinned targets) must simulate as the
// arm itself, with the membrane, through a flex and an edit.
#include <gtest/gtest.h>

#include <cstdio>

#include "conform/bullet/plugin.hpp"
#include "conform/skin/procedural_arm.hpp"
#include "plugin_world.hpp"

using namespace conform;
using conform::test::SoftWorld;

namespace {

struct ArmRun {
  SoftWorld w;
  bullet::Plugin plugin{w.world};
  bullet::SkinnedSoftBody* body = nullptr;
};

void simulate(ArmRun& r, const mesh::SkinnedMesh& mesh, const skin::Skeleton& skeleton) {
  r.body = &r.plugin.add_skinned_body(mesh, skeleton, bullet::Material{});
  skin::PoseTrack track;
  track.set_key(0, skin::Pose::rest(skeleton));
  track.set_key(0.5, test::bent_arm_pose(skeleton, 0.3, 1.2));
  r.body->set_keyframes(track);
  r.w.step(15);
  r.body->begin_tear();
  for (int i = 0; i < 8; ++i) {
    const double z = 0.3712 + 0.01 * i;
    r.body->tear_advance({double(i), {0.09, 0.0023, z}, {0.005, 0.0023, z}});
  }
  r.w.step(15);
}

TEST(PluginBindPose, MeshSpaceOfAnotherScaleSimulatesAsTheBindPose) {
  const skin::Arm arm = skin::make_arm(1);
  mesh::SkinnedMesh small = arm.mesh;
  small.rest = arm.mesh.rest / 100;  // the file's mesh space
  skin::Skeleton scaled = arm.skeleton;
  for (auto& bone : scaled.bones) bone.offset = bone.offset * skin::Versor{{}, 100.0};
  ArmRun plain, mesh_space;
  simulate(plain, arm.mesh, arm.skeleton);
  simulate(mesh_space, small, scaled);
  ASSERT_EQ(plain.body->vertex_count(), mesh_space.body->vertex_count());
  double apart = 0, offset = 0;
  for (std::int32_t v = 0; v < plain.body->vertex_count(); ++v) {
    apart = std::max(apart, (plain.body->position(v) - mesh_space.body->position(v)).norm());
    offset = std::max(offset, (mesh_space.body->position(v) - mesh_space.body->target(v)).norm());
  }
  std::printf("positions apart %.3g m; largest offset from the targets %.3g m\n", apart, offset);
  EXPECT_LT(apart, 1e-6);
  EXPECT_LT(offset, 0.02);  // the wound's lips, about a centimetre
}

}  // namespace
