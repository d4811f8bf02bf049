#include "conform/mesh/cap.hpp"

#include "conform/mesh/adjacency.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace conform::mesh {

namespace {

using Pts = std::vector<Eigen::Vector2d>;

// The forbidden diagonals (cap.hpp) as sorted (low, high) pairs; empty: none.
class Forbidden {
 public:
  Forbidden() = default;
  explicit Forbidden(const ForbiddenDiagonals& pairs) {
    for (const auto& [a, b] : pairs) pairs_.push_back({std::min(a, b), std::max(a, b)});
    std::sort(pairs_.begin(), pairs_.end());
  }
  bool empty() const { return pairs_.empty(); }
  bool operator()(std::int32_t a, std::int32_t b) const {
    return !pairs_.empty() &&
           std::binary_search(pairs_.begin(), pairs_.end(),
                              std::array<std::int32_t, 2>{std::min(a, b), std::max(a, b)});
  }
  // True when a triangle of `t` has a forbidden edge.
  bool used_by(const std::vector<std::array<std::int32_t, 3>>& t) const {
    for (const auto& tri : t)
      for (int k = 0; k < 3; ++k)
        if ((*this)(tri[static_cast<std::size_t>(k)], tri[static_cast<std::size_t>((k + 1) % 3)]))
          return true;
    return false;
  }

