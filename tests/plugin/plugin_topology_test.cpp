// Topology changes applied to a live skinned soft body: survivors keep x and v exactly, new
// nodes are interpolated, mass and momentum are conserved, every piece is its own btSoftBody
// mirroring the mesh, and the pieces keep following the skeleton.
#include <BulletSoftBody/btSoftBody.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include "conform/bullet/convert.hpp"
#include "conform/bullet/plugin.hpp"
#include "conform/mesh/analysis.hpp"
#include "conform/mesh/primitives.hpp"
#include "conform/skin/procedural_arm.hpp"
#include "conform/skin/skinner.hpp"
#include "plugin_world.hpp"

using namespace conform;
using conform::test::SoftWorld;

namespace {

struct Snapshot {
  std::vector<btVector3> x, v;
  double mass = 0;
  Eigen::Vector3d momentum;
  double scale = 0;
};

Snapshot snapshot(const bullet::SkinnedSoftBody& body) {
  Snapshot s;
  for (std::int32_t i = 0; i < body.vertex_count(); ++i) {
    const auto& node = body.body_of(i)->m_nodes[body.node_of(i)];
    EXPECT_FALSE(body.detached(i));  // the snapshots are taken before any drill
    s.x.push_back(node.m_x);
    s.v.push_back(node.m_v);
  }
  s.mass = body.total_mass();
  s.momentum = body.momentum();
  s.scale = body.momentum_scale();
  return s;
}

// Survivors bit-exact, new nodes interpolated, Σm and Σm·v unchanged.
void expect_conserved(const bullet::SkinnedSoftBody& body, const Snapshot& before,
                      const std::vector<mesh::TopologyChange>& changes, const char* what) {
  const auto old = static_cast<std::int32_t>(before.x.size());
  for (std::int32_t i = 0; i < old; ++i) {
    if (body.detached(i)) {  // left Bullet with its state (and mass) unchanged
      ASSERT_EQ(body.body_of(i), nullptr);
      ASSERT_TRUE(conform::bullet::to_bt(body.position(i)) == before.x[std::size_t(i)]);
      ASSERT_TRUE(conform::bullet::to_bt(body.velocity(i)) == before.v[std::size_t(i)]);
      continue;
    }
    const auto& node = body.body_of(i)->m_nodes[body.node_of(i)];
    ASSERT_TRUE(node.m_x == before.x[std::size_t(i)]) << what << " vertex " << i;
    ASSERT_TRUE(node.m_v == before.v[std::size_t(i)]) << what << " vertex " << i;
  }
  const double eps = sizeof(btScalar) == 4 ? 1e-6 : 1e-13;
  for (const auto& change : changes)
    for (std::size_t k = 0; k < change.new_vertices.size(); ++k) {
      const auto& nv = change.new_vertices[k];
      Eigen::Vector3d x = nv.displacement, v = Eigen::Vector3d::Zero();
      for (int j = 0; j < 3; ++j)
        if (nv.parents[std::size_t(j)] >= 0) {
          x += nv.coefficients[std::size_t(j)] * body.position(nv.parents[std::size_t(j)]);
          v += nv.coefficients[std::size_t(j)] * body.velocity(nv.parents[std::size_t(j)]);
        }
      const std::int32_t id = change.base_vertex_count + std::int32_t(k);
      ASSERT_LT((body.position(id) - x).norm(), eps * (1 + x.norm())) << what;
      ASSERT_LT((body.velocity(id) - v).norm(), eps * (1 + v.norm())) << what;
    }
  EXPECT_NEAR(body.total_mass(), before.mass, 1e-9 * before.mass) << what;
  EXPECT_LT((body.momentum() - before.momentum).norm(), 1e-9 * before.scale) << what;
  EXPECT_GT(before.scale, 0) << what;  // a moving body: the momentum check means something
}

// Every Bullet piece mirrors the mesh: the same faces, one link per edge with our rest length,
// one node per vertex, faces of a piece connected, pieces = the mesh's connected pieces.
void expect_mirrors_mesh(const bullet::SkinnedSoftBody& body, const char* what) {
  EXPECT_EQ(conform::test::bullet_internals_problem(body), "") << what;
  const auto& m = body.mesh();
  std::multiset<std::array<std::int32_t, 3>> mesh_faces, bullet_faces;
  auto canonical = [](std::array<std::int32_t, 3> f) {
    std::rotate(f.begin(), std::min_element(f.begin(), f.end()), f.end());
    return f;
  };
  for (const auto& f : m.faces) mesh_faces.insert(canonical({f[0], f[1], f[2]}));
  std::set<std::pair<std::int32_t, std::int32_t>> mesh_edges;
  for (const auto& f : m.faces)
    for (int k = 0; k < 3; ++k)
      mesh_edges.insert(std::minmax(f[std::size_t(k)], f[std::size_t((k + 1) % 3)]));
  std::vector<int> seen(std::size_t(m.vertex_count()), 0);
  std::size_t links = 0;
  for (btSoftBody* sb : body.pieces()) {
    auto vertex = [&](const btSoftBody::Node* n) {
      return body.vertex_of(sb, int(n - &sb->m_nodes[0]));
    };
    for (int i = 0; i < sb->m_nodes.size(); ++i) ++seen[std::size_t(body.vertex_of(sb, i))];
    // Faces connected through shared nodes (a union-find over this body's nodes).
    std::vector<int> parent(std::size_t(sb->m_nodes.size()));
    for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = int(i);
    auto find = [&](int a) {
      while (parent[std::size_t(a)] != a)
        a = parent[std::size_t(a)] = parent[std::size_t(parent[std::size_t(a)])];
      return a;
    };
    std::set<int> with_faces;
    for (int i = 0; i < sb->m_faces.size(); ++i) {
      const auto& f = sb->m_faces[i];
      bullet_faces.insert(canonical({vertex(f.m_n[0]), vertex(f.m_n[1]), vertex(f.m_n[2])}));
      for (int k = 0; k < 3; ++k) {
        const int a = int(f.m_n[k] - &sb->m_nodes[0]),
                  b = int(f.m_n[(k + 1) % 3] - &sb->m_nodes[0]);
        parent[std::size_t(find(a))] = find(b);
        with_faces.insert(a);
      }
    }
    std::set<int> roots;
    for (const int a : with_faces) roots.insert(find(a));
    EXPECT_LE(roots.size(), 1u) << what << ": a btSoftBody holds faces of several pieces";
    for (int i = 0; i < sb->m_links.size(); ++i) {
      const auto& l = sb->m_links[i];
      if (l.m_material != sb->m_materials[0]) continue;  // a bending link (checked below)
      const std::int32_t a = vertex(l.m_n[0]), b = vertex(l.m_n[1]);
      const std::pair<std::int32_t, std::int32_t> e = std::minmax(a, b);
      ASSERT_TRUE(mesh_edges.count(e)) << what << ": link without a face";
      ASSERT_NEAR(double(l.m_rl), body.rest_length(e.first, e.second),
                  1e-6 * double(l.m_rl) + 1e-12);
      ++links;
    }
  }
  EXPECT_EQ(mesh_faces.size(), bullet_faces.size()) << what;
  std::vector<std::array<std::int32_t, 3>> only_mesh, only_bullet;
  std::set_difference(mesh_faces.begin(), mesh_faces.end(), bullet_faces.begin(),
                      bullet_faces.end(), std::back_inserter(only_mesh));
  std::set_difference(bullet_faces.begin(), bullet_faces.end(), mesh_faces.begin(),
                      mesh_faces.end(), std::back_inserter(only_bullet));
  EXPECT_TRUE(only_mesh.empty() && only_bullet.empty())
      << what << ": " << only_mesh.size() << " faces only in the mesh, " << only_bullet.size()
      << " only in Bullet";
  EXPECT_EQ(links, mesh_edges.size()) << what;
  EXPECT_EQ(std::int32_t(links), body.link_count()) << what;
  // One node per vertex that has faces; a vertex without faces is detached (no node).
  std::vector<int> has_face(seen.size(), 0);
  for (const auto& f : m.faces)
    for (const auto v : f) has_face[std::size_t(v)] = 1;
  int detached = 0;
  for (std::size_t v = 0; v < seen.size(); ++v) {
    ASSERT_EQ(seen[v], has_face[v]) << what << " vertex " << v;
    ASSERT_EQ(body.detached(std::int32_t(v)), !has_face[v]) << what << " vertex " << v;
    detached += !has_face[v];
  }
  EXPECT_EQ(detached, body.detached_count()) << what;
  // Bending links: exactly one across each edge of two faces when enabled, none otherwise.
  const auto bending = conform::test::check_bending(body);
  EXPECT_EQ(bending.wrong, 0) << what;
  EXPECT_EQ(bending.links, body.bending_link_count()) << what;
  EXPECT_EQ(bending.links, body.material().bending_stiffness > 0 ? bending.expected : 0) << what;
  EXPECT_EQ(body.piece_count(), mesh::label_pieces(m).count) << what;
}

struct LiveArm {
  SoftWorld w;
  bullet::Plugin plugin{w.world};
  skin::Arm arm = skin::make_arm(1);
  bullet::SkinnedSoftBody* body = nullptr;
  skin::PoseTrack track;
  explicit LiveArm(double bending = 0) {
    body = &plugin.add_skinned_body(arm.mesh, arm.skeleton,
                                    {.model = bullet::MaterialModel::bullet_links,
                                     .pretension = 0.1,
                                     .bending_stiffness = bending});
    track.set_key(0, skin::Pose::rest(arm.skeleton));
    track.set_key(2, conform::test::bent_arm_pose(arm.skeleton, 0.8, 1.2));
    body->set_keyframes(track);
    w.step(20);  // moving: every node has a velocity
  }
};

}  // namespace

