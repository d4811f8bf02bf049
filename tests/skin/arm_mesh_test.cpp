// The procedural arm: closed, consistently oriented, positive volume, normalized weights,
// skeleton matching the IK conventions, sizes scaling with the resolution.
#include <gtest/gtest.h>

#include <cstdint>
#include <unordered_map>

#include "conform/skin/procedural_arm.hpp"

namespace {

using conform::skin::Arm;
using conform::skin::make_arm;

std::uint64_t key(std::int32_t a, std::int32_t b) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
         static_cast<std::uint32_t>(b);
}

// Every directed edge appears exactly once and its reverse exactly once: the surface is
// closed (every undirected edge in exactly two faces) and consistently oriented.
void expect_closed_oriented(const Arm& arm) {
  std::unordered_map<std::uint64_t, int> directed;
  directed.reserve(arm.mesh.faces.size() * 3);
  for (const auto& f : arm.mesh.faces) {
    ASSERT_NE(f[0], f[1]);
    ASSERT_NE(f[1], f[2]);
    ASSERT_NE(f[0], f[2]);
    for (int k = 0; k < 3; ++k) ++directed[key(f[k], f[(k + 1) % 3])];
  }
  std::size_t bad = 0;
  for (const auto& [k, count] : directed) {
    const auto a = static_cast<std::int32_t>(k >> 32),
               b = static_cast<std::int32_t>(k & 0xffffffffu);
    const auto rev = directed.find(key(b, a));
    if (count != 1 || rev == directed.end() || rev->second != 1) ++bad;
  }
  EXPECT_EQ(bad, 0u);
  EXPECT_EQ(directed.size(), arm.mesh.faces.size() * 3);
}

double signed_volume(const Arm& arm) {
  double v = 0;
  for (const auto& f : arm.mesh.faces)
    v += arm.mesh.rest.col(f[0]).dot(arm.mesh.rest.col(f[1]).cross(arm.mesh.rest.col(f[2]))) / 6;
  return v;
}

TEST(ArmMesh, DefaultResolutionIsClosedOrientedAndPaperSized) {
  const Arm arm = make_arm();
  const auto& m = arm.mesh;
  EXPECT_EQ(m.vertex_count(), 2562);
  EXPECT_EQ(m.face_count(), 5120);
  EXPECT_EQ(m.face_count(), 2 * m.vertex_count() - 4);  // Euler: closed genus 0
  expect_closed_oriented(arm);
  for (const auto& f : m.faces)
    for (int k = 0; k < 3; ++k) {
      ASSERT_GE(f[k], 0);
      ASSERT_LT(f[k], m.vertex_count());
    }
  // A tube of radius ~4 cm and length ~0.68 m: volume well within (1.5, 4.5) litres.
  const double vol = signed_volume(arm);
  EXPECT_GT(vol, 1.5e-3);
  EXPECT_LT(vol, 4.5e-3);
}

TEST(ArmMesh, NoDegenerateFaces) {
  const Arm arm = make_arm();
  double min_area = 1e9;
  for (const auto& f : arm.mesh.faces) {
    const auto& r = arm.mesh.rest;
    min_area = std::min(min_area,
                        0.5 * (r.col(f[1]) - r.col(f[0])).cross(r.col(f[2]) - r.col(f[0])).norm());
  }
  EXPECT_GT(min_area, 1e-7);  // m²
}

TEST(ArmMesh, ExtentsMatchIkConventions) {
  const Arm arm = make_arm();
  const auto& r = arm.mesh.rest;
  EXPECT_NEAR(r.row(2).maxCoeff(), 0.63, 1e-12);  // finger tips
  EXPECT_LT(r.row(2).minCoeff(), 0.0);            // shoulder cap behind the joint
  EXPECT_GT(r.row(2).minCoeff(), -0.06);
  EXPECT_LT(r.row(0).cwiseAbs().maxCoeff(), 0.07);
  EXPECT_LT(r.row(1).cwiseAbs().maxCoeff(), 0.07);

  const auto& sk = arm.skeleton;
  ASSERT_EQ(sk.joint_count(), 3);
  ASSERT_EQ(sk.bone_count(), 3);
  EXPECT_TRUE(sk.validate().empty());
  EXPECT_EQ(sk.find_joint("elbow"), 1);
  EXPECT_EQ(sk.joints[0].parent, -1);
  EXPECT_EQ(sk.joints[2].parent, 1);
  // Bind placement of each joint: the product of the rest versors down the chain; the offset
  // is its inverse.
  const double z[3] = {0, 0.30, 0.55};
  conform::skin::Versor g;
  for (int j = 0; j < 3; ++j) {
    g = g * sk.joints[j].rest;
    EXPECT_NEAR((g.apply(Eigen::Vector3d::Zero()) - Eigen::Vector3d(0, 0, z[j])).norm(), 0, 1e-15);
    const auto bind = g * sk.bones[j].offset;
    EXPECT_NEAR(
        (bind.apply(Eigen::Vector3d(0.1, 0.2, 0.3)) - Eigen::Vector3d(0.1, 0.2, 0.3)).norm(), 0,
        1e-15);
  }
}

