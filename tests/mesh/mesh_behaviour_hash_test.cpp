// A fingerprint of the mesh layer's behaviour: 2,000 seeded random cuts (with and without caps),
// tear strokes and drills (with and without tube walls; with a kept FaceIndex and without) on the
// procedural arm, a sheet and a sphere, hashed, against a constant recorded on the code before the
// restructuring of the mesh edits. A refactoring that changes any output changes the hash.
//
// Hashed: every returned TopologyChange (topology integers exactly, coefficients rounded to
// 1e-9), every result's counters and message, and the whole mesh after each group of operations
// (faces and bones exactly; positions rounded to 1e-9 of the input's bounding diagonal; weights,
// UVs and normals to 1e-9), so that the hash does not depend on the last bit of a double.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <random>
#include <string>

#include "conform/mesh/adjacency.hpp"
#include "conform/mesh/analysis.hpp"
#include "conform/mesh/cut.hpp"
#include "conform/mesh/drill.hpp"
#include "conform/mesh/face_index.hpp"
#include "conform/mesh/primitives.hpp"
#include "conform/mesh/tear.hpp"
#include "conform/mesh/topology_change.hpp"
#include "conform/skin/procedural_arm.hpp"

namespace {

using namespace conform::mesh;
using conform::skin::make_arm;
using Plane = conform::cga::Plane<double>;

// FNV-1a over 64-bit words.
class Hasher {
 public:
  explicit Hasher(double length_unit) : length_unit_(length_unit) {}
  void integer(std::int64_t v) {
    for (int i = 0; i < 8; ++i) {
      h_ ^= static_cast<std::uint64_t>(v >> (8 * i)) & 0xff;
      h_ *= 0x100000001b3ull;
    }
  }
  void rounded(double x, double unit) { integer(std::llround(x / unit)); }
  void length(double x) { rounded(x, 1e-9 * length_unit_); }
  void ratio(double x) { rounded(x, 1e-9); }
  void text(const std::string& s) {
    integer(static_cast<std::int64_t>(s.size()));
    for (const char c : s) integer(c);
  }
  void change(const TopologyChange& c) {
    integer(c.base_vertex_count);
    integer(c.base_face_count);
    integer(static_cast<std::int64_t>(c.new_vertices.size()));
    for (const NewVertex& v : c.new_vertices) {
      for (int k = 0; k < 3; ++k) integer(v.parents[k]), ratio(v.coefficients[k]);
      for (int k = 0; k < 3; ++k) length(v.displacement[k]);
    }
    integer(static_cast<std::int64_t>(c.removed_faces.size()));
    for (const std::int32_t f : c.removed_faces) integer(f);
    integer(static_cast<std::int64_t>(c.added_faces.size()));
    for (const Face& f : c.added_faces)
      for (const std::int32_t v : f) integer(v);
  }
  void mesh(const SkinnedMesh& m) {
    integer(m.vertex_count());
    integer(m.face_count());
    for (const Face& f : m.faces)
      for (const std::int32_t v : f) integer(v);
    for (std::int32_t v = 0; v < m.vertex_count(); ++v) {
      for (int k = 0; k < 3; ++k) length(m.rest(k, v)), length(m.current(k, v));
      for (int k = 0; k < kMaxInfluences; ++k) integer(m.bones(k, v)), ratio(m.weights(k, v));
      if (m.has_uvs())
        for (int k = 0; k < 2; ++k) ratio(m.uvs(k, v));
      if (m.has_normals())
        for (int k = 0; k < 3; ++k) ratio(m.normals(k, v));
    }
  }
  std::uint64_t value() const { return h_; }

