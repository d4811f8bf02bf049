// mesh::SplitSearch against mesh::label_pieces: every change of random cuts, tears and drills
// is searched as the plugin searches it (the removed faces as they were, then the added faces'
// vertices and the new vertices as seeds), and the groups it reports must be what a full
// labelling of the mesh after the change says: each complete group a whole piece, and the open
// group the one piece left of its body.
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "conform/mesh/adjacency.hpp"
#include "conform/mesh/analysis.hpp"
#include "conform/mesh/cut.hpp"
#include "conform/mesh/drill.hpp"
#include "conform/mesh/primitives.hpp"
#include "conform/mesh/split_search.hpp"
#include "conform/mesh/tear.hpp"
#include "conform/mesh/topology_change.hpp"

using namespace conform;
using namespace conform::mesh;

namespace {

// Per vertex: the piece of its first face, −1 for a vertex without faces.
std::vector<std::int32_t> vertex_pieces(const SkinnedMesh& m) {
  const Pieces pieces = label_pieces(m);
  std::vector<std::int32_t> out(static_cast<std::size_t>(m.vertex_count()), -1);
  for (std::size_t f = 0; f < m.faces.size(); ++f)
    for (const auto v : m.faces[f])
      if (out[static_cast<std::size_t>(v)] < 0)
        out[static_cast<std::size_t>(v)] = pieces.face_piece[f];
  return out;
}

struct Checked {
  int changes = 0, complete = 0, open = 0;
};

// Applies `change` to `m` (which it was computed for), searching it, and checks the search.
void apply_and_check(SkinnedMesh& m, const TopologyChange& change, SplitSearch& search,
                     const std::string& what, Checked& checked) {
  std::vector<std::int32_t> body = vertex_pieces(m);  // the bodies before the change
  const std::vector<Face> old_faces = m.faces;
  apply(m, change);
  const auto total = static_cast<std::size_t>(m.vertex_count());
  body.resize(total, -1);
  std::vector<std::vector<std::int32_t>> vertex_faces(total);
  for (std::size_t f = 0; f < m.faces.size(); ++f)
    for (const auto v : m.faces[f])
      vertex_faces[static_cast<std::size_t>(v)].push_back(std::int32_t(f));

  search.begin(std::int32_t(total));
  for (const auto f : change.removed_faces) search.seed_removed_face(old_faces[std::size_t(f)]);
  for (const auto& tri : change.added_faces)
    for (const auto v : tri) search.seed(v);
  for (std::int32_t i = 0; i < std::int32_t(change.new_vertices.size()); ++i)
    search.seed(change.base_vertex_count + i);
  search.run({m.faces, vertex_faces, body, change.base_vertex_count});

  const std::vector<std::int32_t> after = vertex_pieces(m);
  const std::int32_t piece_count = label_pieces(m).count;
  std::vector<std::int32_t> piece_size(static_cast<std::size_t>(piece_count), 0);
  for (const auto p : after)
    if (p >= 0) ++piece_size[static_cast<std::size_t>(p)];
  ++checked.changes;
  // Every seed that keeps faces is reached.
  for (const auto v : search.seeds())
    if (!vertex_faces[static_cast<std::size_t>(v)].empty()) {
      ASSERT_NE(search.group_of(v), SplitSearch::kUnreached) << what << ": seed " << v;
    }
  // Each complete group is one whole piece (its vertices once each).
  std::vector<std::uint8_t> reached(static_cast<std::size_t>(piece_count), 0);
  const auto& groups = search.pieces();
  for (std::size_t g = 0; g < groups.size(); ++g) {
    ASSERT_FALSE(groups[g].empty()) << what;
    const std::int32_t p = after[static_cast<std::size_t>(groups[g][0])];
    ASSERT_GE(p, 0) << what;
    for (const auto v : groups[g]) {
      ASSERT_EQ(after[static_cast<std::size_t>(v)], p)
          << what << ": group " << g << " spans pieces";
      ASSERT_EQ(search.group_of(v), std::int32_t(g)) << what;
    }
    ASSERT_EQ(std::int32_t(groups[g].size()), piece_size[static_cast<std::size_t>(p)])
        << what << ": group " << g << " is not its whole piece";
    ASSERT_FALSE(reached[static_cast<std::size_t>(p)]) << what << ": two groups, one piece";
    reached[static_cast<std::size_t>(p)] = 1;
    ++checked.complete;
  }
  // The open group: one piece, of vertices of the open body (or new ones), that holds every
  // vertex of that body the complete groups do not.
  std::int32_t open_piece = -1;
  for (std::size_t v = 0; v < total; ++v) {
    if (search.group_of(std::int32_t(v)) != SplitSearch::kOpen) continue;
    ASSERT_GE(search.open_body(), 0) << what;
    if (open_piece < 0) open_piece = after[v];
    ASSERT_EQ(after[v], open_piece) << what << ": the open group spans pieces";
    if (body[v] >= 0) {
      ASSERT_EQ(body[v], search.open_body()) << what;
    }
  }
  if (open_piece >= 0) {
    ASSERT_FALSE(reached[static_cast<std::size_t>(open_piece)]) << what;
    ++checked.open;
  }
  for (std::size_t v = 0; v < total; ++v) {
    if (vertex_faces[v].empty() || search.group_of(std::int32_t(v)) != SplitSearch::kUnreached)
      continue;
    if (body[v] >= 0 && body[v] == search.open_body()) {
      ASSERT_EQ(after[v], open_piece) << what << ": vertex " << v << " left its body's rest";
    } else {
      ASSERT_FALSE(after[v] == open_piece || reached[static_cast<std::size_t>(after[v])])
          << what << ": unreached vertex " << v << " in a searched piece";
    }
  }
  search.clear();
}

Eigen::Vector3d random_point(std::mt19937& rng, const SkinnedMesh& m) {
  const Eigen::Vector3d lo = m.current.rowwise().minCoeff(), hi = m.current.rowwise().maxCoeff();
  std::uniform_real_distribution<double> u(0, 1);
  return lo + (hi - lo).cwiseProduct(Eigen::Vector3d(u(rng), u(rng), u(rng)));
}

Eigen::Vector3d random_direction(std::mt19937& rng) {
  std::normal_distribution<double> g;
  return Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
}

}  // namespace

