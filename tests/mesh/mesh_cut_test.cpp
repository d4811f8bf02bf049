#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <set>

#include <filesystem>
#include "conform/cga/versor.hpp"

#include "added_face_angles.hpp"
#include "conform/io/import.hpp"
#include "conform/mesh/analysis.hpp"
#include "conform/mesh/cut.hpp"
#include "conform/mesh/primitives.hpp"
#include "conform/skin/procedural_arm.hpp"
#include "skin_reference.hpp"
#include "support/sanitized.hpp"

using namespace conform;
using namespace conform::mesh;
using conform::skin::make_arm;
using Plane = cga::Plane<double>;
using conform::test::added_face_angles;
using conform::test::AngleReport;

namespace {

// The cap faces of a cut: the last 2 × cap_faces added faces when capping succeeded.
std::vector<Face> cap_faces(const CutResult& r) {
  const auto& added = r.change.added_faces;
  return {added.end() - std::min<std::ptrdiff_t>(2 * r.cap_faces, std::ssize(added)), added.end()};
}

// Invariants every cut must keep (the input being closed/manifold/oriented where stated).
// The input's report is cached by address: property tests cut the same input many times.
void expect_valid(const SkinnedMesh& m, const SkinnedMesh& input, const std::string& what) {
  static const SkinnedMesh* cached = nullptr;
  static std::int32_t cached_faces = -1;
  static MeshReport before;
  if (cached != &input || cached_faces != input.face_count()) {
    before = check_mesh(input);
    cached = &input, cached_faces = input.face_count();
  }
  const MeshReport r = check_mesh(m, 1e-14 * std::pow(bounding_diagonal(input), 2));
  EXPECT_TRUE(r.indices_valid) << what;
  EXPECT_TRUE(r.finite) << what;
  EXPECT_EQ(r.tiny_faces, 0) << what;
  if (before.manifold()) {
    EXPECT_EQ(r.overused_edges, 0) << what;
    EXPECT_EQ(r.nonmanifold_vertices, 0) << what << ": " << r.summary();
  }
  if (before.oriented()) {
    EXPECT_EQ(r.misoriented_edges, 0) << what;
  }
  // Skinning data stays well formed: weights sum to 1, sorted decreasing.
  Eigen::Index bad = -1;
  for (Eigen::Index v = 0; v < m.weights.cols() && bad < 0; ++v) {
    if (std::abs(m.weights.col(v).sum() - 1.0) > 1e-12) bad = v;
    for (int k = 1; k < kMaxInfluences; ++k)
      if (m.weights(k - 1, v) < m.weights(k, v)) bad = v;
  }
  EXPECT_EQ(bad, -1) << what;
}

Plane random_plane(std::mt19937& rng, const SkinnedMesh& m) {
  std::normal_distribution<double> g;
  const Eigen::Vector3d lo = m.current.rowwise().minCoeff(), hi = m.current.rowwise().maxCoeff();
  std::uniform_real_distribution<double> u(0, 1);
  const Eigen::Vector3d point =
      lo + (hi - lo).cwiseProduct(Eigen::Vector3d(u(rng), u(rng), u(rng)));
  Eigen::Vector3d n(g(rng), g(rng), g(rng));
  return Plane::from_normal_point(n, point);
}

// The areas of the pieces (cap faces excluded) add up to the input's area.
void expect_area_kept(const SkinnedMesh& input, const SkinnedMesh& out, const CutResult& r,
                      const std::string& what) {
  double cap_area = 0;
  const auto base = r.change.base_face_count;
  (void)base;
  std::vector<std::int32_t> caps;
  // Cap faces are the last 2 × cap_faces added faces when capping succeeded.
  const auto nadded = static_cast<std::int32_t>(r.change.added_faces.size());
  for (std::int32_t k = nadded - 2 * r.cap_faces; k < nadded; ++k) {
    const Face& f = r.change.added_faces[static_cast<std::size_t>(k)];
    const Eigen::Vector3d a = out.current.col(f[0]);
    cap_area += 0.5 * (out.current.col(f[1]) - a).cross(out.current.col(f[2]) - a).norm();
  }
  const double a0 = surface_area(input);
  EXPECT_NEAR(surface_area(out) - cap_area, a0, 1e-9 * a0) << what;
}

}  // namespace

