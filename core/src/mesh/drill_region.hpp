// The drill's working state (drill.hpp, Algorithm 3), shared by its steps: the axis and its
// plane Π, the quadratic of eqs 18–20, the combinations that define new vertices, the patch
// copied out of the mesh (Region) and each hole's bookkeeping (Patch). Internal to core.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

#include "conform/mesh/adjacency.hpp"
#include "conform/mesh/drill.hpp"
#include "conform/mesh/edge_map.hpp"
#include "conform/mesh/topology_change.hpp"
#include "quad_split.hpp"

namespace conform::mesh::drilling {

struct Axis {
  Eigen::Vector3d b, u;    // base and unit direction towards the tip
  Eigen::Vector3d e1, e2;  // an orthonormal frame of the plane Π, with u right-handed
  double length = 0, r2 = 0;
  Axis() = default;
  explicit Axis(const DrillTool& tool) : b(tool.base), r2(tool.radius * tool.radius) {
    length = (tool.tip - tool.base).norm();
    u = (tool.tip - tool.base) / length;
    int k0 = 0;
    for (int k = 1; k < 3; ++k)
      if (std::abs(u[k]) < std::abs(u[k0])) k0 = k;
    e1 = Eigen::Vector3d::Unit(k0).cross(u).normalized();
    e2 = u.cross(e1);
  }
  Eigen::Vector3d radial(const Eigen::Vector3d& x) const {
    const Eigen::Vector3d q = x - b;
    return q - q.dot(u) * u;
  }
  // The projection on Π, from the axis, in the frame (e1, e2): affine, so it commutes with
  // the barycentric combinations that define new vertices.
  Eigen::Vector2d project(const Eigen::Vector3d& x) const {
    const Eigen::Vector3d q = x - b;
    return {q.dot(e1), q.dot(e2)};
  }
};

// The roots α in [0, 1] of |μ + α(ν − μ)|² = r² (eqs 18–20 with α from μ), ascending.
inline int edge_roots(const Eigen::Vector2d& mu, const Eigen::Vector2d& nu, double r2,
                      double out[2]) {
  const Eigen::Vector2d d = nu - mu;
  const double k = d.squaredNorm(), l = 2 * mu.dot(d), n = mu.squaredNorm() - r2;
  if (!(k > 0)) return 0;  // the edge is parallel to the axis: its projection is a point
  // Both ends outside and the closest point (α = −l / 2k) off the edge: no root in [0, 1]
  // (the common case of the walk's neighbours, without a root or a division).
  if (n > 0 && n + l + k > 0 && (l >= 0 || l + 2 * k <= 0)) return 0;
  const double disc = l * l - 4 * k * n;
  if (disc <= 0) return 0;  // misses, or tangent (a double root: touches without crossing)
  const double sq = std::sqrt(disc);
  const double qv = -0.5 * (l + (l >= 0 ? sq : -sq));
  double r0 = qv / k, r1 = qv != 0 ? n / qv : r0;
  if (r0 > r1) std::swap(r0, r1);
  int count = 0;
  if (r0 >= 0 && r0 <= 1) out[count++] = r0;
  if (r1 >= 0 && r1 <= 1 && r1 != r0) out[count++] = r1;
  return count;
}

// The tangent of the smallest angle of triangle (a, b, c): the angle opposite its shortest
// edge, at most 60°, so that its tangent orders angles without trigonometry.
inline double smallest_angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                             const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, bc = c - b, ca = a - c;
  const double lab = ab.squaredNorm(), lbc = bc.squaredNorm(), lca = ca.squaredNorm();
  const double twice_area = ab.cross(ca).norm();
  const double dot = lab <= lbc && lab <= lca ? -ca.dot(bc)  // at c
                     : lbc <= lca             ? -ab.dot(ca)  // at a
                                              : -ab.dot(bc);             // at b
  if (dot > 0) return twice_area / dot;
  return twice_area > 0 ? std::numeric_limits<double>::infinity() : 0;
}

// The quad-diagonal rule (quad_split.hpp) with the drill's measure, smallest_angle.
inline QuadSplit drill_quad_split(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                                  const Eigen::Vector3d& p2, const Eigen::Vector3d& p3) {
  return best_quad_split(p0, p1, p2, p3, [](const auto& a, const auto& b, const auto& c) {
    return smallest_angle(a, b, c);
  });
}

