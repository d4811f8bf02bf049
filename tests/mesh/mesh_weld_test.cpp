// Welding real models at their seams (mesh/weld.hpp, io/weld_model.hpp), the seams kept per
// face corner through export and through cut, tear and drill (mesh/corner_attributes.hpp), on
// the rigged models of Debian's assimp-testmodels as imported, and on a two-triangle seam.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <numeric>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "conform/io/import.hpp"
#include "conform/io/mesh_export.hpp"
#include "conform/io/weld_model.hpp"
#include "conform/mesh/analysis.hpp"
#include "conform/mesh/corner_attributes.hpp"
#include "conform/mesh/cut.hpp"
#include "conform/mesh/drill.hpp"
#include "conform/mesh/tear.hpp"
#include "conform/mesh/weld.hpp"
#include "conform/skin/pose.hpp"
#include "conform/skin/skinner.hpp"

using namespace conform;
using namespace conform::mesh;

namespace {

// The rigged models of assimp-testmodels that import (the weight tolerance of
// animation_with_skeleton.fbx, whose sums are 0.94–1.38, as in io_import_test.cpp).
const char* const kModels[] = {
    "X/Testwuson.X", "X/BCN_Epileptic.X", "FBX/huesitos.fbx",     "FBX/animation_with_skeleton.fbx",
    "X/anim_test.x", "SMD/WusonSMD.smd",  "SMD/holy_grailref.smd"};

struct Loaded {
  std::string file;
  io::SkinnedModel split, welded;  // imported without and with the weld
};

const std::vector<Loaded>& models() {
  static const std::vector<Loaded> out = [] {
    std::vector<Loaded> v;
    for (const char* file : kModels) {
      const auto path = std::filesystem::path(CONFORM_ASSIMP_MODELS) / file;
      if (!std::filesystem::exists(path)) continue;
      io::ImportOptions options;
      options.weld = false;
      Loaded l{file, io::import_model(path.string(), options), {}};
      options.weld = true;
      l.welded = io::import_model(path.string(), options);
      v.push_back(std::move(l));
    }
    return v;
  }();
  return out;
}

// An independent weld: vertices sorted by (mesh, exact rest position), equal runs are one
// vertex; pieces are then counted by a union-find over the faces' edges.
std::int32_t independent_pieces(const io::SkinnedModel& split, std::int32_t* vertices) {
  const auto& m = split.mesh;
  std::vector<std::int32_t> mesh_of(std::size_t(m.vertex_count()), -1);
  for (std::size_t i = 0; i < split.meshes.size(); ++i)
    for (std::int32_t v = 0; v < split.meshes[i].vertex_count; ++v)
      mesh_of[std::size_t(split.meshes[i].first_vertex + v)] = std::int32_t(i);
  using Key = std::tuple<std::int32_t, double, double, double>;
  std::map<Key, std::int32_t> id;
  std::vector<std::int32_t> welded(std::size_t(m.vertex_count()));
  for (std::int32_t v = 0; v < m.vertex_count(); ++v)
    welded[std::size_t(v)] =
        id.try_emplace(Key{mesh_of[std::size_t(v)], m.rest(0, v), m.rest(1, v), m.rest(2, v)},
                       std::int32_t(id.size()))
            .first->second;
  *vertices = std::int32_t(id.size());
  std::vector<std::int32_t> parent(id.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](std::int32_t x) {
    while (parent[std::size_t(x)] != x)
      x = parent[std::size_t(x)] = parent[std::size_t(parent[std::size_t(x)])];
    return x;
  };
  std::vector<char> used(id.size(), 0);
  for (const Face& f : m.faces)
    for (int k = 0; k < 3; ++k) {
      const std::int32_t a = find(welded[std::size_t(f[std::size_t(k)])]),
                         b = find(welded[std::size_t(f[std::size_t((k + 1) % 3)])]);
      used[std::size_t(a)] = used[std::size_t(b)] = 1;
      parent[std::size_t(a)] = b;
    }
  std::int32_t pieces = 0;
  for (std::size_t v = 0; v < id.size(); ++v)
    pieces += used[v] && find(std::int32_t(v)) == std::int32_t(v);
  return pieces;
}

Eigen::Vector3d corner(const SkinnedMesh& m, std::int32_t f, int k) {
  return m.current.col(m.faces[std::size_t(f)][std::size_t(k)]);
}
Eigen::Vector3d unit_normal(const SkinnedMesh& m, std::int32_t f) {
  return (corner(m, f, 1) - corner(m, f, 0)).cross(corner(m, f, 2) - corner(m, f, 0)).normalized();
}
Eigen::Vector3d centroid(const SkinnedMesh& m, std::int32_t f) {
  return (corner(m, f, 0) + corner(m, f, 1) + corner(m, f, 2)) / 3;
}
double mean_edge(const SkinnedMesh& m) {
  double sum = 0;
  for (std::int32_t f = 0; f < m.face_count(); ++f)
    for (int k = 0; k < 3; ++k) sum += (corner(m, f, k) - corner(m, f, (k + 1) % 3)).norm();
  return sum / (3.0 * m.face_count());
}

// Faces with a corner at a welded seam: a vertex whose corners' UVs or normals differ.
std::vector<std::int32_t> seam_faces(const SkinnedMesh& m) {
  std::vector<std::vector<std::pair<std::int32_t, int>>> corners(std::size_t(m.vertex_count()));
  for (std::int32_t f = 0; f < m.face_count(); ++f)
    for (int k = 0; k < 3; ++k)
      corners[std::size_t(m.faces[std::size_t(f)][std::size_t(k)])].push_back({f, k});
  std::vector<char> seam(std::size_t(m.face_count()), 0);
  for (const auto& list : corners)
    for (const auto& [f, k] : list) {
      const auto [g, j] = list.front();
      const bool differ = (m.has_corner_uvs() && m.corner_uvs.col(f).segment<2>(2 * k) !=
                                                     m.corner_uvs.col(g).segment<2>(2 * j)) ||
                          (m.has_corner_normals() && m.corner_normals.col(f).segment<3>(3 * k) !=
                                                         m.corner_normals.col(g).segment<3>(3 * j));
      if (differ) seam[std::size_t(f)] = seam[std::size_t(g)] = 1;
    }
  std::vector<std::int32_t> out;
  for (std::int32_t f = 0; f < m.face_count(); ++f)
    if (seam[std::size_t(f)]) out.push_back(f);
  return out;
}

// Every base face that survives `change` keeps its corner attributes exactly.
void expect_corners_kept(const SkinnedMesh& before, const SkinnedMesh& after,
                         const TopologyChange& change, const std::string& what) {
  std::int32_t differ = 0, kept = 0;
  for (std::int32_t f = 0; f < before.face_count(); ++f) {
    const std::int32_t g = change.face_after(f);
    if (g < 0) continue;
    ++kept;
    if (before.has_corner_uvs() && before.corner_uvs.col(f) != after.corner_uvs.col(g)) ++differ;
    if (before.has_corner_normals() && before.corner_normals.col(f) != after.corner_normals.col(g))
      ++differ;
  }
  EXPECT_EQ(differ, 0) << what;
  EXPECT_GT(kept, 0) << what;
}

}  // namespace

