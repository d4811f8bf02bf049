// Caps of cuts whose cross-section has nested loops (a hollow tube, a torus cut through its
// hole's plane, a tube inside a tube), with both section triangulators, and the section
// triangulation itself against exact areas and triangle counts.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "conform/mesh/analysis.hpp"
#include "conform/mesh/cap.hpp"
#include "conform/mesh/cut.hpp"
#include "conform/mesh/primitives.hpp"

using namespace conform;
using namespace conform::mesh;
using Plane = cga::Plane<double>;
using Loops = std::vector<std::vector<Eigen::Vector2d>>;

namespace {

// A closed surface of revolution about z for each closed profile (ρ > 0, z), `segments`
// around; each component oriented outward (flipped if its volume came out negative), with
// the primitives' height weights so that cuts blend skinning data.
SkinnedMesh revolve(const std::vector<std::vector<Eigen::Vector2d>>& profiles, int segments) {
  SkinnedMesh m;
  std::vector<Eigen::Vector3d> pts;
  for (const auto& prof : profiles) {
    const auto base = static_cast<std::int32_t>(pts.size());
    const auto np = static_cast<std::int32_t>(prof.size());
    for (std::int32_t j = 0; j < np; ++j)
      for (int s = 0; s < segments; ++s) {
        const double a = 2 * M_PI * s / segments;
        pts.emplace_back(prof[static_cast<std::size_t>(j)].x() * std::cos(a),
                         prof[static_cast<std::size_t>(j)].x() * std::sin(a),
                         prof[static_cast<std::size_t>(j)].y());
      }
    const std::size_t first = m.faces.size();
    auto id = [&](std::int32_t j, int s) { return base + (j % np) * segments + s % segments; };
    for (std::int32_t j = 0; j < np; ++j)
      for (int s = 0; s < segments; ++s) {
        m.faces.push_back({id(j, s), id(j, s + 1), id(j + 1, s + 1)});
        m.faces.push_back({id(j, s), id(j + 1, s + 1), id(j + 1, s)});
      }
    double v = 0;
    for (std::size_t f = first; f < m.faces.size(); ++f) {
      const Face& t = m.faces[f];
      v += pts[static_cast<std::size_t>(t[0])].dot(
          pts[static_cast<std::size_t>(t[1])].cross(pts[static_cast<std::size_t>(t[2])]));
    }
    if (v < 0)
      for (std::size_t f = first; f < m.faces.size(); ++f) std::swap(m.faces[f][1], m.faces[f][2]);
  }
  m.rest.resize(3, static_cast<Eigen::Index>(pts.size()));
  for (std::size_t i = 0; i < pts.size(); ++i) m.rest.col(static_cast<Eigen::Index>(i)) = pts[i];
  m.current = m.rest;
  assign_height_weights(m, 0.3, 0.7, 0.1);
  return m;
}

// A rectangle [r0, r1] × [z0, z1] in the (ρ, z) half plane, n points per side.
std::vector<Eigen::Vector2d> rectangle(double r0, double r1, double z0, double z1, int n) {
  std::vector<Eigen::Vector2d> p;
  for (int i = 0; i < n; ++i) p.emplace_back(r0 + (r1 - r0) * i / n, z0);
  for (int i = 0; i < n; ++i) p.emplace_back(r1, z0 + (z1 - z0) * i / n);
  for (int i = 0; i < n; ++i) p.emplace_back(r1 - (r1 - r0) * i / n, z1);
  for (int i = 0; i < n; ++i) p.emplace_back(r0, z1 - (z1 - z0) * i / n);
  return p;
}

std::vector<Eigen::Vector2d> circle(double cx, double cz, double r, int n) {
  std::vector<Eigen::Vector2d> p;
  for (int i = 0; i < n; ++i)
    p.emplace_back(cx + r * std::cos(2 * M_PI * i / n), cz + r * std::sin(2 * M_PI * i / n));
  return p;
}

SkinnedMesh thick_tube() {
  return revolve({rectangle(0.3, 0.5, 0.0, 1.0, 12)}, 48);
}
SkinnedMesh torus() {
  return revolve({circle(0.6, 0.5, 0.2, 24)}, 48);
}
SkinnedMesh tube_in_tube() {
  return revolve({rectangle(0.45, 0.6, 0.0, 1.0, 10), rectangle(0.15, 0.3, 0.1, 0.9, 10)}, 40);
}

// Every piece closed, manifold and oriented, with positive volume; the volumes add up to the
// input's to 1e-9 relative; the pieces' areas less the caps' add up to the input's.
void expect_closed_pieces(const SkinnedMesh& in, const SkinnedMesh& m, const CutOutcome& out,
                          const std::string& what) {
  const double v0 = signed_volume(in);
  double v = 0;
  for (std::int32_t p = 0; p < out.pieces.count; ++p) {
    SkinnedMesh piece = m;
    piece.faces.clear();
    for (auto f : out.pieces.faces_of(p))
      piece.faces.push_back(m.faces[static_cast<std::size_t>(f)]);
    const MeshReport r = check_mesh(piece, 1e-14 * std::pow(bounding_diagonal(in), 2));
    EXPECT_TRUE(r.indices_valid) << what;
    EXPECT_TRUE(r.closed()) << what << " piece " << p << ": " << r.summary();
    EXPECT_TRUE(r.manifold()) << what << " piece " << p << ": " << r.summary();
    EXPECT_TRUE(r.oriented()) << what << " piece " << p << ": " << r.summary();
    EXPECT_EQ(r.tiny_faces, 0) << what;
    const double vp = signed_volume(piece);
    EXPECT_GT(vp, 0) << what << " piece " << p;
    v += vp;
  }
  EXPECT_NEAR(v, v0, 1e-9 * std::abs(v0)) << what;
  double cap_area = 0;
  const auto nadded = static_cast<std::int32_t>(out.result.change.added_faces.size());
  for (std::int32_t k = nadded - 2 * out.result.cap_faces; k < nadded; ++k) {
    const Face& f = out.result.change.added_faces[static_cast<std::size_t>(k)];
    const Eigen::Vector3d a = m.current.col(f[0]);
    cap_area += 0.5 * (m.current.col(f[1]) - a).cross(m.current.col(f[2]) - a).norm();
  }
  EXPECT_NEAR(surface_area(m) - cap_area, surface_area(in), 1e-9 * surface_area(in)) << what;
}

std::vector<SectionTriangulator> triangulators() {
  std::vector<SectionTriangulator> t = {SectionTriangulator::EarClipping};
  if (has_cgal_triangulator()) t.push_back(SectionTriangulator::ConstrainedDelaunay);
  return t;
}
const char* name(SectionTriangulator t) {
  return t == SectionTriangulator::EarClipping ? "ear clipping" : "constrained Delaunay";
}

double polygon_area(const std::vector<Eigen::Vector2d>& p) {
  double a = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    a += p[i].x() * p[(i + 1) % p.size()].y() - p[i].y() * p[(i + 1) % p.size()].x();
  return 0.5 * a;
}

// Checks a section triangulation of `loops`: triangle count V + 2H − 2 per region (given),
// every triangle counter-clockwise with a positive area, the areas adding up to `area`, and
// the empty-circle property on every inner edge (constrained Delaunay). Returns the smallest
// angle.
double expect_cdt(const Loops& loops, const SectionTriangulation& s, std::size_t triangles,
                  double area, const std::string& what) {
  std::vector<Eigen::Vector2d> all;
  for (const auto& l : loops) all.insert(all.end(), l.begin(), l.end());
  auto P = [&](std::int32_t i) { return all[static_cast<std::size_t>(i)]; };
  EXPECT_EQ(s.triangles.size(), triangles) << what;
  double scale = 0;
  for (const auto& q : all) scale = std::max(scale, q.cwiseAbs().maxCoeff());
  double sum = 0, min_angle = M_PI;
  for (const auto& t : s.triangles) {
    const Eigen::Vector2d u = P(t[1]) - P(t[0]), w = P(t[2]) - P(t[0]);
    const double a = 0.5 * (u.x() * w.y() - u.y() * w.x());
    EXPECT_GT(a, 1e-12 * scale * scale) << what << ": a flat or clockwise triangle";
    sum += a;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2d x = P(t[(k + 1) % 3]) - P(t[k]), y = P(t[(k + 2) % 3]) - P(t[k]);
      min_angle = std::min(min_angle, std::acos(x.normalized().dot(y.normalized())));
    }
  }
  EXPECT_NEAR(sum, area, 1e-12 * std::abs(area)) << what;
  int violations = 0;
  for (const auto& t : s.triangles)
    for (const auto& o : s.triangles)
      for (int k = 0; k < 3; ++k)
        for (int j = 0; j < 3; ++j) {
          if (t[k] != o[(j + 1) % 3] || t[(k + 1) % 3] != o[j]) continue;  // shared edge
          const Eigen::Vector2d a = P(t[k]) - P(o[(j + 2) % 3]),
                                b = P(t[(k + 1) % 3]) - P(o[(j + 2) % 3]),
                                c = P(t[(k + 2) % 3]) - P(o[(j + 2) % 3]);
          const double in = a.squaredNorm() * (b.x() * c.y() - b.y() * c.x()) -
                            b.squaredNorm() * (a.x() * c.y() - a.y() * c.x()) +
                            c.squaredNorm() * (a.x() * b.y() - a.y() * b.x());
          violations += in > 1e-10 * std::pow(scale, 4);
        }
  EXPECT_EQ(violations, 0) << what;
  return min_angle;
}

}  // namespace

