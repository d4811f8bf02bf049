#include "conform/mesh/face_index.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <iterator>
#include <random>

#include "conform/cga/plane.hpp"
#include "conform/mesh/analysis.hpp"
#include "conform/mesh/cut.hpp"
#include "conform/mesh/drill.hpp"
#include "conform/mesh/primitives.hpp"
#include "conform/mesh/refine.hpp"
#include "conform/mesh/tear.hpp"
#include "conform/skin/procedural_arm.hpp"

using namespace conform::mesh;
using conform::skin::make_arm;

namespace {

struct Bounds {
  Eigen::Vector3d lo, hi;
};
Bounds bounds(const SkinnedMesh& m) {
  return {m.current.rowwise().minCoeff(), m.current.rowwise().maxCoeff()};
}

// Random segments over the mesh's box grown by 20 %: long ones across it, short ones near the
// surface (from a random vertex), and some with axis-parallel directions (zero components).
std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> random_segments(const SkinnedMesh& m,
                                                                         int count,
                                                                         std::mt19937& rng) {
  const Bounds b = bounds(m);
  const double diag = (b.hi - b.lo).norm();
  const Eigen::Vector3d c = 0.5 * (b.lo + b.hi),
                        half = 0.6 * (b.hi - b.lo) + Eigen::Vector3d::Constant(0.1 * diag);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_int_distribution<Eigen::Index> vertex(0, m.current.cols() - 1);
  auto in_box = [&] {
    return Eigen::Vector3d(c.x() + half.x() * u(rng), c.y() + half.y() * u(rng),
                           c.z() + half.z() * u(rng));
  };
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> out;
  for (int i = 0; i < count; ++i) {
    Eigen::Vector3d p = in_box(), q = in_box();
    if (i % 3 == 1) {  // short, near the surface
      p = m.current.col(vertex(rng)) + 0.02 * diag * Eigen::Vector3d(u(rng), u(rng), u(rng));
      q = p + 0.05 * diag * Eigen::Vector3d(u(rng), u(rng), u(rng));
    } else if (i % 3 == 2) {  // along a coordinate axis (or in a coordinate plane)
      const int k = i % 2 == 0 ? 0 : (i / 3) % 3;
      q = p;
      q[k] = c[k] - (p[k] - c[k]);
      if (i % 2 == 0) q[(k + 1) % 3] += 0.1 * diag * u(rng);
    }
    out.emplace_back(p, q);
  }
  return out;
}

// The index against the brute-force scan: same faces, same parameters; the first hit too.
// Returns the number of hits seen.
int expect_same_as_scan(const FaceIndex& index, const SkinnedMesh& m,
                        const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& segments,
                        const std::string& what) {
  int hits = 0, bad = 0;
  std::vector<SegmentHit> got;
  for (std::size_t i = 0; i < segments.size() && bad < 3; ++i) {
    const auto& [p, q] = segments[i];
    const auto want = scan_segment_hits(m, p, q);
    index.segment_hits(m, p, q, got);
    hits += static_cast<int>(want.size());
    bool same = want.size() == got.size();
    for (std::size_t k = 0; same && k < want.size(); ++k)
      same = want[k].face == got[k].face && want[k].t == got[k].t && want[k].bary == got[k].bary;
    const SegmentHit first = index.first_hit(m, p, q);
    same = same && first.face == (want.empty() ? -1 : want.front().face);
    if (!same) {
      ++bad;
      ADD_FAILURE() << what << ": segment " << i << " scan " << want.size() << " hits, index "
                    << got.size() << ", first " << first.face;
    }
  }
  return hits;
}

}  // namespace

TEST(FaceIndex, EmptyMeshHasNoHits) {
  SkinnedMesh m;
  FaceIndex index(m);
  EXPECT_EQ(index.node_count(), 0);
  EXPECT_TRUE(index.segment_hits(m, {0, 0, 0}, {1, 1, 1}).empty());
  EXPECT_EQ(index.first_hit(m, {0, 0, 0}, {1, 1, 1}).face, -1);
  EXPECT_EQ(index.validate(m), "");
}