TEST(Cut, IcosphereInTwoWithInvariants) {
  const SkinnedMesh in = make_icosphere(3);
  SkinnedMesh m = in;
  Adjacency adj(m);
  const auto out = cut(m, adj, Plane::from_normal_distance({0.2, 0.1, 1.0}, 0.13));
  ASSERT_EQ(out.result.status, CutStatus::Cut);
  EXPECT_EQ(out.pieces.count, 2);
  EXPECT_GT(out.result.crossed_edges, 10);
  expect_valid(m, in, "icosphere");
  expect_area_kept(in, m, out.result, "icosphere");
  // Each piece lies on one side of the plane (up to the snap distance).
  const Plane p = Plane::from_normal_distance({0.2, 0.1, 1.0}, 0.13);
  for (std::int32_t piece = 0; piece < 2; ++piece) {
    double lo = 1e9, hi = -1e9;
    for (auto f : out.pieces.faces_of(piece))
      for (auto v : m.faces[static_cast<std::size_t>(f)]) {
        lo = std::min(lo, p.signed_distance(m.current.col(v)));
        hi = std::max(hi, p.signed_distance(m.current.col(v)));
      }
    EXPECT_TRUE(lo > -0.02 || hi < 0.02) << lo << " " << hi;
  }
  // The adjacency kept up to date equals one rebuilt from scratch.
  Adjacency fresh(m);
  for (std::int32_t h = 0; h < 3 * m.face_count(); ++h) ASSERT_EQ(adj.twin(h), fresh.twin(h)) << h;
}

TEST(Cut, CapsCloseEveryPieceAndKeepVolume) {
  const SkinnedMesh in = make_icosphere(3);
  SkinnedMesh m = in;
  Adjacency adj(m);
  const auto out = cut(m, adj, Plane::from_normal_distance({1, -0.3, 0.4}, -0.2), {.cap = true});
  ASSERT_EQ(out.result.status, CutStatus::Cut);
  EXPECT_EQ(out.result.loops, 1);
  EXPECT_EQ(out.result.capped_loops, 1) << out.result.message;
  ASSERT_EQ(out.pieces.count, 2);
  const double v0 = signed_volume(in);
  double v = 0;
  for (std::int32_t p = 0; p < out.pieces.count; ++p) {
    const auto faces = out.pieces.faces_of(p);
    SkinnedMesh piece = m;
    piece.faces.clear();
    for (auto f : faces) piece.faces.push_back(m.faces[static_cast<std::size_t>(f)]);
    const MeshReport r = check_mesh(piece);
    EXPECT_TRUE(r.closed()) << r.summary();
    EXPECT_TRUE(r.oriented());
    EXPECT_TRUE(r.manifold()) << r.summary();
    EXPECT_GT(signed_volume(piece), 0);
    v += signed_volume(piece);
  }
  EXPECT_NEAR(v, v0, 1e-9 * v0);
  expect_area_kept(in, m, out.result, "capped icosphere");
  expect_valid(m, in, "capped icosphere");
}

// Two closed meshes as one (positions, influences and faces only).
SkinnedMesh together(const SkinnedMesh& a, const SkinnedMesh& b) {
  const Eigen::Index na = a.rest.cols(), nb = b.rest.cols();
  Eigen::Matrix3Xd x(3, na + nb);
  x << a.current, b.current;
  Eigen::Matrix<std::int32_t, kMaxInfluences, Eigen::Dynamic> bones(kMaxInfluences, na + nb);
  bones << a.bones, b.bones;
  Eigen::Matrix<double, kMaxInfluences, Eigen::Dynamic> weights(kMaxInfluences, na + nb);
  weights << a.weights, b.weights;
  SkinnedMesh m;
  m.rest = x, m.current = x, m.bones = bones, m.weights = weights;
  m.faces = a.faces;
  for (Face f : b.faces) {
    for (auto& v : f) v += std::int32_t(na);
    m.faces.push_back(f);
  }
  return m;
}