TEST(Section, NestedLoopsAreasAndCounts) {
  // An outer square, a hole in it, an island in the hole: any orientations.
  Loops loops = {rectangle(0, 4, 0, 4, 3), circle(2, 2, 1.5, 17), rectangle(1.5, 2.5, 1.5, 2.5, 2)};
  std::reverse(loops[2].begin(), loops[2].end());
  std::size_t nv = 0;
  for (const auto& l : loops) nv += l.size();
  const double expected = std::abs(polygon_area(loops[0])) - std::abs(polygon_area(loops[1])) +
                          std::abs(polygon_area(loops[2]));
  std::vector<Eigen::Vector2d> all;
  for (const auto& l : loops) all.insert(all.end(), l.begin(), l.end());
  for (const auto method : triangulators()) {
    const SectionTriangulation s = triangulate_section(loops, method);
    ASSERT_TRUE(s.ok()) << name(method) << ": " << s.problem;
    EXPECT_EQ(s.depth, (std::vector<std::int32_t>{0, 1, 2})) << name(method);
    double area = 0;
    for (const auto& t : s.triangles) {
      const double a =
          0.5 *
          ((all[static_cast<std::size_t>(t[1])] - all[static_cast<std::size_t>(t[0])]).x() *
               (all[static_cast<std::size_t>(t[2])] - all[static_cast<std::size_t>(t[0])]).y() -
           (all[static_cast<std::size_t>(t[1])] - all[static_cast<std::size_t>(t[0])]).y() *
               (all[static_cast<std::size_t>(t[2])] - all[static_cast<std::size_t>(t[0])]).x());
      EXPECT_GT(a, 0) << name(method) << ": a triangle turns clockwise";
      area += a;
    }
    EXPECT_NEAR(area, expected, 1e-12 * expected) << name(method);
    // Two regions: the ring with one hole (V + 2H − 2 triangles) and the island (V − 2).
    const std::size_t ring = loops[0].size() + loops[1].size() + 2 - 2,
                      island = loops[2].size() - 2;
    EXPECT_EQ(s.triangles.size(), ring + island) << name(method);
    (void)nv;
  }
}