TEST(PluginTopology, CutSplitsTheArmIntoTwoLiveBodies) {
  LiveArm a;
  auto& body = *a.body;
  const Snapshot before = snapshot(body);
  const auto result = body.cut(cga::Plane<double>::from_normal_point({0, 0, 1}, {0, 0, 0.42}));
  ASSERT_EQ(result.status, mesh::CutStatus::Cut);
  expect_conserved(body, before, {result.change}, "cut");
  expect_mirrors_mesh(body, "cut");
  EXPECT_EQ(body.piece_count(), 2);
  EXPECT_EQ(a.w.world.getSoftBodyArray().size(), 2);
  EXPECT_GT(body.last_apply().moved_nodes, 0);
  EXPECT_EQ(body.last_apply().new_pieces, 1);
  // Both pieces keep following the skeleton: kinematic nodes sit on targets skinned from the
  // mesh's updated rest positions and weights.
  a.w.step(30);
  skin::Pose pose = skin::Pose::rest(a.arm.skeleton);
  a.track.sample(a.plugin.time(), skin::Blend::linear, pose);
  skin::Skinner<double> skinner(a.arm.skeleton, body.mesh().rest,
                                skin::InfluenceLists::from_mesh(body.mesh()));
  skinner.skin(pose, skin::SkinMode::cga);
  Eigen::Matrix3Xd expected;
  skinner.write(expected);
  int forearm_kinematic = 0;
  for (std::int32_t v = 0; v < body.vertex_count(); ++v) {
    ASSERT_LT((body.target(v) - expected.col(v)).norm(), 1e-12);
    if (!body.kinematic(v)) continue;
    ASSERT_LT((body.position(v) - expected.col(v)).norm(), sizeof(btScalar) == 4 ? 1e-6 : 1e-13);
    forearm_kinematic += body.mesh().rest(2, v) > 0.42;
  }
  EXPECT_GT(forearm_kinematic, 100);
}