// A hole's patch and what the tube needs of it.
struct Patch {
  double t = 2;                   // where the axis pierces it, from B (0) to A (1)
  bool entering = false;          // its pierced face's normal points against B→A
  std::vector<std::int32_t> rim;  // its rim loop (mesh indices), in boundary order; empty: none
  bool cut = false;
  int crossings = 0;  // rim crossings of its edges (refinement's count)
  double limit = 0;   // the longest chord of the rim polygon a face may hold
};

// An affine combination Σ c_i x_{p_i} of at most three ORIGINAL vertices: every point the drill
// makes lies in one original face, so its rest position, weights (§4.3), UVs and normal follow
// from the original corners in one step, however many bisections made it.
struct Combination {
  std::array<std::int32_t, 3> parent{-1, -1, -1};
  std::array<double, 3> coefficient{0, 0, 0};
  int count = 0;
  void add(std::int32_t p, double c) {
    for (int i = 0; i < count; ++i)
      if (parent[i] == p) {
        coefficient[i] += c;
        return;
      }
    // Both ends of an edge lie in the closure of one original face: at most its 3 corners.
    if (count == 3) throw std::logic_error("drill: a new vertex outside its original face");
    parent[count] = p;
    coefficient[count++] = c;
  }
  // (1 − t) a + t b
  static Combination between(const Combination& a, const Combination& b, double t) {
    Combination m;
    for (int i = 0; i < a.count; ++i) m.add(a.parent[i], (1 - t) * a.coefficient[i]);
    for (int i = 0; i < b.count; ++i) m.add(b.parent[i], t * b.coefficient[i]);
    return m;
  }
  NewVertex new_vertex() const {
    // Renormalized: the sum drifts from 1 by rounding only.
    if (count == 2) {
      const double t = coefficient[1] / (coefficient[0] + coefficient[1]);
      return NewVertex::on_edge(parent[0], parent[1], t);
    }
    const double s = coefficient[0] + coefficient[1] + coefficient[2];
    return NewVertex::in_face(parent[0], parent[1], parent[2], coefficient[0] / s,
                              coefficient[1] / s, coefficient[2] / s);
  }
};

// The part of the mesh the drill works on, copied out so that refinement, clipping and the
// rim are computed on a few dozen to a few thousand faces, and applied as ONE change.
//
// Faces are loaded from the mesh on demand (the patch walk, then whatever the longest-edge
// bisection reaches); each local face lies in one original face (its origin). Half-edge
// 3 f + k of local face f runs from v[k] to v[k + 1]; its twin is a local half-edge (≥ 0),
// kBoundary, or an unloaded mesh half-edge h encoded as −2 − h (the `pending` map then leads
// from h back to this side, so that loading h's face links the two).
class Region {
 public:
  static constexpr std::int32_t kBoundary = -1;
  struct Vertex {
    Eigen::Vector3d x;  // current position
    Eigen::Vector2d q;  // projection on Π, from the axis
    Combination def;
    std::int32_t index = -1;  // in the mesh: original vertices from the start, new ones on emit
    int side = 1;             // +1 outside, −1 inside, 0 on the cylinder (snapped)
    bool rim = false;         // a new vertex on the cylinder
    bool loop = false;        // on a rim loop kept for the tube
    int snapped = -1;         // the angle pass that snapped it (64 × round + pass), or −1
  };
  struct LocalFace {
    std::array<std::int32_t, 3> v;
    std::array<std::int32_t, 3> twin;
    std::int32_t origin;  // index into origins
    std::int32_t patch;   // the hole it belongs to
    std::int32_t depth;   // bisections since its original face
  };
  struct Origin {
    std::int32_t face;  // in the mesh
    bool modified = false;
    bool seed = false;  // pierced by the axis
    double bound = -1;  // tangent of the angle guarantee's bound (−1: not computed yet)
  };

