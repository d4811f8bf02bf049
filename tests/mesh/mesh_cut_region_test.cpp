// Regional cuts (cut_region.hpp): a plane limited to a sphere, a box or the section nearest a
// seed point cuts whole sections only. Checked against the unbounded cut of the same plane
// (the regional change is a part of it: the same new vertices, the same removed faces), by
// the region itself (no new vertex outside it), by counting pieces (a closed loop on a genus-0
// surface separates it: Jordan), and by the mesh invariants (manifold, oriented, closed caps).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <set>
#include <tuple>

#include "conform/cga/motor.hpp"
#include "conform/io/import.hpp"
#include "conform/mesh/analysis.hpp"
#include "conform/mesh/cut.hpp"
#include "conform/skin/pose.hpp"
#include "conform/skin/procedural_arm.hpp"
#include "skin_reference.hpp"

using namespace conform;
using namespace conform::mesh;
using conform::skin::make_arm;
using Plane = cga::Plane<double>;

namespace {

// The procedural arm with its elbow bent by `elbow` radians about x (the forearm folds back
// towards the shoulder), skinned by the reference LBS: a plane across the upper arm then also
// crosses the forearm, in a second section.
SkinnedMesh bent_arm(double elbow) {
  SkinnedMesh m = make_arm(1).mesh;
  const Eigen::Vector3d e(0, 0, 0.30);  // the elbow
  const Eigen::Quaterniond q(Eigen::AngleAxisd(elbow, Eigen::Vector3d::UnitX()));
  const auto about_elbow =
      cga::Versor<double>::from_motor(cga::Motor<double>::from_rotation_translation(q, e - q * e));
  m.current =
      conform::test::reference_lbs(m, {cga::Versor<double>::identity(), about_elbow, about_elbow});
  return m;
}

// (parents, coefficients) of a new vertex, to compare the changes of two cuts.
using VertexKey = std::tuple<std::int32_t, std::int32_t, std::int32_t, double, double>;
std::set<VertexKey> new_vertex_keys(const CutResult& r) {
  std::set<VertexKey> keys;
  for (const auto& nv : r.change.new_vertices)
    if (!nv.is_duplicate())
      keys.emplace(nv.parents[0], nv.parents[1], nv.parents[2], nv.coefficients[0],
                   nv.coefficients[1]);
  return keys;
}

// The regional change is a part of the unbounded one: its crossing vertices and removed
// faces are among the unbounded cut's.
void expect_part_of(const CutResult& regional, const CutResult& unbounded,
                    const std::string& what) {
  const auto part = new_vertex_keys(regional), whole = new_vertex_keys(unbounded);
  EXPECT_TRUE(std::includes(whole.begin(), whole.end(), part.begin(), part.end())) << what;
  const auto& pr = regional.change.removed_faces;
  const auto& wr = unbounded.change.removed_faces;  // both sorted
  EXPECT_TRUE(std::includes(wr.begin(), wr.end(), pr.begin(), pr.end())) << what;
  EXPECT_LE(regional.change.new_vertices.size(), unbounded.change.new_vertices.size()) << what;
}

// The largest distance from `center` of the cut's new vertices (positions after apply).
double farthest_new_vertex(const SkinnedMesh& cut_mesh, const CutResult& r,
                           const Eigen::Vector3d& center) {
  double far = 0;
  for (std::int32_t v = r.change.base_vertex_count; v < cut_mesh.vertex_count(); ++v)
    far = std::max(far, (cut_mesh.current.col(v) - center).norm());
  return far;
}

// Every piece closed, oriented and manifold (the input being so), volumes adding up.
void expect_closed_pieces(const SkinnedMesh& in, const SkinnedMesh& m, const Pieces& pieces,
                          const std::string& what) {
  double volume = 0;
  for (std::int32_t p = 0; p < pieces.count; ++p) {
    SkinnedMesh piece = m;
    piece.faces.clear();
    for (auto f : pieces.faces_of(p)) piece.faces.push_back(m.faces[static_cast<std::size_t>(f)]);
    const MeshReport r = check_mesh(piece);
    EXPECT_TRUE(r.closed() && r.oriented() && r.manifold())
        << what << " piece " << p << ": " << r.summary();
    volume += signed_volume(piece);
  }
  EXPECT_NEAR(volume, signed_volume(in), 1e-9 * std::abs(signed_volume(in))) << what;
}

struct Outcome {
  SkinnedMesh mesh;
  CutOutcome out;
};
Outcome run_cut(const SkinnedMesh& in, const Plane& plane, const CutOptions& options) {
  Outcome o{in, {}};
  Adjacency adjacency(o.mesh);
  o.out = cut(o.mesh, adjacency, plane, options);
  return o;
}

const Plane kAcrossUpperArm = Plane::from_normal_point({0, 0, 1}, {0, 0, 0.2});

}  // namespace

