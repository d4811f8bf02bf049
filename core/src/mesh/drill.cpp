#include "conform/mesh/drill.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace conform::mesh {

namespace {

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
int edge_roots(const Eigen::Vector2d& mu, const Eigen::Vector2d& nu, double r2, double out[2]) {
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
double smallest_angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
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

// The quad (p0, p1, p2, p3) split along p0–p2 (true) or p1–p3, whichever keeps the larger
// smallest angle.
bool split_02(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
              const Eigen::Vector3d& p3) {
  return std::min(smallest_angle(p0, p1, p2), smallest_angle(p0, p2, p3)) >=
         std::min(smallest_angle(p0, p1, p3), smallest_angle(p1, p2, p3));
}

// Open addressing (linear probing, Fibonacci hashing) from a 64-bit key to an int32, for the
// drill's scratch tables of a few dozen to a few thousand entries. No erase; clear() is O(1):
// a slot is live only when stamped with the current epoch, so a table kept between drills
// (see Region) is reused without being swept.
class FlatMap {
 public:
  static constexpr std::int32_t kNone = -1;
  explicit FlatMap(std::size_t expected = 32) {
    std::size_t cap = 16;
    while (cap < 2 * expected) cap *= 2;
    rehash(cap);
  }
  void clear() {
    size_ = 0;
    if (++epoch_ == 0) {  // the stamps wrapped: sweep once
      for (Slot& s : slots_) s.epoch = 0;
      epoch_ = 1;
    }
  }
  std::int32_t find(std::uint64_t key) const {
    for (std::size_t s = home(key);; s = (s + 1) & mask_) {
      if (slots_[s].epoch != epoch_) return kNone;
      if (slots_[s].key == key) return slots_[s].value;
    }
  }
  /// Inserts key → value, or overwrites the value when `overwrite`; returns the stored value.
  std::int32_t insert(std::uint64_t key, std::int32_t value, bool overwrite = false) {
    if (2 * (size_ + 1) > slots_.size()) rehash(2 * slots_.size());
    std::size_t s = home(key);
    for (; slots_[s].epoch == epoch_; s = (s + 1) & mask_)
      if (slots_[s].key == key) {
        if (overwrite) slots_[s].value = value;
        return slots_[s].value;
      }
    slots_[s] = {key, value, epoch_};
    ++size_;
    return value;
  }
  static std::uint64_t pair(std::int32_t u, std::int32_t v) {
    return (std::uint64_t(std::uint32_t(u)) << 32) | std::uint32_t(v);
  }

 private:
  struct Slot {
    std::uint64_t key;
    std::int32_t value;
    std::uint32_t epoch;  // live when equal to epoch_
  };
  std::size_t home(std::uint64_t key) const {
    return std::size_t((key * 0x9E3779B97F4A7C15ull) >> shift_);
  }
  void rehash(std::size_t capacity) {
    std::vector<Slot> old = std::move(slots_);
    const std::uint32_t live = epoch_;
    slots_.assign(capacity, Slot{0, kNone, 0});
    epoch_ = 1;
    mask_ = capacity - 1;
    shift_ = 64 - std::countr_zero(capacity);
    size_ = 0;
    for (const Slot& o : old)
      if (o.epoch == live) insert(o.key, o.value);
  }
  std::vector<Slot> slots_;
  std::size_t mask_ = 0, size_ = 0;
  std::uint32_t epoch_ = 1;
  int shift_ = 64;
};

}  // namespace

double axis_distance_squared(const DrillTool& tool, const Eigen::Vector3d& x) {
  const Eigen::Vector3d u = (tool.tip - tool.base).normalized();
  const Eigen::Vector3d q = x - tool.base;
  return (q - q.dot(u) * u).squaredNorm();
}

namespace {

void check_input(const SkinnedMesh& mesh, const Adjacency& adjacency, const DrillTool& tool) {
  if (!tool.tip.allFinite() || !tool.base.allFinite() || !std::isfinite(tool.radius))
    throw std::invalid_argument("drill: tip, base and radius must be finite");
  if (!(tool.radius > 0)) throw std::invalid_argument("drill: the radius must be positive");
  if (!((tool.tip - tool.base).norm() > 0))
    throw std::invalid_argument("drill: tip and base must differ");
  if (!adjacency.matches(mesh))
    throw std::invalid_argument("drill: the adjacency does not describe this mesh");
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

DrillResult drill_impl(SkinnedMesh& mesh, Adjacency& adjacency, FaceIndex* index,
                       const DrillTool& tool, const DrillOptions& options,
                       const std::vector<SegmentHit>& hits);

std::vector<SegmentHit> pierced_faces(const SkinnedMesh& mesh, FaceIndex* index,
                                      const DrillTool& tool, const DrillOptions& options) {
  if (options.search == FaceSearch::Scan) return scan_segment_hits(mesh, tool.base, tool.tip);
  if (index) {
    index->ensure_fitted(mesh);
    return index->segment_hits(mesh, tool.base, tool.tip);
  }
  // No index kept by the caller: for one query a scan (O(F)) is cheaper than a build.
  return scan_segment_hits(mesh, tool.base, tool.tip);
}

}  // namespace

DrillResult drill(SkinnedMesh& mesh, Adjacency& adjacency, const DrillTool& tool,
                  const DrillOptions& options) {
  check_input(mesh, adjacency, tool);
  return drill_impl(mesh, adjacency, nullptr, tool, options,
                    pierced_faces(mesh, nullptr, tool, options));
}

DrillResult drill(SkinnedMesh& mesh, Adjacency& adjacency, FaceIndex& index, const DrillTool& tool,
                  const DrillOptions& options) {
  check_input(mesh, adjacency, tool);
  if (!index.matches(mesh))
    throw std::invalid_argument("drill: the face index does not describe this mesh");
  return drill_impl(mesh, adjacency, &index, tool, options,
                    pierced_faces(mesh, &index, tool, options));
}

namespace {

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
    const std::int32_t known = vertex_of_.find(std::uint64_t(g));
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
    vertex_of_.insert(std::uint64_t(g), id);
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