TEST(SplitSearch, RandomCutsMatchLabelPieces) {
  std::mt19937 rng(14);
  const std::vector<std::pair<std::string, SkinnedMesh>> models = {
      {"sheet", make_sheet(24, 16)},
      {"cylinder", make_cylinder(24, 16, 0.2, 1.0)},
      {"icosphere", make_icosphere(2)}};
  Checked checked;
  SplitSearch search;
  for (const auto& [name, model] : models)
    for (int trial = 0; trial < 12; ++trial) {
      SkinnedMesh m = model;
      for (int k = 0; k < 3; ++k) {  // several cuts: later ones meet several bodies
        const auto plane =
            cga::Plane<double>::from_normal_point(random_direction(rng), random_point(rng, m));
        const CutResult r = compute_cut(m, plane, {.cap = (k % 2) == 1});
        if (r.status != CutStatus::Cut) continue;
        apply_and_check(m, r.change, search,
                        name + " trial " + std::to_string(trial) + " cut " + std::to_string(k),
                        checked);
        if (HasFatalFailure()) return;
      }
    }
  EXPECT_GT(checked.changes, 40);
  EXPECT_GT(checked.complete, 20);
}

TEST(SplitSearch, CutsThroughABentSheetMatchLabelPieces) {
  // A sheet bent into a trough (z = 2x²): a flat-ish plane cuts it along two lines, two
  // clusters of removed faces in one body, and three pieces (what the proof must not miss).
  std::mt19937 rng(3);
  SkinnedMesh bent = make_sheet(24, 16);
  for (std::int32_t v = 0; v < bent.vertex_count(); ++v)
    bent.current(2, v) = 2 * bent.current(0, v) * bent.current(0, v);
  std::normal_distribution<double> tilt(0, 0.2);
  std::uniform_real_distribution<double> height(0.05, 0.45), shift(-0.3, 0.3);
  Checked checked;
  SplitSearch search;
  for (int trial = 0; trial < 24; ++trial) {
    SkinnedMesh m = bent;
    const auto plane = cga::Plane<double>::from_normal_point(
        Eigen::Vector3d(tilt(rng), tilt(rng), 1), Eigen::Vector3d(shift(rng), 0, height(rng)));
    const CutResult r = compute_cut(m, plane, {.cap = false});
    if (r.status != CutStatus::Cut) continue;
    apply_and_check(m, r.change, search, "bent trial " + std::to_string(trial), checked);
    if (HasFatalFailure()) return;
  }
  EXPECT_GT(checked.changes, 12);
  EXPECT_GT(checked.complete, 12);
}