// A quad of two triangles split at its diagonal as a file would be: the diagonal's two
// vertices appear twice, with different UVs on each side.
TEST(Weld, KeepsTheSeamPerCorner) {
  SkinnedMesh m;
  m.rest.resize(3, 6);
  m.rest << 0, 1, 1, 0, 1, 0,  //
      0, 0, 1, 0, 1, 1,        //
      0, 0, 0, 0, 0, 0;
  m.current = m.rest;
  m.faces = {{0, 1, 2}, {3, 4, 5}};
  m.uvs.resize(2, 6);
  m.uvs << 0, 1, 1, 0.5, 0.9, 0.5,  //
      0, 0, 1, 0.5, 0.9, 0.9;
  m.normals.setZero(3, 6);
  m.normals.row(2).setOnes();
  m.bones.setZero(4, 6);
  m.weights.setZero(4, 6);
  m.weights.row(0).setOnes();
  const SkinnedMesh in = m;
  const WeldResult r = weld(m);
  EXPECT_EQ(m.vertex_count(), 4);
  EXPECT_EQ(r.merged, 2);
  EXPECT_EQ(r.kept_apart, 0);
  EXPECT_EQ(m.faces, (std::vector<Face>{{0, 1, 2}, {0, 2, 3}}));
  ASSERT_TRUE(m.has_corner_uvs());
  for (std::int32_t f = 0; f < 2; ++f)
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(m.corner_uvs.col(f).segment<2>(2 * k),
                in.uvs.col(in.faces[std::size_t(f)][std::size_t(k)]));

  // A vertex at a welded position whose weights differ (vertex 3 all bone 1, its copy 0 all
  // bone 0) welds with their mean weights by default; kept apart on request.
  SkinnedMesh odd = in;
  odd.bones(0, 3) = 1;
  SkinnedMesh odd_apart = odd;
  const WeldResult averaged = weld(odd);
  EXPECT_EQ(odd.vertex_count(), 4);
  EXPECT_EQ(averaged.kept_apart, 0);
  const std::int32_t w = averaged.vertex_map[3];
  EXPECT_EQ(averaged.vertex_map[0], w);
  ASSERT_EQ(averaged.averaged, (std::vector<std::int32_t>{w}));
  EXPECT_EQ(averaged.largest_weight_difference, 1);
  EXPECT_EQ(odd.bones(0, w), 0);  // equal halves: the lower bone first
  EXPECT_EQ(odd.bones(1, w), 1);
  EXPECT_EQ(odd.weights(0, w), 0.5);
  EXPECT_EQ(odd.weights(1, w), 0.5);
  const WeldResult apart = weld(odd_apart, {.differing_weights = DifferingWeights::keep_apart});
  EXPECT_EQ(odd_apart.vertex_count(), 5);
  EXPECT_EQ(apart.kept_apart, 1);
  EXPECT_TRUE(apart.averaged.empty());

  // Written back, the seam's vertices are split again: 6 vertices.
  const auto path = std::filesystem::temp_directory_path() / "conform_weld_seam.ply";
  io::write_mesh(path, m, {.format = io::MeshFormat::PlyAscii});
  std::ifstream is(path);
  std::string text((std::istreambuf_iterator<char>(is)), {});
  EXPECT_NE(text.find("element vertex 6\n"), std::string::npos) << text;
  EXPECT_NE(text.find("property double nx"), std::string::npos);
  std::filesystem::remove(path);

  // A cut across the seam: each new corner takes the UV of its own side.
  Adjacency adjacency(m);
  const auto out = cut(m, adjacency, cga::Plane<double>::from_normal_point({0, 1, 0}, {0, 0.5, 0}));
  ASSERT_EQ(out.result.status, CutStatus::Cut);
  ASSERT_TRUE(m.has_corner_uvs());
  for (std::int32_t f = 0; f < m.face_count(); ++f)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d p = corner(m, f, k);
      const Eigen::Vector2d uv = m.corner_uvs.col(f).segment<2>(2 * k);
      // Side of the diagonal x = y: below it (face 0's side) uv = (x, y); above it the
      // second triangle's map, (0.5 + 0.4 x, 0.5 + 0.4 y).
      const Eigen::Vector3d c = centroid(m, f);
      const Eigen::Vector2d expected = c.x() > c.y()
                                           ? Eigen::Vector2d(p.x(), p.y())
                                           : Eigen::Vector2d(0.5 + 0.4 * p.x(), 0.5 + 0.4 * p.y());
      EXPECT_NEAR((uv - expected).norm(), 0, 1e-12) << "face " << f << " corner " << k;
    }
}