  std::int32_t loaded(std::int32_t g) const { return face_of_.find(std::uint64_t(g)); }

  std::int32_t load_face(std::int32_t g, std::int32_t patch) {
    const auto lf = static_cast<std::int32_t>(faces.size());
    face_of_.insert(std::uint64_t(g), lf);
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
      const std::int32_t other = pending_.find(std::uint64_t(h));
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
  FlatMap crossing_vertex{64}, next{64}, rim_edges{64}, in_a{64};
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
    if (code <= -2) pending_.insert(std::uint64_t(-2 - code), h, true);
  }

  const SkinnedMesh* mesh_ = nullptr;
  const Adjacency* adjacency_ = nullptr;
  Axis axis_;
  FlatMap vertex_of_{256}, face_of_{128}, pending_{128};
};

// The post-change mesh, seen from the drill's change before it is applied: positions of old and
// new vertices, and whether a directed edge between two rim vertices will exist.
struct Outcome {
  const SkinnedMesh& mesh;
  const Adjacency& adjacency;
  const TopologyChange& change;
  const std::vector<Eigen::Vector3d>& new_x;  // positions of change.new_vertices
  const FlatMap& rim_edges;  // directed edges of the change's added faces between rim vertices
  Eigen::Vector3d pos(std::int32_t v) const {
    return v < change.base_vertex_count ? Eigen::Vector3d(mesh.current.col(v))
                                        : new_x[std::size_t(v - change.base_vertex_count)];
  }
  // x → y is a half-edge of the changed mesh: of an added face, or of an original face that
  // the change keeps.
  bool has(std::int32_t x, std::int32_t y) const {
    if (rim_edges.find(FlatMap::pair(x, y)) >= 0) return true;
    if (x >= change.base_vertex_count || y >= change.base_vertex_count) return false;
    const std::int32_t h = adjacency.find(x, y);
    return h >= 0 &&
           !std::binary_search(change.removed_faces.begin(), change.removed_faces.end(), h / 3);
  }
};

// Appends to `change` the tube walls joining consecutive holes along the axis, where the drill
// enters then leaves the surface (see drill.hpp, step 6): a strip of triangles between their
// rim loops, through intermediate rings of new vertices when ring_spacing > 0. Everything is
// decided on the change before it is applied (Outcome), so that the drill applies one change.
void add_tubes(const Outcome& out, const Axis& axis, const std::vector<Patch>& patches,
               double ring_spacing, TopologyChange& change, std::vector<Eigen::Vector3d>& new_x,
               FlatMap& rim_edges, FlatMap& in_a, DrillResult& result) {
  std::vector<const Patch*> cut;
  for (const auto& p : patches)
    if (p.cut) cut.push_back(&p);
  std::sort(cut.begin(), cut.end(), [](const Patch* a, const Patch* b) { return a->t < b->t; });
  const std::int32_t nv0 = change.base_vertex_count;
  auto pos = [&](std::int32_t v) { return out.pos(v); };
  // The rim vertices' angles about the axis, in the frame of Π.
  auto angle = [&](std::int32_t v) {
    const Eigen::Vector2d q = axis.project(pos(v));
    return std::atan2(q.y(), q.x());
  };
  constexpr double pi = std::numbers::pi;
  auto wrap = [](double a) { return std::remainder(a, 2 * pi); };
  // Cumulative turning along a closed loop from its first vertex (loop.size() + 1 values).
  auto turning = [&](const std::vector<std::int32_t>& loop) {
    std::vector<double> cum(loop.size() + 1, 0.0);
    double previous = angle(loop[0]), first = previous;
    for (std::size_t k = 0; k < loop.size(); ++k) {
      const double next = k + 1 < loop.size() ? angle(loop[k + 1]) : first;
      cum[k + 1] = cum[k] + wrap(next - previous);
      previous = next;
    }
    return cum;
  };
  // Both loops wind once about the axis the same way.
  auto winds_with = [&](const std::vector<double>& a, const std::vector<double>& b) {
    return std::abs(std::abs(a.back()) - 2 * pi) <= 1e-6 && std::abs(a.back() - b.back()) <= 1e-6;
  };
  // The winding number of a loop of positions about the axis (crossings of the ray along e1,
  // signed): no trigonometry, for the rings.
  auto winding = [&](const std::vector<Eigen::Vector2d>& q) {
    int w = 0;
    for (std::size_t k = 0; k < q.size(); ++k) {
      const Eigen::Vector2d &p0 = q[k], &p1 = q[(k + 1) % q.size()];
      const double cross = p0.x() * p1.y() - p0.y() * p1.x();
      if (p0.y() <= 0 && p1.y() > 0 && cross > 0) ++w;
      if (p1.y() <= 0 && p0.y() > 0 && cross < 0) --w;
    }
    return w;
  };
  auto fail = [&](const std::string& why) {
    if (!result.message.empty()) result.message += "; ";
    result.message += why;
  };
  // The strip between loops P and Q (Q[0] the nearest of Q to P[0] in angle), merged by angle.
  auto zip = [&](const std::vector<std::int32_t>& P, const std::vector<double>& alpha,
                 const std::vector<std::int32_t>& Q, const std::vector<double>& beta,
                 std::vector<Face>& faces) {
    const double sign = alpha.back() > 0 ? 1 : -1, delta = wrap(angle(Q[0]) - angle(P[0]));
    const std::size_t n = P.size(), m = Q.size();
    for (std::size_t ia = 0, jb = 0; ia < n || jb < m;) {
      const bool along_p =
          jb == m || (ia < n && sign * alpha[ia + 1] <= sign * (delta + beta[jb + 1]));
      if (along_p) {
        faces.push_back({P[ia], P[(ia + 1) % n], Q[jb % m]});
        ++ia;
      } else {
        faces.push_back({Q[(jb + 1) % m], Q[jb], P[ia % n]});
        ++jb;
      }
    }
  };
  // The strip between two rings of equal size whose k-th vertices correspond (on one segment
  // between the rims): quads, each split along its shorter diagonal.
  auto ladder = [&](const std::vector<std::int32_t>& P, const std::vector<std::int32_t>& Q,
                    std::vector<Face>& faces) {
    const std::size_t n = P.size();
    for (std::size_t k = 0; k < n; ++k) {
      const std::int32_t p0 = P[k], p1 = P[(k + 1) % n], q0 = Q[k], q1 = Q[(k + 1) % n];
      if ((pos(p1) - pos(q0)).squaredNorm() <= (pos(p0) - pos(q1)).squaredNorm())
        faces.push_back({p0, p1, q0}), faces.push_back({q1, q0, p1});
      else
        faces.push_back({p0, p1, q1}), faces.push_back({q1, q0, p0});
    }
  };
  std::vector<Face> faces;
  for (std::size_t i = 0; i + 1 < cut.size();) {
    const Patch& pa = *cut[i];
    const Patch& pb = *cut[i + 1];
    if (!pa.entering || pb.entering) {
      ++i;
      continue;
    }
    i += 2;
    if (pa.rim.empty() || pb.rim.empty()) {
      fail("tube: a rim is not one simple loop of rim vertices");
      continue;
    }
    // The tube runs along the entry rim against its boundary order and along the exit rim in
    // its boundary order: both then turn the same way about the axis.
    const std::vector<std::int32_t> A(pa.rim.rbegin(), pa.rim.rend());
    const double a0 = angle(A[0]);
    std::size_t j0 = 0;
    for (std::size_t j = 1; j < pb.rim.size(); ++j)
      if (std::abs(wrap(angle(pb.rim[j]) - a0)) < std::abs(wrap(angle(pb.rim[j0]) - a0))) j0 = j;
    std::vector<std::int32_t> B(pb.rim.begin() + static_cast<std::ptrdiff_t>(j0), pb.rim.end());
    B.insert(B.end(), pb.rim.begin(), pb.rim.begin() + static_cast<std::ptrdiff_t>(j0));
    const std::vector<double> alpha = turning(A), beta = turning(B);
    if (!winds_with(alpha, beta)) {
      fail("tube: the rims do not wind once around the axis in matching directions");
      continue;
    }
    // The tube must only add edges: the rims share no vertex; along the rims the strip uses
    // the reverse of a boundary half-edge (checked below), and across it edges that the
    // changed mesh does not have (ring vertices are new: no edge has them).
    bool ok = true;
    in_a.clear();
    for (auto v : A) in_a.insert(std::uint64_t(v), 1);
    for (auto v : B) ok = ok && in_a.find(std::uint64_t(v)) < 0;
    // Rings: each rim vertex's partner on the other rim is the one nearest in turning; ring k
    // of K lies at s = k / (K + 1) on the segments from the nearer rim's vertices to their
    // partners, so that it has that rim's spacing. K makes the rings at most ring_spacing ×
    // the rims' mean edge apart (without them one triangle spans the whole wall).
    const double sign = alpha.back() > 0 ? 1 : -1, delta = wrap(angle(B[0]) - a0);
    const std::size_t n = A.size(), m = B.size();
    const std::size_t first_ring = change.new_vertices.size();
    std::vector<std::vector<std::int32_t>> loops{A};
    std::size_t a_family = 1;  // loops[0, a_family) have A's size and correspondence
    if (ok && ring_spacing > 0) {
      std::vector<std::size_t> partner_a(n), partner_b(m);
      for (std::size_t ia = 0, jb = 0; ia < n; ++ia) {
        while (jb + 1 < m && std::abs(sign * (delta + beta[jb + 1]) - sign * alpha[ia]) <
                                 std::abs(sign * (delta + beta[jb]) - sign * alpha[ia]))
          ++jb;
        partner_a[ia] = jb;
      }
      for (std::size_t jb = 0, ia = 0; jb < m; ++jb) {
        while (ia + 1 < n && std::abs(sign * alpha[ia + 1] - sign * (delta + beta[jb])) <
                                 std::abs(sign * alpha[ia] - sign * (delta + beta[jb])))
          ++ia;
        partner_b[jb] = ia;
      }
      double rims = 0, across = 0;
      for (std::size_t k = 0; k < n; ++k) {
        rims += (pos(A[(k + 1) % n]) - pos(A[k])).norm();
        across += (pos(B[partner_a[k]]) - pos(A[k])).norm() / double(n);
      }
      for (std::size_t k = 0; k < m; ++k) rims += (pos(B[(k + 1) % m]) - pos(B[k])).norm();
      const double step = ring_spacing * rims / double(n + m);
      const int rings = std::min(64, std::max(0, int(std::ceil(across / step)) - 1));
      std::vector<Eigen::Vector2d> q;
      for (int r = 1; r <= rings; ++r) {
        const double s = double(r) / (rings + 1);
        const bool from_a = s <= 0.5;
        std::vector<std::int32_t> ring;
        q.clear();
        for (std::size_t k = 0; k < (from_a ? n : m); ++k) {
          const std::int32_t a = from_a ? A[k] : A[partner_b[k]];
          const std::int32_t b = from_a ? B[partner_a[k]] : B[k];
          ring.push_back(nv0 + std::int32_t(change.new_vertices.size()));
          change.new_vertices.push_back(NewVertex::on_edge(a, b, s));
          new_x.push_back((1 - s) * pos(a) + s * pos(b));
          q.push_back(axis.project(new_x.back()));
        }
        if (winding(q) != int(sign)) {  // a ring folds back: no rings for this tube
          change.new_vertices.resize(first_ring);
          new_x.resize(first_ring);
          loops.resize(1);
          a_family = 1;
          break;
        }
        loops.push_back(std::move(ring));
        if (from_a) a_family = loops.size();
      }
    }
    loops.push_back(B);
    const std::size_t first_face = faces.size();
    for (std::size_t k = 0; ok && k + 1 < loops.size(); ++k) {
      if (k + 1 < a_family || k >= a_family) {
        ladder(loops[k], loops[k + 1], faces);
        continue;
      }
      // Between the last ring of A's spacing and the first of B's: merged by angle.
      const auto& P = loops[k];
      const auto& Q = loops[k + 1];
      zip(P, k == 0 ? alpha : turning(P), Q, k + 2 == loops.size() ? beta : turning(Q), faces);
    }
    for (std::size_t f = first_face; f < faces.size() && ok; ++f)
      for (int e = 0; e < 3 && ok; ++e) {
        const std::int32_t x = faces[f][e], y = faces[f][(e + 1) % 3];
        if (x >= nv0 + std::int32_t(first_ring) || y >= nv0 + std::int32_t(first_ring))
          continue;  // a ring vertex: a new edge
        const bool across =
            (in_a.find(std::uint64_t(x)) >= 0) != (in_a.find(std::uint64_t(y)) >= 0);
        ok = !out.has(x, y) && (!across || !out.has(y, x));
      }
    if (!ok) {
      faces.resize(first_face);
      change.new_vertices.resize(first_ring);
      new_x.resize(first_ring);
      fail("tube: the rims share vertices or edges");
      continue;
    }
    // Later tubes see this one's edges between rim vertices (ring vertices are on no rim).
    const std::int32_t rings_from = nv0 + std::int32_t(first_ring);
    for (std::size_t f = first_face; f < faces.size(); ++f)
      for (int e = 0; e < 3; ++e) {
        const std::int32_t x = faces[f][e], y = faces[f][(e + 1) % 3];
        if (x < rings_from && y < rings_from) rim_edges.insert(FlatMap::pair(x, y), 1);
      }
    result.tube_faces += static_cast<std::int32_t>(faces.size() - first_face);
    ++result.tubes;
  }
  change.added_faces.insert(change.added_faces.end(), faces.begin(), faces.end());
}

DrillResult drill_impl(SkinnedMesh& mesh, Adjacency& adjacency, FaceIndex* index,
                       const DrillTool& tool, const DrillOptions& options,
                       const std::vector<SegmentHit>& hits) {
  const Axis axis(tool);
  DrillResult result;
  // The drill's one change: applied to the mesh, its adjacency and the index.
  auto commit = [&](TopologyChange&& ch) {
    apply(mesh, ch, &adjacency);
    if (index) index->update(mesh, ch);
    result.changes.push_back(std::move(ch));
  };
  std::vector<std::int32_t> seeds;
  for (const SegmentHit& h : hits) seeds.push_back(h.face);
  std::sort(seeds.begin(), seeds.end());
  seeds.erase(std::unique(seeds.begin(), seeds.end()), seeds.end());
  if (seeds.empty()) {
    result.message = "the drill's axis does not pierce the surface";
    return result;
  }

  // 1–2. The patches: one breadth-first walk from each pierced face not yet reached.
  thread_local Region region;
  region.reset(mesh, adjacency, axis);
  std::vector<Patch> patches;
  for (auto s : seeds) {
    if (region.loaded(s) >= 0) continue;
    region.walk(s, static_cast<std::int32_t>(patches.size()));
    patches.emplace_back();
  }
  // Where the axis pierces each patch first, and whether it enters the surface there.
  for (const SegmentHit& h : hits) {
    const Region::LocalFace& lf = region.faces[std::size_t(region.loaded(h.face))];
    region.origins[std::size_t(lf.origin)].seed = true;
    Patch& p = patches[std::size_t(lf.patch)];
    if (h.t >= p.t) continue;
    p.t = h.t;
    const Face& t = mesh.faces[std::size_t(h.face)];
    const Eigen::Vector3d n = (mesh.current.col(t[1]) - mesh.current.col(t[0]))
                                  .cross(mesh.current.col(t[2]) - mesh.current.col(t[0]));
    p.entering = n.dot(axis.u) < 0;
  }

  // 3–4. Refinement where the rim crosses: a face holding a chord of the rim polygon longer
  // than the patch's limit is bisected (longest edge first, neighbours kept conforming). The
  // inscribed polygon loses Σ r²(θ − sin θ)/2 ≈ πr² θ²/6 at most for chords of angle ≤ θ: the
  // limit, 1.2 × the circumference / min_rim_points (θ ≈ 0.31 for 24), keeps that under 1.7 %;
  // it shrinks while a patch has fewer than min_rim_points crossings. A face's depth counts
  // its bisections; two halve a triangle as one 1-to-4 split does: `refinements` is depth / 2.
  const int min_rim = std::max(options.min_rim_points, 3);
  const int max_depth = 2 * std::max(options.max_refinements, 0);
  for (auto& p : patches) p.limit = 1.2 * 2 * std::numbers::pi * tool.radius / min_rim;
  auto& work = region.work;
  for (int pass = 0;; ++pass) {
    work.clear();
    for (std::size_t f = region.faces.size(); f-- > 0;) work.push_back(std::int32_t(f));
    while (!work.empty()) {
      const std::int32_t f = work.back();
      work.pop_back();
      const Region::LocalFace& lf = region.faces[std::size_t(f)];
      const double limit = patches[std::size_t(lf.patch)].limit;
      if (lf.depth >= max_depth || region.projected_diameter2(f) <= limit * limit ||
          region.rim_extent(f) <= limit)
        continue;
      region.touched.clear();
      region.refine(f);
      work.insert(work.end(), region.touched.rbegin(), region.touched.rend());
    }
    // Count the crossings, each edge once (from its lower half-edge, or its only loaded one).
    for (auto& p : patches) p.crossings = 0;
    for (std::size_t f = 0; f < region.faces.size(); ++f) {
      const Region::LocalFace& lf = region.faces[f];
      for (int k = 0; k < 3; ++k) {
        const std::int32_t tw = lf.twin[k];
        if (tw >= 0 && tw < std::int32_t(3 * f) + k) continue;
        const auto &a = region.verts[std::size_t(lf.v[k])],
                   &b = region.verts[std::size_t(lf.v[(k + 1) % 3])];
        patches[std::size_t(lf.patch)].crossings += a.side != b.side;
      }
    }
    bool again = false;
    for (auto& p : patches)
      if (p.crossings < min_rim && pass < max_depth) p.limit *= 0.75, again = true;
    if (!again) break;
  }
  for (const auto& p : patches)
    if (p.crossings > 0 && p.crossings < min_rim)
      result.message = "fewer rim points than min_rim_points after max_refinements";

  // 5. Classify: +1 outside, −1 inside, 0 on the cylinder. A vertex closer to the rim than
  // snap_fraction of an edge it ends is taken as a rim vertex (no slivers).
  auto crossing_t = [&](std::int32_t a, std::int32_t b) {
    double roots[2];
    const int n =
        edge_roots(region.verts[std::size_t(a)].q, region.verts[std::size_t(b)].q, axis.r2, roots);
    return n > 0 ? roots[0] : 0.5;
  };
  auto snap_near = [&] {
    for (std::size_t f = 0; f < region.faces.size(); ++f)
      for (int k = 0; k < 3; ++k) {
        const Region::LocalFace& lf = region.faces[f];
        if (lf.twin[k] >= 0 && lf.twin[k] < std::int32_t(3 * f) + k) continue;  // each edge once
        const std::int32_t a = std::min(lf.v[k], lf.v[(k + 1) % 3]),
                           b = std::max(lf.v[k], lf.v[(k + 1) % 3]);
        auto &va = region.verts[std::size_t(a)], &vb = region.verts[std::size_t(b)];
        if (va.side * vb.side >= 0) continue;
        const double t = crossing_t(a, b);
        if (t < options.snap_fraction)
          va.side = 0, ++result.snapped_rim_vertices;
        else if (t > 1 - options.snap_fraction)
          vb.side = 0, ++result.snapped_rim_vertices;
      }
  };
  // No slivers: every face the drill adds keeps its smallest angle at least
  // min(min_angle, half the smallest angle of the original face it lies in). Rivara's
  // bisection keeps half; a face the rim clips is cut into pieces (below) whose angles depend
  // on where the rim crosses its edges: while a piece would be sharper than the bound, one more
  // vertex of that face is taken as a rim vertex (snapped): the nearest to its crossing point
  // of those whose snap leaves the face's pieces within the bound and whose crossing point is
  // within kAngleSnap of the crossed edge from it. A snap changes the pieces of the faces
  // around the vertex, hence the passes; every pass snaps at least one vertex for good, so
  // they end. A face that no such snap mends is bisected (Rivara) and the classification
  // starts again (at most kMendRounds times); in the last round the nearest vertex that
  // mends the face is snapped however far (else the nearest), so that the bound holds.
  const double angle_floor = std::max(options.min_angle, 0.0);
  auto crossing_x = [&](std::int32_t u, std::int32_t w) -> Eigen::Vector3d {
    const std::int32_t a = std::min(u, w), b = std::max(u, w);
    const double t = crossing_t(a, b);
    return (1 - t) * region.verts[std::size_t(a)].x + t * region.verts[std::size_t(b)].x;
  };
  // The smallest angle of the pieces of local face f that stay (as emitted below), as its
  // tangent (smallest_angle); +∞ when the rim does not clip f.
  auto pieces_angle = [&](const std::array<std::int32_t, 3>& t) {
    const auto& X = region.verts;
    const int s[3] = {X[std::size_t(t[0])].side, X[std::size_t(t[1])].side,
                      X[std::size_t(t[2])].side};
    const bool in = s[0] < 0 || s[1] < 0 || s[2]<0, out = s[0]> 0 || s[1] > 0 || s[2] > 0;
    if (!in || !out) return std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k)
      if (s[k] == 0) {
        // The piece between the rim vertex, the outside vertex and the crossing.
        const std::int32_t v0 = t[k], v1 = t[(k + 1) % 3], v2 = t[(k + 2) % 3];
        const std::int32_t outside = X[std::size_t(v1)].side > 0 ? v1 : v2;
        return smallest_angle(X[std::size_t(v0)].x, X[std::size_t(outside)].x, crossing_x(v1, v2));
      }
    int lone = 0;
    for (int k = 0; k < 3; ++k)
      if (s[(k + 1) % 3] == s[(k + 2) % 3]) lone = k;
    const std::int32_t v0 = t[lone], v1 = t[(lone + 1) % 3], v2 = t[(lone + 2) % 3];
    const Eigen::Vector3d x01 = crossing_x(v0, v1), x20 = crossing_x(v2, v0);
    const Eigen::Vector3d &p0 = X[std::size_t(v0)].x, &p1 = X[std::size_t(v1)].x,
                          &p2 = X[std::size_t(v2)].x;
    if (s[lone] > 0) return smallest_angle(p0, x01, x20);
    // The quad (x01, v1, v2, x20), split as split_02 would.
    return std::max(std::min(smallest_angle(x01, p1, p2), smallest_angle(x01, p2, x20)),
                    std::min(smallest_angle(x01, p1, x20), smallest_angle(p1, p2, x20)));
  };
  auto bound = [&](const Region::LocalFace& lf) {
    auto& o = region.origins[std::size_t(lf.origin)];
    if (o.bound < 0) {
      const Face& t = mesh.faces[std::size_t(o.face)];
      const double original = std::atan(
          smallest_angle(mesh.current.col(t[0]), mesh.current.col(t[1]), mesh.current.col(t[2])));
      o.bound = std::tan(std::min(angle_floor, 0.5 * original));  // as a tangent
    }
    return o.bound;
  };
  constexpr double kAngleSnap = 0.1;
  constexpr int kMendRounds = 4;
  auto& unmended = region.work;
  for (int round = 0;; ++round) {
    const bool last = round == kMendRounds;
    if (round > 0) {  // after bisections: classify afresh
      for (auto& v : region.verts) v.side = region.inside(v.q) ? -1 : 1;
      result.snapped_rim_vertices = 0;
    }
    snap_near();
    unmended.clear();
    // Only clipped faces make pieces, and a snap never clips a face that was not: after the
    // first pass, only the clipped faces with a vertex snapped in the pass before are seen.
    auto& clipped = region.clipped;
    clipped.clear();
    if (angle_floor > 0)
      for (std::size_t f = 0; f < region.faces.size(); ++f) {
        bool in = false, out = false;
        for (auto v : region.faces[f].v) {
          in = in || region.verts[std::size_t(v)].side < 0;
          out = out || region.verts[std::size_t(v)].side > 0;
        }
        if (in && out) clipped.push_back(std::int32_t(f));
      }
    for (int pass = 0; pass < 64; ++pass) {
      bool snapped = false;
      const int stamp = 64 * round + pass;
      for (const std::int32_t f : clipped) {
        const Region::LocalFace& lf = region.faces[std::size_t(f)];
        if (pass > 0 && region.verts[std::size_t(lf.v[0])].snapped != stamp - 1 &&
            region.verts[std::size_t(lf.v[1])].snapped != stamp - 1 &&
            region.verts[std::size_t(lf.v[2])].snapped != stamp - 1)
          continue;
        const double b = bound(lf);
        if (pieces_angle(lf.v) >= b) continue;
        // The candidates: the ends of the edges the rim crosses, by distance to the crossing
        // (and that distance over the edge's length).
        struct Candidate {
          double distance2, fraction;
          std::int32_t v;
        };
        std::array<Candidate, 3> candidates;
        int count = 0;
        for (int k = 0; k < 3; ++k) {
          const std::int32_t v = lf.v[k];
          const auto& x = region.verts[std::size_t(v)];
          if (x.side == 0) continue;
          Candidate c{std::numeric_limits<double>::infinity(), 1, v};
          for (const std::int32_t w : {lf.v[(k + 1) % 3], lf.v[(k + 2) % 3]})
            if (region.verts[std::size_t(w)].side == -x.side) {
              const double d2 = (crossing_x(v, w) - x.x).squaredNorm();
              if (d2 < c.distance2)
                c.distance2 = d2,
                c.fraction = std::sqrt(d2 / (region.verts[std::size_t(w)].x - x.x).squaredNorm());
            }
          if (c.distance2 < std::numeric_limits<double>::infinity()) candidates[count++] = c;
        }
        if (count == 0) continue;
        // At most three: an insertion sort (stable, as std::sort is on so few; its inlined
        // threshold of 16 draws a false -Warray-bounds from GCC 12 under the sanitizers).
        for (int i = 1; i < count; ++i)
          for (int j = i; j > 0 && candidates[j].distance2 < candidates[j - 1].distance2; --j)
            std::swap(candidates[j], candidates[j - 1]);
        std::int32_t pick = last ? candidates[0].v : -1;
        for (int c = 0; c < count; ++c) {
          if (!last && candidates[c].fraction > kAngleSnap) continue;
          auto& side = region.verts[std::size_t(candidates[c].v)].side;
          const int was = side;
          side = 0;
          const bool mends = pieces_angle(lf.v) >= b;
          side = was;
          if (mends) {
            pick = candidates[c].v;
            break;
          }
        }
        if (pick < 0) {
          unmended.push_back(f);
          continue;
        }
        region.verts[std::size_t(pick)].side = 0;
        region.verts[std::size_t(pick)].snapped = stamp;
        ++result.snapped_rim_vertices;
        snapped = true;
      }
      if (!snapped) break;
    }
    if (last) break;
    // The faces still unmended (a later snap may have mended one).
    std::vector<std::int32_t> mend;
    for (const std::int32_t f : unmended)
      if (pieces_angle(region.faces[std::size_t(f)].v) < bound(region.faces[std::size_t(f)]))
        mend.push_back(f);
    // A snapped vertex stands for a rim point up to an edge's length away: the rim's chords
    // from it (on Π) may exceed the refinement's limit. Faces holding such a chord are
    // bisected too: a clipped face with a rim vertex (the chord to its crossing) and a removed
    // face with two (their edge).
    for (std::size_t f = 0; f < region.faces.size(); ++f) {
      const Region::LocalFace& lf = region.faces[f];
      if (lf.depth >= max_depth) continue;
      const auto& X = region.verts;
      int zero = -1, zeros = 0, in = 0, out = 0;
      for (int k = 0; k < 3; ++k) {
        const int side = X[std::size_t(lf.v[k])].side;
        if (side == 0) zero = k, ++zeros;
        in += side<0, out += side> 0;
      }
      if (zeros == 0 || in == 0) continue;
      double chord2 = 0;
      if (zeros == 1 && out == 1) {
        const std::int32_t v1 = lf.v[(zero + 1) % 3], v2 = lf.v[(zero + 2) % 3];
        const std::int32_t a = std::min(v1, v2), b = std::max(v1, v2);
        const double t = crossing_t(a, b);
        chord2 = (X[std::size_t(lf.v[zero])].q -
                  ((1 - t) * X[std::size_t(a)].q + t * X[std::size_t(b)].q))
                     .squaredNorm();
      } else if (zeros == 2) {
        const std::int32_t u = lf.v[(zero + 1) % 3], w = lf.v[(zero + 2) % 3];
        chord2 = X[std::size_t(u)].side == 0
                     ? (X[std::size_t(lf.v[zero])].q - X[std::size_t(u)].q).squaredNorm()
                     : (X[std::size_t(lf.v[zero])].q - X[std::size_t(w)].q).squaredNorm();
      }
      const double limit = patches[std::size_t(lf.patch)].limit;
      if (chord2 > limit * limit) mend.push_back(std::int32_t(f));
    }
    if (mend.empty()) break;
    std::sort(mend.begin(), mend.end());
    mend.erase(std::unique(mend.begin(), mend.end()), mend.end());
    for (auto f : mend) region.refine(f);
  }
  int depth = 0;
  for (const auto& lf : region.faces) depth = std::max(depth, int(lf.depth));
  result.refinements = (depth + 1) / 2;
  // Faces with a vertex inside are removed (2) or, with one outside too, clipped (1).
  auto& fate = region.fate;
  fate.assign(region.faces.size(), 0);
  for (std::size_t f = 0; f < region.faces.size(); ++f) {
    const Region::LocalFace& lf = region.faces[f];
    bool in = false, out = false;
    for (auto v : lf.v) {
      in = in || region.verts[std::size_t(v)].side < 0;
      out = out || region.verts[std::size_t(v)].side > 0;
    }
    if (!in) continue;
    fate[f] = out ? 1 : 2;
    region.origins[std::size_t(lf.origin)].modified = true;
    patches[std::size_t(lf.patch)].cut = true;
    ++result.removed_area_faces;
  }
  auto& crossing_vertex = region.crossing_vertex;
  auto cross_vertex = [&](std::int32_t u, std::int32_t w) {
    const std::int32_t a = std::min(u, w), b = std::max(u, w);
    const std::int32_t made = static_cast<std::int32_t>(region.verts.size());
    const std::int32_t id = crossing_vertex.insert(FlatMap::pair(a, b), made);
    if (id == made) region.verts[std::size_t(region.between(a, b, crossing_t(a, b)))].rim = true;
    return id;
  };
  auto area = [&](std::int32_t a, std::int32_t b, std::int32_t c) {
    const Eigen::Vector3d &pa = region.verts[std::size_t(a)].x,
                          &pb = region.verts[std::size_t(b)].x,
                          &pc = region.verts[std::size_t(c)].x;
    return 0.5 * (pb - pa).cross(pc - pa).norm();
  };
  // The faces that replace the modified original faces (local vertices), and the hole's
  // boundary half-edges (the surface on their left) per patch, for the tube.
  auto& added = region.added;
  auto& hole_edges = region.hole_edges;  // (patch, from, to)
  for (std::size_t f = 0; f < region.faces.size(); ++f) {
    const Region::LocalFace& lf = region.faces[f];
    const auto& t = lf.v;
    if (fate[f] == 0) {
      if (region.origins[std::size_t(lf.origin)].modified) added.push_back(t);
      continue;
    }
    const double a0 = area(t[0], t[1], t[2]);
    if (fate[f] == 2) {
      result.removed_area += a0;
      // An edge shared with a kept face (both ends on the rim) borders the hole.
      for (int k = 0; k < 3; ++k) {
        const std::int32_t tw = lf.twin[k];
        if (tw == Region::kBoundary || (tw >= 0 && fate[std::size_t(tw / 3)] != 0)) continue;
        hole_edges.push_back({lf.patch, t[(k + 1) % 3], t[k]});
      }
      continue;
    }
    const int s[3] = {region.verts[std::size_t(t[0])].side, region.verts[std::size_t(t[1])].side,
                      region.verts[std::size_t(t[2])].side};
    double kept = 0;
    auto keep = [&](std::int32_t a, std::int32_t b, std::int32_t c) {
      added.push_back({a, b, c});
      kept += area(a, b, c);
    };
    auto cut = [&](std::int32_t from, std::int32_t to) {
      hole_edges.push_back({lf.patch, from, to});
    };
    int zero = -1;
    for (int k = 0; k < 3; ++k)
      if (s[k] == 0) zero = k;
    if (zero >= 0) {
      const std::int32_t v0 = t[zero], v1 = t[(zero + 1) % 3], v2 = t[(zero + 2) % 3];
      const std::int32_t x = cross_vertex(v1, v2);
      if (s[(zero + 1) % 3] > 0)
        keep(v0, v1, x), cut(x, v0);
      else
        keep(v0, x, v2), cut(v0, x);
    } else {
      int lone = 0;
      for (int k = 0; k < 3; ++k)
        if (s[(k + 1) % 3] == s[(k + 2) % 3]) lone = k;
      const std::int32_t v0 = t[lone], v1 = t[(lone + 1) % 3], v2 = t[(lone + 2) % 3];
      const std::int32_t x01 = cross_vertex(v0, v1), x20 = cross_vertex(v2, v0);
      if (s[lone] > 0) {
        keep(v0, x01, x20), cut(x01, x20);
      } else {
        const auto& X = region.verts;
        if (split_02(X[std::size_t(x01)].x, X[std::size_t(v1)].x, X[std::size_t(v2)].x,
                     X[std::size_t(x20)].x))
          keep(x01, v1, v2), keep(x01, v2, x20);
        else
          keep(x01, v1, x20), keep(v1, v2, x20);
        cut(x20, x01);
      }
    }
    result.removed_area += a0 - kept;
  }
  for (const auto& p : patches) result.holes += p.cut;
  if (result.holes == 0) {
    result.message = "the drill pierces the surface but removes nothing";
    return result;
  }