  // One Region per thread is kept between drills, so that its tables are reused (a haptic
  // loop drills often; fresh tables cost more in allocation and page faults than in use).
  void reset(const SkinnedMesh& mesh, const Adjacency& adjacency, const Axis& axis) {
    mesh_ = &mesh, adjacency_ = &adjacency, axis_ = axis;
    verts.clear(), faces.clear(), origins.clear(), touched.clear();
    vertex_of_.clear(), face_of_.clear(), pending_.clear();
    work.clear(), fate.clear(), added.clear(), hole_edges.clear();
    crossing_vertex.clear(), next.clear(), rim_edges.clear(), new_x.clear(), clipped.clear();
  }

  std::vector<Vertex> verts;
  std::vector<LocalFace> faces;
  std::vector<Origin> origins;

  bool inside(const Eigen::Vector2d& q) const { return q.squaredNorm() < axis_.r2; }

  std::int32_t vertex(std::int32_t g) {
    const std::int32_t known = vertex_of_.find(0, g);
    if (known >= 0) return known;
    const Eigen::Vector3d x = mesh_->current.col(g);
    // Only the positions the drill reads are checked (a whole-mesh check is O(V)).
    if (!x.allFinite()) throw std::invalid_argument("drill: non-finite positions");
    Vertex v;
    v.x = x;
    v.q = axis_.project(x);
    v.def.add(g, 1);
    v.index = g;
    v.side = inside(v.q) ? -1 : 1;
    const auto id = static_cast<std::int32_t>(verts.size());
    verts.push_back(v);
    vertex_of_.insert(0, g, id);
    return id;
  }

  // The new vertex (1 − t) a + t b.
  std::int32_t between(std::int32_t a, std::int32_t b, double t) {
    Vertex v;
    const Vertex &va = verts[std::size_t(a)], &vb = verts[std::size_t(b)];
    v.x = (1 - t) * va.x + t * vb.x;
    v.q = (1 - t) * va.q + t * vb.q;
    v.def = Combination::between(va.def, vb.def, t);
    v.side = inside(v.q) ? -1 : 1;
    verts.push_back(v);
    return static_cast<std::int32_t>(verts.size() - 1);
  }

  std::int32_t loaded(std::int32_t g) const { return face_of_.find(0, g); }

  std::int32_t load_face(std::int32_t g, std::int32_t patch) {
    const auto lf = static_cast<std::int32_t>(faces.size());
    face_of_.insert(0, g, lf);
    const Face& t = mesh_->faces[std::size_t(g)];
    LocalFace f{{vertex(t[0]), vertex(t[1]), vertex(t[2])},
                {kBoundary, kBoundary, kBoundary},
                static_cast<std::int32_t>(origins.size()),
                patch,
                0};
    origins.push_back({g});
    faces.push_back(f);
    for (int k = 0; k < 3; ++k) {
      const std::int32_t h = 3 * g + k, here = 3 * lf + k;
      const std::int32_t other = pending_.find(0, h);
      if (other >= 0) {
        link(here, other);
      } else if (const std::int32_t gh = adjacency_->twin(h); gh >= 0) {
        set_twin(here, -2 - gh);
      }
    }
    return lf;
  }

  // An edge comes within r of the axis: an end inside, or its projection's closest point.
  // (Sides are the raw inside tests until the snapping of step 5.)
  bool edge_near(std::int32_t a, std::int32_t b) const {
    const Vertex &va = verts[std::size_t(a)], &vb = verts[std::size_t(b)];
    if (va.side < 0 || vb.side < 0) return true;
    double roots[2];
    return edge_roots(va.q, vb.q, axis_.r2, roots) == 2;
  }
  bool face_near(std::int32_t g) {
    const Face& t = mesh_->faces[std::size_t(g)];
    const std::int32_t a = vertex(t[0]), b = vertex(t[1]), c = vertex(t[2]);
    return edge_near(a, b) || edge_near(b, c) || edge_near(c, a);
  }

  // Breadth-first from the pierced face g over faces that come within r of the axis: the patch
  // of one hole. Faces already loaded (another seed's patch) are skipped.
  void walk(std::int32_t g, std::int32_t patch) {
    std::size_t head = faces.size();
    load_face(g, patch);
    for (; head < faces.size(); ++head) {
      const std::int32_t from = origins[std::size_t(faces[head].origin)].face;
      for (int k = 0; k < 3; ++k) {
        const std::int32_t n = adjacency_->neighbor(from, k);
        if (n < 0 || loaded(n) >= 0 || !face_near(n)) continue;
        load_face(n, patch);
      }
    }
  }