TEST(Cut, CapsFollowEachLoopsDirectionWhenPiecesOverlap) {
  // A running simulation's pieces overlap: a small closed sphere inside a larger one. The
  // inner sphere's loop lies inside the outer's but is no hole of it (it runs the same way):
  // each is capped as a disc of its own, and every piece is closed and oriented (one section
  // for both made the inner loop a hole: cap faces oriented like their neighbours).
  const SkinnedMesh in = together(make_icosphere(3, 1.0), make_icosphere(3, 0.5));
  SkinnedMesh m = in;
  Adjacency adj(m);
  const auto out = cut(m, adj, Plane::from_normal_distance({0.1, 0.2, 1}, 0.1), {.cap = true});
  ASSERT_EQ(out.result.status, CutStatus::Cut);
  EXPECT_EQ(out.result.loops, 2);
  EXPECT_EQ(out.result.capped_loops, 2) << out.result.message;
  EXPECT_EQ(out.result.nested_loops, 0);
  ASSERT_EQ(out.pieces.count, 4);
  for (std::int32_t p = 0; p < out.pieces.count; ++p) {
    SkinnedMesh piece = m;
    piece.faces.clear();
    for (auto f : out.pieces.faces_of(p)) piece.faces.push_back(m.faces[std::size_t(f)]);
    const MeshReport r = check_mesh(piece);
    EXPECT_TRUE(r.closed() && r.oriented() && r.manifold()) << "piece " << p << ": " << r.summary();
    EXPECT_GT(signed_volume(piece), 0) << "piece " << p;
  }
}

// `m` with every face reversed (an inside-out surface) and moved by `shift`.
SkinnedMesh inside_out(SkinnedMesh m, const Eigen::Vector3d& shift = Eigen::Vector3d::Zero()) {
  for (Face& f : m.faces) std::swap(f[1], f[2]);
  m.rest.colwise() += shift, m.current.colwise() += shift;
  return m;
}

TEST(Cut, CapsOfAnInsideOutSurfaceAreOrientedLikeItsFaces) {
  // A surface can be inside out (a piece turned through itself in a running simulation, a
  // model wound the other way): its loop runs clockwise with no loop around it. Its caps are
  // oriented like its own faces, alone, beside an outward sphere in the same plane, and
  // inside one (then the outward sphere's loop runs against the inside-out one's nesting).
  const SkinnedMesh ball = make_icosphere(3, 1.0), small = make_icosphere(3, 0.5);
  struct Case {
    std::string name;
    SkinnedMesh mesh;
    int inside_out_pieces;
  };
  const std::vector<Case> cases = {
      {"alone", inside_out(ball), 2},
      {"beside an outward sphere", together(inside_out(ball, {3, 0, 0}), ball), 2},
      {"around an outward sphere", together(inside_out(ball), small), 2}};
  for (const Case& c : cases) {
    SkinnedMesh m = c.mesh;
    Adjacency adj(m);
    const auto out = cut(m, adj, Plane::from_normal_distance({0.1, 0.2, 1}, 0.1), {.cap = true});
    ASSERT_EQ(out.result.status, CutStatus::Cut) << c.name;
    EXPECT_EQ(out.result.capped_loops, out.result.loops) << c.name << ": " << out.result.message;
    int negative = 0;
    for (std::int32_t p = 0; p < out.pieces.count; ++p) {
      SkinnedMesh piece = m;
      piece.faces.clear();
      for (auto f : out.pieces.faces_of(p)) piece.faces.push_back(m.faces[std::size_t(f)]);
      const MeshReport r = check_mesh(piece);
      EXPECT_TRUE(r.closed() && r.oriented() && r.manifold())
          << c.name << ", piece " << p << ": " << r.summary();
      negative += signed_volume(piece) < 0;
    }
    EXPECT_EQ(negative, c.inside_out_pieces) << c.name;
  }
}

TEST(Cut, OnePlaneManyPieces) {
  // A U-shaped tube (the cylinder bent by hand) cut across both legs gives three pieces.
  SkinnedMesh m = make_cylinder(24, 40, 0.1, 2.0);
  for (Eigen::Index v = 0; v < m.current.cols(); ++v) {
    const double z = m.rest(2, v), a = z / 2.0 * M_PI;  // bend the axis along a half circle
    const double x = m.rest(0, v);
    m.current(0, v) = (0.5 + x) * std::cos(a);
    m.current(2, v) = (0.5 + x) * std::sin(a);
  }
  const SkinnedMesh in = m;
  Adjacency adj(m);
  const auto out = cut(m, adj, Plane::from_normal_distance({0, 0, 1}, 0.2), {.cap = true});
  ASSERT_EQ(out.result.status, CutStatus::Cut);
  EXPECT_EQ(out.pieces.count, 3);
  EXPECT_EQ(out.result.capped_loops, 2) << out.result.message;
  expect_valid(m, in, "U tube");
  expect_area_kept(in, m, out.result, "U tube");
}

