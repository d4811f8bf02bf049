// Skinning kernels: job validation, eq 17 kernels against the general G(4,1) sandwich, CGA
// against matrix LBS, versor blend against dual quaternions, dilations, candy wrapper, threads.
#include <gtest/gtest.h>

#include <numbers>
#include <random>

#include "conform/skin/baselines.hpp"
#include "conform/skin/procedural_arm.hpp"
#include "conform/skin/skinner.hpp"

namespace {

using namespace conform;
using skin::Pose;
using skin::SkinMode;
using skin::Versor;

Eigen::Quaterniond random_rotation(std::mt19937& rng, double max_angle) {
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(-max_angle, max_angle);
  return Eigen::Quaterniond(
      Eigen::AngleAxisd(u(rng), Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized()));
}

// Rotations at every joint, a translated root, and dilations when `dilate`.
Pose random_pose(const skin::Skeleton& sk, std::mt19937& rng, bool dilate) {
  std::uniform_real_distribution<double> scale(0.7, 1.4), t(-0.2, 0.2);
  Pose p = Pose::rest(sk);
  for (std::int32_t j = 0; j < sk.joint_count(); ++j) {
    const auto& rest = sk.joints[static_cast<std::size_t>(j)].rest;
    Eigen::Vector3d tr = rest.motor.translation();
    if (j == 0) tr += Eigen::Vector3d(t(rng), t(rng), t(rng));
    p.set_local(j, random_rotation(rng, 2.5), tr, dilate ? scale(rng) : 1.0);
  }
  return p;
}

double max_diff(const skin::SoaPoints<double>& a, const skin::SoaPoints<double>& b) {
  double m = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    m = std::max(
        m,
        (Eigen::Vector3d(a.x[i], a.y[i], a.z[i]) - Eigen::Vector3d(b.x[i], b.y[i], b.z[i])).norm());
  return m;
}

struct Fixture {
  skin::Arm arm = skin::make_arm();
  skin::InfluenceLists lists = skin::InfluenceLists::from_mesh(arm.mesh);
};

TEST(SkinJobs, ValidationRejectsBadInput) {
  std::vector<double> x(3, 0.0), y(3, 0.0), z(2, 0.0), o(3, 0.0);
  std::vector<std::int32_t> bones{0, 1, 5};
  std::vector<double> w{1, 1, 1};
  std::vector<skin::Kernel34<double>> kernels(2);
  skin::CgaSkinningJob<double> job{kernels, {x, y, z, 1, bones, w}, {o, o, o}};
  EXPECT_NE(job.validate().find("differ"), std::string::npos);
  std::vector<double> z3(3, 0.0);
  job.input.z = z3;
  EXPECT_NE(job.validate().find("bone id 5"), std::string::npos);
  bones[2] = 1;
  EXPECT_EQ(job.validate(), "");
  job.input.influences = 2;
  EXPECT_NE(job.validate().find("influences"), std::string::npos);
  job.input.influences = 1;
  std::vector<double> short_out(2, 0.0);
  job.output.x = short_out;
  EXPECT_NE(job.validate().find("output"), std::string::npos);
  skin::VersorBlendJob<double> vjob{{}, {x, y, z3, 1, bones, w}, {o, o, o}};
  EXPECT_NE(vjob.validate().find("no bones"), std::string::npos);
}

TEST(SkinInfluences, SelectKeepsLargestRenormalized) {
  skin::InfluenceLists l;
  l.offsets = {0, 5, 5, 6};
  l.bones = {0, 1, 2, 3, 4, 7};
  l.weights = {0.1, 0.4, 0.05, 0.3, 0.15, 1.0};
  EXPECT_EQ(l.max_per_vertex(), 5);
  EXPECT_EQ(l.validate(8), "");
  EXPECT_NE(l.validate(7).find("bone id 7"), std::string::npos);
  const auto s = skin::Influences<double>::select(l, 2);
  ASSERT_EQ(s.count, 2);
  const std::size_t n = 3;
  EXPECT_EQ(s.bones[0], 1);
  EXPECT_EQ(s.bones[n + 0], 3);
  EXPECT_NEAR(s.weights[0], 0.4 / 0.7, 1e-15);
  EXPECT_NEAR(s.weights[n + 0], 0.3 / 0.7, 1e-15);
  EXPECT_EQ(s.weights[1], 1.0);  // a vertex without influences follows bone 0
  EXPECT_EQ(s.weights[n + 1], 0.0);
  EXPECT_EQ(s.bones[2], 7);
  EXPECT_EQ(s.weights[2], 1.0);
  l.weights[0] = 0.2;
  EXPECT_NE(l.validate(8).find("sum to"), std::string::npos);
}

// The 3×4 kernel of eq 17's per-term down-projection equals V up(x) V⁻¹ computed with the
// general geometric product, for versors with rotations, translations and dilations.
TEST(SkinCga, KernelsEqualGeneralSandwich) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1), s(0.5, 2.0);
  std::vector<Versor> versors;
  for (int i = 0; i < 5; ++i)
    versors.push_back(Versor::from_trs(Eigen::Vector3d(u(rng), u(rng), u(rng)),
                                       random_rotation(rng, 3.0), s(rng)));
  std::vector<skin::Kernel34<double>> kernels(versors.size());
  skin::versor_kernels<double>(versors, kernels);
  const int n = 50, K = 3;
  std::vector<double> x(n), y(n), z(n), ox(n), oy(n), oz(n), w(n * K);
  std::vector<std::int32_t> b(n * K);
  std::uniform_int_distribution<int> bone(0, 4);
  for (int v = 0; v < n; ++v) {
    x[v] = u(rng), y[v] = u(rng), z[v] = u(rng);
    double a = std::abs(u(rng)) + 0.1, c = std::abs(u(rng)) * a, d = std::abs(u(rng)) * c;
    const double sum = a + c + d;
    w[v] = a / sum, w[n + v] = c / sum, w[2 * n + v] = d / sum;
    for (int k = 0; k < K; ++k) b[k * n + v] = bone(rng);
  }
  skin::CgaSkinningJob<double> job{kernels, {x, y, z, K, b, w}, {ox, oy, oz}};
  ASSERT_EQ(job.validate(), "");
  job.run();
  for (int v = 0; v < n; ++v) {
    const std::int32_t bb[3] = {b[v], b[n + v], b[2 * n + v]};
    const double ww[3] = {w[v], w[n + v], w[2 * n + v]};
    const Eigen::Vector3d ref = skin::skin_point_by_sandwich(versors, bb, ww, {x[v], y[v], z[v]});
    EXPECT_NEAR((ref - Eigen::Vector3d(ox[v], oy[v], oz[v])).norm(), 0, 1e-12) << v;
  }
}