TEST(CutRegion, BentArmUnboundedPlaneCutsBothLimbs) {
  // The premise: the unbounded plane crosses the upper arm and the forearm (3 pieces).
  const SkinnedMesh in = bent_arm(2.2);
  const Outcome all = run_cut(in, kAcrossUpperArm, {.cap = true});
  ASSERT_EQ(all.out.result.status, CutStatus::Cut);
  EXPECT_EQ(all.out.result.loops, 2);
  EXPECT_EQ(all.out.pieces.count, 3);
  // The same plane with a region that holds everything is the unbounded cut, exactly.
  CutOptions everything{.cap = true};
  everything.region = CutRegion::sphere({0, 0, 0.3}, 10.0);
  const Outcome same = run_cut(in, kAcrossUpperArm, everything);
  EXPECT_EQ(same.out.result.sections, 2);
  EXPECT_EQ(same.out.result.kept_sections, 2);
  EXPECT_EQ(same.mesh.faces, all.mesh.faces);
  EXPECT_EQ(same.mesh.current, all.mesh.current);
}

TEST(CutRegion, SphereKeepsTheUpperArmSectionOnly) {
  const SkinnedMesh in = bent_arm(2.2);
  const Outcome all = run_cut(in, kAcrossUpperArm, {.cap = true});
  const Eigen::Vector3d center(0, 0, 0.2);
  const double radius = 0.09;  // the arm's radius is under 6 cm; the forearm's loop is 14 cm off
  CutOptions options{.cap = true};
  options.region = CutRegion::sphere(center, radius);
  const Outcome o = run_cut(in, kAcrossUpperArm, options);
  const CutResult& r = o.out.result;
  ASSERT_EQ(r.status, CutStatus::Cut) << r.message;
  EXPECT_EQ(r.sections, 2);
  EXPECT_EQ(r.kept_sections, 1);
  EXPECT_EQ(r.loops, 1);
  EXPECT_EQ(r.capped_loops, 1) << r.message;
  EXPECT_EQ(o.out.pieces.count, 2);  // shoulder | elbow, forearm and hand
  EXPECT_LE(farthest_new_vertex(o.mesh, r, center), radius);
  EXPECT_GT(r.change.new_vertices.size(), 32u);  // at least one crossing per segment around
  expect_part_of(r, all.out.result, "upper arm");
  expect_closed_pieces(in, o.mesh, o.out.pieces, "upper arm");
  // Nothing outside the kept section moved or changed: the faces the regional cut did not
  // remove are the input's, at the same slots unless the slot protocol moved them.
  std::multiset<std::array<std::int32_t, 3>> before(in.faces.begin(), in.faces.end()),
      after(o.mesh.faces.begin(), o.mesh.faces.end());
  for (auto f : r.change.removed_faces)
    before.erase(before.find(in.faces[static_cast<std::size_t>(f)]));
  for (const auto& f : before) EXPECT_TRUE(after.count(f)) << "a face outside the cut changed";
}

TEST(CutRegion, SeedPicksTheSectionNearestToIt) {
  const SkinnedMesh in = bent_arm(2.2);
  const Outcome all = run_cut(in, kAcrossUpperArm, {.cap = true});
  // A point beside the forearm, where the plane crosses it (y ≈ −0.14 at z = 0.2).
  CutOptions options{.cap = true};
  options.region = CutRegion::seed({0, -0.2, 0.2});
  const Outcome o = run_cut(in, kAcrossUpperArm, options);
  const CutResult& r = o.out.result;
  ASSERT_EQ(r.status, CutStatus::Cut) << r.message;
  EXPECT_EQ(r.kept_sections, 1);
  EXPECT_EQ(o.out.pieces.count, 2);  // the hand's end | the rest
  for (std::int32_t v = r.change.base_vertex_count; v < o.mesh.vertex_count(); ++v)
    ASSERT_LT(o.mesh.current(1, v), -0.05) << "a new vertex on the upper arm's side";
  expect_part_of(r, all.out.result, "forearm seed");
  expect_closed_pieces(in, o.mesh, o.out.pieces, "forearm seed");
  // Both seeds' cuts together are the unbounded cut's new vertices.
  options.region = CutRegion::seed({0, 0.05, 0.2});
  const Outcome other = run_cut(in, kAcrossUpperArm, options);
  auto joined = new_vertex_keys(r);
  const auto second = new_vertex_keys(other.out.result);
  joined.insert(second.begin(), second.end());
  EXPECT_EQ(joined, new_vertex_keys(all.out.result));
}

