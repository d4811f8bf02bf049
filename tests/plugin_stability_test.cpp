// Stability: 1000 random cut, tear and drill events on the arm in a running simulation — no
// NaN, no hang, no node farther than the model's size from its target, total mass conserved,
// and the Bullet pieces still mirror the mesh.
#include <BulletSoftBody/btSoftBody.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <random>

#include "conform/bullet/plugin.hpp"
#include "conform/mesh/analysis.hpp"
#include "conform/skin/procedural_arm.hpp"
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
  auto& body = plugin.add_skinned_body(
      arm.mesh, arm.skeleton, {.model = bullet::MaterialModel::bullet_links, .pretension = 0.05});
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
  Eigen::Vector3d blade_dir = Eigen::Vector3d::UnitZ(), blade_at = Eigen::Vector3d::Zero(),
                  blade_normal = Eigen::Vector3d::UnitX();
  int tear_left = 0;
  double worst = 0, slowest = 0;
  const auto start = std::chrono::steady_clock::now();
  // CONFORM_STABILITY_EVENTS overrides the count for diagnosis only.
  const char* override_events = std::getenv("CONFORM_STABILITY_EVENTS");
  const int events = override_events ? std::atoi(override_events) : 1000;
  const std::clock_t cpu_start = std::clock();
  for (int e = 0; e < events; ++e) {
    const double pick = unit(rng);
    // A random surface point (on a face) at its simulated place, and that face's normal.
    auto surface_point = [&](Eigen::Vector3d& normal) {
      const auto& f =
          body.mesh().faces[std::size_t(rng() % std::uint32_t(body.mesh().face_count()))];
      const Eigen::Vector3d a = body.position(f[0]), b = body.position(f[1]),
                            c = body.position(f[2]);
      const Eigen::Vector3d n = (b - a).cross(c - a);
      normal = n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : random_unit(rng);
      return Eigen::Vector3d((a + b + c) / 3);
    };
    Eigen::Vector3d n;
    const std::int32_t vertices_before = body.vertex_count();
    const auto t0 = std::chrono::steady_clock::now();
    if (pick < 0.05) {
      const Eigen::Vector3d p = surface_point(n);
      body.cut(cga::Plane<double>::from_normal_point(random_unit(rng), p));
      ++cuts;
    } else if (pick < 0.25) {
      // A drill along the surface normal, as a drill is held.
      const Eigen::Vector3d p = surface_point(n);
      // The paper's 6 rim points (not the default 24) keep the refinement, and the mesh, small.
      body.drill({p - 0.02 * n, p + 0.02 * n, 0.008 + 0.012 * unit(rng)},
                 {.min_rim_points = 6, .max_refinements = 2});
      ++drills;
    } else {
      if (tear_left == 0) {
        blade_at = surface_point(blade_normal);
        blade_dir = blade_normal.cross(random_unit(rng)).normalized();
        body.begin_tear();
        tear_left = 5 + int(rng() % 20);
        ++tears;
      }
      // The blade crosses the surface along its normal and moves along a tangent.
      body.tear_advance(
          {double(e), blade_at - 0.03 * blade_normal, blade_at + 0.03 * blade_normal});
      blade_at += 0.004 * blade_dir;
      --tear_left;
      ++tear_steps;
    }
    slowest = std::max(
        slowest, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    if (std::getenv("CONFORM_STABILITY_VERBOSE")) {
      std::printf("event %d: %s +%d vertices, pieces %d / %d\n", e,
                  pick < 0.05   ? "cut"
                  : pick < 0.25 ? "drill"
                                : "tear",
                  body.vertex_count() - vertices_before, body.piece_count(),
                  mesh::label_pieces(body.mesh()).count);
    }
    ASSERT_EQ(conform::test::bullet_internals_problem(body), "") << "event " << e;
    w.step();
    ASSERT_NEAR(body.total_mass(), mass, 1e-9 * mass) << "event " << e;
    for (std::int32_t v = 0; v < body.vertex_count(); ++v) {
      const Eigen::Vector3d x = body.position(v);
      ASSERT_TRUE(x.allFinite() && body.velocity(v).allFinite())
          << "event " << e << " vertex " << v;
      worst = std::max(worst, (x - body.target(v)).norm());
    }
    ASSERT_LT(worst, size) << "event " << e;
    if ((e + 1) % 100 == 0)
      std::printf("  %4d events: %.1f s CPU, %d vertices, %d faces, %d pieces\n", e + 1,
                  double(std::clock() - cpu_start) / CLOCKS_PER_SEC, body.vertex_count(),
                  body.mesh().face_count(), body.piece_count());
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf(
      "stability: %d events (%d cuts, %d drills, %d tear steps in %d tears) in %.1f s; "
      "slowest event %.1f ms; %d vertices, %d faces, %d pieces; worst node-target distance "
      "%.4f m (model size %.3f m)\n",
      events, cuts, drills, tear_steps, tears, seconds, 1e3 * slowest, body.vertex_count(),
      body.mesh().face_count(), body.piece_count(), worst, size);
  EXPECT_GT(cuts, events / 20);
  EXPECT_GT(drills, events / 10);
  EXPECT_GT(tear_steps, events / 2);
  EXPECT_EQ(body.piece_count(), mesh::label_pieces(body.mesh()).count);
  // Bullet still mirrors the mesh: every face once, one link per edge, one node per vertex.
  int faces = 0, nodes = 0;
  for (btSoftBody* sb : body.pieces()) faces += sb->m_faces.size(), nodes += sb->m_nodes.size();
  EXPECT_EQ(faces, body.mesh().face_count());
  EXPECT_EQ(nodes + body.detached_count(), body.vertex_count());
  // Detached vertices are exactly those without faces.
  std::vector<char> has_face(std::size_t(body.vertex_count()), 0);
  for (const auto& f : body.mesh().faces)
    for (const auto v : f) has_face[std::size_t(v)] = 1;
  for (std::int32_t v = 0; v < body.vertex_count(); ++v)
    ASSERT_EQ(body.detached(v), !has_face[std::size_t(v)]) << "vertex " << v;
  std::vector<std::uint64_t> edges;
  for (const auto& f : body.mesh().faces)
    for (int k = 0; k < 3; ++k) {
      const auto a = std::uint32_t(std::min(f[std::size_t(k)], f[std::size_t((k + 1) % 3)]));
      const auto b = std::uint32_t(std::max(f[std::size_t(k)], f[std::size_t((k + 1) % 3)]));
      edges.push_back((std::uint64_t(a) << 32) | b);
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  EXPECT_EQ(std::size_t(body.link_count()), edges.size());
}
