// apply() (topology_change.hpp) against a straightforward reference written here from the
// documented semantics: every array rebuilt from scratch, new vertices computed one by one with
// a map-based weight blend, face slots filled by the three documented steps on a plain vector.
// Removal-only, add-only and mixed changes, chained new vertices, meshes with and without UVs,
// normals and skinning data, random changes, and the adjacency kept against a rebuilt one.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>

#include "conform/mesh/analysis.hpp"
#include "conform/mesh/cut.hpp"
#include "conform/mesh/primitives.hpp"
#include "conform/mesh/topology_change.hpp"
#include "conform/skin/procedural_arm.hpp"

using namespace conform;
using namespace conform::mesh;
using conform::skin::ArmOptions;
using conform::skin::make_arm;

namespace {

SkinnedMesh reference_apply(const SkinnedMesh& in, const TopologyChange& change) {
  const Eigen::Index nv0 = in.vertex_count();
  const auto nnew = static_cast<Eigen::Index>(change.new_vertices.size());
  const bool skin = in.bones.cols() == nv0 && in.weights.cols() == nv0;
  SkinnedMesh out;
  out.rest.resize(3, nv0 + nnew);
  out.current.resize(3, nv0 + nnew);
  if (in.has_uvs()) out.uvs.resize(2, nv0 + nnew);
  if (in.has_normals()) out.normals.resize(3, nv0 + nnew);
  if (skin)
    out.bones.resize(kMaxInfluences, nv0 + nnew), out.weights.resize(kMaxInfluences, nv0 + nnew);
  for (Eigen::Index v = 0; v < nv0; ++v) {
    out.rest.col(v) = in.rest.col(v);
    out.current.col(v) = in.current.col(v);
    if (in.has_uvs()) out.uvs.col(v) = in.uvs.col(v);
    if (in.has_normals()) out.normals.col(v) = in.normals.col(v);
    if (skin) out.bones.col(v) = in.bones.col(v), out.weights.col(v) = in.weights.col(v);
  }
  for (Eigen::Index i = 0; i < nnew; ++i) {
    const NewVertex& nv = change.new_vertices[static_cast<std::size_t>(i)];
    const Eigen::Index o = nv0 + i;
    out.rest.col(o).setZero();
    out.current.col(o) = nv.displacement;
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    if (in.has_uvs()) out.uvs.col(o).setZero();
    std::map<std::int32_t, double> blend;
    for (int k = 0; k < 3; ++k) {
      const std::int32_t p = nv.parents[static_cast<std::size_t>(k)];
      if (p < 0) continue;
      const double c = nv.coefficients[static_cast<std::size_t>(k)];
      out.rest.col(o) += c * out.rest.col(p);
      out.current.col(o) += c * out.current.col(p);
      if (in.has_uvs()) out.uvs.col(o) += c * out.uvs.col(p);
      if (in.has_normals()) normal += c * out.normals.col(p);
      if (skin && c != 0)
        for (int j = 0; j < kMaxInfluences; ++j)
          if (out.weights(j, p) != 0) blend[out.bones(j, p)] += c * out.weights(j, p);
    }
    if (in.has_normals())
      out.normals.col(o) = normal.norm() > 1e-300 ? Eigen::Vector3d(normal.normalized())
                                                  : Eigen::Vector3d(out.normals.col(nv.parents[0]));
    if (skin) {
      std::vector<std::pair<std::int32_t, double>> sorted(blend.begin(), blend.end());
      std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) {
        return a.second > b.second || (a.second == b.second && a.first < b.first);
      });
      sorted.resize(std::min<std::size_t>(sorted.size(), kMaxInfluences));
      double sum = 0;
      for (const auto& [bone, w] : sorted) sum += std::max(0.0, w);
      for (int j = 0; j < kMaxInfluences; ++j) {
        const bool keep = j < static_cast<int>(sorted.size()) && sum > 0 &&
                          sorted[static_cast<std::size_t>(j)].second > 0;
        out.bones(j, o) = keep ? sorted[static_cast<std::size_t>(j)].first : 0;
        out.weights(j, o) = keep ? sorted[static_cast<std::size_t>(j)].second / sum : 0;
      }
    }
  }
  // Faces: the three documented steps.
  out.faces = in.faces;
  const auto& removed = change.removed_faces;
  const auto& added = change.added_faces;
  std::size_t k = 0;
  for (; k < removed.size() && k < added.size(); ++k)
    out.faces[static_cast<std::size_t>(removed[k])] = added[k];
  for (std::size_t a = k; a < added.size(); ++a) out.faces.push_back(added[a]);
  for (std::size_t r = removed.size(); r-- > k;) {
    out.faces[static_cast<std::size_t>(removed[r])] = out.faces.back();
    out.faces.pop_back();
  }
  return out;
}