TEST(CutRegion, InsideNeedsTheWholeLoopTouchingOneOfItsPoints) {
  const SkinnedMesh in = bent_arm(2.2);
  const Eigen::Vector3d on_skin(0, 0.045, 0.2);  // near the upper arm's skin, off its axis
  CutOptions options{.cap = true};
  options.region = CutRegion::sphere(on_skin, 0.02);
  const Outcome inside = run_cut(in, kAcrossUpperArm, options);
  EXPECT_EQ(inside.out.result.status, CutStatus::Missed);
  EXPECT_EQ(inside.out.result.kept_sections, 0);
  EXPECT_NE(inside.out.result.message.find("outside the region"), std::string::npos);
  EXPECT_EQ(inside.mesh.faces, in.faces);  // a no-op
  options.region.keep = CutRegion::Keep::touching;
  const Outcome touching = run_cut(in, kAcrossUpperArm, options);
  ASSERT_EQ(touching.out.result.status, CutStatus::Cut);
  EXPECT_EQ(touching.out.result.kept_sections, 1);
  EXPECT_EQ(touching.out.pieces.count, 2);
  EXPECT_GT(farthest_new_vertex(touching.mesh, touching.out.result, on_skin), 0.02);
}

TEST(CutRegion, OrientedBoxAroundTheForearm) {
  const SkinnedMesh in = bent_arm(2.2);
  // A box along the forearm's axis (direction (0, −sin 2.2, cos 2.2) from the elbow).
  const Eigen::Vector3d along(0, -std::sin(2.2), std::cos(2.2));
  Eigen::Matrix3d axes;
  axes.col(0) = Eigen::Vector3d::UnitX(), axes.col(1) = along,
  axes.col(2) = axes.col(0).cross(along);
  const Eigen::Vector3d center = Eigen::Vector3d(0, 0, 0.3) + 0.17 * along;
  CutOptions options{.cap = true};
  options.region = CutRegion::box(center, {0.07, 0.1, 0.07}, axes);
  const Outcome o = run_cut(in, kAcrossUpperArm, options);
  ASSERT_EQ(o.out.result.status, CutStatus::Cut) << o.out.result.message;
  EXPECT_EQ(o.out.result.kept_sections, 1);
  EXPECT_EQ(o.out.pieces.count, 2);
  for (std::int32_t v = o.out.result.change.base_vertex_count; v < o.mesh.vertex_count(); ++v)
    ASSERT_TRUE(options.region.contains(o.mesh.current.col(v))) << "vertex " << v;
  expect_closed_pieces(in, o.mesh, o.out.pieces, "forearm box");
}