TEST(Weld, PieceCountEqualsAnIndependentWeld) {
  int checked = 0;
  for (const auto& [file, split, welded] : models()) {
    std::int32_t vertices = 0;
    const std::int32_t expected = independent_pieces(split, &vertices);
    const MeshReport before = check_mesh(split.mesh), after = check_mesh(welded.mesh);
    std::printf(
        "%s: %d → %d vertices, %d → %d pieces (independent %d, %d vertices), %d → %d "
        "boundary edges, %zu warnings\n",
        file.c_str(), split.mesh.vertex_count(), welded.mesh.vertex_count(),
        label_pieces(split.mesh).count, label_pieces(welded.mesh).count, expected, vertices,
        before.boundary_edges, after.boundary_edges, welded.warnings.size());
    EXPECT_EQ(label_pieces(welded.mesh).count, expected) << file;
    EXPECT_EQ(welded.mesh.face_count(), split.mesh.face_count()) << file;
    EXPECT_EQ(welded.influences.vertex_count(), welded.mesh.vertex_count()) << file;
    // The weight rule, measured: vertices kept apart at a welded position because their
    // weights differ, and what welding them anyway would change.
    SkinnedMesh anyway = split.mesh;
    const WeldResult ignoring = weld(anyway, {.weight_tolerance = INFINITY});
    SkinnedMesh ruled = split.mesh;
    const WeldResult r = weld(ruled, {.differing_weights = DifferingWeights::keep_apart});
    EXPECT_EQ(after.overused_edges, before.overused_edges)
        << file << ": welded only coincident copies";
    std::printf("  weight rule: %d kept apart (welding them anyway: %d vertices, %d pieces)\n",
                r.kept_apart, anyway.vertex_count(), label_pieces(anyway).count);
    EXPECT_EQ(ignoring.kept_apart, 0);
    // By default (mean weights) exactly the kept-apart copies weld too (here without the
    // import's per-mesh groups, as `ruled`).
    SkinnedMesh mean = split.mesh;
    const WeldResult m = weld(mean);
    EXPECT_EQ(mean.vertex_count(), ruled.vertex_count() - r.kept_apart) << file;
    EXPECT_EQ(std::int32_t(m.averaged.size()), r.kept_apart) << file;
    EXPECT_LE(welded.mesh.vertex_count(), ruled.vertex_count()) << file;
    // The independent weld joins bit-equal positions whatever their weights: it has the kept
    // apart ones fewer (X/Testwuson.X: 7, of 2124), less those only near (BCN_Epileptic.X: 1).
    EXPECT_GE(welded.mesh.vertex_count(), vertices) << file;
    EXPECT_LE(welded.mesh.vertex_count(), vertices + r.kept_apart) << file;
    ++checked;
  }
  if (checked == 0) GTEST_SKIP() << "assimp-testmodels not installed";
  EXPECT_GT(checked, 3);
}