// Without dilations every term V c V⁻¹ has weight 1, so summing the conformal points first and
// down-projecting once (eq 17 as written) equals the per-term down-projection.
TEST(SkinCga, PerTermDownProjectionEqualsSumThenProject) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  const Versor a = Versor::from_trs({u(rng), u(rng), u(rng)}, random_rotation(rng, 3), 1.0);
  const Versor b = Versor::from_trs({u(rng), u(rng), u(rng)}, random_rotation(rng, 3), 1.0);
  const Eigen::Vector3d x(0.3, -0.2, 0.7);
  const auto c = cga::Point<double>::up(x).mv();
  const auto sum = (a.mv() * c * a.inverse()->mv()) * 0.3 + (b.mv() * c * b.inverse()->mv()) * 0.7;
  const std::vector<Versor> vs{a, b};
  const std::int32_t bones[2] = {0, 1};
  const double w[2] = {0.3, 0.7};
  EXPECT_NEAR((*cga::down(sum) - skin::skin_point_by_sandwich(vs, bones, w, x)).norm(), 0, 1e-13);
}

TEST(SkinCga, RestPoseReproducesRestPositions) {
  Fixture f;
  skin::Skinner<double> s(f.arm.skeleton, f.arm.mesh.rest, f.lists);
  for (auto mode :
       {SkinMode::cga, SkinMode::versor, SkinMode::matrix_lbs, SkinMode::dual_quaternion}) {
    s.skin(Pose::rest(f.arm.skeleton), mode);
    Eigen::Matrix3Xd out;
    s.write(out);
    EXPECT_LT((out - f.arm.mesh.rest).cwiseAbs().maxCoeff(), 1e-15) << skin::skin_mode_name(mode);
  }
}