TEST(FaceIndex, MatchesTheScanOnRandomSegments) {
  std::mt19937 rng(11);
  const std::vector<std::pair<std::string, SkinnedMesh>> meshes = {
      {"arm", make_arm(1).mesh}, {"sphere", make_icosphere(4)}, {"sheet", make_sheet(40, 40)}};
  for (const auto& [name, m] : meshes) {
    const FaceIndex index(m);
    EXPECT_EQ(index.validate(m), "") << name;
    EXPECT_EQ(index.face_count(), m.face_count());
    // Balanced: about log2(F / 4) + 1 levels.
    EXPECT_LE(index.depth(), static_cast<int>(std::log2(m.face_count() / 4.0)) + 3) << name;
    const int hits = expect_same_as_scan(index, m, random_segments(m, 3000, rng), name);
    EXPECT_GT(hits, 500) << name << ": the segments must actually meet the surface";
  }
}

TEST(FaceIndex, SegmentsThroughVerticesAndEdgesOfASheet) {
  // Vertical segments exactly through grid vertices and edge midpoints: every face sharing
  // the vertex or edge is hit (closed bounds), by the index as by the scan.
  const SkinnedMesh m = make_sheet(10, 10);
  const FaceIndex index(m);
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> segments;
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j <= 20; ++j) {
      const double x = -0.5 + 0.05 * i, y = -0.5 + 0.05 * j;
      segments.emplace_back(Eigen::Vector3d(x, y, -1), Eigen::Vector3d(x, y, 1));
    }
  expect_same_as_scan(index, m, segments, "grid");
  // Through the middle vertex (0, 0): six faces meet there.
  EXPECT_EQ(index.segment_hits(m, {0, 0, -1}, {0, 0, 1}).size(),
            scan_segment_hits(m, {0, 0, -1}, {0, 0, 1}).size());
  EXPECT_GE(index.segment_hits(m, {0, 0, -1}, {0, 0, 1}).size(), 6u);
}

TEST(FaceIndex, RefitFollowsMovedPositions) {
  std::mt19937 rng(12);
  SkinnedMesh m = make_arm(1).mesh;
  FaceIndex index(m);
  const int nodes = index.node_count();
  // Bend and shift the arm: a rotation about x growing with z, plus a translation.
  for (Eigen::Index v = 0; v < m.current.cols(); ++v) {
    const Eigen::Vector3d x = m.current.col(v);
    const double a = 2.0 * x.z();
    m.current.col(v) = Eigen::Vector3d(x.x() + 0.3, std::cos(a) * x.y() - std::sin(a) * x.z(),
                                       std::sin(a) * x.y() + std::cos(a) * x.z());
  }
  index.mark_moved();
  EXPECT_FALSE(index.fitted());
  index.ensure_fitted(m);
  EXPECT_TRUE(index.fitted());
  EXPECT_EQ(index.node_count(), nodes) << "a refit keeps the tree";
  EXPECT_EQ(index.validate(m), "");
  EXPECT_GT(expect_same_as_scan(index, m, random_segments(m, 2000, rng), "moved arm"), 500);
}