 private:
  double length_unit_;
  std::uint64_t h_ = 0xcbf29ce484222325ull;
};

enum class Shape { Arm, Sheet, Sphere };

struct Subject {
  Shape shape;
  SkinnedMesh mesh;
  double size;  // bounding diagonal of the input
};

Eigen::Vector3d uniform_in_box(std::mt19937& rng, const SkinnedMesh& m) {
  std::uniform_real_distribution<double> u(0, 1);
  const Eigen::Vector3d lo = m.current.rowwise().minCoeff(), hi = m.current.rowwise().maxCoeff();
  return lo + (hi - lo).cwiseProduct(Eigen::Vector3d(u(rng), u(rng), u(rng)));
}

Eigen::Vector3d random_direction(std::mt19937& rng) {
  std::normal_distribution<double> g;
  Eigen::Vector3d n(g(rng), g(rng), g(rng));
  return n.norm() > 1e-6 ? n.normalized() : Eigen::Vector3d::UnitZ();
}

struct Tally {
  int operations = 0;
  int changed = 0;  // operations that changed the mesh
  int tubes = 0;
  int capped = 0;
  int unsnapped = 0;      // drills that un-snapped a rim vertex the hole would pinch
  int inside_out = 0;     // capped cuts with loops of an inside-out surface
  int cut_unsnapped = 0;  // capped cuts that kept a vertex off the plane (it pinched a loop)
  int border_stops = 0;   // tear steps refused: their path went through a vertex on a border
  int thin_waits = 0;     // tear steps waiting: the blade in a face too thin for a new tip
};

void random_cut(std::mt19937& rng, const Subject& s, SkinnedMesh& m, Adjacency& adj, Hasher& h,
                Tally& tally) {
  CutOptions o;
  o.cap = std::uniform_int_distribution<int>(0, 1)(rng) == 1;
  const Plane p = Plane::from_normal_point(random_direction(rng), uniform_in_box(rng, s.mesh));
  const std::int32_t misoriented = o.cap ? check_mesh(m).misoriented_edges : 0;
  const CutOutcome out = cut(m, adj, p, o);
  // Caps are oriented like the faces they close, an inside-out surface's too.
  if (o.cap) {
    EXPECT_LE(check_mesh(m).misoriented_edges, misoriented) << "cut " << tally.operations;
  }
  const CutResult& r = out.result;
  h.integer(static_cast<int>(r.status));
  h.change(r.change);
  for (const std::int8_t side : r.added_side) h.integer(side);
  for (const std::int64_t v : {r.crossed_edges, r.snapped_vertices, r.loops, r.capped_loops,
                               r.nested_loops, r.cap_faces, out.pieces.count})
    h.integer(v);
  h.text(r.message);
  tally.changed += !r.change.empty();
  tally.capped += r.capped_loops > 0;
  tally.inside_out += r.inside_out_loops > 0;
  tally.cut_unsnapped += r.unsnapped_vertices > 0;
}

void random_drill(std::mt19937& rng, const Subject& s, SkinnedMesh& m, Adjacency& adj,
                  FaceIndex& index, Hasher& h, Tally& tally) {
  std::uniform_real_distribution<double> u(0, 1);
  DrillOptions o;
  const int kind = std::uniform_int_distribution<int>(0, 3)(rng);
  o.tube = kind >= 2 && s.shape != Shape::Sheet;
  o.tube_ring_spacing = kind == 3 ? 1.5 : 0;
  const bool use_index = u(rng) < 0.5;
  DrillTool tool;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero(), axis = Eigen::Vector3d::UnitZ();
  switch (s.shape) {
    case Shape::Arm: {  // across the arm, through both walls
      const double z = 0.02 + 0.58 * u(rng), a = 2 * std::numbers::pi * u(rng);
      centre = {0.004 * (u(rng) - 0.5), 0.004 * (u(rng) - 0.5), z};
      axis = {std::cos(a), std::sin(a), 0.3 * (u(rng) - 0.5)};
      tool.radius = 0.004 + 0.008 * u(rng);
      break;
    }
    case Shape::Sheet:
      centre = {0.8 * (u(rng) - 0.5), 0.8 * (u(rng) - 0.5), 0};
      axis = Eigen::Vector3d(0.3 * (u(rng) - 0.5), 0.3 * (u(rng) - 0.5), 1);
      tool.radius = 0.02 + 0.08 * u(rng);
      break;
    case Shape::Sphere:
      centre = 0.3 * Eigen::Vector3d(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
      axis = random_direction(rng);
      tool.radius = 0.05 + 0.15 * u(rng);
      break;
  }
  axis.normalize();
  tool.tip = centre + s.size * axis;
  tool.base = centre - s.size * axis;
  const DrillResult r = use_index ? drill(m, adj, index, tool, o) : drill(m, adj, tool, o);
  if (!use_index) index.build(m);
  h.integer(static_cast<std::int64_t>(r.changes.size()));
  for (const TopologyChange& c : r.changes) h.change(c);
  for (const std::int64_t v :
       {r.holes, r.rim_vertices, r.snapped_rim_vertices, r.removed_area_faces,
        std::int32_t(r.refinements), r.tubes, r.tube_faces})
    h.integer(v);
  h.length(std::sqrt(std::max(0.0, r.removed_area)));
  h.text(r.message);
  tally.changed += !r.changes.empty();
  tally.tubes += r.tubes;
  tally.unsnapped += r.unsnapped_rim_vertices > 0;
}

void random_tear(std::mt19937& rng, const Subject& s, SkinnedMesh& m, Adjacency& adj,
                 FaceIndex& index, Hasher& h, Tally& tally) {
  std::uniform_real_distribution<double> u(-1, 1);
  const bool use_index = u(rng) < 0;
  Tear tear = use_index ? Tear(m, adj, index) : Tear(m, adj);
  Eigen::Vector2d p(0.2 * u(rng), 0.2 * u(rng));
  if (s.shape == Shape::Arm) p = {std::numbers::pi * u(rng), 0.3 + 0.2 * u(rng)};
  double heading = std::numbers::pi * u(rng);
  const double turn = 0.05 * u(rng);
  const double step = s.shape == Shape::Sheet ? 0.012 : s.shape == Shape::Sphere ? 0.03 : 0.006;
  bool changed = false;
  for (int i = 0; i < 8; ++i) {
    ScalpelSample sample;
    sample.t = i;
    switch (s.shape) {
      case Shape::Sheet:
        sample.a = {p.x(), p.y(), 0.5};
        sample.b = {p.x(), p.y(), -0.5};
        break;
      case Shape::Sphere: {  // radial, through the surface at (lon, lat) = p
        const Eigen::Vector3d d(std::cos(p.y()) * std::cos(p.x()),
                                std::cos(p.y()) * std::sin(p.x()), std::sin(p.y()));
        sample.a = 0.5 * d;
        sample.b = 1.5 * d;
        break;
      }
      case Shape::Arm:  // radial from the arm's axis at (angle, z) = p
        sample.a = {0, 0, p.y()};
        sample.b = {0.2 * std::cos(p.x()), 0.2 * std::sin(p.x()), p.y()};
        break;
    }
    const TearStep st = tear.advance(sample);
    h.integer(st.extended);
    h.integer(static_cast<std::int64_t>(st.changes.size()));
    for (const TopologyChange& c : st.changes) h.change(c);
    h.text(tear.message());
    tally.border_stops += tear.message().rfind("the path crosses a vertex on a border", 0) == 0;
    tally.thin_waits += tear.message().rfind("the blade is in a face too thin", 0) == 0;
    changed |= !st.changes.empty();
    const double arc = s.shape == Shape::Arm ? 8 : 1;  // the arm's p.x is an angle
    p += step * Eigen::Vector2d(arc * std::cos(heading), std::sin(heading));
    heading += turn;
  }
  h.integer(tear.path_length());
  h.integer(tear.steps());
  for (const std::int32_t v : tear.left_border()) h.integer(v);
  for (const std::int32_t v : tear.right_border()) h.integer(v);
  h.length(tear.length());
  if (tear.started() && u(rng) < 0) {
    for (const auto& [v, d] : tear.open(0.01 * s.size)) {
      h.integer(v);
      for (int k = 0; k < 3; ++k) h.length(d[k]);
    }
  }
  if (!use_index) index.build(m);
  tally.changed += changed;
}

TEST(MeshBehaviourHash, TwoThousandRandomOperations) {
  std::vector<Subject> subjects;
  subjects.push_back({Shape::Arm, make_arm(1).mesh, 0});
  subjects.push_back({Shape::Sheet, make_sheet(30, 30), 0});
  subjects.push_back({Shape::Sphere, make_icosphere(3), 0});
  for (Subject& s : subjects) s.size = bounding_diagonal(s.mesh);

  std::mt19937 rng(14);
  Hasher h(1.0);
  Tally tally;
  constexpr int kOperations = 2000, kGroup = 5;  // a fresh copy every kGroup operations
  for (int group = 0; tally.operations < kOperations; ++group) {
    const Subject& s = subjects[group % subjects.size()];
    Hasher local(s.size);
    SkinnedMesh m = s.mesh;
    Adjacency adj(m);
    FaceIndex index(m);
    for (int i = 0; i < kGroup && tally.operations < kOperations; ++i, ++tally.operations) {
      const int kind = std::uniform_int_distribution<int>(0, 2)(rng);
      if (kind == 0) {
        random_cut(rng, s, m, adj, local, tally);
        index.build(m);  // the cut does not keep an index
      } else if (kind == 1) {
        random_drill(rng, s, m, adj, index, local, tally);
      } else {
        random_tear(rng, s, m, adj, index, local, tally);
      }
    }
    local.mesh(m);
    h.integer(static_cast<std::int64_t>(local.value()));
  }
  // The operations do something (the hash is not of no-ops alone).
  EXPECT_GT(tally.changed, kOperations / 2);
  EXPECT_GT(tally.tubes, 20);
  EXPECT_GT(tally.capped, 20);
  RecordProperty("changed", tally.changed);
  RecordProperty("tubes", tally.tubes);
  RecordProperty("capped", tally.capped);
  RecordProperty("unsnapped", tally.unsnapped);
  RecordProperty("inside_out", tally.inside_out);
  std::printf(
      "capped cuts %d, with inside-out loops %d, unsnapped %d, tear border stops %d, thin waits "
      "%d\n",
      tally.capped, tally.inside_out, tally.cut_unsnapped, tally.border_stops, tally.thin_waits);
  char hex[32];
  std::snprintf(hex, sizeof hex, "0x%016llx", static_cast<unsigned long long>(h.value()));
  // Recorded on the code before the mesh edits were restructured (commit 98647a8):
  // 0x0431338af34689ee, unchanged by the restructuring. The tear's walk bound then
  // changed the message of 4 samples that already failed (their walks left the region the
  // blade swept by more than 8 edges); every mesh change is the same: 0xf46e68cfa1d01bdd.
  // The drill's pinch check (drill_pinch.hpp) then changed the 5 drills that had left a
  // non-manifold rim vertex (the `unsnapped` tally): 0xf75c5816d4884971.
  // Capping an inside-out group of loops with its triangles reversed (oriented_sections.hpp)
  // then changed exactly the 7 capped cuts that had left misoriented cap edges (the
  // `inside_out` tally; the orientation check above failed for those 7 before):
  // 0xd109ee957e8decf6. Keeping a vertex off the plane when its snap pinched a loop (cut.cpp's
  // rounds) then changed the one capped cut that does so (`cut_unsnapped`; without the rounds
  // the hash is the one before): 0x99201f199ccf7065. Refusing a tear path through a vertex on
  // a border in every split (the fuzz finding tear_path_through_border_vertex_pinch.bin, whose
  // path left such a vertex joined across the opening) then stopped 2 tear steps here
  // (`border_stops`): 0x647599644fe9423a. Putting the tip past the old tip's fan, on the
  // track's edge, where the blade is in a fan face too thin for a tip inside it
  // (split_with_tip_past_fan) then extended 45 of the 226 steps that waited there
  // (`thin_waits`): 0x67835672fdc60b5b. Letting that tip go on the vertex where Π leaves the
  // fan's face, or on its exit edge within a snap behind the hit, then extended 13 more:
  // 0x5d6279ae7968a2a2.
  EXPECT_EQ(tally.unsnapped, 5);
  EXPECT_EQ(tally.inside_out, 7);
  EXPECT_EQ(tally.cut_unsnapped, 1);
  EXPECT_EQ(tally.border_stops, 2);
  EXPECT_EQ(tally.thin_waits, 168);
  EXPECT_EQ(h.value(), 0x5d6279ae7968a2a2ull) << "behaviour hash " << hex;
}

}  // namespace