TEST(SplitSearch, RandomTearsMatchLabelPieces) {
  std::mt19937 rng(41);
  Checked checked;
  SplitSearch search;
  std::uniform_real_distribution<double> centre(-0.1, 0.1), radius(0.12, 0.3),
      angle(0, 6.283185307179586);
  for (int trial = 0; trial < 12; ++trial) {
    // Along an arc of a random circle (a tear splits nothing: every change leaves the sheet
    // one piece, found by the open group or by the proof that the body is unbroken).
    SkinnedMesh m = make_sheet(30, 30);
    SkinnedMesh torn = m;
    Adjacency adjacency(torn);
    Tear tear(torn, adjacency);
    const Eigen::Vector3d c(centre(rng), centre(rng), 0);
    const double r = radius(rng), a0 = angle(rng), turn = 0.3 + 0.07 * trial;
    const int samples = 120;
    for (int i = 0; i < samples; ++i) {
      const double a = a0 + turn * 6.283185307179586 * i / (samples - 1);
      const Eigen::Vector3d p = c + r * Eigen::Vector3d(std::cos(a), std::sin(a), 0);
      const TearStep step =
          tear.advance({double(i), p - Eigen::Vector3d(0, 0, 0.1), p + Eigen::Vector3d(0, 0, 0.1)});
      for (std::size_t k = 0; k < step.changes.size(); ++k) {
        apply_and_check(m, step.changes[k], search,
                        "tear " + std::to_string(trial) + " sample " + std::to_string(i), checked);
        if (HasFatalFailure()) return;
      }
    }
    ASSERT_EQ(m.faces, torn.faces) << "the replayed changes are the tear's";
  }
  EXPECT_GT(checked.changes, 100);
  EXPECT_GT(checked.open, 0);
}

TEST(SplitSearch, RandomDrillsMatchLabelPieces) {
  std::mt19937 rng(7);
  Checked checked;
  SplitSearch search;
  std::uniform_real_distribution<double> u(-0.4, 0.4), r(0.03, 0.12);
  for (int trial = 0; trial < 12; ++trial) {
    SkinnedMesh m = make_cylinder(24, 20, 0.2, 1.0);
    SkinnedMesh drilled = m;
    Adjacency adjacency(drilled);
    for (int k = 0; k < 3; ++k) {  // through both walls, across the axis at a random height
      const double z = 0.5 + u(rng), a = 3.141592653589793 * u(rng);
      const Eigen::Vector3d across(std::cos(a), std::sin(a), 0);
      const DrillResult d = drill(drilled, adjacency,
                                  {Eigen::Vector3d(0, 0, z) + 0.5 * across,
                                   Eigen::Vector3d(0, 0, z) - 0.5 * across, r(rng)});
      for (const auto& change : d.changes) {
        apply_and_check(m, change, search, "drill " + std::to_string(trial), checked);
        if (HasFatalFailure()) return;
      }
    }
    ASSERT_EQ(m.faces, drilled.faces) << "the replayed changes are the drill's";
  }
  EXPECT_GT(checked.changes, 20);
  EXPECT_GT(checked.open, 0);
}