TEST(PluginTopology, RegionalCutSeversTheUpperArmOnlyKeepingMassAndMomentum) {
  // The arm bending its elbow past a right angle, so that a plane across the upper arm also
  // crosses the forearm. A sphere at the upper arm (placed from the joints' transforms) limits
  // the cut to that loop: two pieces, not three, and no new node outside the sphere.
  SoftWorld w;
  bullet::Plugin plugin{w.world};
  const skin::Arm arm = skin::make_arm(1);
  auto& body = plugin.add_skinned_body(
      arm.mesh, arm.skeleton, {.model = bullet::MaterialModel::bullet_links, .pretension = 0.1});
  skin::PoseTrack track;
  track.set_key(0, skin::Pose::rest(arm.skeleton));
  track.set_key(0.5, conform::test::bent_arm_pose(arm.skeleton, 0, 2.6));
  body.set_keyframes(track);
  w.step(24);  // still moving: every node has a velocity
  const auto joints = body.joint_transforms();
  const Eigen::Vector3d shoulder = joints[0].apply(cga::Vec3<double>::Zero()),
                        elbow = joints[1].apply(cga::Vec3<double>::Zero());
  const Eigen::Vector3d p = shoulder + (elbow - shoulder) * (2.0 / 3);
  const auto plane = cga::Plane<double>::from_normal_point(elbow - shoulder, p);
  body.sync_mesh();
  ASSERT_EQ(mesh::compute_cut(body.mesh(), plane, {.cap = true}).loops, 2);  // unbounded
  mesh::CutOptions options{.cap = true};
  options.region = mesh::CutRegion::sphere(p, 0.09);
  const Snapshot before = snapshot(body);
  const auto result = body.cut(plane, options);
  ASSERT_EQ(result.status, mesh::CutStatus::Cut) << result.message;
  EXPECT_EQ(result.sections, 2);  // the unbounded plane would cut the forearm too
  EXPECT_EQ(result.kept_sections, 1);
  EXPECT_EQ(result.capped_loops, 1) << result.message;
  expect_conserved(body, before, {result.change}, "regional cut");
  expect_mirrors_mesh(body, "regional cut");
  EXPECT_EQ(body.piece_count(), 2);
  for (std::int32_t v = result.change.base_vertex_count; v < body.vertex_count(); ++v)
    ASSERT_LE((body.position(v) - p).norm(), 0.09) << "vertex " << v;
  w.step(10);  // both pieces simulate on
  for (std::int32_t v = 0; v < body.vertex_count(); ++v) ASSERT_TRUE(body.position(v).allFinite());
}

