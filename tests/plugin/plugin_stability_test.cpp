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
#include "support/sanitized.hpp"

using namespace conform;
using conform::test::SoftWorld;

namespace {

Eigen::Vector3d random_unit(std::mt19937& rng) {
  std::normal_distribution<double> n(0, 1);
  Eigen::Vector3d d(n(rng), n(rng), n(rng));
  return d.norm() > 1e-6 ? Eigen::Vector3d(d.normalized()) : Eigen::Vector3d::UnitX();
}

// The arm running its keyframes (shoulder and elbow moving), and what the events did to it.
struct RunningArm {
  SoftWorld w;
  bullet::Plugin plugin{w.world};
  skin::Arm arm = skin::make_arm(1);
  bullet::SkinnedSoftBody* body = nullptr;
  double size = 0, mass = 0;  // the model's bounding diagonal, the body's total mass
  std::mt19937 rng{20261122};
  std::uniform_real_distribution<double> unit{0, 1};
  int cuts = 0, tear_steps = 0, drills = 0, tears = 0;
  // The open tear's blade: where it is, its direction of travel, the surface normal there,
  // and the steps it has left.
  Eigen::Vector3d blade_dir = Eigen::Vector3d::UnitZ(), blade_at = Eigen::Vector3d::Zero(),
                  blade_normal = Eigen::Vector3d::UnitX();
  int tear_left = 0;
  double worst = 0, slowest = 0;  // node-target distance (m), event time (s)

  RunningArm() {
    body = &plugin.add_skinned_body(
        arm.mesh, arm.skeleton, {.model = bullet::MaterialModel::bullet_links, .pretension = 0.05});
    skin::PoseTrack track;
    track.set_key(0, skin::Pose::rest(arm.skeleton));
    track.set_key(4, conform::test::bent_arm_pose(arm.skeleton, 0.6, 1.3));
    track.set_key(8, conform::test::bent_arm_pose(arm.skeleton, -0.3, 0.2));
    body->set_keyframes(track);
    size = mesh::bounding_diagonal(arm.mesh);
    mass = body->total_mass();
  }

  // A random surface point (on a face) at its simulated place, and that face's normal.
  Eigen::Vector3d surface_point(Eigen::Vector3d& normal) {
    const auto& f =
        body->mesh().faces[std::size_t(rng() % std::uint32_t(body->mesh().face_count()))];
    const Eigen::Vector3d a = body->position(f[0]), b = body->position(f[1]),
                          c = body->position(f[2]);
    const Eigen::Vector3d n = (b - a).cross(c - a);
    normal = n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : random_unit(rng);
    return (a + b + c) / 3;
  }

  void cut() {
    Eigen::Vector3d n;
    const Eigen::Vector3d p = surface_point(n);
    body->cut(cga::Plane<double>::from_normal_point(random_unit(rng), p));
    ++cuts;
  }

  // A drill along the surface normal, as a drill is held.
  void drill() {
    Eigen::Vector3d n;
    const Eigen::Vector3d p = surface_point(n);
    // The paper's 6 rim points (not the default 24) keep the refinement, and the mesh, small.
    body->drill({p - 0.02 * n, p + 0.02 * n, 0.008 + 0.012 * unit(rng)},
                {.min_rim_points = 6, .max_refinements = 2});
    ++drills;
  }

  // One step of the open tear, or of a new one (5 to 24 steps) at a random surface point.
  void tear_step(int event) {
    if (tear_left == 0) {
      blade_at = surface_point(blade_normal);
      blade_dir = blade_normal.cross(random_unit(rng)).normalized();
      body->begin_tear();
      tear_left = 5 + int(rng() % 20);
      ++tears;
    }
    // The blade crosses the surface along its normal and moves along a tangent.
    body->tear_advance(
        {double(event), blade_at - 0.03 * blade_normal, blade_at + 0.03 * blade_normal});
    blade_at += 0.004 * blade_dir;
    --tear_left;
    ++tear_steps;
  }

  // Event `event`: a cut (5 %), a drill (20 %) or a tear step (75 %), timed; its kind.
  const char* random_event(int event) {
    const double pick = unit(rng);
    const auto t0 = std::chrono::steady_clock::now();
    const char* kind = pick < 0.05 ? "cut" : pick < 0.25 ? "drill" : "tear";
    if (pick < 0.05)
      cut();
    else if (pick < 0.25)
      drill();
    else
      tear_step(event);
    slowest = std::max(
        slowest, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    return kind;
  }
};

// After event `e`: Bullet's internals agree with the plugin's books; then one step, after
// which the mass is the same, every node finite and no node farther than the model's size
// from its target.
void check_step_after_event(RunningArm& r, int e) {
  ASSERT_EQ(conform::test::bullet_internals_problem(*r.body), "") << "event " << e;
  r.w.step();
  ASSERT_NEAR(r.body->total_mass(), r.mass, 1e-9 * r.mass) << "event " << e;
  for (std::int32_t v = 0; v < r.body->vertex_count(); ++v) {
    const Eigen::Vector3d x = r.body->position(v);
    ASSERT_TRUE(x.allFinite() && r.body->velocity(v).allFinite())
        << "event " << e << " vertex " << v;
    r.worst = std::max(r.worst, (x - r.body->target(v)).norm());
  }
  ASSERT_LT(r.worst, r.size) << "event " << e;
}

// Bullet still mirrors the mesh: one body per piece, every face once, one node per vertex not
// detached (detached are exactly those without faces), one link per edge.
void expect_bullet_mirrors_mesh(const bullet::SkinnedSoftBody& body) {
  EXPECT_EQ(body.piece_count(), mesh::label_pieces(body.mesh()).count);
  int faces = 0, nodes = 0;
  for (btSoftBody* sb : body.pieces()) faces += sb->m_faces.size(), nodes += sb->m_nodes.size();
  EXPECT_EQ(faces, body.mesh().face_count());
  EXPECT_EQ(nodes + body.detached_count(), body.vertex_count());
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

}  // namespace

TEST(PluginStability, ThousandRandomEventsOnARunningArm) {
  RunningArm r;
  const bullet::SkinnedSoftBody& body = *r.body;
  const auto start = std::chrono::steady_clock::now();
  // CONFORM_STABILITY_EVENTS overrides the count for diagnosis only; 250 in the sanitized stage.
  const char* override_events = std::getenv("CONFORM_STABILITY_EVENTS");
  const int events =
      override_events ? std::atoi(override_events) : conform::test::trial_count(1000, 250);
  const std::clock_t cpu_start = std::clock();
  for (int e = 0; e < events; ++e) {
    const std::int32_t vertices_before = body.vertex_count();
    const char* kind = r.random_event(e);
    if (std::getenv("CONFORM_STABILITY_VERBOSE"))
      std::printf("event %d: %s +%d vertices, pieces %d / %d\n", e, kind,
                  body.vertex_count() - vertices_before, body.piece_count(),
                  mesh::label_pieces(body.mesh()).count);
    ASSERT_NO_FATAL_FAILURE(check_step_after_event(r, e));
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
      events, r.cuts, r.drills, r.tear_steps, r.tears, seconds, 1e3 * r.slowest,
      body.vertex_count(), body.mesh().face_count(), body.piece_count(), r.worst, r.size);
  EXPECT_GT(r.cuts, events / 20);
  EXPECT_GT(r.drills, events / 10);
  EXPECT_GT(r.tear_steps, events / 2);
  expect_bullet_mirrors_mesh(body);
}
