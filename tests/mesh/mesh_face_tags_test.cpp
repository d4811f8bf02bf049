// Face tags (skinned_mesh.hpp): skin, cap, tube wall and the change that made each face,
// checked against the geometry that defines them (a cap lies in its cutting plane, a tube wall
// on the drill's cylinder and closes the holes' rims) rather than against the producers' books.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>

#include "conform/io/mesh_export.hpp"
#include "conform/mesh/cut.hpp"
#include "conform/mesh/drill.hpp"
#include "conform/mesh/face_index.hpp"
#include "conform/mesh/primitives.hpp"
#include "conform/mesh/tear.hpp"

using namespace conform;
using namespace conform::mesh;
using Plane = cga::Plane<double>;

namespace {

// The face lies in the plane: every corner within 1e-9 of it. (The cuts of these tests do
// not snap, kCutExactly: a vertex the cut snaps is taken as on the plane without moving.)
bool on_plane(const SkinnedMesh& m, const Face& f, const cga::Plane<double>& p) {
  for (auto v : f)
    if (std::abs(p.signed_distance(m.current.col(v))) > 1e-9) return false;
  return true;
}

std::int32_t count_kind(const SkinnedMesh& m, FaceKind kind) {
  std::int32_t n = 0;
  for (std::int32_t f = 0; f < m.face_count(); ++f) n += m.face_tag(f).kind == kind;
  return n;
}

const CutOptions kCutExactly{.snap_fraction = 0, .min_angle = 0, .cap = true};

}  // namespace

TEST(FaceTags, CapFacesAndOnlyThemAreTaggedCap) {
  SkinnedMesh m = make_icosphere(3);
  ASSERT_FALSE(m.has_face_tags());  // a model's mesh: all skin, op 0
  const std::int32_t f0 = m.face_count();
  Adjacency adj(m);
  const Plane plane = Plane::from_normal_distance({1, -0.3, 0.4}, -0.2);
  const auto out = cut(m, adj, plane, kCutExactly);
  ASSERT_EQ(out.result.capped_loops, 1) << out.result.message;
  ASSERT_TRUE(m.has_face_tags());
  EXPECT_EQ(m.edits, 1u);
  // A face is tagged cap exactly when it lies in the cutting plane (no face of the sphere does).
  std::int32_t caps = 0;
  for (std::int32_t f = 0; f < m.face_count(); ++f) {
    const bool in_plane = on_plane(m, m.faces[std::size_t(f)], plane);
    EXPECT_EQ(m.face_tag(f).kind == FaceKind::cap, in_plane) << "face " << f;
    caps += in_plane;
  }
  EXPECT_EQ(caps, 2 * out.result.cap_faces);  // both sides
  EXPECT_EQ(count_kind(m, FaceKind::tube), 0);
  // Added faces carry the change's op; the faces the cut left alone stay the model's (op 0).
  std::int32_t made = 0;
  for (std::int32_t f = 0; f < m.face_count(); ++f) made += m.face_tag(f).op == 1;
  EXPECT_EQ(made, std::int32_t(out.result.change.added_faces.size()));
  EXPECT_EQ(m.face_count() - made, f0 - std::int32_t(out.result.change.removed_faces.size()));
  // With the default options (snapping): as many cap faces as the cut made.
  SkinnedMesh snapped = make_icosphere(3);
  Adjacency snapped_adjacency(snapped);
  const auto default_cut = cut(snapped, snapped_adjacency, plane, {.cap = true});
  ASSERT_EQ(default_cut.result.capped_loops, 1);
  EXPECT_EQ(count_kind(snapped, FaceKind::cap), 2 * default_cut.result.cap_faces);
}