  double edge_length2(std::int32_t f, int k) const {
    const LocalFace& t = faces[std::size_t(f)];
    return (verts[std::size_t(t.v[k])].x - verts[std::size_t(t.v[(k + 1) % 3])].x).squaredNorm();
  }
  // The longest edge of f, ties broken by the vertices: a strict order of the edges, so that
  // the two faces of an edge agree on whether it is their longest.
  int longest_edge(std::int32_t f) const {
    const LocalFace& t = faces[std::size_t(f)];
    int best = 0;
    double best_len = edge_length2(f, 0);
    auto key = [&](int k) {
      const std::int32_t a = t.v[k], b = t.v[(k + 1) % 3];
      return std::pair{std::min(a, b), std::max(a, b)};
    };
    for (int k = 1; k < 3; ++k) {
      const double len = edge_length2(f, k);
      if (len > best_len || (len == best_len && key(k) > key(best))) best = k, best_len = len;
    }
    return best;
  }

  // Splits local face f at the midpoint of its edge k, and the face across it (each 1-to-2).
  void bisect(std::int32_t f, int k) {
    const LocalFace F = faces[std::size_t(f)];
    const std::int32_t a = F.v[k], b = F.v[(k + 1) % 3], c = F.v[(k + 2) % 3];
    const std::int32_t t_ab = F.twin[k], t_bc = F.twin[(k + 1) % 3], t_ca = F.twin[(k + 2) % 3];
    const std::int32_t m = between(a, b, 0.5);
    origins[std::size_t(F.origin)].modified = true;
    const auto f2 = static_cast<std::int32_t>(faces.size());
    faces[std::size_t(f)] = {
        {a, m, c}, {kBoundary, kBoundary, kBoundary}, F.origin, F.patch, F.depth + 1};
    faces.push_back({{m, b, c}, {kBoundary, kBoundary, kBoundary}, F.origin, F.patch, F.depth + 1});
    touched.push_back(f), touched.push_back(f2);
    link(3 * f + 1, 3 * f2 + 2);  // m→c, c→m
    set_twin(3 * f + 2, t_ca);
    set_twin(3 * f2 + 1, t_bc);
    if (t_ab < 0) return;  // a boundary edge (an unloaded twin was loaded by the caller)
    const std::int32_t g = t_ab / 3, j = t_ab % 3;  // edge j of g runs b → a
    const LocalFace G = faces[std::size_t(g)];
    const std::int32_t d = G.v[(j + 2) % 3];
    const std::int32_t t_ad = G.twin[(j + 1) % 3], t_db = G.twin[(j + 2) % 3];
    origins[std::size_t(G.origin)].modified = true;
    const auto g2 = static_cast<std::int32_t>(faces.size());
    faces[std::size_t(g)] = {
        {b, m, d}, {kBoundary, kBoundary, kBoundary}, G.origin, G.patch, G.depth + 1};
    faces.push_back({{m, a, d}, {kBoundary, kBoundary, kBoundary}, G.origin, G.patch, G.depth + 1});
    touched.push_back(g), touched.push_back(g2);
    link(3 * g, 3 * f2);          // b→m, m→b
    link(3 * g + 1, 3 * g2 + 2);  // m→d, d→m
    set_twin(3 * g + 2, t_db);
    link(3 * g2, 3 * f);  // m→a, a→m
    set_twin(3 * g2 + 1, t_ad);
  }

  // Rivara's longest-edge bisection of f: bisect the terminal edge of f's longest-edge
  // propagation path (the longest edge of both its faces, or a boundary) until f itself is
  // split. Neighbours stay conforming, and every triangle made keeps at least half the
  // smallest angle of the triangle it came from: no slivers.
  void refine(std::int32_t f) {
    const std::array<std::int32_t, 3> start = faces[std::size_t(f)].v;
    for (int guard = 0; faces[std::size_t(f)].v == start && guard < 64; ++guard) {
      std::int32_t cur = f;
      int k = longest_edge(cur);
      for (;;) {
        std::int32_t tw = faces[std::size_t(cur)].twin[k];
        if (tw <= -2) {  // the neighbour is not loaded yet
          load_face((-2 - tw) / 3, faces[std::size_t(cur)].patch);
          tw = faces[std::size_t(cur)].twin[k];
        }
        if (tw < 0) break;
        const std::int32_t g = tw / 3;
        const int j = longest_edge(g);
        if (j == tw % 3) break;  // the terminal edge
        cur = g, k = j;
      }
      bisect(cur, k);
    }
  }