TEST(Cut, PropertyRandomPlanes) {
  struct Model {
    std::string name;
    SkinnedMesh mesh;
    bool closed;
  };
  std::vector<Model> models = {{"icosphere", make_icosphere(3), true},
                               {"sheet", make_sheet(30, 20), false},
                               {"cylinder", make_cylinder(32, 20, 0.2, 1.0), true},
                               {"arm", make_arm(1).mesh, true}};
  std::mt19937 rng(1234);
  const int trials = conform::test::trial_count(400, 100);  // per model
  int cuts = 0, capped_all = 0;
  std::map<std::string, double> smallest;  // of the faces the cuts added, caps excluded
  for (const Model& model : models) smallest[model.name] = M_PI;
  for (const Model& model : models) {
    for (int trial = 0; trial < trials; ++trial) {
      SkinnedMesh m = model.mesh;
      Adjacency adj(m);
      const Plane p = random_plane(rng, m);
      const bool cap = trial % 2 == 0;
      const auto out = cut(m, adj, p, {.cap = cap});
      const std::string what = model.name + " trial " + std::to_string(trial);
      if (out.result.status != CutStatus::Cut) {
        EXPECT_TRUE(out.result.change.empty()) << what;
        EXPECT_EQ(m.faces, model.mesh.faces) << what;
        continue;
      }
      ++cuts;
      EXPECT_GE(out.pieces.count, 2) << what;
      {
        const AngleReport ar =
            added_face_angles(model.mesh, m, kCutMinAngle, cap_faces(out.result));
        smallest[model.name] = std::min(smallest[model.name], ar.smallest);
        EXPECT_GE(ar.worst_ratio, 1 - 1e-9) << what << ": a sliver";
      }
      expect_valid(m, model.mesh, what);
      expect_area_kept(model.mesh, m, out.result, what);
      if (cap && model.closed && out.result.capped_loops == out.result.loops) {
        ++capped_all;
        const MeshReport r = check_mesh(m);
        EXPECT_TRUE(r.closed()) << what << ": " << r.summary();
        double v = 0;
        for (std::int32_t piece = 0; piece < out.pieces.count; ++piece)
          v += signed_volume(m, out.pieces.faces_of(piece));
        const double v0 = signed_volume(model.mesh);
        EXPECT_NEAR(v, v0, 1e-9 * std::abs(v0)) << what;
      }
    }
  }
  EXPECT_GT(cuts, 2 * trials);  // of 4 × trials
  EXPECT_GT(capped_all, 250 * trials / 400);
  for (const auto& [name, a] : smallest)
    RecordProperty("smallest_added_angle_deg_" + name, std::to_string(a * 180 / M_PI));
}

TEST(Cut, NewVerticesCarryAttributesAndWeights) {
  const SkinnedMesh in = make_cylinder(16, 12, 0.3, 1.0);
  SkinnedMesh m = in;
  Adjacency adj(m);
  const auto out = cut(m, adj, Plane::from_normal_distance({0.1, 0, 1}, 0.37));
  ASSERT_EQ(out.result.status, CutStatus::Cut);
  const auto& nvs = out.result.change.new_vertices;
  for (std::size_t i = 0; i < nvs.size(); ++i) {
    const auto v = static_cast<Eigen::Index>(in.vertex_count() + static_cast<std::int32_t>(i));
    const NewVertex& nv = nvs[i];
    if (nv.is_duplicate()) {
      EXPECT_EQ(m.rest.col(v), m.rest.col(nv.parents[0]));
      EXPECT_EQ(m.weights.col(v), m.weights.col(nv.parents[0]));
      continue;
    }
    const double t = nv.coefficients[1];
    EXPECT_GE(t, 0.01);
    EXPECT_LE(t, 0.99);
    const auto a = nv.parents[0], b = nv.parents[1];
    EXPECT_LT((m.rest.col(v) - ((1 - t) * in.rest.col(a) + t * in.rest.col(b))).norm(), 1e-14);
    EXPECT_LT((m.uvs.col(v) - ((1 - t) * in.uvs.col(a) + t * in.uvs.col(b))).norm(), 1e-14);
    EXPECT_NEAR(m.normals.col(v).norm(), 1.0, 1e-12);
    // §4.3: the blended weight of each bone (no more than 3 bones here, so no truncation).
    for (int bone = 0; bone < 3; ++bone) {
      auto w = [&](const SkinnedMesh& mm, Eigen::Index x) {
        double s = 0;
        for (int k = 0; k < kMaxInfluences; ++k)
          if (mm.bones(k, x) == bone) s += mm.weights(k, x);
        return s;
      };
      EXPECT_NEAR(w(m, v), (1 - t) * w(in, a) + t * w(in, b), 1e-12);
    }
  }
}