TEST(FaceTags, CapSplitByALaterCutStaysCap) {
  // A cylinder capped across, then cut lengthwise without cap: the first cap is cut in two; its
  // pieces lie in the first plane, keep the cap kind and get the second change's op.
  SkinnedMesh m = make_cylinder(24, 20, 0.1, 1.0);
  Adjacency adj(m);
  const Plane across = Plane::from_normal_distance({0, 0, 1}, 0.53);
  ASSERT_EQ(cut(m, adj, across, kCutExactly).result.capped_loops, 1);
  const Plane along = Plane::from_normal_distance({1, 0.2, 0}, 0.013);
  const auto second = cut(m, adj, along, {});
  ASSERT_EQ(second.result.status, CutStatus::Cut);
  std::map<std::uint32_t, std::int32_t> cap_ops;
  for (std::int32_t f = 0; f < m.face_count(); ++f) {
    const bool in_plane = on_plane(m, m.faces[std::size_t(f)], across);
    EXPECT_EQ(m.face_tag(f).kind == FaceKind::cap, in_plane) << "face " << f;
    if (in_plane) ++cap_ops[m.face_tag(f).op];
  }
  EXPECT_GT(cap_ops[1], 0);  // cap faces the second cut missed
  EXPECT_GT(cap_ops[2], 0);  // cap faces it split: still cap
}

TEST(FaceTags, TubeWallIsTaggedTubeAndClosesTheRims) {
  SkinnedMesh m = make_icosphere(4);
  Adjacency adj(m);
  FaceIndex index(m);
  const DrillTool tool{{0.1, 0.05, 2}, {0.1, 0.05, -2}, 0.2};
  DrillOptions options;  // no snapping: every rim vertex is on the cylinder
  options.snap_fraction = 0;
  options.min_angle = 0;
  options.tube = true;
  const DrillResult d = drill(m, adj, index, tool, options);
  ASSERT_EQ(d.tubes, 1) << d.message;
  EXPECT_EQ(count_kind(m, FaceKind::tube), d.tube_faces);
  EXPECT_EQ(count_kind(m, FaceKind::cap), 0);
  const auto on_cylinder = [&](std::int32_t v) {
    return std::abs(std::sqrt(axis_distance_squared(tool, m.current.col(v))) - tool.radius) <= 1e-9;
  };
  // Every tube face lies on the cylinder, and the tube part's border edges are exactly the
  // edges it shares with skin faces: the wall closes the two rims and nothing else.
  std::map<std::pair<std::int32_t, std::int32_t>, std::pair<int, int>> edges;  // (tube, skin)
  for (std::int32_t f = 0; f < m.face_count(); ++f) {
    const Face& t = m.faces[std::size_t(f)];
    const bool tube = m.face_tag(f).kind == FaceKind::tube;
    for (int k = 0; k < 3; ++k) {
      const std::int32_t a = t[std::size_t(k)], b = t[std::size_t((k + 1) % 3)];
      auto& e = edges[{std::min(a, b), std::max(a, b)}];
      (tube ? e.first : e.second)++;
      if (tube) {
        EXPECT_TRUE(on_cylinder(a)) << "tube face " << f;
      }
    }
    if (tube) {
      EXPECT_EQ(m.face_tag(f).op, 1u);
    }
  }
  std::int32_t rim_edges = 0;
  for (const auto& [edge, uses] : edges) {
    if (uses.first == 1) {
      EXPECT_EQ(uses.second, 1) << edge.first << "-" << edge.second;
      EXPECT_TRUE(on_cylinder(edge.first) && on_cylinder(edge.second));
      ++rim_edges;
    }
    if (uses.first == 0) {
      EXPECT_EQ(uses.second, 2);  // closed elsewhere
    }
  }
  EXPECT_GE(rim_edges, 2 * 24);  // two rims of at least min_rim_points edges
}

TEST(FaceTags, RefusedWhenInconsistentOrOutOfRange) {
  SkinnedMesh m = make_sheet(2, 1);
  TopologyChange c;
  c.base_vertex_count = m.vertex_count();
  c.base_face_count = m.face_count();
  c.removed_faces = {0};
  c.added_faces = {m.faces[0]};
  c.new_surface = {{0, 2, FaceKind::cap}};
  EXPECT_EQ(c.validate(), "new surface run out of range or overlapping");
  c.new_surface = {{0, 1, FaceKind(7)}};
  EXPECT_EQ(c.validate(), "new surface of unknown kind");
  c.new_surface = {{0, 1, FaceKind::cap}};
  c.edit = EditKind(9);
  EXPECT_EQ(c.validate(), "a change of unknown edit kind");
  c.edit = EditKind::other;
  EXPECT_EQ(c.validate(), "");
  m.face_tags.resize(1);
  try {
    apply(m, c);
    ADD_FAILURE() << "a mesh with 1 tag for 4 faces was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "apply: the mesh has 1 face tags for 4 faces");
  }
  m.face_tags.clear();
  apply(m, c);
  EXPECT_EQ(m.face_tag(0), (FaceTag{FaceKind::cap, 1, EditKind::other}));  // made by hand
  EXPECT_EQ(m.face_tag(1), (FaceTag{FaceKind::skin, 0, EditKind::model}));
}