  // The projection of face f contains the axis (the disc may lie wholly inside it).
  bool contains_axis(std::int32_t f) const {
    const LocalFace& t = faces[std::size_t(f)];
    double s[3];
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2d &p = verts[std::size_t(t.v[k])].q,
                            &q = verts[std::size_t(t.v[(k + 1) % 3])].q;
      s[k] = p.x() * q.y() - p.y() * q.x();  // (p × q): the axis' side of edge p→q
    }
    return (s[0] >= 0 && s[1] >= 0 && s[2] >= 0 && s[0] + s[1] + s[2] > 0) ||
           (s[0] <= 0 && s[1] <= 0 && s[2] <= 0 && s[0] + s[1] + s[2] < 0);
  }

  // The longest edge of face f on Π, squared: a bound on its rim extent (points on a triangle's
  // edges are no farther apart than its longest edge), without roots.
  double projected_diameter2(std::int32_t f) const {
    const LocalFace& t = faces[std::size_t(f)];
    const Eigen::Vector2d &a = verts[std::size_t(t.v[0])].q, &b = verts[std::size_t(t.v[1])].q,
                          &c = verts[std::size_t(t.v[2])].q;
    return std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
  }

  // How far apart (on Π) the rim's crossings of face f's edges are: the longest chord of the
  // rim polygon that f will hold; +∞ when the whole disc lies inside the pierced face f, 0
  // when the rim does not cross f.
  double rim_extent(std::int32_t f) const {
    const LocalFace& t = faces[std::size_t(f)];
    Eigen::Vector2d points[6];
    int n = 0, in = 0;
    for (int k = 0; k < 3; ++k) {
      const Vertex &a = verts[std::size_t(t.v[k])], &b = verts[std::size_t(t.v[(k + 1) % 3])];
      in += a.side < 0;
      if (a.side < 0 && b.side < 0) continue;
      double roots[2];
      const int count = edge_roots(a.q, b.q, axis_.r2, roots);
      if (a.side != b.side || count == 2)
        for (int i = 0; i < count; ++i) points[n++] = a.q + roots[i] * (b.q - a.q);
    }
    if (in == 3) return 0;
    if (n < 2)
      return in == 0 && origins[std::size_t(t.origin)].seed && contains_axis(f)
                 ? std::numeric_limits<double>::infinity()
                 : 0;
    double extent = 0;
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j) extent = std::max(extent, (points[i] - points[j]).norm());
    return extent;
  }

  std::int32_t twin(std::int32_t h) const { return faces[std::size_t(h / 3)].twin[h % 3]; }

  std::vector<std::int32_t> touched;  // faces written by bisect() since the caller cleared it

  // drill_impl's scratch, kept with the rest.
  std::vector<std::int32_t> work;
  std::vector<std::uint8_t> fate;
  std::vector<Face> added;
  std::vector<std::array<std::int32_t, 3>> hole_edges;
  EdgeMap crossing_vertex{64}, next{64}, rim_edges{64}, in_a{64};
  std::vector<Eigen::Vector3d> new_x;
  std::vector<std::int32_t> clipped;

 private:
  void link(std::int32_t h, std::int32_t t) {
    faces[std::size_t(h / 3)].twin[h % 3] = t;
    faces[std::size_t(t / 3)].twin[t % 3] = h;
  }
  void set_twin(std::int32_t h, std::int32_t code) {
    if (code >= 0) return link(h, code);
    faces[std::size_t(h / 3)].twin[h % 3] = code;
    if (code <= -2) pending_.insert(0, -2 - code, h, true);
  }

  const SkinnedMesh* mesh_ = nullptr;
  const Adjacency* adjacency_ = nullptr;
  Axis axis_;
  EdgeMap vertex_of_{256}, face_of_{128}, pending_{128};  // keyed (0, index)
};

}  // namespace conform::mesh::drilling