TEST(Weld, ImportEqualsWeldingTheSplitModel) {
  // import_model with the weld is the split import followed by weld_model; its skinning is the
  // split model's, vertex by vertex through the weld's map, in the bind pose and along each
  // model's animation (io_import_test.cpp checks the split model against assimp's matrix LBS).
  int checked = 0;
  for (const auto& [file, split, welded] : models()) {
    io::SkinnedModel again = split;
    const WeldResult r = io::weld_model(again, {});
    ASSERT_EQ(again.mesh.vertex_count(), welded.mesh.vertex_count()) << file;
    EXPECT_EQ(again.mesh.rest, welded.mesh.rest) << file;
    EXPECT_EQ(again.mesh.faces, welded.mesh.faces) << file;
    skin::Skinner<double> a(split.skeleton, split.mesh.rest, split.influences),
        b(welded.skeleton, welded.mesh.rest, welded.influences);
    const double diag = bounding_diagonal(split.mesh);
    double worst = 0, worst_mean = 0, worst_part = 0;
    skin::Pose pose = skin::Pose::rest(split.skeleton);
    for (int step = -1; step < 8; ++step) {
      if (step >= 0) {
        if (split.animations.empty()) break;
        const auto& anim = split.animations.front();
        anim.sample(split.skeleton, step / 7.0 * anim.duration(), skin::Blend::linear, pose);
      }
      Eigen::Matrix3Xd pa, pb;
      a.skin(pose, skin::SkinMode::cga);
      a.write(pa);
      b.skin(pose, skin::SkinMode::cga);
      b.write(pb);
      // Copies welded with their mean weights: the welded vertex against their mean position,
      // relative to how far the file's own copies part.
      std::vector<Eigen::Vector3d> sum(r.averaged.size(), Eigen::Vector3d::Zero());
      std::vector<double> count(r.averaged.size(), 0), spread(r.averaged.size(), 0);
      for (std::int32_t v = 0; v < split.mesh.vertex_count(); ++v) {
        const std::int32_t w = r.vertex_map[std::size_t(v)];
        const auto at = std::lower_bound(r.averaged.begin(), r.averaged.end(), w);
        if (at != r.averaged.end() && *at == w) {
          const auto k = std::size_t(at - r.averaged.begin());
          sum[k] += pa.col(v), ++count[k];
          spread[k] = std::max(spread[k], (pa.col(v) - pb.col(w)).norm());
          continue;
        }
        worst = std::max(worst, (pa.col(v) - pb.col(w)).norm());
      }
      for (std::size_t k = 0; k < r.averaged.size(); ++k) {
        const double off = (sum[k] / count[k] - pb.col(r.averaged[k])).norm();
        worst_mean = std::max(worst_mean, off / std::max(spread[k], 1e-12 * diag));
        worst_part = std::max(worst_part, spread[k]);
      }
    }
    // A vertex welded into another one at most the tolerance away (1e-7 of the rest diagonal)
    // skins as that one; on these models all welded copies are bit-equal: 0. Copies welded with
    // their mean weights (X/Testwuson.X: 7) skin near their copies' mean position.
    EXPECT_LE(worst, 1.01e-7 * diag) << file;
    EXPECT_LE(worst_mean, 1e-3) << file;
    std::printf(
        "%s: welded skinning vs split, worst %.3g of the diagonal; %zu mean-weight "
        "positions, a copy up to %.3g of the diagonal from the welded vertex, which is off "
        "their mean by at most %.3g of that\n",
        file.c_str(), worst / diag, r.averaged.size(), worst_part / diag, worst_mean);
    ++checked;
  }
  if (checked == 0) GTEST_SKIP() << "assimp-testmodels not installed";
}