TEST(SkinCga, EqualsMatrixLbsAndVersorBlendEqualsDualQuaternions) {
  Fixture f;
  skin::Skinner<double> cga(f.arm.skeleton, f.arm.mesh.rest, f.lists);
  skin::Skinner<double> ref(f.arm.skeleton, f.arm.mesh.rest, f.lists);
  std::mt19937 rng(11);
  double worst_lbs = 0, worst_dq = 0, lbs_vs_dq = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const Pose p = random_pose(f.arm.skeleton, rng, trial % 2 == 1);
    cga.skin(p, SkinMode::cga);
    ref.skin(p, SkinMode::matrix_lbs);
    worst_lbs = std::max(worst_lbs, max_diff(cga.output(), ref.output()));
    const auto lbs = ref.output();
    cga.skin(p, SkinMode::versor);
    ref.skin(p, SkinMode::dual_quaternion);
    worst_dq = std::max(worst_dq, max_diff(cga.output(), ref.output()));
    lbs_vs_dq = std::max(lbs_vs_dq, max_diff(lbs, ref.output()));
  }
  EXPECT_LT(worst_lbs, 1e-12);
  EXPECT_LT(worst_dq, 1e-12);
  // The two families really differ on these poses (so the comparisons above can fail).
  EXPECT_GT(lbs_vs_dq, 1e-3);
}

// A bone dilated by d scales the vertices bound only to it by d about its joint; the whole
// mesh agrees with matrix LBS carrying the same uniform scale.
TEST(SkinCga, DilationScalesAboutTheJoint) {
  Fixture f;
  const auto& sk = f.arm.skeleton;
  skin::Skinner<double> cga(sk, f.arm.mesh.rest, f.lists), lbs(sk, f.arm.mesh.rest, f.lists);
  for (double d : {0.5, 1.3, 2.0}) {
    Pose p = Pose::rest(sk);
    p.apply_local(1, Versor::from_dilator({d}));  // the elbow joint: dilate the forearm
    cga.skin(p, SkinMode::cga);
    lbs.skin(p, SkinMode::matrix_lbs);
    EXPECT_LT(max_diff(cga.output(), lbs.output()), 1e-12);
    const Eigen::Vector3d elbow(0, 0, 0.30);
    int checked = 0;
    const auto& o = cga.output();
    for (int v = 0; v < f.arm.mesh.vertex_count(); ++v) {
      if (f.arm.mesh.weights(0, v) != 1.0 || f.arm.mesh.bones(0, v) != 1) continue;
      const Eigen::Vector3d x = f.arm.mesh.rest.col(v);
      const Eigen::Vector3d expected = elbow + d * (x - elbow);
      EXPECT_NEAR((Eigen::Vector3d(o.x[v], o.y[v], o.z[v]) - expected).norm(), 0, 1e-14);
      ++checked;
    }
    EXPECT_GT(checked, 500);
    // The upper arm does not move.
    for (int v = 0; v < f.arm.mesh.vertex_count(); ++v)
      if (f.arm.mesh.weights(0, v) == 1.0 && f.arm.mesh.bones(0, v) == 0) {
        ASSERT_NEAR(o.z[v], f.arm.mesh.rest(2, v), 1e-15);
      }
    // Dilation in the versor-blend mode matches DQ + scale too.
    cga.skin(p, SkinMode::versor);
    lbs.skin(p, SkinMode::dual_quaternion);
    EXPECT_LT(max_diff(cga.output(), lbs.output()), 1e-12);
  }
}