TEST(CutRegion, BadRegionsThrowNamingTheField) {
  const SkinnedMesh in = bent_arm(2.2);
  auto message = [&](const CutRegion& region) {
    CutOptions options;
    options.region = region;
    try {
      (void)compute_cut(in, kAcrossUpperArm, options);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no throw");
  };
  EXPECT_EQ(message(CutRegion::sphere({0, 0, 0}, -1)),
            "cut region: radius = -1 must be finite and > 0");
  EXPECT_EQ(message(CutRegion::sphere({0, 0, NAN}, 1)),
            "cut region: center = (  0   0 nan) must be finite");
  EXPECT_EQ(message(CutRegion::box({0, 0, 0}, {1, 0, 1})),
            "cut region: half_extents = (1 0 1) must be finite and > 0");
  Eigen::Matrix3d skew = Eigen::Matrix3d::Identity();
  skew(0, 1) = 0.5;
  EXPECT_NE(message(CutRegion::box({0, 0, 0}, {1, 1, 1}, skew)).find("axes must be orthonormal"),
            std::string::npos);
  EXPECT_EQ(message(CutRegion::seed({0, 0, 0.2})), "no throw");
}

TEST(CutRegion, PropertyRandomPlanesOnTheBentArm) {
  // Random planes through the bent arm, a seed at a random point: one section kept, a part of
  // the unbounded cut, invariants kept, and a sphere just holding its new vertices (Keep::inside)
  // gives the same cut.
  const SkinnedMesh in = bent_arm(2.2);
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(0, 1);
  const Eigen::Vector3d lo = in.current.rowwise().minCoeff(), hi = in.current.rowwise().maxCoeff();
  int cuts = 0, multi = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const Eigen::Vector3d p = lo + (hi - lo).cwiseProduct(Eigen::Vector3d(u(rng), u(rng), u(rng)));
    const Plane plane = Plane::from_normal_point(Eigen::Vector3d(g(rng), g(rng), g(rng)), p);
    const std::string what = "trial " + std::to_string(trial);
    const Outcome all = run_cut(in, plane, {.cap = true});
    if (all.out.result.status != CutStatus::Cut) continue;
    CutOptions options{.cap = true};
    options.region = CutRegion::seed(p);
    const Outcome o = run_cut(in, plane, options);
    ASSERT_EQ(o.out.result.status, CutStatus::Cut) << what;
    ++cuts;
    multi += o.out.result.sections > 1;
    EXPECT_EQ(o.out.result.kept_sections, 1) << what;
    expect_part_of(o.out.result, all.out.result, what);
    const MeshReport report = check_mesh(o.mesh);
    EXPECT_TRUE(report.manifold() && report.oriented()) << what << ": " << report.summary();
    if (o.out.result.capped_loops == o.out.result.loops) {
      EXPECT_TRUE(report.closed()) << what;
      EXPECT_EQ(o.out.pieces.count, 1 + o.out.result.loops) << what;  // genus 0: Jordan
    }
    CutOptions sphere{.cap = true};
    sphere.region = CutRegion::sphere(p, farthest_new_vertex(o.mesh, o.out.result, p) * (1 + 1e-9));
    const Outcome s = run_cut(in, plane, sphere);
    EXPECT_GE(s.out.result.kept_sections, 1) << what;
    EXPECT_LE(farthest_new_vertex(s.mesh, s.out.result, p), sphere.region.radius) << what;
    if (s.out.result.kept_sections == 1) {
      EXPECT_EQ(s.mesh.faces, o.mesh.faces) << what;
    }
    if (testing::Test::HasFailure()) return;
  }
  EXPECT_GT(cuts, 30);
  EXPECT_GT(multi, 5);  // planes that cross both limbs, where the region matters
  RecordProperty("cuts", cuts);
  RecordProperty("multi_section_cuts", multi);
}

namespace {

// What a regional cut of a closed genus-0 model by `plane`, seeded at `p`, must keep (see the
// file's comment); counts into the totals. False when the plane misses the model.
struct RealTotals {
  int cuts = 0, sliced_elsewhere = 0;
  std::size_t unbounded_new = 0, regional_new = 0;
};
void check_seeded_cut(const SkinnedMesh& in, const Plane& plane, const Eigen::Vector3d& p,
                      const std::string& what, RealTotals& totals) {
  CutOptions options{.cap = true};
  options.region = CutRegion::seed(p);
  const Outcome o = run_cut(in, plane, options);
  if (o.out.result.status != CutStatus::Cut) return;
  const Outcome all = run_cut(in, plane, {.cap = true});
  ++totals.cuts;
  totals.sliced_elsewhere += o.out.result.sections > 1;
  totals.unbounded_new += all.out.result.change.new_vertices.size();
  totals.regional_new += o.out.result.change.new_vertices.size();
  EXPECT_EQ(o.out.result.kept_sections, 1) << what;
  expect_part_of(o.out.result, all.out.result, what);
  const MeshReport report = check_mesh(o.mesh);
  EXPECT_TRUE(report.manifold() && report.oriented()) << what << ": " << report.summary();
  if (o.out.result.capped_loops == o.out.result.loops) {
    EXPECT_TRUE(report.closed()) << what;
    EXPECT_EQ(o.out.pieces.count, 1 + o.out.result.loops) << what;  // genus 0: Jordan
    expect_closed_pieces(in, o.mesh, o.out.pieces, what);
  }
  CutOptions sphere{.cap = true};
  sphere.region = CutRegion::sphere(p, farthest_new_vertex(o.mesh, o.out.result, p) * (1 + 1e-9));
  const Outcome s = run_cut(in, plane, sphere);
  EXPECT_GE(s.out.result.kept_sections, 1) << what;
  EXPECT_LE(farthest_new_vertex(s.mesh, s.out.result, p), sphere.region.radius) << what;
  if (s.out.result.kept_sections == 1) {
    EXPECT_EQ(s.mesh.faces, o.mesh.faces) << what;
  }
}

}  // namespace

