// Tear and drill on the real rigged models of Debian's assimp-testmodels (the cut's are in
// mesh_cut_test.cpp). Real models need not be closed, manifold or connected, and their faces
// vary in size and shape: every invariant is checked relative to what held for the input
// (no new overused, misoriented or tiny faces; areas; pieces), over many random strokes and
// drills aimed at random faces.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "conform/io/import.hpp"
#include "conform/mesh/analysis.hpp"
#include "conform/mesh/drill.hpp"
#include "conform/mesh/tear.hpp"

using namespace conform;
using namespace conform::mesh;

namespace {

const char* const kModels[] = {"FBX/huesitos.fbx", "X/anim_test.x",
                               "glTF2/simple_skin/simple_skin.gltf"};

struct RealModel {
  std::string file;
  SkinnedMesh mesh;
};
// The installed ones, loaded once.
const std::vector<RealModel>& real_models() {
  static const std::vector<RealModel> models = [] {
    std::vector<RealModel> out;
    for (const char* file : kModels) {
      const std::filesystem::path path = std::filesystem::path(CONFORM_ASSIMP_MODELS) / file;
      if (std::filesystem::exists(path)) out.push_back({file, io::load_model(path.string()).mesh});
    }
    return out;
  }();
  return models;
}

Eigen::Vector3d corner(const SkinnedMesh& m, std::int32_t f, int k) {
  return m.current.col(m.faces[static_cast<std::size_t>(f)][static_cast<std::size_t>(k)]);
}

Eigen::Vector3d unit_normal(const SkinnedMesh& m, std::int32_t f) {
  return (corner(m, f, 1) - corner(m, f, 0)).cross(corner(m, f, 2) - corner(m, f, 0)).normalized();
}

double mean_edge(const SkinnedMesh& m) {
  double sum = 0;
  for (std::int32_t f = 0; f < m.face_count(); ++f)
    for (int k = 0; k < 3; ++k) sum += (corner(m, f, k) - corner(m, f, (k + 1) % 3)).norm();
  return sum / (3.0 * m.face_count());
}

// What must hold after any operation, relative to the input.
void expect_no_worse(const SkinnedMesh& m, const SkinnedMesh& in, const std::string& what) {
  const double tiny = 1e-14 * std::pow(bounding_diagonal(in), 2);
  const MeshReport before = check_mesh(in, tiny), after = check_mesh(m, tiny);
  EXPECT_TRUE(after.indices_valid) << what;
  EXPECT_TRUE(after.finite) << what;
  EXPECT_LE(after.tiny_faces, before.tiny_faces) << what;
  EXPECT_LE(after.overused_edges, before.overused_edges) << what << ": " << after.summary();
  EXPECT_LE(after.misoriented_edges, before.misoriented_edges) << what << ": " << after.summary();
  Eigen::Index bad = -1;  // one check, not one assertion per vertex
  for (Eigen::Index v = in.vertex_count(); v < m.vertex_count() && bad < 0; ++v)
    if (std::abs(m.weights.col(v).sum() - 1.0) > 1e-12 || !m.rest.col(v).allFinite()) bad = v;
  EXPECT_EQ(bad, -1) << what << ": a new vertex without renormalized weights or rest position";
}

double border_length(const SkinnedMesh& m, const std::vector<std::int32_t>& border) {
  double length = 0;
  for (std::size_t i = 1; i < border.size(); ++i)
    length += (m.current.col(border[i]) - m.current.col(border[i - 1])).norm();
  return length;
}

}  // namespace