  // The change: new vertices that the added faces use (refinement's first, then the rim's),
  // each one combination of original vertices; the modified original faces out, the pieces in.
  TopologyChange ch;
  ch.base_vertex_count = mesh.vertex_count();
  ch.base_face_count = mesh.face_count();
  for (const Face& t : added)
    for (auto v : t)
      if (region.verts[std::size_t(v)].index < 0) region.verts[std::size_t(v)].index = -2;
  auto& new_x = region.new_x;  // their positions, for the tube
  for (auto& v : region.verts)
    if (v.index == -2) {
      v.index = ch.base_vertex_count + static_cast<std::int32_t>(ch.new_vertices.size());
      ch.new_vertices.push_back(v.def.new_vertex());
      if (options.tube) new_x.push_back(v.x);
      result.rim_vertices += v.rim;
    }
  for (const auto& o : region.origins)
    if (o.modified) ch.removed_faces.push_back(o.face);
  std::sort(ch.removed_faces.begin(), ch.removed_faces.end());

  // The rim loops, for the tube: per patch, the hole's boundary half-edges chained into one
  // loop of rim vertices (empty when they are not one simple loop).
  if (options.tube)
    for (std::size_t p = 0; p < patches.size(); ++p) {
      if (!patches[p].cut) continue;
      auto& next = region.next;
      next.clear();
      std::size_t count = 0;
      std::int32_t start = -1;
      bool simple = true;
      for (const auto& [patch, from, to] : hole_edges) {
        if (patch != std::int32_t(p)) continue;
        simple = simple && next.insert(std::uint64_t(from), to) == to;
        ++count, start = from;
      }
      std::vector<std::int32_t> loop;
      for (std::int32_t v = start; simple && count >= 3;) {
        const auto& x = region.verts[std::size_t(v)];
        if (!(x.rim || x.side == 0)) break;
        loop.push_back(v);
        v = next.find(std::uint64_t(v));
        if (v < 0 || loop.size() > count) break;
        if (v == start) {
          if (loop.size() == count) {
            for (auto& l : loop) {
              region.verts[std::size_t(l)].loop = true;
              l = region.verts[std::size_t(l)].index;
            }
            patches[p].rim = std::move(loop);
          }
          break;
        }
      }
    }
  // The added faces, in mesh indices; with the tube, their half-edges between rim vertices
  // (the only ones the tube's checks need).
  ch.added_faces.reserve(added.size());
  for (const Face& t : added) {
    const auto &a = region.verts[std::size_t(t[0])], &b = region.verts[std::size_t(t[1])],
               &c = region.verts[std::size_t(t[2])];
    ch.added_faces.push_back({a.index, b.index, c.index});
    if (options.tube) {
      if (a.loop && b.loop) region.rim_edges.insert(FlatMap::pair(a.index, b.index), 1);
      if (b.loop && c.loop) region.rim_edges.insert(FlatMap::pair(b.index, c.index), 1);
      if (c.loop && a.loop) region.rim_edges.insert(FlatMap::pair(c.index, a.index), 1);
    }
  }
  // 6. The tube walls join the rims in the same change.
  if (options.tube) {
    const Outcome out{mesh, adjacency, ch, new_x, region.rim_edges};
    add_tubes(out, axis, patches, options.tube_ring_spacing, ch, new_x, region.rim_edges,
              region.in_a, result);
  }
  commit(std::move(ch));
  return result;
}

}  // namespace

}  // namespace conform::mesh