TEST(FaceIndex, UpdatedByTopologyChanges) {
  // Refinements, a cut, drills and a tear applied one after the other, the index updated for
  // each: it stays sound and answers as the scan does on the changed mesh.
  std::mt19937 rng(13);
  SkinnedMesh m = make_arm(1).mesh;
  Adjacency adj(m);
  FaceIndex index(m);
  auto check = [&](const std::string& what) {
    ASSERT_EQ(index.validate(m), "") << what;
    expect_same_as_scan(index, m, random_segments(m, 400, rng), what);
  };
  // Refine a band of edges (faces appended and refilled).
  std::vector<EdgeSplit> splits;
  for (std::int32_t f = 0; f < m.face_count(); f += 7) {
    const Face& t = m.faces[static_cast<std::size_t>(f)];
    splits.push_back({t[0], t[1], 0.4});
  }
  const TopologyChange refine = split_edges(m, adj, splits);
  apply(m, refine, &adj);
  index.update(m, refine);
  check("refined");
  // A cut separates the hand (changes with faces moved by swap-with-last as well).
  const auto plane = conform::cga::Plane<double>::from_normal_point({0, 0.2, 1}, {0, 0, 0.5});
  const CutResult cut = compute_cut(m, plane);
  apply(m, cut.change, &adj);
  index.update(m, cut.change);
  check("cut");
  // A drill through both walls with a tube, and a tear, given the index: they update it.
  DrillOptions tube;
  tube.tube = true;
  const DrillResult d = drill(m, adj, index, {{0, -0.2, 0.42}, {0, 0.2, 0.42}, 0.01}, tube);
  EXPECT_EQ(d.holes, 2) << d.message;
  check("drilled");
  Tear tear(m, adj, index);
  for (int i = 0; i < 40; ++i) {
    const double z = 0.1 + 0.15 * i / 39.0, a = 0.3 + 0.4 * i / 39.0;
    tear.advance({double(i), {0, 0, z}, {0.2 * std::cos(a), 0.2 * std::sin(a), z}});
  }
  EXPECT_GT(tear.steps(), 30) << tear.message();
  check("torn");
  // Opening moves positions: the tear marks the index, a refit brings it back.
  tear.open(0.01);
  EXPECT_FALSE(index.fitted());
  index.refit(m);
  check("opened");
  // A change computed for another mesh is refused.
  TopologyChange stale = refine;
  EXPECT_THROW(index.update(m, stale), std::invalid_argument);
}

TEST(FaceIndex, ManyLocalChangesKeepQueriesExact) {
  // Repeated refinement in one spot grows the tree locally (leaf splits); queries stay exact.
  std::mt19937 rng(14);
  SkinnedMesh m = make_sheet(8, 8);
  Adjacency adj(m);
  FaceIndex index(m);
  for (int round = 0; round < 6; ++round) {
    std::vector<EdgeSplit> splits;
    for (std::int32_t f = 0; f < m.face_count(); ++f) {
      const Face& t = m.faces[static_cast<std::size_t>(f)];
      const Eigen::Vector3d c =
          (m.current.col(t[0]) + m.current.col(t[1]) + m.current.col(t[2])) / 3;
      if (c.head<2>().norm() < 0.15)
        for (int k = 0; k < 3; ++k) splits.push_back({t[k], t[(k + 1) % 3], 0.5});
    }
    const TopologyChange ch = split_edges(m, adj, splits);
    apply(m, ch, &adj);
    index.update(m, ch);
  }
  EXPECT_GT(m.face_count(), 1000);
  EXPECT_EQ(index.validate(m), "");
  expect_same_as_scan(index, m, random_segments(m, 1000, rng), "refined sheet");
}

TEST(FaceIndex, SlotBookkeepingOfRandomChanges) {
  // Changes that remove random faces (often at the end of the face list, where apply() pops
  // and swaps) and put back a random part of them, in random order: the index follows the
  // slots exactly.
  std::mt19937 rng(15);
  SkinnedMesh m = make_icosphere(3);
  FaceIndex index(m);
  for (int round = 0; round < 60 && m.face_count() > 40; ++round) {
    std::vector<std::int32_t> removed;
    std::uniform_int_distribution<std::int32_t> any(0, m.face_count() - 1);
    for (int i = 0; i < 12; ++i) removed.push_back(round % 2 ? any(rng) : m.face_count() - 1 - i);
    std::sort(removed.begin(), removed.end());
    removed.erase(std::unique(removed.begin(), removed.end()), removed.end());
    TopologyChange ch;
    ch.base_vertex_count = m.vertex_count();
    ch.base_face_count = m.face_count();
    ch.removed_faces = removed;
    std::shuffle(removed.begin(), removed.end(), rng);
    const auto keep = std::uniform_int_distribution<std::size_t>(0, removed.size())(rng);
    for (std::size_t k = 0; k < keep; ++k)
      ch.added_faces.push_back(m.faces[static_cast<std::size_t>(removed[k])]);
    apply(m, ch);
    index.update(m, ch);
    ASSERT_EQ(index.validate(m), "") << round;
  }
  expect_same_as_scan(index, m, random_segments(m, 1000, rng), "after random removals");
}