TEST(Cut, WeightsKeepFourLargestAndRenormalize) {
  SkinnedMesh m = make_sheet(1, 1);
  m.bones.col(0) << 0, 1, 2, 3;
  m.weights.col(0) << 0.4, 0.3, 0.2, 0.1;
  m.bones.col(2) << 4, 5, 6, 7;
  m.weights.col(2) << 0.7, 0.1, 0.1, 0.1;
  m.bones.conservativeResize(4, 5);
  m.weights.conservativeResize(4, 5);
  m.rest.conservativeResize(3, 5);
  m.current.conservativeResize(3, 5);
  m.uvs.resize(2, 0);
  m.normals.resize(3, 0);
  blend_influences(m, {0, 2, -1}, {0.5, 0.5, 0}, 4);
  // Blend: 0:.2 1:.15 2:.1 3:.05 4:.35 5:.05 6:.05 7:.05 → keep 4, 0, 1, 2 → renormalize by .8.
  EXPECT_EQ(m.bones(0, 4), 4);
  EXPECT_EQ(m.bones(1, 4), 0);
  EXPECT_EQ(m.bones(2, 4), 1);
  EXPECT_EQ(m.bones(3, 4), 2);
  EXPECT_NEAR(m.weights(0, 4), 0.35 / 0.8, 1e-15);
  EXPECT_NEAR(m.weights(3, 4), 0.1 / 0.8, 1e-15);
}

TEST(Cut, DegenerateInputs) {
  const SkinnedMesh in = make_icosphere(2);
  {  // plane missing the mesh: documented no-op
    SkinnedMesh m = in;
    Adjacency adj(m);
    const auto out = cut(m, adj, Plane::from_normal_distance({0, 0, 1}, 5));
    EXPECT_EQ(out.result.status, CutStatus::Missed);
    EXPECT_TRUE(out.result.change.empty());
    EXPECT_EQ(out.pieces.count, 1);
  }
  {  // tangent at the north pole (a vertex): touches only
    SkinnedMesh m = make_icosphere(0);
    const Eigen::Vector3d top = m.current.col(0);
    Adjacency adj(m);
    const auto out = cut(m, adj, Plane::from_normal_point(top, top));
    EXPECT_EQ(out.result.status, CutStatus::Missed);
  }
  {  // NaN and zero normals, NaN positions: clear errors, mesh untouched
    SkinnedMesh m = in;
    Adjacency adj(m);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    Plane bad;
    bad.e1 = nan, bad.e3 = 1;
    EXPECT_THROW(cut(m, adj, bad), std::invalid_argument);
    Plane zero;
    EXPECT_THROW(cut(m, adj, zero), std::invalid_argument);
    SkinnedMesh broken = in;
    broken.current(0, 3) = nan;
    EXPECT_THROW(compute_cut(broken, Plane::from_normal_distance({0, 0, 1}, 0)),
                 std::invalid_argument);
    EXPECT_EQ(m.faces, in.faces);
  }
  {  // plane through vertices (the icosphere's equator has vertices at z = 0) and along edges
    SkinnedMesh s = make_sheet(10, 10);
    const SkinnedMesh s0 = s;
    Adjacency adj(s);
    const auto out = cut(s, adj, Plane::from_normal_distance({1, 0, 0}, 0.0));  // a grid line
    ASSERT_EQ(out.result.status, CutStatus::Cut);
    EXPECT_EQ(out.result.crossed_edges, 0);
    EXPECT_EQ(out.pieces.count, 2);
    expect_valid(s, s0, "sheet along edges");
    expect_area_kept(s0, s, out.result, "sheet along edges");
    SkinnedMesh e = in;
    Adjacency adj2(e);
    const auto out2 = cut(e, adj2, Plane::from_normal_distance({0, 0, 1}, 0.0), {.cap = true});
    ASSERT_EQ(out2.result.status, CutStatus::Cut);
    EXPECT_EQ(out2.pieces.count, 2);
    EXPECT_EQ(out2.result.capped_loops, 1) << out2.result.message;
    expect_valid(e, in, "equator");
    EXPECT_TRUE(check_mesh(e).closed());
  }
  {  // coplanar faces: a flat sheet in the cutting plane is a no-op; a cylinder's cap plane too
    SkinnedMesh s = make_sheet(4, 4);
    Adjacency adj(s);
    EXPECT_EQ(cut(s, adj, Plane::from_normal_distance({0, 0, 1}, 0.0)).result.status,
              CutStatus::Missed);
    SkinnedMesh c = make_cylinder(8, 4, 0.5, 1.0);
    Adjacency adjc(c);
    EXPECT_EQ(cut(c, adjc, Plane::from_normal_distance({0, 0, 1}, 1.0)).result.status,
              CutStatus::Missed);
  }
  {  // a plane through a ring of the cylinder (vertices and edges in the plane), capped
    SkinnedMesh c = make_cylinder(12, 6, 0.5, 1.0);
    const SkinnedMesh c0 = c;
    Adjacency adj(c);
    const auto out = cut(c, adj, Plane::from_normal_distance({0, 0, 1}, 0.5), {.cap = true});
    ASSERT_EQ(out.result.status, CutStatus::Cut);
    EXPECT_EQ(out.pieces.count, 2);
    EXPECT_EQ(out.result.capped_loops, 1) << out.result.message;
    expect_valid(c, c0, "ring");
    EXPECT_TRUE(check_mesh(c).closed());
  }
}