TEST(RealModels, TearStrokesAcrossRandomFaces) {
  // A blade across the surface, through a random face along its normal, moving in a random
  // tangent direction: the tear keeps the area, the number of pieces and equal borders, and
  // makes nothing worse. These models are not welded (huesitos.fbx is 11 pieces with 114
  // boundary edges at its seams, simple_skin.gltf an 8-face strip), so a stroke stops where
  // its walk meets a boundary (documented: the sample is a no-op) or the blade leaves the model.
  int strokes = 0, grew = 0;
  for (const auto& [file, in] : real_models()) {
    // Short steps, a blade a tenth of the model long: real models have few, long faces.
    const double edge = mean_edge(in), reach = 0.05 * bounding_diagonal(in),
                 step = std::min(0.25 * edge, 0.01 * bounding_diagonal(in));
    const Pieces pieces = label_pieces(in);
    std::mt19937 rng(17);
    std::uniform_int_distribution<std::int32_t> face(0, in.face_count() - 1);
    std::uniform_real_distribution<double> angle(0, 2 * std::acos(-1.0));
    for (int trial = 0; trial < 60; ++trial) {
      const std::int32_t f = face(rng);
      const Eigen::Vector3d n = unit_normal(in, f);
      if (!n.allFinite()) continue;
      const Eigen::Vector3d c = (corner(in, f, 0) + corner(in, f, 1) + corner(in, f, 2)) / 3;
      const Eigen::Vector3d t1 = n.unitOrthogonal(), t2 = n.cross(t1);
      const double a = angle(rng);
      const Eigen::Vector3d heading = std::cos(a) * t1 + std::sin(a) * t2;
      SkinnedMesh m = in;
      Adjacency adjacency(m);
      Tear tear(m, adjacency);
      for (int i = 0; i < 24; ++i) {
        const Eigen::Vector3d p = c + step * i * heading;
        // The blade's end point a sits above the surface: the tear starts at its first hit.
        grew += tear.advance({double(i), p + reach * n, p - reach * n}).extended;
      }
      if (!tear.started()) continue;
      ++strokes;
      const std::string what = file + " trial " + std::to_string(trial);
      expect_no_worse(m, in, what);
      EXPECT_EQ(label_pieces(m).count, pieces.count) << what;
      const double area = surface_area(in);
      EXPECT_NEAR(surface_area(m), area, 1e-9 * area) << what;
      EXPECT_NEAR(border_length(m, tear.left_border()), border_length(m, tear.right_border()),
                  1e-12 * border_length(m, tear.right_border()) + 1e-15)
          << what;
      if (testing::Test::HasFailure()) return;
    }
  }
  if (strokes == 0) GTEST_SKIP() << "assimp-testmodels not installed";
  EXPECT_GT(strokes, 100);
  EXPECT_GT(grew, 6 * strokes) << "strokes extend until they meet a boundary";  // 11.8 measured
  RecordProperty("strokes", strokes);
  RecordProperty("extended_samples", grew);
}

TEST(RealModels, DrillsThroughRandomFaces) {
  // A drill along a random face's normal through its centroid, of radius 0.3 to 3 mean edges:
  // the rim's new vertices lie on the cylinder, the area removed is what the drill reports,
  // and nothing gets worse.
  int drills = 0;
  for (const auto& [file, in] : real_models()) {
    const double edge = mean_edge(in);
    std::mt19937 rng(23);
    std::uniform_int_distribution<std::int32_t> face(0, in.face_count() - 1);
    std::uniform_real_distribution<double> radius(0.3 * edge, 3 * edge);
    const double area = surface_area(in);
    for (int trial = 0; trial < 80; ++trial) {
      const std::int32_t f = face(rng);
      const Eigen::Vector3d n = unit_normal(in, f);
      if (!n.allFinite()) continue;
      const Eigen::Vector3d c = (corner(in, f, 0) + corner(in, f, 1) + corner(in, f, 2)) / 3;
      const DrillTool tool{c - 2 * edge * n, c + 2 * edge * n, radius(rng)};
      SkinnedMesh m = in;
      Adjacency adjacency(m);
      const DrillResult d = drill(m, adjacency, tool);
      const std::string what = file + " trial " + std::to_string(trial);
      if (d.holes == 0) continue;
      ++drills;
      expect_no_worse(m, in, what);
      EXPECT_NEAR(surface_area(m), area - d.removed_area, 1e-9 * area) << what;
      EXPECT_GT(d.removed_area, 0) << what;
      for (std::int32_t v = m.vertex_count() - d.rim_vertices; v < m.vertex_count(); ++v)
        EXPECT_NEAR(std::sqrt(axis_distance_squared(tool, m.current.col(v))), tool.radius,
                    1e-9 * bounding_diagonal(in))
            << what << ": rim vertex " << v;
      if (testing::Test::HasFailure()) return;
    }
  }
  if (drills == 0) GTEST_SKIP() << "assimp-testmodels not installed";
  EXPECT_EQ(drills, 240) << "every drill through a face makes a hole";
  RecordProperty("drills", drills);
}