namespace {

// The longest root-to-leaf path a batch of `added` faces may add: the path down to the leaf
// that takes them, one level for the new parent, and a built subtree (log2(added / 4) + 1
// levels, +1 for rounding); one-by-one insertions near their hints split leaves (a few levels).
int depth_bound(int before, std::size_t added) {
  return before + static_cast<int>(std::ceil(std::log2(std::max<double>(added, 4) / 4.0))) + 4;
}

// The vertex of `m` nearest to direction `d`.
std::int32_t nearest_vertex(const SkinnedMesh& m, const Eigen::Vector3d& d) {
  Eigen::Index best = 0;
  (m.current.colwise() - d).colwise().squaredNorm().minCoeff(&best);
  return static_cast<std::int32_t>(best);
}

}  // namespace

TEST(FaceIndex, LargeBatchInsideAClosedMeshStaysExact) {
  // A rings-like tube wall of new vertices inside a sphere (radius 0.4, far from every surface
  // leaf), added in ONE change together with surface faces put back in their slots: the index
  // stays sound, exact, and not much deeper.
  std::mt19937 rng(16);
  SkinnedMesh m = make_icosphere(4);
  FaceIndex index(m);
  const int depth_before = index.depth();
  TopologyChange ch;
  ch.base_vertex_count = m.vertex_count();
  ch.base_face_count = m.face_count();
  for (std::int32_t f = 0; f < m.face_count(); f += 97) ch.removed_faces.push_back(f);
  for (auto f : ch.removed_faces) ch.added_faces.push_back(m.faces[static_cast<std::size_t>(f)]);
  constexpr int kAround = 24, kRings = 12;
  for (int j = 0; j < kRings; ++j)
    for (int i = 0; i < kAround; ++i) {
      const double z = -0.6 + 1.2 * j / (kRings - 1), a = 2 * M_PI * i / kAround,
                   rho = std::sqrt(1 - z * z);
      const Eigen::Vector3d d(rho * std::cos(a), rho * std::sin(a), z);
      ch.new_vertices.push_back(
          NewVertex::on_edge(nearest_vertex(m, d), nearest_vertex(m, -d), 0.3));
    }
  auto vid = [&](int j, int i) { return ch.base_vertex_count + j * kAround + (i % kAround); };
  for (int j = 0; j + 1 < kRings; ++j)
    for (int i = 0; i < kAround; ++i) {
      ch.added_faces.push_back({vid(j, i), vid(j, i + 1), vid(j + 1, i + 1)});
      ch.added_faces.push_back({vid(j, i), vid(j + 1, i + 1), vid(j + 1, i)});
    }
  apply(m, ch);
  index.update(m, ch);
  ASSERT_EQ(index.validate(m), "");
  EXPECT_LE(index.depth(), depth_bound(depth_before, ch.added_faces.size()))
      << "before " << depth_before;
  // Segments across the sphere, through the tube, and along its axis.
  auto segments = random_segments(m, 3000, rng);
  for (int i = 0; i < 200; ++i) {
    const double z = -0.7 + 1.4 * i / 199.0;
    segments.emplace_back(Eigen::Vector3d(-1.2, 0.01 * i, z), Eigen::Vector3d(1.2, -0.01 * i, z));
  }
  EXPECT_GT(expect_same_as_scan(index, m, segments, "tube in a sphere"), 1000);
  // The same change without the faces put back: no hints at all (pure addition).
  SkinnedMesh m2 = make_icosphere(4);
  FaceIndex index2(m2);
  TopologyChange add = ch;
  add.removed_faces.clear();
  add.added_faces.erase(
      add.added_faces.begin(),
      add.added_faces.begin() + static_cast<std::ptrdiff_t>(ch.removed_faces.size()));
  apply(m2, add);
  index2.update(m2, add);
  ASSERT_EQ(index2.validate(m2), "");
  EXPECT_LE(index2.depth(), depth_bound(depth_before, add.added_faces.size()));
  EXPECT_GT(expect_same_as_scan(index2, m2, segments, "tube added alone"), 1000);
}