TEST(Section, SideBySideAndDegenerateLoops) {
  const Loops two = {circle(0, 0, 1, 12), circle(3, 0, 1, 12)};
  for (const auto method : triangulators()) {
    const SectionTriangulation s = triangulate_section(two, method);
    ASSERT_TRUE(s.ok()) << s.problem;
    EXPECT_EQ(s.triangles.size(), 20u) << name(method);
    EXPECT_EQ(s.depth, (std::vector<std::int32_t>{0, 0}));
    EXPECT_FALSE(triangulate_section({{{0, 0}, {1, 0}}}, method).ok()) << name(method);
    EXPECT_FALSE(triangulate_section({{{0, 0}, {1, 0}, {NAN, 1}}}, method).ok()) << name(method);
  }
  if (has_cgal_triangulator()) {
    // Crossing loops are reported, not triangulated.
    const SectionTriangulation s = triangulate_section({circle(0, 0, 1, 12), circle(1, 0, 1, 12)},
                                                       SectionTriangulator::ConstrainedDelaunay);
    EXPECT_FALSE(s.ok());
    EXPECT_TRUE(s.triangles.empty());
  } else {
    EXPECT_FALSE(triangulate_section(two, SectionTriangulator::ConstrainedDelaunay).ok());
  }
}

TEST(Section, EarClippingEndsConstrainedDelaunay) {
  // An ellipse with an off-centre elliptic hole: after the flips no inner edge has the fourth
  // point of its two triangles inside the circumcircle of the other three (the empty-circle
  // property of the constrained Delaunay triangulation), and the smallest angle is CGAL's
  // (the constrained Delaunay triangulation maximizes it).
  Loops loops(2);
  for (int i = 0; i < 62; ++i) {
    const double a = 2 * M_PI * i / 62;
    loops[0].emplace_back(0.04 * std::cos(a), 0.03 * std::sin(a));
    if (i % 2 == 0) loops[1].emplace_back(0.008 + 0.015 * std::cos(a), 0.01 * std::sin(-a));
  }
  const SectionTriangulation s = triangulate_section(loops, SectionTriangulator::EarClipping);
  ASSERT_TRUE(s.ok()) << s.problem;
  // V + 2H − 2 triangles with H = 1; the hole runs clockwise, so its signed area subtracts.
  const std::size_t triangles = loops[0].size() + loops[1].size();
  const double area = polygon_area(loops[0]) + polygon_area(loops[1]);
  const double min_angle = expect_cdt(loops, s, triangles, area, "ear clipping");
  if (has_cgal_triangulator()) {
    const SectionTriangulation c =
        triangulate_section(loops, SectionTriangulator::ConstrainedDelaunay);
    ASSERT_TRUE(c.ok()) << c.problem;
    EXPECT_NEAR(min_angle, expect_cdt(loops, c, triangles, area, "constrained Delaunay"), 1e-9);
  }
  RecordProperty("min_angle_degrees", std::to_string(min_angle * 180 / M_PI));
}