TEST(PluginTopology, TearStepsEditInPlace) {
  LiveArm a;
  auto& body = *a.body;
  body.begin_tear();
  int extended = 0;
  for (int i = 0; i <= 20; ++i) {
    const double z = 0.08 + 0.005 * i;
    const Snapshot before = snapshot(body);
    const auto step = body.tear_advance({double(i), {0, 0, z}, {0.15, 0, z}});
    extended += step.extended;
    expect_conserved(body, before, step.changes, "tear step");
    // A tear step never splits the arm: only local edits, no node moves between bodies.
    EXPECT_EQ(body.last_apply().moved_nodes, 0);
    EXPECT_EQ(body.last_apply().new_pieces, 0);
    a.w.step();
  }
  EXPECT_GT(extended, 10) << body.tear()->message();
  expect_mirrors_mesh(body, "tear");
  EXPECT_EQ(body.piece_count(), 1);
}

// The inside of the holes (vertices left without faces) leaves Bullet: no node, link or face
// of theirs remains, their mass and momentum stay in the books, and they lie inside the drill.
TEST(PluginTopology, DrillDetachesTheHolesInsideKeepingMassAndMomentum) {
  LiveArm a;
  auto& body = *a.body;
  const Snapshot before = snapshot(body);
  // Through both walls of the upper arm, at its current (posed) place.
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  int n = 0;
  for (std::int32_t v = 0; v < body.vertex_count(); ++v)
    if (std::abs(a.arm.mesh.rest(2, v) - 0.15) < 0.01) c += body.position(v), ++n;
  c /= n;
  const mesh::DrillTool tool{c + Eigen::Vector3d(0, 0.2, 0), c - Eigen::Vector3d(0, 0.2, 0), 0.012};
  const auto result = body.drill(tool);
  ASSERT_EQ(result.holes, 2) << result.message;
  expect_conserved(body, before, result.changes, "drill");
  expect_mirrors_mesh(body, "drill");
  EXPECT_EQ(body.piece_count(), 1);
  // Proven whole around the two holes, not by searching around the arm from one to the other.
  EXPECT_LT(body.last_apply().searched_vertices, body.vertex_count() / 4);
  EXPECT_GT(body.detached_count(), 0);
  EXPECT_EQ(body.last_apply().detached_nodes, body.detached_count());
  int nodes = 0;
  for (btSoftBody* sb : body.pieces()) nodes += sb->m_nodes.size();
  EXPECT_EQ(nodes + body.detached_count(), body.vertex_count());
  for (std::int32_t v = 0; v < body.vertex_count(); ++v)
    if (body.detached(v)) {
      EXPECT_LT(mesh::axis_distance_squared(tool, body.position(v)),
                tool.radius * tool.radius * (1 + 1e-9));
      EXPECT_GT(body.mass(v), 0);  // the removed material's mass, kept in the books
    }
  const double mass = body.total_mass();
  a.w.step(30);
  EXPECT_EQ(body.total_mass(), mass);
  for (std::int32_t v = 0; v < body.vertex_count(); ++v)
    if (body.detached(v)) {  // out of Bullet, riding its skinned target
      EXPECT_EQ(body.position(v), body.target(v));
      EXPECT_EQ(body.body_of(v), nullptr);
    }
  for (std::int32_t v = 0; v < body.vertex_count(); ++v)
    ASSERT_TRUE(body.position(v).allFinite() && body.velocity(v).allFinite());
  expect_mirrors_mesh(body, "drill, 30 steps later");
}