TEST(Weld, ExportWritesTheSeamsBack) {
  // The welded model written as PLY has the split model's vertices again: per face corner,
  // the same position, UV and normal as the file's.
  int checked = 0;
  for (const auto& [file, split, welded] : models()) {
    const auto path = std::filesystem::temp_directory_path() / "conform_weld_export.ply";
    io::write_mesh(path, welded.mesh, {.format = io::MeshFormat::PlyAscii, .rest_positions = true});
    std::ifstream is(path);
    std::string line;
    std::size_t vertices = 0, faces = 0, properties = 0;
    while (std::getline(is, line) && line != "end_header") {
      std::istringstream ls(line);
      std::string word, kind;
      ls >> word >> kind;
      if (word == "element" && kind == "vertex") ls >> vertices;
      if (word == "element" && kind == "face") ls >> faces;
      if (word == "property" && kind == "double") ++properties;
    }
    std::vector<std::vector<double>> v(vertices, std::vector<double>(properties));
    for (auto& row : v)
      for (auto& x : row) is >> x;
    ASSERT_EQ(faces, std::size_t(split.mesh.face_count())) << file;
    const bool uvs = split.mesh.has_uvs(), normals = split.mesh.has_normals();
    ASSERT_EQ(properties, 3u + (uvs ? 2 : 0) + (normals ? 3 : 0)) << file;
    std::size_t differ = 0;
    double worst = 0;
    for (std::int32_t f = 0; f < split.mesh.face_count(); ++f) {
      int n = 0;
      std::array<std::size_t, 3> idx{};
      is >> n >> idx[0] >> idx[1] >> idx[2];
      for (int k = 0; k < 3; ++k) {
        const std::int32_t s = split.mesh.faces[std::size_t(f)][std::size_t(k)];
        const auto& row = v[idx[std::size_t(k)]];
        std::vector<double> want;
        if (uvs) want.insert(want.end(), {split.mesh.uvs(0, s), split.mesh.uvs(1, s)});
        if (normals)
          want.insert(want.end(), {split.mesh.normals(0, s), split.mesh.normals(1, s),
                                   split.mesh.normals(2, s)});
        differ += !std::equal(want.begin(), want.end(), row.begin() + 3);
        worst = std::max(worst,
                         (Eigen::Vector3d(row[0], row[1], row[2]) - split.mesh.rest.col(s)).norm());
      }
    }
    std::filesystem::remove(path);
    EXPECT_EQ(differ, 0u) << file << ": corner UVs and normals as in the file";
    EXPECT_EQ(worst, 0) << file;  // every welded copy was bit-equal
    // assimp had already joined what was identical, so the wedges are the file's vertices.
    EXPECT_EQ(vertices, std::size_t(split.mesh.vertex_count())) << file;
    std::printf("%s: %zu vertices written (file %d, welded %d)\n", file.c_str(), vertices,
                split.mesh.vertex_count(), welded.mesh.vertex_count());
    ++checked;
  }
  if (checked == 0) GTEST_SKIP() << "assimp-testmodels not installed";
}