TEST(Section, ForbiddenDiagonalsAreNotUsed) {
  // A convex octagon whose Delaunay triangulation would use diagonals from vertex 0: with
  // all of them forbidden (a cut passes the mesh edges in the plane so), no triangle joins 0
  // to a vertex other than its neighbours, and the octagon is still covered (6 triangles of
  // its area). A square with both diagonals forbidden cannot be triangulated: a problem.
  Loops octagon(1);
  for (int i = 0; i < 8; ++i)
    octagon[0].emplace_back(std::cos(2 * M_PI * i / 8), 0.6 * std::sin(2 * M_PI * i / 8));
  ForbiddenDiagonals from0;
  for (std::int32_t v = 2; v <= 6; ++v) from0.push_back({v, 0});
  for (const auto method : {SectionTriangulator::EarClipping, SectionTriangulator::Best}) {
    const SectionTriangulation s = triangulate_section(octagon, method, from0);
    ASSERT_TRUE(s.ok()) << s.problem;
    ASSERT_EQ(s.triangles.size(), 6u);
    double area = 0;
    for (const auto& t : s.triangles) {
      const Eigen::Vector2d a = octagon[0][std::size_t(t[0])], b = octagon[0][std::size_t(t[1])],
                            c = octagon[0][std::size_t(t[2])];
      area += 0.5 * ((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
      for (int k = 0; k < 3; ++k) {
        const std::int32_t u = t[std::size_t(k)], w = t[std::size_t((k + 1) % 3)];
        if (u == 0 || w == 0) {
          EXPECT_TRUE(u + w == 1 || u + w == 7) << u << "-" << w;
        }
      }
    }
    EXPECT_NEAR(area, polygon_area(octagon[0]), 1e-12);
  }
  const Loops square = {{{0, 0}, {1, 0}, {1, 1}, {0, 1}}};
  const SectionTriangulation none =
      triangulate_section(square, SectionTriangulator::Best, {{0, 2}, {1, 3}});
  EXPECT_FALSE(none.ok());
  EXPECT_TRUE(none.triangles.empty());
}

TEST(CapNested, HollowTubeCutAcross) {
  const SkinnedMesh in = thick_tube();
  ASSERT_TRUE(check_mesh(in).closed());
  ASSERT_GT(signed_volume(in), 0);
  for (const auto method : triangulators()) {
    SkinnedMesh m = in;
    Adjacency adj(m);
    const auto out = cut(m, adj, Plane::from_normal_point({0.2, -0.1, 1}, {0.01, 0.02, 0.43}),
                         {.cap = true, .cap_triangulator = method});
    ASSERT_EQ(out.result.status, CutStatus::Cut);
    EXPECT_EQ(out.result.loops, 2) << name(method);
    EXPECT_EQ(out.result.capped_loops, 2) << name(method) << ": " << out.result.message;
    EXPECT_EQ(out.result.nested_loops, 1) << name(method);
    EXPECT_EQ(out.pieces.count, 2);
    expect_closed_pieces(in, m, out, std::string("hollow tube, ") + name(method));
  }
}

TEST(CapNested, TorusCutThroughItsHolesPlane) {
  const SkinnedMesh in = torus();
  for (const auto method : triangulators()) {
    SkinnedMesh m = in;
    Adjacency adj(m);
    const auto out = cut(m, adj, Plane::from_normal_point({0.05, 0.02, 1}, {0, 0, 0.51}),
                         {.cap = true, .cap_triangulator = method});
    ASSERT_EQ(out.result.status, CutStatus::Cut);
    EXPECT_EQ(out.result.loops, 2) << name(method);
    EXPECT_EQ(out.result.capped_loops, 2) << name(method) << ": " << out.result.message;
    EXPECT_EQ(out.result.nested_loops, 1) << name(method);
    EXPECT_EQ(out.pieces.count, 2);
    expect_closed_pieces(in, m, out, std::string("torus, ") + name(method));
  }
}

TEST(CapNested, TubeInsideTubeHasAnIslandInAHole) {
  const SkinnedMesh in = tube_in_tube();
  for (const auto method : triangulators()) {
    SkinnedMesh m = in;
    Adjacency adj(m);
    const auto out = cut(m, adj, Plane::from_normal_point({-0.1, 0.15, 1}, {0, 0, 0.52}),
                         {.cap = true, .cap_triangulator = method});
    ASSERT_EQ(out.result.status, CutStatus::Cut);
    EXPECT_EQ(out.result.loops, 4) << name(method);
    EXPECT_EQ(out.result.capped_loops, 4) << name(method) << ": " << out.result.message;
    EXPECT_EQ(out.result.nested_loops, 3) << name(method);
    EXPECT_EQ(out.pieces.count, 4);
    expect_closed_pieces(in, m, out, std::string("tube in tube, ") + name(method));
  }
}

TEST(CapNested, PropertyRandomPlanes) {
  // Random planes through the hollow shapes: whenever every loop was capped, the pieces are
  // closed and keep the volume; most cuts must be capped whole.
  const std::vector<std::pair<std::string, SkinnedMesh>> models = {
      {"hollow tube", thick_tube()}, {"torus", torus()}, {"tube in tube", tube_in_tube()}};
  std::mt19937 rng(2024);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(-0.4, 0.4);
  for (const auto method : triangulators()) {
    int cuts = 0, capped = 0, nested = 0;
    for (const auto& [model, in] : models)
      for (int trial = 0; trial < 60; ++trial) {
        SkinnedMesh m = in;
        Adjacency adj(m);
        const Eigen::Vector3d n(0.3 * g(rng), 0.3 * g(rng), 1.0);
        const Plane p = Plane::from_normal_point(n, {u(rng), u(rng), 0.5 + u(rng)});
        const auto out = cut(m, adj, p, {.cap = true, .cap_triangulator = method});
        if (out.result.status != CutStatus::Cut) continue;
        ++cuts;
        if (out.result.capped_loops != out.result.loops) continue;
        ++capped;
        nested += out.result.nested_loops > 0;
        expect_closed_pieces(in, m, out,
                             model + " trial " + std::to_string(trial) + ", " + name(method));
        if (testing::Test::HasFailure()) return;
      }
    EXPECT_GT(cuts, 150) << name(method);
    EXPECT_GT(capped, 0.9 * cuts) << name(method);
    EXPECT_GT(nested, 60) << name(method);
  }
}

namespace {

// A convex polygon through `corners` points of an ellipse, with `flat` points evenly spaced on
// every edge (collinear with the edge's ends, as the crossings of split quads' diagonals are).
std::vector<Eigen::Vector2d> ellipse_with_flat_points(int corners, int flat, double a, double b,
                                                      Eigen::Vector2d centre) {
  std::vector<Eigen::Vector2d> loop;
  for (int i = 0; i < corners; ++i) {
    const double t0 = 2 * M_PI * i / corners, t1 = 2 * M_PI * (i + 1) / corners;
    const Eigen::Vector2d p0 = centre + Eigen::Vector2d(a * std::cos(t0), b * std::sin(t0)),
                          p1 = centre + Eigen::Vector2d(a * std::cos(t1), b * std::sin(t1));
    for (int j = 0; j <= flat; ++j) loop.push_back(p0 + (p1 - p0) * (double(j) / (flat + 1)));
  }
  return loop;
}

}  // namespace

TEST(Section, ConvexLoopsWithAndWithoutFlatVertices) {
  // A plain ellipse (the ear clipper's strip), an ellipse polygon with a point on every edge
  // (the arm's sections), a square with many points per side (both loop edges of a triangle
  // carry flat runs) and a symmetric ellipse (exactly cocircular quadruples), with both
  // triangulators: constrained Delaunay, exact areas, V − 2 triangles, the same smallest angle.
  const std::vector<std::pair<std::string, Loops>> cases = {
      {"ellipse", {ellipse_with_flat_points(64, 0, 0.04, 0.03, {0.01, 0.2})}},
      {"ellipse with midpoints", {ellipse_with_flat_points(32, 1, 0.04, 0.038, {-0.3, 0.07})}},
      {"square with runs", {ellipse_with_flat_points(4, 6, 1.0, 1.0, {2.0, -1.0})}},
      {"near circle with runs", {ellipse_with_flat_points(20, 3, 0.5, 0.5001, {0, 0})}},
  };
  for (const auto& [what, loops] : cases) {
    const double area = std::abs(polygon_area(loops[0]));
    double angle[2] = {-1, -1};
    for (const auto method : triangulators()) {
      const SectionTriangulation s = triangulate_section(loops, method);
      ASSERT_TRUE(s.ok()) << what << ", " << name(method) << ": " << s.problem;
      EXPECT_EQ(s.depth, std::vector<std::int32_t>{0});
      angle[method == SectionTriangulator::EarClipping ? 0 : 1] =
          expect_cdt(loops, s, loops[0].size() - 2, area, what + ", " + name(method));
    }
    if (angle[1] >= 0) {
      EXPECT_NEAR(angle[0], angle[1], 1e-9) << what;
    }
  }
}

TEST(Section, FlatVerticesOnHolesAndIslands) {
  // Runs of collinear points on an outer loop, on a hole and on an island in the hole.
  Loops loops = {ellipse_with_flat_points(16, 2, 4, 3, {0, 0}),
                 ellipse_with_flat_points(8, 3, 2, 1.5, {0.3, 0}),
                 ellipse_with_flat_points(6, 1, 0.5, 0.4, {0.4, 0.1})};
  std::reverse(loops[1].begin(), loops[1].end());
  const double area = std::abs(polygon_area(loops[0])) - std::abs(polygon_area(loops[1])) +
                      std::abs(polygon_area(loops[2]));
  const std::size_t triangles = loops[0].size() + loops[1].size() + 2 - 2 + loops[2].size() - 2;
  for (const auto method : triangulators()) {
    const SectionTriangulation s = triangulate_section(loops, method);
    ASSERT_TRUE(s.ok()) << name(method) << ": " << s.problem;
    EXPECT_EQ(s.depth, (std::vector<std::int32_t>{0, 1, 2})) << name(method);
    expect_cdt(loops, s, triangles, area, name(method));
  }
}