// The vertex arrays' bound (skinned_soft_body.hpp, "Vertices are never reclaimed"): they grow
// by exactly the changes' new vertices; the vertices left detached are all inside a drill's
// holes and out of Bullet (its nodes are the attached vertices, one each); every edit
// conserves Σm and Σm·v with the detached ones in the books.
TEST(PluginTopology, DetachedVerticesAreBoundedByTheHoles) {
  LiveArm a;
  auto& body = *a.body;
  const std::int32_t v0 = body.vertex_count();
  std::int64_t added = 0;
  std::vector<mesh::DrillTool> tools;
  const auto drill_at = [&](double z, double radius) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    int n = 0;
    for (std::int32_t v = 0; v < v0; ++v)
      if (std::abs(a.arm.mesh.rest(2, v) - z) < 0.01) c += body.position(v), ++n;
    c /= n;
    const mesh::DrillTool tool{c + Eigen::Vector3d(0, 0.2, 0), c - Eigen::Vector3d(0, 0.2, 0),
                               radius};
    const double mass = body.total_mass(), scale = body.momentum_scale();
    const Eigen::Vector3d momentum = body.momentum();
    std::vector<std::uint8_t> was(std::size_t(body.vertex_count()));
    for (std::int32_t v = 0; v < body.vertex_count(); ++v) was[std::size_t(v)] = body.detached(v);
    const auto result = body.drill(tool);
    ASSERT_EQ(result.holes, 2) << result.message;
    for (const auto& change : result.changes) added += std::int64_t(change.new_vertices.size());
    EXPECT_NEAR(body.total_mass(), mass, 1e-9 * mass);
    EXPECT_LT((body.momentum() - momentum).norm(), 1e-9 * scale);
    for (std::int32_t v = 0; v < body.vertex_count(); ++v) {
      if (!body.detached(v) || (v < std::int32_t(was.size()) && was[std::size_t(v)])) continue;
      EXPECT_LT(mesh::axis_distance_squared(tool, body.position(v)),
                tool.radius * tool.radius * (1 + 1e-9))
          << "vertex " << v << " detached outside the hole";
    }
    tools.push_back(tool);
    a.w.step(5);
  };
  drill_at(0.10, 0.012);
  drill_at(0.20, 0.015);
  const double mass = body.total_mass(), scale = body.momentum_scale();
  const Eigen::Vector3d momentum = body.momentum();
  const auto cut = body.cut(cga::Plane<double>::from_normal_point({0, 0, 1}, {0, 0, 0.42}));
  ASSERT_EQ(cut.status, mesh::CutStatus::Cut);
  added += std::int64_t(cut.change.new_vertices.size());
  EXPECT_NEAR(body.total_mass(), mass, 1e-9 * mass);
  EXPECT_LT((body.momentum() - momentum).norm(), 1e-9 * scale);
  a.w.step(5);
  drill_at(0.50, 0.012);

  EXPECT_EQ(body.vertex_count(), v0 + added);
  int nodes = 0;
  for (btSoftBody* sb : body.pieces()) nodes += sb->m_nodes.size();
  EXPECT_EQ(nodes, body.vertex_count() - body.detached_count());
  EXPECT_GT(body.detached_count(), 0);
  std::printf("after 3 drills and a cut: %d vertices, %d detached (%.1f %%), %d Bullet nodes\n",
              body.vertex_count(), body.detached_count(),
              100.0 * body.detached_count() / body.vertex_count(), nodes);
  expect_mirrors_mesh(body, "drills and a cut");
}