TEST(FaceTags, EachFaceNamesTheKindOfEditThatMadeIt) {
  // A cut (op 1), a drill (op 2), then a tear (ops 3 on, one per change it applies) on one
  // sphere: every face's edit is the kind of the operation whose op it carries, the model's
  // faces alone have op 0 and edit model, and every operation left faces of its kind.
  SkinnedMesh m = make_icosphere(4);
  Adjacency adj(m);
  ASSERT_EQ(
      cut(m, adj, Plane::from_normal_distance({0, 0, 1}, 0.6), {.cap = true}).result.capped_loops,
      1);
  const std::uint32_t after_cut = m.edits;
  FaceIndex index(m);
  const DrillResult d = drill(m, adj, index, {{0.5, 0.1, 2}, {0.5, 0.1, -2}, 0.15}, {});
  ASSERT_GT(d.holes, 0) << d.message;
  const std::uint32_t after_drill = m.edits;
  Tear tear(m, adj);
  for (int i = 0; i < 20; ++i) {
    const double a = -0.6 + 0.04 * i;  // a stroke over the sphere's side, away from the hole
    tear.advance({double(i),
                  {-2 * std::cos(a), 2 * std::sin(a), -0.1},
                  {-0.5 * std::cos(a), 0.5 * std::sin(a), 0.1}});
  }
  ASSERT_GT(m.edits, after_drill + 2);
  std::map<EditKind, std::int32_t> faces;
  for (std::int32_t f = 0; f < m.face_count(); ++f) {
    const FaceTag tag = m.face_tag(f);
    const EditKind expected = tag.op == 0             ? EditKind::model
                              : tag.op <= after_cut   ? EditKind::cut
                              : tag.op <= after_drill ? EditKind::drill
                                                      : EditKind::tear;
    EXPECT_EQ(tag.edit, expected) << "face " << f << ", op " << tag.op;
    ++faces[tag.edit];
  }
  for (const EditKind k : {EditKind::model, EditKind::cut, EditKind::drill, EditKind::tear})
    EXPECT_GT(faces[k], 0) << int(k);
  EXPECT_EQ(faces[EditKind::other], 0);
}

TEST(FaceTags, PlyCarriesSurfaceOpAndEdit) {
  SkinnedMesh m = make_icosphere(2);
  Adjacency adj(m);
  const Plane plane = Plane::from_normal_distance({0, 0, 1}, 0.3);
  ASSERT_EQ(cut(m, adj, plane, {.cap = true}).result.capped_loops, 1);
  const auto path = std::filesystem::temp_directory_path() /
                    ("conform_face_tags_" + std::to_string(::getpid()) + ".ply");
  io::write_mesh(path, m, {.format = io::MeshFormat::PlyAscii, .uvs = false});
  std::ifstream is(path);
  std::string line, header;
  int nv = 0, nf = 0;
  while (std::getline(is, line) && line != "end_header") {
    header += line + "\n";
    std::sscanf(line.c_str(), "element vertex %d", &nv);
    std::sscanf(line.c_str(), "element face %d", &nf);
  }
  EXPECT_NE(header.find("property list uchar int vertex_indices\nproperty uchar surface\n"
                        "property uint op\nproperty uchar edit\n"),
            std::string::npos)
      << header;
  ASSERT_EQ(nf, m.face_count());
  for (int i = 0; i < nv; ++i) std::getline(is, line);
  for (int f = 0; f < nf; ++f) {
    int n = 0, a = 0, b = 0, c = 0, surface = -1, edit = -1;
    unsigned op = 99;
    is >> n >> a >> b >> c >> surface >> op >> edit;
    EXPECT_EQ(surface, int(m.face_tag(f).kind)) << f;
    EXPECT_EQ(op, m.face_tag(f).op) << f;
    EXPECT_EQ(edit, int(m.face_tag(f).edit)) << f;
  }
  std::filesystem::remove(path);
}