TEST(ArmMesh, WeightsSumToOneSortedAndSmoothAtJoints) {
  const Arm arm = make_arm();
  const auto& m = arm.mesh;
  int blended_elbow = 0, blended_wrist = 0;
  for (int v = 0; v < m.vertex_count(); ++v) {
    EXPECT_NEAR(m.weights.col(v).sum(), 1.0, 1e-12);
    for (int k = 0; k + 1 < 4; ++k) EXPECT_GE(m.weights(k, v), m.weights(k + 1, v));
    for (int k = 0; k < 4; ++k) {
      EXPECT_GE(m.weights(k, v), 0);
      EXPECT_GE(m.bones(k, v), 0);
      EXPECT_LT(m.bones(k, v), 3);
      if (m.weights(k, v) == 0) {
        EXPECT_EQ(m.bones(k, v), 0);
      }
    }
    const double z = m.rest(2, v);
    const bool mixed = m.weights(1, v) > 0;
    if (mixed && std::abs(z - 0.30) < 0.04) {
      ++blended_elbow;
    }
    if (mixed && std::abs(z - 0.55) < 0.03) {
      ++blended_wrist;
    }
    // Far from the joints a vertex follows one bone, the right one.
    const int expected = z < 0.25 ? 0 : (z > 0.35 && z < 0.51) ? 1 : z > 0.59 ? 2 : -1;
    if (expected >= 0) {
      EXPECT_EQ(m.bones(0, v), expected);
      EXPECT_EQ(m.weights(0, v), 1.0);
    }
  }
  // Several rings blend across each joint.
  EXPECT_GE(blended_elbow, 5 * 32);
  EXPECT_GE(blended_wrist, 3 * 32);
  // Smooth: along the axis, the forearm weight changes by at most ~one ring's worth of the
  // smoothstep's largest slope (1.5 / width) times the ring spacing.
  double max_step = 0;
  for (int i = 0; i + 1 < 80; ++i) {
    const int a = 1 + i * 32, b = 1 + (i + 1) * 32;
    auto fore = [&](int v) {
      double w = 0;
      for (int k = 0; k < 4; ++k)
        if (m.bones(k, v) == 1) w += m.weights(k, v);
      return w;
    };
    max_step = std::max(max_step, std::abs(fore(b) - fore(a)));
  }
  EXPECT_LT(max_step, 0.25);
}

TEST(ArmMesh, NormalsPointOutward) {
  const Arm arm = make_arm();
  const auto& m = arm.mesh;
  ASSERT_TRUE(m.has_normals());
  ASSERT_TRUE(m.has_uvs());
  for (int v = 0; v < m.vertex_count(); ++v) {
    EXPECT_NEAR(m.normals.col(v).norm(), 1.0, 1e-12);
    // Outward from the axis in the tube part.
    const double z = m.rest(2, v);
    if (z > 0.02 && z < 0.58) {  // the tube part, away from the caps
      const Eigen::Vector2d radial(m.rest(0, v), m.rest(1, v));
      EXPECT_GT(m.normals.col(v).head<2>().dot(radial), 0);
    }
  }
  EXPECT_TRUE(m.current.isApprox(m.rest));
}

TEST(ArmMesh, ResolutionScalesCounts) {
  for (int n : {2, 4}) {
    const Arm arm = make_arm(n);
    EXPECT_EQ(arm.mesh.vertex_count(), 2560 * n * n + 2);
    EXPECT_EQ(arm.mesh.face_count(), 5120 * n * n);
    expect_closed_oriented(arm);
    EXPECT_GT(signed_volume(arm), 1.5e-3);
  }
  // Volume converges with the resolution (a sanity check of the geometry, not of the counts).
  EXPECT_NEAR(signed_volume(make_arm(1)), signed_volume(make_arm(4)),
              0.02 * signed_volume(make_arm(4)));
}

TEST(ArmMesh, ExplicitCountsAndBadOptions) {
  conform::skin::ArmOptions o;
  o.segments = 7;
  o.rings = 3;
  const Arm arm = make_arm(o);
  EXPECT_EQ(arm.mesh.vertex_count(), 23);
  EXPECT_EQ(arm.mesh.face_count(), 42);
  expect_closed_oriented(arm);
  EXPECT_THROW(make_arm(0), std::invalid_argument);
  o.forearm = -1;
  EXPECT_THROW(make_arm(o), std::invalid_argument);
}

}  // namespace