TEST(Weld, CappedCutsCloseEveryLoopAndKeepTheCorners) {
  // Planes at 35, 50 and 65 % of each welded model along each axis (slightly tilted): every
  // face the cut does not touch keeps its corners exactly, and new corners have unit normals.
  // On the models that welding makes one closed manifold surface (the split files were 3 to
  // 176 pieces) every loop is capped; the split files' cuts were open curves at the seams.
  // X/Testwuson.X and SMD/WusonSMD.smd stay open after welding (non-manifold vertices), yet
  // every closed loop of theirs is capped too (2 of 15 each were not, before the cut kept
  // vertices that would pinch a loop off the plane). X/BCN_Epileptic.X has crossing shells:
  // loops that cross in the section, and a loop through a vertex where its surface meets the
  // plane in several fans by itself; its counts and reasons are printed, not checked.
  int cuts = 0, loops = 0, capped = 0, split_loops = 0, split_capped = 0;
  for (const auto& [file, split, welded] : models()) {
    const SkinnedMesh& in = welded.mesh;
    const MeshReport report = check_mesh(in);
    const bool closed = report.closed() && report.manifold() && label_pieces(in).count == 1;
    const Eigen::Vector3d lo = in.current.rowwise().minCoeff(),
                          hi = in.current.rowwise().maxCoeff();
    int model_loops = 0, model_capped = 0;
    for (int axis = 0; axis < 3; ++axis)
      for (const double at : {0.35, 0.5, 0.65}) {
        const Eigen::Vector3d normal =
            Eigen::Vector3d::Unit(axis) + Eigen::Vector3d(0.05, 0.1, 0.15);
        const auto plane = cga::Plane<double>::from_normal_point(normal, lo + at * (hi - lo));
        SkinnedMesh m = in;
        Adjacency adjacency(m);
        const auto out = cut(m, adjacency, plane, {.cap = true});
        if (out.result.status != CutStatus::Cut) continue;
        const std::string what =
            file + " axis " + std::to_string(axis) + " at " + std::to_string(at);
        ++cuts;
        model_loops += out.result.loops, model_capped += out.result.capped_loops;
        if (out.result.capped_loops < out.result.loops)
          std::printf("%s: %s\n", what.c_str(), out.result.message.c_str());
        if (closed) {
          EXPECT_EQ(out.result.capped_loops, out.result.loops)
              << what << ": " << out.result.message;
          EXPECT_GT(out.result.loops, 0) << what;
          SkinnedMesh s = split.mesh;
          Adjacency split_adjacency(s);
          const auto split_out = cut(s, split_adjacency, plane, {.cap = true});
          split_loops += split_out.result.loops, split_capped += split_out.result.capped_loops;
          loops += out.result.loops, capped += out.result.capped_loops;
        }
        expect_corners_kept(in, m, out.result.change, what);
        for (std::int32_t f = 0; f < m.face_count() && m.has_corner_normals(); ++f)
          for (int k = 0; k < 3; ++k)
            ASSERT_NEAR(m.corner_normals.col(f).segment<3>(3 * k).norm(), 1, 1e-3)
                << what;  // files: 1e-5
      }
    std::printf("%s%s: %d of %d loops capped\n", file.c_str(), closed ? " (closed)" : "",
                model_capped, model_loops);
    if (file != "X/BCN_Epileptic.X") {
      EXPECT_EQ(model_capped, model_loops) << file;
    }
  }
  if (cuts == 0) GTEST_SKIP() << "assimp-testmodels not installed";
  std::printf("closed models: %d of %d loops capped welded; split: %d of %d\n", capped, loops,
              split_capped, split_loops);
  EXPECT_GT(cuts, 20);
  EXPECT_GT(loops, 10);
  EXPECT_LT(split_capped, capped);
}

