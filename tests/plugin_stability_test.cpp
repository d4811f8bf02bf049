// Stability: 1000 random cut, tear and drill events on the arm in a running simulation — no
// NaN, no hang, no node farther than the model's size from its target, total mass conserved,
// and the Bullet pieces still mirror the mesh.
#include <BulletSoftBody/btSoftBody.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <random>

#include "conform/bullet/plugin.hpp"
#include "conform/mesh/analysis.hpp"
#include "conform/mesh/procedural_arm.hpp"
#include "plugin_world.hpp"

using namespace conform;
using conform::test::SoftWorld;

namespace {

Eigen::Vector3d random_unit(std::mt19937& rng) {
  std::normal_distribution<double> n(0, 1);
  Eigen::Vector3d d(n(rng), n(rng), n(rng));
  return d.norm() > 1e-6 ? Eigen::Vector3d(d.normalized()) : Eigen::Vector3d::UnitX();
}

skin::Pose pose_at(const skin::Skeleton& skeleton, double shoulder, double elbow) {
  skin::Pose pose = skin::Pose::rest(skeleton);
  pose.apply_local(
      0, skin::Versor::from_trs(
             cga::Vec3<double>(0, 0, 0),
             cga::Quat<double>(Eigen::AngleAxisd(shoulder, Eigen::Vector3d::UnitY())), 1.0));
  pose.apply_local(1,
                   skin::Versor::from_trs(
                       cga::Vec3<double>(0, 0, 0),
                       cga::Quat<double>(Eigen::AngleAxisd(elbow, Eigen::Vector3d::UnitX())), 1.0));
  return pose;
}

}  // namespace

TEST(PluginStability, ThousandRandomEventsOnARunningArm) {
  SoftWorld w;
  bullet::Plugin plugin(w.world);
  const auto arm = mesh::make_arm(1);
  auto& body = plugin.add_skinned_body(arm.mesh, arm.skeleton, {.pretension = 0.05});
  skin::PoseTrack track;
  track.set_key(0, skin::Pose::rest(arm.skeleton));
  track.set_key(4, pose_at(arm.skeleton, 0.6, 1.3));
  track.set_key(8, pose_at(arm.skeleton, -0.3, 0.2));
  body.set_keyframes(track);
  const double size = mesh::bounding_diagonal(arm.mesh);
  const double mass = body.total_mass();
  std::mt19937 rng(20261122);
  std::uniform_real_distribution<double> unit(0, 1);
  int cuts = 0, tear_steps = 0, drills = 0, tears = 0;
  Eigen::Vector3d blade_dir = Eigen::Vector3d::UnitZ(), blade_at = Eigen::Vector3d::Zero();
  int tear_left = 0;
  double worst = 0, slowest = 0;
  const auto start = std::chrono::steady_clock::now();
  const int events = 1000;
  for (int e = 0; e < events; ++e) {
    const double pick = unit(rng);
    // A random surface point (a vertex that still has faces) at its simulated place.
    auto surface_vertex = [&] {
      const auto& f =
          body.mesh().faces[std::size_t(rng() % std::uint32_t(body.mesh().face_count()))];
      return f[rng() % 3];
    };
    const auto t0 = std::chrono::steady_clock::now();
    if (pick < 0.1) {
      const Eigen::Vector3d p = body.position(surface_vertex());
      body.cut(cga::Plane<double>::from_normal_point(random_unit(rng), p));
      ++cuts;
    } else if (pick < 0.3) {
      const Eigen::Vector3d p = body.position(surface_vertex());
      const Eigen::Vector3d d = random_unit(rng);
      body.drill({p + 0.03 * d, p - 0.03 * d, 0.004 + 0.008 * unit(rng)});
      ++drills;
    } else {
      if (tear_left == 0) {
        const std::int32_t v = surface_vertex();
        blade_at = body.position(v);
        blade_dir = random_unit(rng);
        body.begin_tear();
        tear_left = 5 + int(rng() % 20);
        ++tears;
      }
      // The blade: through the surface along the outward offset from the posed arm's axis.
      const Eigen::Vector3d outward = blade_dir.cross(Eigen::Vector3d::UnitZ()).normalized();
      body.tear_advance({double(e), blade_at - 0.05 * outward, blade_at + 0.05 * outward});
      blade_at += 0.004 * blade_dir;
      --tear_left;
      ++tear_steps;
    }
    slowest = std::max(
        slowest, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    w.step();
    ASSERT_NEAR(body.total_mass(), mass, 1e-9 * mass) << "event " << e;
    for (std::int32_t v = 0; v < body.vertex_count(); ++v) {
      const Eigen::Vector3d x = body.position(v);
      ASSERT_TRUE(x.allFinite() && body.velocity(v).allFinite())
          << "event " << e << " vertex " << v;
      worst = std::max(worst, (x - body.target(v)).norm());
    }
    ASSERT_LT(worst, size) << "event " << e;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf(
      "stability: %d events (%d cuts, %d drills, %d tear steps in %d tears) in %.1f s; "
      "slowest event %.1f ms; %d vertices, %d faces, %d pieces; worst node-target distance "
      "%.4f m (model size %.3f m)\n",
      events, cuts, drills, tear_steps, tears, seconds, 1e3 * slowest, body.vertex_count(),
      body.mesh().face_count(), body.piece_count(), worst, size);
  EXPECT_GT(cuts, 50);
  EXPECT_GT(drills, 100);
  EXPECT_GT(tear_steps, 500);
  EXPECT_GT(body.piece_count(), 10);
  EXPECT_EQ(body.piece_count(), mesh::label_pieces(body.mesh()).count);
}