void expect_same(const SkinnedMesh& got, const SkinnedMesh& want, const std::string& what) {
  ASSERT_EQ(got.vertex_count(), want.vertex_count()) << what;
  ASSERT_EQ(got.faces, want.faces) << what;
  EXPECT_LE((got.rest - want.rest).cwiseAbs().maxCoeff(), 1e-12) << what;
  EXPECT_LE((got.current - want.current).cwiseAbs().maxCoeff(), 1e-12) << what;
  ASSERT_EQ(got.uvs.cols(), want.uvs.cols()) << what;
  if (want.uvs.size() > 0) {
    EXPECT_LE((got.uvs - want.uvs).cwiseAbs().maxCoeff(), 1e-12) << what;
  }
  ASSERT_EQ(got.normals.cols(), want.normals.cols()) << what;
  if (want.normals.size() > 0) {
    EXPECT_LE((got.normals - want.normals).cwiseAbs().maxCoeff(), 1e-12) << what;
  }
  ASSERT_EQ(got.bones.cols(), want.bones.cols()) << what;
  if (want.bones.size() > 0) {
    EXPECT_TRUE((got.bones.array() == want.bones.array()).all()) << what;
    EXPECT_LE((got.weights - want.weights).cwiseAbs().maxCoeff(), 1e-12) << what;
  }
}

// A small arm (normals, UVs and weights filled), posed so that current differs from rest.
SkinnedMesh attributed_arm() {
  SkinnedMesh m = make_arm(ArmOptions{.segments = 12, .rings = 20}).mesh;
  m.current = 1.1 * m.rest;
  m.current.row(0).array() += 0.05;
  return m;
}

// A random well-formed change: removed faces, new vertices of every kind (some with earlier
// new vertices as parents), added faces over old and new vertices.
TopologyChange random_change(const SkinnedMesh& m, std::mt19937& rng, int removals, int news,
                             int additions) {
  TopologyChange c;
  c.base_vertex_count = m.vertex_count();
  c.base_face_count = m.face_count();
  std::set<std::int32_t> removed;
  std::uniform_int_distribution<std::int32_t> face(0, m.face_count() - 1);
  while (static_cast<int>(removed.size()) < removals) removed.insert(face(rng));
  c.removed_faces.assign(removed.begin(), removed.end());
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < news; ++i) {
    std::uniform_int_distribution<std::int32_t> vertex(0, m.vertex_count() + i - 1);
    const std::int32_t a = vertex(rng), b = vertex(rng), d = vertex(rng);
    const double t = u(rng), p = u(rng) * 0.5, q = u(rng) * 0.5;
    switch (i % 3) {
      case 0:
        c.new_vertices.push_back(NewVertex::on_edge(a, b, t));
        break;
      case 1:
        c.new_vertices.push_back(NewVertex::in_face(a, b, d, p, q, 1 - p - q));
        break;
      default:
        c.new_vertices.push_back(NewVertex::duplicate(a));
    }
    if (i % 5 == 0) c.new_vertices.back().displacement = Eigen::Vector3d(u(rng), u(rng), u(rng));
  }
  std::uniform_int_distribution<std::int32_t> any(0, m.vertex_count() + news - 1);
  while (static_cast<int>(c.added_faces.size()) < additions) {
    const Face f{any(rng), any(rng), any(rng)};
    if (f[0] != f[1] && f[1] != f[2] && f[0] != f[2]) c.added_faces.push_back(f);
  }
  EXPECT_EQ(c.validate(), "");
  return c;
}

void check(const SkinnedMesh& in, const TopologyChange& change, const std::string& what) {
  SkinnedMesh got = in;
  apply(got, change);
  expect_same(got, reference_apply(in, change), what);
  // Where every surviving base face went.
  for (std::int32_t f = 0; f < in.face_count(); ++f) {
    const std::int32_t to = change.face_after(f);
    if (std::binary_search(change.removed_faces.begin(), change.removed_faces.end(), f)) {
      EXPECT_EQ(to, -1) << what;
    } else {
      ASSERT_GE(to, 0) << what;
      EXPECT_EQ(got.faces[static_cast<std::size_t>(to)], in.faces[static_cast<std::size_t>(f)])
          << what << " face " << f;
    }
  }
}

}  // namespace