// The same edits with bending links: survivors exact, Σm and Σm·v conserved, and the bending
// links always exactly those across the edges of two faces (none across a cut, tear or hole).
TEST(PluginTopology, EditsKeepBendingLinksAcrossEdgesOfTwoFacesOnly) {
  LiveArm a(0.5);
  auto& body = *a.body;
  expect_mirrors_mesh(body, "bending, built");
  EXPECT_GT(body.bending_link_count(), 0);
  Snapshot before = snapshot(body);
  body.begin_tear();
  std::vector<mesh::TopologyChange> changes;
  for (int i = 0; i <= 10; ++i) {
    const double z = 0.08 + 0.005 * i;
    const auto step = body.tear_advance({double(i), {0, 0, z}, {0.15, 0, z}});
    changes.insert(changes.end(), step.changes.begin(), step.changes.end());
  }
  expect_conserved(body, before, changes, "bending tear");
  expect_mirrors_mesh(body, "bending tear");
  EXPECT_GT(body.last_apply().removed_bending, 0);
  a.w.step(5);
  before = snapshot(body);
  const auto cut = body.cut(cga::Plane<double>::from_normal_point({0, 0, 1}, {0, 0, 0.42}));
  ASSERT_EQ(cut.status, mesh::CutStatus::Cut);
  expect_conserved(body, before, {cut.change}, "bending cut");
  expect_mirrors_mesh(body, "bending cut");
  EXPECT_EQ(body.piece_count(), 2);
  a.w.step(5);
  before = snapshot(body);
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  int n = 0;
  for (std::int32_t v = 0; v < a.arm.mesh.vertex_count(); ++v)
    if (std::abs(a.arm.mesh.rest(2, v) - 0.25) < 0.01) c += body.position(v), ++n;
  c /= n;
  const auto drill =
      body.drill({c + Eigen::Vector3d(0, 0.2, 0), c - Eigen::Vector3d(0, 0.2, 0), 0.012});
  ASSERT_EQ(drill.holes, 2) << drill.message;
  expect_conserved(body, before, drill.changes, "bending drill");
  expect_mirrors_mesh(body, "bending drill");
  a.w.step(30);
  for (std::int32_t v = 0; v < body.vertex_count(); ++v)
    ASSERT_TRUE(body.position(v).allFinite() && body.velocity(v).allFinite());
}

// The piece a cut moves into a new body starts in arrays sized for it; later edits that add
// more nodes, faces and links than that room make them grow (and every pointer follow).
TEST(PluginTopology, EditsOnASplitOffPieceGrowItsArrays) {
  LiveArm a;
  auto& body = *a.body;
  const auto cut = body.cut(cga::Plane<double>::from_normal_point({0, 0, 1}, {0, 0, 0.42}));
  ASSERT_EQ(cut.status, mesh::CutStatus::Cut);
  ASSERT_EQ(body.piece_count(), 2);
  a.w.step(5);
  // The new body: the one not holding vertex 0 (the shoulder end).
  btSoftBody* hand = nullptr;
  for (btSoftBody* sb : body.pieces())
    if (sb != body.body_of(0)) hand = sb;
  ASSERT_NE(hand, nullptr);
  const int nodes_before = hand->m_nodes.size(), faces_before = hand->m_faces.size();
  int drilled = 0;
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    int n = 0;
    for (std::int32_t v = 0; v < body.vertex_count(); ++v)
      if (body.body_of(v) == hand) c += body.position(v), ++n;
    c /= n;
    c.z() += 0.02 * (i - 1);
    const Snapshot before = [&] {
      Snapshot s;  // snapshot() expects no detached vertex; only the sums are compared here
      s.mass = body.total_mass();
      s.momentum = body.momentum();
      s.scale = body.momentum_scale();
      return s;
    }();
    const auto result =
        body.drill({c + Eigen::Vector3d(0, 0.2, 0), c - Eigen::Vector3d(0, 0.2, 0), 0.008});
    drilled += result.holes;
    EXPECT_NEAR(body.total_mass(), before.mass, 1e-9 * before.mass);
    EXPECT_LT((body.momentum() - before.momentum).norm(), 1e-9 * before.scale);
    expect_mirrors_mesh(body, "drill in the split-off piece");
    a.w.step(2);
  }
  EXPECT_GT(drilled, 0);
  EXPECT_GT(hand->m_nodes.size(), nodes_before + 16);  // past the room it was made with
  EXPECT_GT(hand->m_faces.size(), faces_before + 16);
  a.w.step(20);
  for (std::int32_t v = 0; v < body.vertex_count(); ++v)
    ASSERT_TRUE(body.position(v).allFinite() && body.velocity(v).allFinite());
  expect_mirrors_mesh(body, "split-off piece, 20 steps later");
}