TEST(FaceIndex, RandomLargeBatchesStayExact) {
  // Rounds of changes that remove random faces and add many random ones (triangles between
  // random vertices, crossing the sphere's inside), some small, most large: the index follows
  // exactly, and each round deepens it by no more than a built subtree would.
  std::mt19937 rng(17);
  SkinnedMesh m = make_icosphere(3);
  FaceIndex index(m);
  const std::size_t sizes[] = {3000, 17, 5, 400, 1200, 16, 64};
  for (std::size_t round = 0; round < std::size(sizes); ++round) {
    const int depth_before = index.depth();
    TopologyChange ch;
    ch.base_vertex_count = m.vertex_count();
    ch.base_face_count = m.face_count();
    std::uniform_int_distribution<std::int32_t> any_face(0, m.face_count() - 1);
    std::uniform_int_distribution<std::int32_t> any_vertex(0, m.vertex_count() - 1);
    for (int i = 0; i < 30; ++i) ch.removed_faces.push_back(any_face(rng));
    std::sort(ch.removed_faces.begin(), ch.removed_faces.end());
    ch.removed_faces.erase(std::unique(ch.removed_faces.begin(), ch.removed_faces.end()),
                           ch.removed_faces.end());
    while (ch.added_faces.size() < sizes[round]) {
      const Face t{any_vertex(rng), any_vertex(rng), any_vertex(rng)};
      if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) ch.added_faces.push_back(t);
    }
    apply(m, ch);
    index.update(m, ch);
    ASSERT_EQ(index.validate(m), "") << round;
    EXPECT_LE(index.depth(), depth_bound(depth_before, ch.added_faces.size())) << round;
    expect_same_as_scan(index, m, random_segments(m, 600, rng), "round " + std::to_string(round));
  }
}

TEST(FaceIndex, DrillWithTubeRingsKeepsTheIndexExact) {
  // The drill's one change with tube walls and rings (~1,300 faces inside the limb at the
  // paper's size): sound, exact, and the tree only a subtree's depth deeper.
  std::mt19937 rng(18);
  SkinnedMesh m = make_arm(1).mesh;
  Adjacency adj(m);
  FaceIndex index(m);
  const int depth_before = index.depth();
  const std::int32_t faces_before = m.face_count();
  DrillOptions o;
  o.tube = true;
  o.tube_ring_spacing = 2;
  const DrillResult d = drill(m, adj, index, {{0, -0.2, 0.42}, {0, 0.2, 0.42}, 0.01}, o);
  ASSERT_EQ(d.tubes, 1) << d.message;
  ASSERT_EQ(index.validate(m), "");
  const auto added = static_cast<std::size_t>(m.face_count() - faces_before);
  EXPECT_GT(added, 500u);
  EXPECT_LE(index.depth(), depth_bound(depth_before, added)) << "before " << depth_before;
  RecordProperty("depth", std::to_string(depth_before) + " -> " + std::to_string(index.depth()) +
                              " (" + std::to_string(faces_before) + " -> " +
                              std::to_string(m.face_count()) + " faces)");
  auto segments = random_segments(m, 2000, rng);
  for (int i = 0; i < 200; ++i) {  // along and across the drill's axis
    const double s = 0.004 * (i % 10) - 0.02, z = 0.42 + 0.0002 * (i / 10);
    segments.emplace_back(Eigen::Vector3d(s, -0.3, z), Eigen::Vector3d(-s, 0.3, z + 0.001 * s));
    segments.emplace_back(Eigen::Vector3d(-0.02, 0.01 * (i % 40) - 0.2, z),
                          Eigen::Vector3d(0.02, 0.01 * (i % 40) - 0.2, z));
  }
  EXPECT_GT(expect_same_as_scan(index, m, segments, "rings drill"), 500);
}