TEST(Apply, RemovalOnlyAddOnlyAndMixedMatchTheReference) {
  const SkinnedMesh arm = attributed_arm();
  std::mt19937 rng(5);
  struct Shape {
    int removals, news, additions;
    const char* what;
  };
  for (const Shape s :
       {Shape{40, 0, 0, "removal only"}, Shape{0, 30, 50, "add only"},
        Shape{0, 0, 25, "faces added over old vertices"}, Shape{0, 20, 0, "vertices only"},
        Shape{30, 20, 10, "more removed"}, Shape{10, 20, 30, "more added"},
        Shape{25, 12, 25, "as many"}, Shape{1, 1, 1, "one of each"}})
    for (int trial = 0; trial < 20; ++trial)
      check(arm, random_change(arm, rng, s.removals, s.news, s.additions),
            std::string(s.what) + " trial " + std::to_string(trial));
}

TEST(Apply, RemovingTheLastFacesAndEveryFace) {
  const SkinnedMesh arm = attributed_arm();
  TopologyChange c;
  c.base_vertex_count = arm.vertex_count();
  c.base_face_count = arm.face_count();
  for (std::int32_t f = arm.face_count() - 5; f < arm.face_count(); ++f)
    c.removed_faces.push_back(f);
  check(arm, c, "the last five");
  c.removed_faces.clear();
  for (std::int32_t f = 0; f < arm.face_count(); f += 2) c.removed_faces.push_back(f);
  check(arm, c, "every other face");
  c.removed_faces.resize(static_cast<std::size_t>(arm.face_count()));
  for (std::int32_t f = 0; f < arm.face_count(); ++f)
    c.removed_faces[static_cast<std::size_t>(f)] = f;
  check(arm, c, "every face");
}

TEST(Apply, MeshesWithoutOptionalArrays) {
  std::mt19937 rng(11);
  SkinnedMesh bare = make_icosphere(2);
  bare.uvs.resize(2, 0);
  bare.normals.resize(3, 0);
  for (int trial = 0; trial < 20; ++trial)
    check(bare, random_change(bare, rng, 8, 10, 12), "no uvs/normals " + std::to_string(trial));
  SkinnedMesh unskinned = bare;
  unskinned.bones.resize(kMaxInfluences, 0);
  unskinned.weights.resize(kMaxInfluences, 0);
  for (int trial = 0; trial < 20; ++trial)
    check(unskinned, random_change(unskinned, rng, 8, 10, 12), "no skin " + std::to_string(trial));
}

TEST(Apply, AdjacencyKeptEqualsRebuilt) {
  // Real changes (cuts, with and without caps) applied one after another keep the adjacency
  // equal to one rebuilt from scratch, and the mesh equal to the reference's.
  SkinnedMesh m = attributed_arm();
  Adjacency adjacency(m);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  int cuts = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const Eigen::Vector3d lo = m.current.rowwise().minCoeff(), hi = m.current.rowwise().maxCoeff();
    const Eigen::Vector3d point =
        0.5 * (lo + hi) + 0.4 * (hi - lo).cwiseProduct(Eigen::Vector3d(u(rng), u(rng), u(rng)));
    const auto plane =
        cga::Plane<double>::from_normal_point(Eigen::Vector3d(u(rng), u(rng), u(rng)), point);
    const CutResult r = compute_cut(m, plane, {.cap = trial % 2 == 0});
    if (r.status != CutStatus::Cut) continue;
    ++cuts;
    const SkinnedMesh want = reference_apply(m, r.change);
    apply(m, r.change, &adjacency);
    expect_same(m, want, "cut " + std::to_string(trial));
    const Adjacency fresh(m);
    ASSERT_EQ(adjacency.face_count(), fresh.face_count());
    for (std::int32_t h = 0; h < 3 * m.face_count(); ++h)
      ASSERT_EQ(adjacency.twin(h), fresh.twin(h)) << "cut " << trial << " half-edge " << h;
  }
  EXPECT_GT(cuts, 10);
}

TEST(Apply, InvalidChangesLeaveTheMeshUntouched) {
  const SkinnedMesh arm = attributed_arm();
  SkinnedMesh m = arm;
  Adjacency adjacency(m);
  TopologyChange c;
  c.base_vertex_count = arm.vertex_count();
  c.base_face_count = arm.face_count();
  c.removed_faces = {5, 3};  // not increasing
  EXPECT_THROW(apply(m, c, &adjacency), std::invalid_argument);
  c.removed_faces = {3};
  c.added_faces = {{0, 1, arm.vertex_count()}};  // a vertex that does not exist
  EXPECT_THROW(apply(m, c, &adjacency), std::invalid_argument);
  c.base_face_count += 1;  // computed for another mesh
  c.added_faces.clear();
  EXPECT_THROW(apply(m, c, &adjacency), std::invalid_argument);
  expect_same(m, arm, "after the failed applies");
  EXPECT_EQ(adjacency.face_count(), arm.face_count());
}