// A change that only removes the faces whose rest centroid satisfies `remove`.
template <class Predicate>
mesh::TopologyChange remove_faces_where(const mesh::SkinnedMesh& m, Predicate remove) {
  mesh::TopologyChange change;
  change.base_vertex_count = m.vertex_count();
  change.base_face_count = m.face_count();
  for (std::int32_t f = 0; f < m.face_count(); ++f) {
    const auto& t = m.faces[std::size_t(f)];
    const Eigen::Vector3d c = (m.rest.col(t[0]) + m.rest.col(t[1]) + m.rest.col(t[2])) / 3;
    if (remove(c)) change.removed_faces.push_back(f);
  }
  return change;
}

// The split search proves a body whole from the changed region alone when it can (two holes
// far apart: no growing until the searches from both meet), and still finds every split (a
// ring cut out around a disk, a strip across the sheet), whichever way it ends.
TEST(PluginTopology, SplitSearchStaysLocalForHolesAndFindsEverySplit) {
  SoftWorld w;
  bullet::Plugin plugin(w.world);
  const mesh::SkinnedMesh sheet = test::one_bone_sheet(40, 40, 1.0, 1.0);
  auto& body = plugin.add_skinned_body(
      sheet, test::one_bone_skeleton(),
      {.model = bullet::MaterialModel::bullet_links, .pretension = 0.1, .kinematic_weight = 2});
  w.step(3);
  auto near = [](double x, double y, double r) {
    return [=](const Eigen::Vector3d& c) { return std::hypot(c.x() - x, c.y() - y) < r; };
  };
  // Two holes: one piece, found without searching the sheet.
  body.sync_mesh();
  const auto a = near(-0.3, 0, 0.06), b = near(0.3, 0, 0.06);
  body.apply(remove_faces_where(body.mesh(), [&](auto& c) { return a(c) || b(c); }));
  expect_mirrors_mesh(body, "two holes");
  EXPECT_EQ(body.piece_count(), 1);
  EXPECT_EQ(body.last_apply().moved_nodes, 0);
  EXPECT_LT(body.last_apply().searched_vertices, body.vertex_count() / 8);
  // A ring around a disk: the disk is a piece of its own, though every removed face is in one
  // cluster with vertices on both of its sides.
  w.step();
  body.sync_mesh();
  body.apply(remove_faces_where(body.mesh(), [](const Eigen::Vector3d& c) {
    const double r = std::hypot(c.x(), c.y());
    return r > 0.1 && r < 0.14;
  }));
  expect_mirrors_mesh(body, "ring");
  EXPECT_EQ(body.piece_count(), 2);
  EXPECT_GT(body.last_apply().moved_nodes, 0);
  // A hole in the disk and a strip across the sheet in one change: three pieces.
  w.step();
  body.sync_mesh();
  const auto in_disk = near(0.02, 0, 0.03);
  body.apply(remove_faces_where(body.mesh(), [&](const Eigen::Vector3d& c) {
    return in_disk(c) || std::abs(c.y() - 0.3) < 0.02;
  }));
  expect_mirrors_mesh(body, "strip and hole");
  EXPECT_EQ(body.piece_count(), 3);
  w.step(3);
  for (std::int32_t v = 0; v < body.vertex_count(); ++v) ASSERT_TRUE(body.position(v).allFinite());
  EXPECT_EQ(conform::test::bullet_internals_problem(body), "");
}

TEST(PluginTopology, ApplyRejectsAChangeForAnotherMesh) {
  LiveArm a;
  mesh::TopologyChange change;
  change.base_vertex_count = a.body->vertex_count() + 1;
  change.base_face_count = a.body->mesh().face_count();
  EXPECT_THROW(a.body->apply(change), std::invalid_argument);
  expect_mirrors_mesh(*a.body, "rejected");
}