// Twisting the wrist by 170°: matrix/CGA LBS collapses the blended ring toward the axis
// (candy wrapper), the versor blend keeps its radius.
TEST(SkinVersor, NoCandyWrapper) {
  Fixture f;
  const auto& sk = f.arm.skeleton;
  skin::Skinner<double> s(sk, f.arm.mesh.rest, f.lists);
  Pose p = Pose::rest(sk);
  p.apply_local(2, Versor::from_motor(cga::Motor<double>::from_axis_angle(
                       {0, 0, 1}, 170.0 * std::numbers::pi / 180)));
  auto radius_ratio = [&](SkinMode mode) {
    s.skin(p, mode);
    double worst = 1e9;
    for (int v = 0; v < f.arm.mesh.vertex_count(); ++v) {
      if (std::abs(f.arm.mesh.rest(2, v) - 0.55) > 0.005) continue;
      const double r0 = f.arm.mesh.rest.col(v).head<2>().norm();
      const double r1 = std::hypot(s.output().x[v], s.output().y[v]);
      worst = std::min(worst, r1 / r0);
    }
    return worst;
  };
  EXPECT_LT(radius_ratio(SkinMode::cga), 0.3);
  EXPECT_GT(radius_ratio(SkinMode::versor), 0.99);
}

TEST(SkinCga, ThreadCountDoesNotChangeResults) {
  const skin::Arm arm = skin::make_arm(2);  // above the single-thread threshold
  const auto lists = skin::InfluenceLists::from_mesh(arm.mesh);
  skin::Skinner<double> one(arm.skeleton, arm.mesh.rest, lists),
      two(arm.skeleton, arm.mesh.rest, lists);
  one.set_threads(1);
  two.set_threads(2);
  std::mt19937 rng(5);
  const Pose p = random_pose(arm.skeleton, rng, true);
  for (auto mode :
       {SkinMode::cga, SkinMode::versor, SkinMode::matrix_lbs, SkinMode::dual_quaternion}) {
    one.skin(p, mode);
    two.skin(p, mode);
    EXPECT_EQ(one.output().x, two.output().x);
    EXPECT_EQ(one.output().z, two.output().z);
  }
}

TEST(SkinCga, FloatAgreesWithDouble) {
  Fixture f;
  skin::Skinner<double> d(f.arm.skeleton, f.arm.mesh.rest, f.lists);
  skin::Skinner<float> s(f.arm.skeleton, f.arm.mesh.rest, f.lists);
  std::mt19937 rng(9);
  const Pose p = random_pose(f.arm.skeleton, rng, true);
  for (auto mode : {SkinMode::cga, SkinMode::versor}) {
    d.skin(p, mode);
    s.skin(p, mode);
    double worst = 0;
    for (std::size_t i = 0; i < d.vertex_count(); ++i)
      worst = std::max(worst, std::abs(d.output().x[i] - s.output().x[i]) +
                                  std::abs(d.output().z[i] - s.output().z[i]));
    EXPECT_LT(worst, 1e-5);
  }
}

TEST(SkinModes, Parse) {
  EXPECT_EQ(skin::parse_skin_mode("lbs"), SkinMode::cga);
  EXPECT_EQ(skin::parse_skin_mode("versor"), SkinMode::versor);
  EXPECT_FALSE(skin::parse_skin_mode("quux").has_value());
  skin::Blend b;
  EXPECT_TRUE(skin::parse_blend("log", b));
  EXPECT_EQ(b, skin::Blend::log);
  EXPECT_FALSE(skin::parse_blend("cubic", b));
}

TEST(SkinSkinner, RejectsBadBoneIds) {
  Fixture f;
  f.lists.bones[10] = 3;  // the arm has 3 bones
  EXPECT_THROW(skin::Skinner<double>(f.arm.skeleton, f.arm.mesh.rest, f.lists),
               std::invalid_argument);
}

}  // namespace
