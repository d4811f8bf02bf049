// Animation sampling (linear / log versor blends), poses, keyframes made on the fly.
#include <gtest/gtest.h>

#include <numbers>

#include "conform/skin/animation.hpp"
#include "conform/skin/procedural_arm.hpp"
#include "conform/skin/skinner.hpp"

namespace {

using namespace conform;
using skin::Blend;
using skin::Pose;
using skin::Versor;

skin::Skeleton arm_skeleton() {
  return skin::make_arm().skeleton;
}

// Between keys, the log blend of a pure rotation is slerp; the linear blend is nlerp (which
// differs from slerp between keys, so the first check can fail).
TEST(SkinAnimation, LogBlendOfRotationIsSlerp) {
  const auto sk = arm_skeleton();
  skin::Animation anim;
  anim.name = "bend";
  anim.ticks_per_second = 10;
  anim.duration_ticks = 10;
  skin::Channel ch;
  ch.joint = 1;
  const Eigen::Quaterniond q0(Eigen::AngleAxisd(0.2, Eigen::Vector3d(1, 0, 0)));
  const Eigen::Quaterniond q1(Eigen::AngleAxisd(2.6, Eigen::Vector3d(0.3, 1, 0.2).normalized()));
  ch.rotation = {{0, q0}, {10, q1}};
  anim.channels.push_back(ch);
  ASSERT_EQ(anim.validate(sk), "");
  EXPECT_DOUBLE_EQ(anim.duration(), 1.0);
  Pose p;
  double nlerp_gap = 0;
  for (double t : {0.0, 0.1, 0.37, 0.5, 0.81, 1.0}) {
    anim.sample(sk, t, Blend::log, p);
    const Eigen::Quaterniond slerp = q0.slerp(t, q1);
    const Eigen::Quaterniond got = p.local[1].motor.rotation().normalized();
    EXPECT_NEAR(std::abs(got.dot(slerp)), 1.0, 1e-13) << t;
    EXPECT_NEAR(p.local[1].scale, 1.0, 1e-15);
    // translation of the joint falls back to the rest transform
    EXPECT_NEAR((p.local[1].motor.translation() - Eigen::Vector3d(0, 0, 0.30)).norm(), 0, 1e-14);
    anim.sample(sk, t, Blend::linear, p);
    nlerp_gap =
        std::max(nlerp_gap, 1 - std::abs(p.local[1].motor.rotation().normalized().dot(slerp)));
  }
  EXPECT_GT(nlerp_gap, 1e-4);
  // Unanimated joints keep their rest transform.
  EXPECT_NEAR((p.local[2].motor.translation() - Eigen::Vector3d(0, 0, 0.25)).norm(), 0, 1e-15);
}

TEST(SkinAnimation, TranslationAndScaleTracks) {
  const auto sk = arm_skeleton();
  skin::Animation anim;
  anim.ticks_per_second = 2;
  anim.duration_ticks = 4;
  skin::Channel ch;
  ch.joint = 0;
  ch.translation = {{0, {0, 0, 0}}, {2, {1, 0, 0}}, {4, {1, 2, 0}}};
  ch.scale = {{0, 1.0}, {4, 4.0}};
  anim.channels.push_back(ch);
  ASSERT_EQ(anim.validate(sk), "");
  EXPECT_EQ(anim.key_times(), (std::vector<double>{0, 1, 2}));
  Pose p;
  anim.sample(sk, 0.5, Blend::linear, p);
  EXPECT_NEAR((p.local[0].motor.translation() - Eigen::Vector3d(0.5, 0, 0)).norm(), 0, 1e-15);
  EXPECT_NEAR(p.local[0].scale, 1.75, 1e-15);
  anim.sample(sk, 1.0, Blend::log, p);
  EXPECT_NEAR((p.local[0].motor.translation() - Eigen::Vector3d(1, 0, 0)).norm(), 0, 1e-15);
  EXPECT_NEAR(p.local[0].scale, 2.0, 1e-15);  // geometric mean of 1 and 4
  anim.sample(sk, 1.5, Blend::log, p);
  EXPECT_NEAR((p.local[0].motor.translation() - Eigen::Vector3d(1, 1, 0)).norm(), 0, 1e-15);
  // Outside the keys the end keys hold.
  anim.sample(sk, 7.0, Blend::log, p);
  EXPECT_NEAR((p.local[0].motor.translation() - Eigen::Vector3d(1, 2, 0)).norm(), 0, 1e-15);
  EXPECT_NEAR(p.local[0].scale, 4.0, 1e-15);
  anim.sample(sk, -1.0, Blend::log, p);
  EXPECT_NEAR(p.local[0].motor.translation().norm(), 0, 1e-15);
}

TEST(SkinAnimation, ValidateNamesTheProblem) {
  const auto sk = arm_skeleton();
  skin::Animation anim;
  anim.name = "bad";
  skin::Channel ch;
  ch.joint = 1;
  ch.translation = {{0, {0, std::nan(""), 0}}};
  anim.channels.push_back(ch);
  EXPECT_NE(anim.validate(sk).find("NaN"), std::string::npos);
  anim.channels[0].translation.clear();
  anim.channels[0].rotation = {{1, Eigen::Quaterniond::Identity()},
                               {0, Eigen::Quaterniond::Identity()}};
  EXPECT_NE(anim.validate(sk).find("not sorted"), std::string::npos);
  anim.channels[0].rotation.clear();
  anim.channels[0].scale = {{0, -1.0}};
  EXPECT_NE(anim.validate(sk).find("scale"), std::string::npos);
  anim.channels[0].scale.clear();
  anim.channels[0].joint = 9;
  EXPECT_NE(anim.validate(sk).find("out of range"), std::string::npos);
  anim.channels[0].joint = 0;
  anim.ticks_per_second = 0;
  EXPECT_NE(anim.validate(sk).find("ticks"), std::string::npos);
}

// Keyframes made on the fly: set the elbow's rotation and dilation in two keys, blend; the
// skinned forearm follows the blended joint.
TEST(SkinKeyframes, SetLocalAndBlend) {
  const skin::Arm arm = skin::make_arm();
  const auto& sk = arm.skeleton;
  Pose a = Pose::rest(sk), b = Pose::rest(sk);
  const Eigen::Vector3d elbow_t(0, 0, 0.30);
  b.set_local(1,
              Eigen::Quaterniond(Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitX())),
              elbow_t, 1.5);
  skin::PoseTrack track;
  track.set_key(1.0, b);
  track.set_key(0.0, a);
  ASSERT_EQ(track.size(), 2u);
  Pose mid;
  ASSERT_TRUE(track.sample(0.5, Blend::log, mid));
  // Halfway: a 45° bend and the geometric mean of the dilations.
  const double angle =
      2 * std::acos(std::min(1.0, std::abs(mid.local[1].motor.rotation().normalized().w())));
  EXPECT_NEAR(angle, std::numbers::pi / 4, 1e-12);
  EXPECT_NEAR(mid.local[1].scale, std::sqrt(1.5), 1e-14);
  ASSERT_TRUE(track.sample(0.5, Blend::linear, mid));
  EXPECT_NEAR(mid.local[1].scale, 1.25, 1e-14);

  // The wrist joint (child of the elbow) ends where the bent, dilated forearm puts it.
  std::vector<Versor> global(3);
  skin::global_versors(sk, b, global);
  const Eigen::Vector3d wrist = global[2].apply(Eigen::Vector3d::Zero());
  // rotation by +90° about x takes +z to −y; the 0.25 m forearm is dilated by 1.5
  EXPECT_NEAR((wrist - Eigen::Vector3d(0, -0.375, 0.30)).norm(), 0, 1e-14);

  skin::Skinner<double> s(sk, arm.mesh.rest, skin::InfluenceLists::from_mesh(arm.mesh));
  s.skin(b, skin::SkinMode::cga);
  // Finger tip (last vertex, bound to the hand) = wrist + 1.5 · R(0.08 m along +z).
  const auto last = s.vertex_count() - 1;
  EXPECT_NEAR((Eigen::Vector3d(s.output().x[last], s.output().y[last], s.output().z[last]) -
               Eigen::Vector3d(0, -0.375 - 1.5 * 0.08, 0.30))
                  .norm(),
              0, 1e-12);
  Pose empty;
  EXPECT_FALSE(skin::PoseTrack{}.sample(0, Blend::log, empty));
}

}  // namespace