TEST(Weld, DrilledHolesAtSeamsAreWhole) {
  // A drill along the normal of a face at a seam, of radius 0.6 mean edges: the area removed
  // per hole is πr² within 5 % (on the split model the hole was cut off at the seam), and
  // the faces away from the hole keep their corners.
  int drills = 0, within = 0;
  for (const auto& [file, split, welded] : models()) {
    const SkinnedMesh& in = welded.mesh;
    const double edge = mean_edge(in);
    const std::vector<std::int32_t> seams = seam_faces(in);
    for (std::size_t i = 0; i < seams.size() && i < 100 * 3; i += 3) {
      const std::int32_t f = seams[i];
      const Eigen::Vector3d n = unit_normal(in, f);
      if (!n.allFinite()) continue;
      const Eigen::Vector3d c = centroid(in, f);
      const double r = 0.6 * edge;
      // Only where the surface is one flat disc of the radius around the axis: every face
      // within 2r of the centre has its normal within 10° of the axis (no second layer, no
      // thin wall behind it).
      bool flat = true;
      for (std::int32_t g = 0; g < in.face_count() && flat; ++g)
        if ((centroid(in, g) - c).norm() < 2 * r && !(unit_normal(in, g).dot(n) > 0.985))
          flat = false;
      if (!flat) continue;
      SkinnedMesh m = in;
      Adjacency adjacency(m);
      const DrillResult d = drill(m, adjacency, {c - r * n, c + r * n, r});
      if (d.holes == 0) continue;
      ++drills;
      const double per_hole = d.removed_area / d.holes, disc = std::acos(-1.0) * r * r;
      within += std::abs(per_hole - disc) <= 0.05 * disc;
      EXPECT_NEAR(per_hole, disc, 0.05 * disc) << file << " face " << f << " holes " << d.holes
                                               << " tubes " << d.tubes << " " << d.message;
      for (const auto& change : d.changes) expect_corners_kept(in, m, change, file);
      if (testing::Test::HasFailure()) return;
    }
  }
  if (drills == 0) GTEST_SKIP() << "assimp-testmodels not installed";
  std::printf("%d drills at seams, %d within 5 %% of pi r^2\n", drills, within);
  EXPECT_GT(drills, 10);
}

// The point of the surface nearest p (brute force) and its face.
std::pair<Eigen::Vector3d, std::int32_t> nearest_point(const SkinnedMesh& m,
                                                       const Eigen::Vector3d& p) {
  double best = INFINITY;
  std::pair<Eigen::Vector3d, std::int32_t> out{p, -1};
  for (std::int32_t f = 0; f < m.face_count(); ++f) {
    const Eigen::Vector3d a = corner(m, f, 0), b = corner(m, f, 1), c = corner(m, f, 2);
    // Closest point on triangle: the plane's projection if inside, else the nearest edge point.
    const Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.squaredNorm() == 0) continue;
    Eigen::Vector3d q = p - (p - a).dot(n) / n.squaredNorm() * n;
    const bool inside = (b - a).cross(q - a).dot(n) >= 0 && (c - b).cross(q - b).dot(n) >= 0 &&
                        (a - c).cross(q - c).dot(n) >= 0;
    if (!inside) {
      double edge_best = INFINITY;
      for (const auto& [u, v] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
        const double t = std::clamp((p - u).dot(v - u) / (v - u).squaredNorm(), 0.0, 1.0);
        const Eigen::Vector3d e = u + t * (v - u);
        if ((e - p).squaredNorm() < edge_best) edge_best = (e - p).squaredNorm(), q = e;
      }
    }
    if ((q - p).squaredNorm() < best) best = (q - p).squaredNorm(), out = {q, f};
  }
  return out;
}