TEST(CutRegion, RealModelSeededCuts) {
  // huesitos.fbx (welded: one closed surface, a branching tube on a chain of bones). Planes
  // across every bone a third of the way to its child, and random planes through random
  // vertices, each limited by a seed at its point: one section cut, a part of the unbounded
  // cut, closed pieces counted by Jordan, and a sphere just holding the new vertices
  // (Keep::inside) gives the same cut.
  const std::filesystem::path path =
      std::filesystem::path(CONFORM_ASSIMP_MODELS) / "FBX/huesitos.fbx";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "assimp-testmodels not installed";
  const io::SkinnedModel model = io::load_model(path.string());
  const SkinnedMesh& in = model.mesh;
  const MeshReport input = check_mesh(in);
  ASSERT_TRUE(input.closed() && input.manifold());
  ASSERT_EQ(label_pieces(in).count, 1);
  // Genus 0 (Euler characteristic 2), so that every closed loop separates.
  std::set<std::pair<std::int32_t, std::int32_t>> edges;
  for (const auto& f : in.faces)
    for (int k = 0; k < 3; ++k) edges.insert(std::minmax(f[k], f[(k + 1) % 3]));
  ASSERT_EQ(in.vertex_count() - std::ssize(edges) + in.face_count(), 2);
  RealTotals totals;
  // Joint positions in the bind pose (the rest pose's global versors: the mesh's space).
  const skin::Skeleton& skeleton = model.skeleton;
  std::vector<skin::Versor> global(skeleton.joints.size());
  skin::global_versors(skeleton, skin::Pose::rest(skeleton), global);
  std::vector<std::uint8_t> is_bone(skeleton.joints.size(), 0);
  for (const auto& bone : skeleton.bones) is_bone[static_cast<std::size_t>(bone.joint)] = 1;
  auto origin = [&](std::size_t j) {
    return Eigen::Vector3d(global[j].apply(cga::Vec3<double>::Zero()));
  };
  int bone_cuts = 0;
  for (std::size_t j = 0; j < skeleton.joints.size(); ++j) {
    const std::int32_t parent = skeleton.joints[j].parent;
    if (parent < 0 || !is_bone[static_cast<std::size_t>(parent)]) continue;
    const Eigen::Vector3d from = origin(static_cast<std::size_t>(parent)), to = origin(j);
    if ((to - from).norm() < 1e-6) continue;
    const Eigen::Vector3d p = from + (to - from) / 3;
    const int before = totals.cuts;
    check_seeded_cut(
        in, Plane::from_normal_point(to - from, p), p,
        skeleton.joints[static_cast<std::size_t>(parent)].name + " -> " + skeleton.joints[j].name,
        totals);
    bone_cuts += totals.cuts - before;
  }
  EXPECT_GE(bone_cuts, 3);
  std::mt19937 rng(11);
  std::normal_distribution<double> g;
  std::uniform_int_distribution<std::int32_t> vertex(0, in.vertex_count() - 1);
  for (int trial = 0; trial < 40; ++trial) {
    const Eigen::Vector3d p = in.current.col(vertex(rng));
    check_seeded_cut(in, Plane::from_normal_point(Eigen::Vector3d(g(rng), g(rng), g(rng)), p), p,
                     "trial " + std::to_string(trial), totals);
    if (testing::Test::HasFailure()) return;
  }
  EXPECT_GT(totals.cuts, 30);
  EXPECT_GT(totals.sliced_elsewhere, 3);  // the unbounded plane also cut another branch
  RecordProperty("cuts", totals.cuts);
  RecordProperty("sliced_elsewhere", totals.sliced_elsewhere);
  RecordProperty("unbounded_new_vertices", static_cast<int>(totals.unbounded_new));
  RecordProperty("regional_new_vertices", static_cast<int>(totals.regional_new));
}