TEST(Cut, SnappingAvoidsSlivers) {
  SkinnedMesh s = make_sheet(10, 10);
  const SkinnedMesh s0 = s;
  Adjacency adj(s);
  // 0.1 % of an edge away from a grid line: snapped onto it rather than making needles.
  const auto out = cut(s, adj, Plane::from_normal_distance({1, 0, 0}, 0.0001));
  ASSERT_EQ(out.result.status, CutStatus::Cut);
  EXPECT_GT(out.result.snapped_vertices, 0);
  double min_ratio = 1;
  for (const Face& f : s.faces) {
    const Eigen::Vector3d a = s.current.col(f[0]);
    min_ratio = std::min(
        min_ratio, 0.5 * (s.current.col(f[1]) - a).cross(s.current.col(f[2]) - a).norm() / 0.005);
  }
  EXPECT_GT(min_ratio, 0.01 * 0.01);
  expect_valid(s, s0, "snapped");
  EXPECT_GE(added_face_angles(s0, s, kCutMinAngle).worst_ratio, 1 - 1e-9);
  // A plane close to a grid line's vertices at a slant: crossings near them are snapped by
  // the angle they would make, not only within 1 % of an edge.
  SkinnedMesh t = s0;
  Adjacency adj2(t);
  const auto slant = cut(t, adj2, Plane::from_normal_distance({1, 0.02, 0}, 0.004));
  ASSERT_EQ(slant.result.status, CutStatus::Cut);
  EXPECT_GT(slant.result.snapped_vertices, 0);
  expect_valid(t, s0, "slant");
  EXPECT_GE(added_face_angles(s0, t, kCutMinAngle).worst_ratio, 1 - 1e-9);
  expect_area_kept(s0, t, slant.result, "slant");
}