TEST(Weld, TearsCrossSeams) {
  // Strokes along a flank from a face at a seam: each sample's blade goes along the start
  // face's normal through the surface point nearest the straight stroke (so it follows the
  // surface), one mean edge apart, and a stroke counts when its faces all lie within 45° of the
  // start's normal and away from the welded model's open boundaries (a flank, not around a limb or
  // off an edge), and its two ends lie in different pieces of the split model (it crosses a seam).
  // Such a stroke extends the tear at ≥ 90 % of its samples after the first hit, over all such
  // strokes (measured 95 %; the rest wait for the blade in a face too thin for a new tip, by
  // design: tear.hpp); on the split model the same strokes stop at the seams.
  int crossing = 0, complete = 0, samples = 0, grew = 0, split_samples = 0, split_grew = 0;
  for (const auto& [file, split, welded] : models()) {
    const SkinnedMesh& in = welded.mesh;
    const Pieces charts = label_pieces(split.mesh);  // the split model's pieces, same faces
    const double diag = bounding_diagonal(in), edge = mean_edge(in);
    const double step = edge, reach = 0.01 * diag;
    const int samples_per_stroke = 12;
    std::vector<char> near_boundary(std::size_t(in.face_count()), 0);
    {
      std::map<std::pair<std::int32_t, std::int32_t>, int> uses;
      for (const Face& f : in.faces)
        for (int k = 0; k < 3; ++k)
          ++uses[std::minmax(f[std::size_t(k)], f[std::size_t((k + 1) % 3)])];
      std::vector<char> boundary_vertex(std::size_t(in.vertex_count()), 0);
      for (const auto& [e, n] : uses)
        if (n == 1)
          boundary_vertex[std::size_t(e.first)] = boundary_vertex[std::size_t(e.second)] = 1;
      for (std::int32_t f = 0; f < in.face_count(); ++f)
        for (const auto v : in.faces[std::size_t(f)])
          near_boundary[std::size_t(f)] |= boundary_vertex[std::size_t(v)];
    }
    const std::vector<std::int32_t> seams = seam_faces(in);
    for (std::size_t i = 0; i < seams.size() && i < 60 * 5; i += 5) {
      const std::int32_t f = seams[i];
      const Eigen::Vector3d n = unit_normal(in, f);
      if (!n.allFinite()) continue;
      for (int dir = 0; dir < 4; ++dir) {
        const double a = dir * std::acos(-1.0) / 2;
        const Eigen::Vector3d heading =
            std::cos(a) * n.unitOrthogonal() + std::sin(a) * n.cross(n.unitOrthogonal());
        const Eigen::Vector3d c = centroid(in, f);
        std::vector<Eigen::Vector3d> points, normals;
        bool flank = true;
        std::int32_t last = f;
        for (int s = 0; s < samples_per_stroke && flank; ++s) {
          const auto [q, g] = nearest_point(in, c + step * s * heading);
          flank = g >= 0 && !near_boundary[std::size_t(g)] &&
                  unit_normal(in, g).dot(n) > std::cos(std::acos(-1.0) / 4);
          points.push_back(q);
          if (g >= 0) normals.push_back(unit_normal(in, g));
          last = g;
        }
        if (!flank || charts.face_piece[std::size_t(f)] == charts.face_piece[std::size_t(last)])
          continue;
        // The same stroke on the welded and on the split model.
        int counts[2][2] = {{0, 0}, {0, 0}};  // [welded, split][samples, extended]
        for (int which = 0; which < 2; ++which) {
          SkinnedMesh m = which == 0 ? in : split.mesh;
          Adjacency adjacency(m);
          Tear tear(m, adjacency);
          for (int s = 0; s < samples_per_stroke; ++s) {
            const Eigen::Vector3d p = points[std::size_t(s)],
                                  blade = reach * normals[std::size_t(s)];
            const bool extended = tear.advance({double(s), p + blade, p - blade}).extended;
            if (tear.started() && s > 0) ++counts[which][0], counts[which][1] += extended;
          }
        }
        ++crossing;
        samples += counts[0][0], grew += counts[0][1];
        split_samples += counts[1][0], split_grew += counts[1][1];
        complete += counts[0][1] >= 0.9 * counts[0][0];
      }
    }
  }
  if (crossing == 0) GTEST_SKIP() << "assimp-testmodels not installed";
  std::printf(
      "%d strokes along flanks across seams: %d of %d later samples extend the tear "
      "(%d extend at >= 90 %% of theirs); on the split model %d of %d\n",
      crossing, grew, samples, complete, split_grew, split_samples);
  EXPECT_GT(crossing, 20);
  EXPECT_GE(grew, 0.9 * samples);
  EXPECT_GE(complete, 0.8 * crossing);  // measured 49 of 56 strokes on their own
  EXPECT_LT(split_grew, 0.9 * split_samples) << "the split model's tears stop at seams";
}