 private:
  std::vector<std::array<std::int32_t, 2>> pairs_;
};

double twice_area(const Pts& p, const std::vector<std::int32_t>& idx) {
  double a = 0;
  for (std::size_t i = 0; i < idx.size(); ++i) {
    const auto& u = p[static_cast<std::size_t>(idx[i])];
    const auto& v = p[static_cast<std::size_t>(idx[(i + 1) % idx.size()])];
    a += u.x() * v.y() - u.y() * v.x();
  }
  return a;
}

// Crossing-number test of q against the closed polygon `idx` of `p`.
bool inside(const Pts& p, const std::vector<std::int32_t>& idx, const Eigen::Vector2d& q) {
  bool in = false;
  for (std::size_t i = 0, j = idx.size() - 1; i < idx.size(); j = i++) {
    const auto& a = p[static_cast<std::size_t>(idx[i])];
    const auto& b = p[static_cast<std::size_t>(idx[j])];
    if ((a.y() > q.y()) != (b.y() > q.y()) &&
        q.x() < a.x() + (q.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y()))
      in = !in;
  }
  return in;
}

double cross(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

// Ear clipping of the polygon `poly` (indices into p, possibly repeating a vertex where a
// bridge enters and leaves a hole), counter-clockwise; appends counter-clockwise triangles.
// False when no ear can be found (not simple).
//
// The polygon is a circular linked list, so clipping is O(1), and only reflex (or flat)
// vertices are tested against a candidate ear: a convex vertex cannot lie inside an ear
// unless a reflex one does too. A nearly convex loop, the usual cut section, is therefore
// clipped in O(n) rather than O(n²).
bool ear_clip(const Pts& p, const std::vector<std::int32_t>& poly,
              std::vector<std::array<std::int32_t, 3>>& out, const Forbidden& forbidden) {
  const auto m = static_cast<std::int32_t>(poly.size());
  if (m < 3) return false;
  auto P = [&](std::int32_t node) -> const Eigen::Vector2d& {
    return p[static_cast<std::size_t>(poly[static_cast<std::size_t>(node)])];
  };
  double scale = 0;
  for (auto i : poly) scale = std::max(scale, p[static_cast<std::size_t>(i)].cwiseAbs().maxCoeff());
  const double eps = 1e-14 * scale * scale;
  const std::size_t first = out.size();
  std::vector<std::int32_t> prev(static_cast<std::size_t>(m)), next(static_cast<std::size_t>(m));
  std::vector<std::uint8_t> reflex(static_cast<std::size_t>(m)),
      alive(static_cast<std::size_t>(m), 1);
  std::vector<std::int32_t> blockers;  // nodes that were reflex or flat when last looked at
  auto at = [](std::vector<std::int32_t>& v, std::int32_t k) -> std::int32_t& {
    return v[static_cast<std::size_t>(k)];
  };
  auto update = [&](std::int32_t k) {
    const bool was = reflex[static_cast<std::size_t>(k)] != 0;
    const bool now = !(cross(P(at(prev, k)), P(k), P(at(next, k))) > eps);
    reflex[static_cast<std::size_t>(k)] = now;
    if (now && !was) blockers.push_back(k);
  };
  for (std::int32_t k = 0; k < m; ++k) at(prev, k) = (k + m - 1) % m, at(next, k) = (k + 1) % m;
  for (std::int32_t k = 0; k < m; ++k) update(k);
  // Round robin: after an ear is clipped the search resumes two vertices on, so that a convex
  // polygon is cut into halves, quarters, … rather than into a fan (fewer flips afterwards).
  std::int32_t left = m, cur = 0, misses = 0;
  while (left > 3) {
    if (misses >= left) return false;  // a whole round without an ear
    const std::int32_t b = cur, a = at(prev, b), c = at(next, b);
    bool ear = reflex[static_cast<std::size_t>(b)] == 0 &&
               !forbidden(poly[static_cast<std::size_t>(a)], poly[static_cast<std::size_t>(c)]);
    if (ear) {
      const Eigen::Vector2d &A = P(a), &B = P(b), &C = P(c);
      for (const std::int32_t q : blockers) {
        if (!alive[static_cast<std::size_t>(q)] || !reflex[static_cast<std::size_t>(q)] || q == a ||
            q == b || q == c)
          continue;
        const Eigen::Vector2d& Q = P(q);
        if (Q == A || Q == B || Q == C) continue;
        if (cross(A, B, Q) >= 0 && cross(B, C, Q) >= 0 && cross(C, A, Q) >= 0) {
          ear = false;
          break;
        }
      }
    }
    if (!ear) {
      cur = c, ++misses;
      continue;
    }
    out.push_back({poly[static_cast<std::size_t>(a)], poly[static_cast<std::size_t>(b)],
                   poly[static_cast<std::size_t>(c)]});
    alive[static_cast<std::size_t>(b)] = 0;
    at(next, a) = c, at(prev, c) = a;
    --left;
    update(a), update(c);
    std::erase_if(blockers, [&](std::int32_t q) {
      return !alive[static_cast<std::size_t>(q)] || !reflex[static_cast<std::size_t>(q)];
    });
    cur = at(next, c), misses = 0;
  }
  const std::int32_t n0 = cur, n1 = at(next, n0), n2 = at(next, n1);
  const std::array<std::int32_t, 3> idx = {poly[static_cast<std::size_t>(n0)],
                                           poly[static_cast<std::size_t>(n1)],
                                           poly[static_cast<std::size_t>(n2)]};
  auto Q = [&](std::int32_t i) -> const Eigen::Vector2d& { return p[static_cast<std::size_t>(i)]; };
  if (cross(Q(idx[0]), Q(idx[1]), Q(idx[2])) > eps) {
    out.push_back(idx);
    return true;
  }
  // The last three are collinear (collinear boundary points, e.g. along a flat face): the
  // middle one b lies on the diagonal (a, c); flip that diagonal with the triangle across it,
  // (a, c, d) → (a, b, d), (b, c, d).
  for (int r = 0; r < 3; ++r) {
    const std::int32_t a = idx[static_cast<std::size_t>(r)],
                       b = idx[static_cast<std::size_t>((r + 1) % 3)],
                       c = idx[static_cast<std::size_t>((r + 2) % 3)];
    const Eigen::Vector2d ac = Q(c) - Q(a);
    const double along = ac.dot(Q(b) - Q(a));
    if (!(along > 0 && along < ac.squaredNorm())) continue;  // b is not between a and c
    for (std::size_t t = first; t < out.size(); ++t)
      for (std::size_t k = 0; k < 3; ++k)
        if (out[t][k] == a && out[t][(k + 1) % 3] == c) {
          const std::int32_t d = out[t][(k + 2) % 3];
          if (cross(Q(a), Q(b), Q(d)) <= eps || cross(Q(b), Q(c), Q(d)) <= eps || forbidden(b, d))
            return false;
          out[t] = {a, b, d};
          out.push_back({b, c, d});
          return true;
        }
  }
  return false;
}

// A convex polygon (no turn below −eps, counter-clockwise) triangulated as a strip from its
// corner farthest from the centroid (an end of its long axis), each step taking the Delaunay
// diagonal of the quadrilateral at the strip's front unless that would make a flat triangle
// (flat vertices: collinear runs of boundary points). The usual cut section, close to an
// ellipse, then comes out Delaunay or nearly so, and the flips after it are few (a balanced
// ear clipping needs O(n) flips of O(n) cost each there). False, with `out` as it was, when
// the polygon is not convex or a step has no non-flat triangle.
bool convex_strip(const Pts& p, const std::vector<std::int32_t>& poly,
                  std::vector<std::array<std::int32_t, 3>>& out) {
  const auto m = static_cast<std::int32_t>(poly.size());
  if (m < 3) return false;
  auto P = [&](std::int32_t k) -> const Eigen::Vector2d& {
    return p[static_cast<std::size_t>(poly[static_cast<std::size_t>(k)])];
  };
  double scale = 0;
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (std::int32_t k = 0; k < m; ++k)
    scale = std::max(scale, P(k).cwiseAbs().maxCoeff()), centroid += P(k);
  centroid /= m;
  const double eps = 1e-14 * scale * scale;
  std::int32_t start = -1;
  double far = -1;
  for (std::int32_t k = 0; k < m; ++k) {
    const double turn = cross(P((k + m - 1) % m), P(k), P((k + 1) % m));
    if (turn < -eps) return false;
    const double d = (P(k) - centroid).squaredNorm();
    if (turn > eps && d > far) far = d, start = k;
  }
  if (start < 0) return false;
  auto id = [&](std::int32_t k) { return poly[static_cast<std::size_t>(k)]; };
  auto solid = [&](std::int32_t a, std::int32_t b, std::int32_t c) {
    return cross(P(a), P(b), P(c)) > eps;
  };
  const std::size_t first = out.size();
  std::int32_t r = (start + m - 1) % m, l = (start + 1) % m;
  out.push_back({id(r), id(start), id(l)});
  for (std::int32_t remaining = m - 1; remaining > 3; --remaining) {
    const std::int32_t ahead = (l + 1) % m, behind = (r + m - 1) % m;
    // The quadrilateral (behind, r, l, ahead): diagonal (r, ahead) when `ahead` lies inside
    // the circle through (behind, r, l), else (behind, l).
    const Eigen::Vector2d u = P(behind) - P(ahead), v = P(r) - P(ahead), w = P(l) - P(ahead);
    const double in = u.squaredNorm() * (v.x() * w.y() - v.y() * w.x()) -
                      v.squaredNorm() * (u.x() * w.y() - u.y() * w.x()) +
                      w.squaredNorm() * (u.x() * v.y() - u.y() * v.x());
    const bool take_ahead = solid(r, l, ahead), take_behind = solid(behind, r, l);
    if (take_ahead && (in > 0 || !take_behind)) {
      out.push_back({id(r), id(l), id(ahead)}), l = ahead;
    } else if (take_behind) {
      out.push_back({id(behind), id(r), id(l)}), r = behind;
    } else {
      out.resize(first);
      return false;
    }
  }
  if (m > 3) {
    if (!solid(r, l, (l + 1) % m)) {
      out.resize(first);
      return false;
    }
    out.push_back({id(r), id(l), id((l + 1) % m)});
  }
  return true;
}

// Joins the clockwise hole `hole` into the counter-clockwise polygon `poly` by a bridge from
// the hole's rightmost vertex M to a vertex of poly that M sees (Eberly's construction: the
// nearest edge hit by the ray from M towards +x, then the reflex vertex within the triangle
// (M, hit, edge end) closest in angle to the ray, if any). False if no edge is hit.
bool bridge(const Pts& p, std::vector<std::int32_t>& poly, const std::vector<std::int32_t>& hole) {
  std::size_t mi = 0;
  for (std::size_t i = 1; i < hole.size(); ++i) {
    const auto& a = p[static_cast<std::size_t>(hole[i])];
    const auto& b = p[static_cast<std::size_t>(hole[mi])];
    if (a.x() > b.x() || (a.x() == b.x() && a.y() < b.y())) mi = i;
  }
  const Eigen::Vector2d M = p[static_cast<std::size_t>(hole[mi])];
  const std::size_t n = poly.size();
  double best_x = INFINITY;
  std::size_t best = n;  // the poly index of the visible candidate
  for (std::size_t i = 0; i < n; ++i) {
    const auto& a = p[static_cast<std::size_t>(poly[i])];
    const auto& b = p[static_cast<std::size_t>(poly[(i + 1) % n])];
    // Edges crossing the horizontal through M from below to above (the outer boundary is
    // counter-clockwise, so its edges to the right of an inside point go upwards).
    if (!(a.y() <= M.y() && b.y() >= M.y()) || a.y() == b.y()) continue;
    const double x = a.x() + (M.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
    if (x < M.x() || x >= best_x) continue;
    best_x = x;
    if (x == a.x() && a.y() == M.y())
      best = i;
    else if (x == b.x() && b.y() == M.y())
      best = (i + 1) % n;
    else
      best = a.x() > b.x() ? i : (i + 1) % n;
  }
  if (best == n) return false;
  const Eigen::Vector2d I(best_x, M.y());
  const Eigen::Vector2d Pc = p[static_cast<std::size_t>(poly[best])];
  if (Pc != I) {
    // Reflex vertices of poly inside the triangle (M, I, Pc) may hide Pc: take the one with
    // the smallest angle to the ray, the nearest on ties.
    const double orient = cross(M, I, Pc);
    double best_tan = INFINITY, best_d = INFINITY;
    for (std::size_t i = 0; i < n; ++i) {
      const auto& q = p[static_cast<std::size_t>(poly[i])];
      if (i == best || q.x() < M.x()) continue;
      const auto& prev = p[static_cast<std::size_t>(poly[(i + n - 1) % n])];
      const auto& next = p[static_cast<std::size_t>(poly[(i + 1) % n])];
      if (cross(prev, q, next) > 0) continue;  // convex
      const bool in = orient * cross(M, I, q) >= 0 && orient * cross(I, Pc, q) >= 0 &&
                      orient * cross(Pc, M, q) >= 0;
      if (!in) continue;
      const double dx = q.x() - M.x(), tan = std::abs(q.y() - M.y()) / std::max(dx, 1e-300);
      const double d = (q - M).squaredNorm();
      if (tan < best_tan || (tan == best_tan && d < best_d)) best_tan = tan, best_d = d, best = i;
    }
  }
  std::vector<std::int32_t> merged;
  merged.reserve(n + hole.size() + 2);
  merged.insert(merged.end(), poly.begin(), poly.begin() + static_cast<std::ptrdiff_t>(best) + 1);
  for (std::size_t k = 0; k <= hole.size(); ++k) merged.push_back(hole[(mi + k) % hole.size()]);
  merged.push_back(poly[best]);
  merged.insert(merged.end(), poly.begin() + static_cast<std::ptrdiff_t>(best) + 1, poly.end());
  poly = std::move(merged);
  return true;
}

// Lawson's flips on the triangles [first, end) of `t`: every edge shared by two triangles whose
// fourth point lies inside the other's circumcircle is flipped, until none is (or a generous
// flip budget runs out). Edges used once — the loops — never flip, so the result is the
// constrained Delaunay triangulation of the region (up to ties among cocircular points).
//
// Half-edge h = 3 i + k runs from t[first + i][k] to t[first + i][k + 1]; twins are paired
// once by sorting the undirected edges, then kept up to date across flips (no hashing).
void delaunay_flips(const Pts& p, std::vector<std::array<std::int32_t, 3>>& t, std::size_t first,
                    const Forbidden& forbidden = {}) {
  const std::size_t n = t.size() - first;
  if (n < 2) return;
  auto P = [&](std::int32_t i) -> const Eigen::Vector2d& { return p[static_cast<std::size_t>(i)]; };
  auto tri = [&](std::int32_t i) -> std::array<std::int32_t, 3>& {
    return t[first + static_cast<std::size_t>(i)];
  };
  double scale = 0;
  for (std::size_t i = first; i < t.size(); ++i)
    for (auto v : t[i]) scale = std::max(scale, P(v).cwiseAbs().maxCoeff());
  const double eps_area = 1e-14 * scale * scale, eps_circle = 1e-12 * std::pow(scale, 4);
  const auto nh = static_cast<std::int32_t>(3 * n);
  auto from = [&](std::int32_t h) { return tri(h / 3)[static_cast<std::size_t>(h % 3)]; };
  auto to = [&](std::int32_t h) { return tri(h / 3)[static_cast<std::size_t>((h % 3 + 1) % 3)]; };
  // Pair twins through per-vertex lists of outgoing half-edges: an inner edge is used exactly
  // once in each direction (else it is a loop edge, or degenerate, and is kept).
  std::vector<std::int32_t> twin(static_cast<std::size_t>(nh), -1);
  {
    std::vector<std::int32_t> head(p.size(), -1), next_out(static_cast<std::size_t>(nh));
    for (std::int32_t h = 0; h < nh; ++h) {
      next_out[static_cast<std::size_t>(h)] = head[static_cast<std::size_t>(from(h))];
      head[static_cast<std::size_t>(from(h))] = h;
    }
    auto uses = [&](std::int32_t u, std::int32_t v, std::int32_t& last) {
      int count = 0;
      for (std::int32_t g = head[static_cast<std::size_t>(u)]; g >= 0;
           g = next_out[static_cast<std::size_t>(g)])
        if (to(g) == v) ++count, last = g;
      return count;
    };
    for (std::int32_t h = 0; h < nh; ++h) {
      std::int32_t g = -1, same = -1;
      if (twin[static_cast<std::size_t>(h)] < 0 && uses(to(h), from(h), g) == 1 &&
          uses(from(h), to(h), same) == 1)
        twin[static_cast<std::size_t>(h)] = g, twin[static_cast<std::size_t>(g)] = h;
    }
  }
  auto link = [&](std::int32_t x, std::int32_t y) {
    twin[static_cast<std::size_t>(x)] = y;
    if (y >= 0) twin[static_cast<std::size_t>(y)] = x;
  };
  auto incircle = [&](std::int32_t a, std::int32_t b, std::int32_t c, std::int32_t d) {
    const Eigen::Vector2d u = P(a) - P(d), v = P(b) - P(d), w = P(c) - P(d);
    return u.squaredNorm() * (v.x() * w.y() - v.y() * w.x()) -
           v.squaredNorm() * (u.x() * w.y() - u.y() * w.x()) +
           w.squaredNorm() * (u.x() * v.y() - u.y() * v.x());
  };
  std::vector<std::int32_t> stack;
  stack.reserve(static_cast<std::size_t>(nh));
  for (std::int32_t h = 0; h < nh; ++h)
    if (twin[static_cast<std::size_t>(h)] > h) stack.push_back(h);
  std::size_t budget = 20 * n * n + 100;
  while (!stack.empty() && budget-- > 0) {
    const std::int32_t h = stack.back();
    stack.pop_back();
    const std::int32_t o = twin[static_cast<std::size_t>(h)];
    if (o < 0) continue;  // a loop edge
    const std::int32_t i = h / 3, k = h % 3, j = o / 3, l = o % 3;
    std::array<std::int32_t, 3>&ti = tri(i), &tj = tri(j);
    const std::int32_t a = ti[static_cast<std::size_t>(k)],
                       b = ti[static_cast<std::size_t>((k + 1) % 3)],
                       c = ti[static_cast<std::size_t>((k + 2) % 3)],
                       d = tj[static_cast<std::size_t>((l + 2) % 3)];
    if (!(incircle(a, b, c, d) > eps_circle) || forbidden(c, d)) continue;
    // (a, b, c) and (b, a, d) → (a, d, c) and (d, b, c), when both turn counter-clockwise.
    if (!(cross(P(a), P(d), P(c)) > eps_area) || !(cross(P(d), P(b), P(c)) > eps_area)) continue;
    const std::int32_t bc = twin[static_cast<std::size_t>(3 * i + (k + 1) % 3)],
                       ca = twin[static_cast<std::size_t>(3 * i + (k + 2) % 3)],
                       ad = twin[static_cast<std::size_t>(3 * j + (l + 1) % 3)],
                       db = twin[static_cast<std::size_t>(3 * j + (l + 2) % 3)];
    ti = {a, d, c};
    tj = {d, b, c};
    link(3 * i, ad), link(3 * i + 1, 3 * j + 2), link(3 * i + 2, ca);
    link(3 * j, db), link(3 * j + 1, bc);
    for (const std::int32_t e : {3 * i, 3 * i + 2, 3 * j, 3 * j + 1})
      if (twin[static_cast<std::size_t>(e)] >= 0) stack.push_back(e);
  }
}

bool ear_clip_section(const std::vector<Pts>& loops, SectionTriangulation& out,
                      const Forbidden& forbidden = {}) {
  Pts p;
  std::vector<std::vector<std::int32_t>> idx(loops.size());
  for (std::size_t l = 0; l < loops.size(); ++l)
    for (const auto& q : loops[l]) {
      idx[l].push_back(static_cast<std::int32_t>(p.size()));
      p.push_back(q);
    }
  const std::size_t nl = loops.size();
  // Nesting: depth = how many other loops contain the loop; parent = the deepest of those.
  std::vector<double> area(nl);
  for (std::size_t l = 0; l < nl; ++l) area[l] = std::abs(twice_area(p, idx[l]));
  out.depth.assign(nl, 0);
  std::vector<std::ptrdiff_t> parent(nl, -1);
  for (std::size_t l = 0; l < nl; ++l)
    for (std::size_t o = 0; o < nl; ++o) {
      if (o == l || !inside(p, idx[o], p[static_cast<std::size_t>(idx[l][0])])) continue;
      ++out.depth[l];
      if (parent[l] < 0 || area[o] < area[static_cast<std::size_t>(parent[l])])
        parent[l] = static_cast<std::ptrdiff_t>(o);
    }
  // Even depth: an outer boundary (made counter-clockwise); odd: a hole of its parent
  // (clockwise), bridged in from the rightmost hole leftwards.
  for (std::size_t l = 0; l < nl; ++l) {
    const bool ccw = twice_area(p, idx[l]) > 0;
    if (ccw != (out.depth[l] % 2 == 0)) std::reverse(idx[l].begin(), idx[l].end());
  }
  for (std::size_t l = 0; l < nl; ++l) {
    if (out.depth[l] % 2 != 0) continue;
    std::vector<std::size_t> holes;
    for (std::size_t h = 0; h < nl; ++h)
      if (parent[h] == static_cast<std::ptrdiff_t>(l) && out.depth[h] == out.depth[l] + 1)
        holes.push_back(h);
    auto max_x = [&](std::size_t h) {
      double x = -INFINITY;
      for (auto i : idx[h]) x = std::max(x, p[static_cast<std::size_t>(i)].x());
      return x;
    };
    std::sort(holes.begin(), holes.end(),
              [&](std::size_t a, std::size_t b) { return max_x(a) > max_x(b); });
    std::vector<std::int32_t> poly = idx[l];
    for (auto h : holes)
      if (!bridge(p, poly, idx[h])) {
        out.problem = "a hole of the section could not be bridged to its outer loop";
        return false;
      }
    if (!(holes.empty() && forbidden.empty() && convex_strip(p, poly, out.triangles)) &&
        !ear_clip(p, poly, out.triangles, forbidden)) {
      out.problem = "a loop whose projection is not a simple polygon";
      return false;
    }
  }
  delaunay_flips(p, out.triangles, 0, forbidden);
  return true;
}

// Flat vertices: a cut across a mesh of quads split into triangles crosses each quad's
// diagonal on the straight segment between its two side crossings, so every other vertex of
// such a section lies on the line through its neighbours (within rounding). Those vertices
// make the loop non-strictly convex (no strip), and their orientation tests sit at the limit
// of floating point (CGAL's filters fail there and fall back to exact arithmetic). So they are
// taken out, the remaining corners triangulated, and each run of flat vertices put back by
// splitting the one section triangle on its edge into a fan from that triangle's third vertex
// (its triangles keep a positive area: that vertex is off the line). The flips that follow
// make the whole constrained Delaunay again.
struct Corners {
  std::vector<Pts> loops;               // the loops without their flat vertices
  std::vector<std::int32_t> original;   // corner (loops concatenated) → vertex (the same)
  std::vector<std::int32_t> run_start;  // per corner: the first flat vertex after it, or −1
  std::vector<std::int32_t> run_length;
  bool any_flat = false;
};

Corners find_corners(const std::vector<Pts>& loops) {
  Corners c;
  c.loops.resize(loops.size());
  std::int32_t base = 0;
  for (std::size_t l = 0; l < loops.size(); ++l) {
    const Pts& q = loops[l];
    const auto m = static_cast<std::int32_t>(q.size());
    double scale = 0;
    for (const auto& x : q) scale = std::max(scale, x.cwiseAbs().maxCoeff());
    const double eps = 1e-14 * scale * scale;
    std::vector<std::uint8_t> flat(static_cast<std::size_t>(m), 0);
    std::int32_t corners = 0;
    for (std::int32_t k = 0; k < m; ++k) {
      const Eigen::Vector2d &a = q[static_cast<std::size_t>((k + m - 1) % m)],
                            &b = q[static_cast<std::size_t>(k)],
                            &d = q[static_cast<std::size_t>((k + 1) % m)];
      const double along = (b - a).dot(d - a);  // b strictly between a and d, not a spike
      flat[static_cast<std::size_t>(k)] =
          std::abs(cross(a, b, d)) <= eps && along > 0 && along < (d - a).squaredNorm();
      corners += !flat[static_cast<std::size_t>(k)];
    }
    if (corners < 3 || corners == m) {  // nothing to take out, or too little would be left
      for (std::int32_t k = 0; k < m; ++k) {
        c.loops[l].push_back(q[static_cast<std::size_t>(k)]);
        c.original.push_back(base + k);
        c.run_start.push_back(-1), c.run_length.push_back(0);
      }
      base += m;
      continue;
    }
    c.any_flat = true;
    std::int32_t k0 = 0;
    while (flat[static_cast<std::size_t>(k0)]) ++k0;  // start at a corner
    for (std::int32_t j = 0; j < m;) {
      const std::int32_t k = (k0 + j) % m;
      c.loops[l].push_back(q[static_cast<std::size_t>(k)]);
      c.original.push_back(base + k);
      std::int32_t run = 0;
      while (flat[static_cast<std::size_t>((k + 1 + run) % m)]) ++run;
      c.run_start.push_back(run > 0 ? base + (k + 1) % m : -1);
      c.run_length.push_back(run);
      j += 1 + run;
    }
    base += m;
  }
  return c;
}

// Puts the flat vertices back (see Corners): `out` holds the corners' triangulation, in
// vertex ids already. Flat vertices of a loop follow one another in the loop's order, so the
// run after corner a (to the next corner b) is run_start .. run_start + length − 1, wrapping
// within the loop.
bool put_back_flat(const std::vector<Pts>& loops, const Corners& c, SectionTriangulation& out) {
  // Directed edge → triangle. Splitting a triangle moves one of its other edges into a new
  // triangle: that entry is overwritten, so later runs on it find where it went.
  EdgeMap where;
  where.reserve(3 * out.triangles.size());
  for (std::size_t t = 0; t < out.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k)
      where.insert(out.triangles[t][static_cast<std::size_t>(k)],
                   out.triangles[t][static_cast<std::size_t>((k + 1) % 3)],
                   static_cast<std::int32_t>(t), true);
  auto find = [&](std::int32_t u, std::int32_t v) { return where.find(u, v); };
  std::vector<std::int32_t> loop_start(loops.size() + 1, 0);
  for (std::size_t l = 0; l < loops.size(); ++l)
    loop_start[l + 1] = loop_start[l] + static_cast<std::int32_t>(loops[l].size());
  auto loop_of = [&](std::int32_t v) {
    return static_cast<std::size_t>(std::upper_bound(loop_start.begin(), loop_start.end(), v) -
                                    loop_start.begin() - 1);
  };
  std::vector<std::int32_t> run;
  const std::size_t n = c.original.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (c.run_length[i] == 0) continue;
    const std::int32_t a = c.original[i];
    const std::size_t l = loop_of(a);
    const std::int32_t lo = loop_start[l], size = loop_start[l + 1] - lo;
    run.clear();
    for (std::int32_t j = 0; j < c.run_length[i]; ++j)
      run.push_back(lo + (c.run_start[i] - lo + j) % size);
    const std::int32_t b = lo + (run.back() - lo + 1) % size;
    // The section lies on one side of the loop edge (a, b): the triangle holding it holds
    // either a → b or b → a.
    std::int32_t t = find(a, b);
    bool forward = true;
    if (t < 0) t = find(b, a), forward = false;
    if (t < 0) return false;
    std::array<std::int32_t, 3>& tri = out.triangles[static_cast<std::size_t>(t)];
    std::int32_t apex = -1;
    for (auto v : tri)
      if (v != a && v != b) apex = v;
    if (!forward) std::reverse(run.begin(), run.end());
    const std::int32_t from = forward ? a : b, to = forward ? b : a;
    // (from, to, apex) → (from, r0, apex), (r0, r1, apex), …, (r_last, to, apex).
    tri = {from, run.front(), apex};
    for (std::size_t j = 0; j + 1 < run.size(); ++j)
      out.triangles.push_back({run[j], run[j + 1], apex});
    out.triangles.push_back({run.back(), to, apex});
    where.insert(to, apex, static_cast<std::int32_t>(out.triangles.size() - 1), true);
  }
  return true;
}

}  // namespace

bool has_cgal_triangulator() {
  return detail::cdt_available();
}

namespace {

// The triangulation by `method` (not Best), forbidden diagonals aside; false when it failed.
bool triangulate_as_asked(const std::vector<Pts>& loops, SectionTriangulator method,
                          SectionTriangulation& out) {
  auto triangulate = [&](const std::vector<Pts>& l) {
    return method == SectionTriangulator::ConstrainedDelaunay ? detail::cdt_section(l, out)
                                                              : ear_clip_section(l, out);
  };
  const Corners corners =
      method == SectionTriangulator::ConstrainedDelaunay ? find_corners(loops) : Corners{};
  bool ok = false;
  // Ear clipping strips convex loops with their flat vertices in place; CGAL gets the corners.
  if (method == SectionTriangulator::ConstrainedDelaunay && corners.any_flat &&
      triangulate(corners.loops)) {
    for (auto& t : out.triangles)
      for (auto& v : t) v = corners.original[static_cast<std::size_t>(v)];
    ok = put_back_flat(loops, corners, out);
    if (ok) {
      Pts all;
      for (const auto& l : loops) all.insert(all.end(), l.begin(), l.end());
      delaunay_flips(all, out.triangles, 0);
    }
  }
  if (!ok) {  // no flat vertices, or the corners alone did not triangulate: the loops as given
    out = SectionTriangulation{};
    ok = triangulate(loops);
  }
  return ok;
}

}  // namespace

SectionTriangulation triangulate_section(const std::vector<std::vector<Eigen::Vector2d>>& loops,
                                         SectionTriangulator method,
                                         const ForbiddenDiagonals& forbidden_pairs) {
  SectionTriangulation out;
  for (const auto& l : loops) {
    if (l.size() < 3) {
      out.problem = "a loop with fewer than 3 vertices";
      return out;
    }
    for (const auto& q : l)
      if (!q.allFinite()) {
        out.problem = "a non-finite loop vertex";
        return out;
      }
  }
  if (method == SectionTriangulator::Best)
    method = detail::cdt_available() ? SectionTriangulator::ConstrainedDelaunay
                                     : SectionTriangulator::EarClipping;
  bool ok = triangulate_as_asked(loops, method, out);
  const Forbidden forbidden(forbidden_pairs);
  if (ok && forbidden.used_by(out.triangles)) {
    // Again by ear clipping that avoids them (the constrained Delaunay cannot be told to).
    out = SectionTriangulation{};
    ok = ear_clip_section(loops, out, forbidden);
    if (ok && forbidden.used_by(out.triangles)) {  // only a hole's bridge can still use one
      ok = false;
      out.problem =
          "the section cannot be triangulated without joining two loop vertices "
          "that a mesh edge in the plane already joins";
    }
  }
  if (!ok) {
    out.triangles.clear();
    if (out.problem.empty()) out.problem = "the section could not be triangulated";
  }
  return out;
}

}  // namespace conform::mesh