TEST(Cut, ReDeformation) {
  // Cut the posed mesh, then re-skin the result with another pose, against skinning the
  // original with that pose and applying the same change.
  const SkinnedMesh original = make_arm(1).mesh;
  const auto [pose1, pose2] = conform::test::arm_test_poses();
  SkinnedMesh posed = original;
  posed.current = conform::test::reference_lbs(original, pose1);
  for (const double z : {0.12, 0.31, 0.5, 0.58}) {  // upper arm, elbow, forearm/wrist blend, hand
    SkinnedMesh a = posed;
    Adjacency adj(a);
    const auto out = cut(a, adj, Plane::from_normal_point({0.2, 0.1, 1}, {0, 0, z}), {.cap = true});
    ASSERT_EQ(out.result.status, CutStatus::Cut);
    a.current = conform::test::reference_lbs(a, pose2);  // re-skin the changed mesh
    SkinnedMesh b = original;
    b.current = conform::test::reference_lbs(original, pose2);
    apply(b, out.result.change);  // the same change applied to the re-posed original
    ASSERT_EQ(a.vertex_count(), b.vertex_count());
    EXPECT_EQ(a.faces, b.faces);
    double worst_same = 0, worst_blend = 0;
    std::vector<char> exact;
    for (Eigen::Index v = 0; v < a.current.cols(); ++v) {
      const double err = (a.current.col(v) - b.current.col(v)).norm();
      // New vertices whose parents have the same influences deform exactly like their
      // parents' interpolation; where the influences differ, LBS of an interpolated point is
      // not the interpolation of LBS'd points (a t(1 − t) term), so only closeness holds.
      bool same = true;
      if (v >= original.vertex_count()) {
        const auto& nv =
            out.result.change.new_vertices[static_cast<std::size_t>(v - original.vertex_count())];
        if (nv.is_duplicate()) {
          same = exact[static_cast<std::size_t>(nv.parents[0])];
        } else {
          for (int k = 1; k < 3; ++k)
            if (nv.parents[k] >= 0 &&
                (a.weights.col(nv.parents[k]) != a.weights.col(nv.parents[0]) ||
                 a.bones.col(nv.parents[k]) != a.bones.col(nv.parents[0])))
              same = false;
        }
      }
      exact.push_back(same);
      (same ? worst_same : worst_blend) = std::max(same ? worst_same : worst_blend, err);
    }
    EXPECT_LT(worst_same, 1e-9) << "z " << z;
    EXPECT_LT(worst_blend, 2e-3) << "z " << z;  // well under the arm's 6 mm ring spacing
    RecordProperty("worst_blended_z" + std::to_string(int(z * 100)), std::to_string(worst_blend));
    RecordProperty("worst_exact_z" + std::to_string(int(z * 100)), std::to_string(worst_same));
  }
}

TEST(Cut, PropertyRealModels) {
  // Real rigged models from assimp-testmodels (they need not be closed or manifold: the
  // invariants that hold for the input are checked).
  int cuts = 0, capped = 0, unsnapped = 0;
  for (const char* file :
       {"FBX/huesitos.fbx", "X/anim_test.x", "glTF2/simple_skin/simple_skin.gltf"}) {
    const std::filesystem::path path = std::filesystem::path(CONFORM_ASSIMP_MODELS) / file;
    if (!std::filesystem::exists(path)) continue;
    // Welded, as users get them. Welded, huesitos.fbx is closed, and in capped trial 184 two
    // vertices snapped onto the plane make a mesh edge in the plane with both faces on the
    // positive side (a crease touching the plane): the section triangulation must not use it
    // as a diagonal, or that edge gets four faces (cap.hpp, forbidden diagonals).
    const SkinnedMesh in = io::load_model(path.string()).mesh;
    std::mt19937 rng(99);
    for (int trial = 0; trial < 200; ++trial) {
      SkinnedMesh m = in;
      Adjacency adj(m);
      const auto out = cut(m, adj, random_plane(rng, m), {.cap = trial % 2 == 0});
      if (out.result.status != CutStatus::Cut) continue;
      ++cuts;
      const std::string what = std::string(file) + " trial " + std::to_string(trial);
      expect_valid(m, in, what);
      expect_area_kept(in, m, out.result, what);
      EXPECT_GE(added_face_angles(in, m, kCutMinAngle, cap_faces(out.result)).worst_ratio, 1 - 1e-9)
          << what << ": a sliver";
      // Every loop is capped, also where a vertex snapped onto the plane near a saddle would
      // make the section meet itself (4 of huesitos' 92 capped trials did, uncapped, before
      // the cut kept such vertices off the plane: `unsnapped_vertices`).
      if (trial % 2 == 0) {
        EXPECT_EQ(out.result.capped_loops, out.result.loops) << what << ": " << out.result.message;
        capped += out.result.loops > 0;
        unsnapped += out.result.unsnapped_vertices > 0;
      }
      if (testing::Test::HasFailure()) return;
    }
  }
  if (cuts == 0) GTEST_SKIP() << "assimp-testmodels not installed";
  EXPECT_GT(cuts, 100);
  EXPECT_GT(unsnapped, 0);  // the case occurs
  std::printf("capped trials %d, of which %d kept a pinching vertex off the plane\n", capped,
              unsnapped);
  RecordProperty("unsnapped_trials", unsnapped);
}
