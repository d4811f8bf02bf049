#include "conform/mesh/cap.hpp"

#include "conform/mesh/adjacency.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace conform::mesh {

namespace {

using Pts = std::vector<Eigen::Vector2d>;

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
bool ear_clip(const Pts& p, std::vector<std::int32_t> idx,
              std::vector<std::array<std::int32_t, 3>>& out) {
  if (idx.size() < 3) return false;
  auto P = [&](std::int32_t i) -> const Eigen::Vector2d& { return p[static_cast<std::size_t>(i)]; };
  double scale = 0;
  for (auto i : idx) scale = std::max(scale, P(i).cwiseAbs().maxCoeff());
  const double eps = 1e-14 * scale * scale;
  const std::size_t first = out.size();
  // Round robin: after an ear is clipped the search resumes two vertices on, so that a convex
  // polygon is cut into halves, quarters, … rather than into a fan (fewer flips afterwards).
  std::size_t start = 0;
  while (idx.size() > 3) {
    const std::size_t m = idx.size();
    bool clipped = false;
    for (std::size_t step = 0; step < m && !clipped; ++step) {
      const std::size_t i = (start + step) % m;
      const std::int32_t a = idx[(i + m - 1) % m], b = idx[i], c = idx[(i + 1) % m];
      if (cross(P(a), P(b), P(c)) <= eps) continue;  // reflex or flat: not an ear
      bool blocked = false;
      for (std::size_t j = 0; j < m && !blocked; ++j) {
        const std::int32_t q = idx[j];
        if (q == a || q == b || q == c || P(q) == P(a) || P(q) == P(b) || P(q) == P(c)) continue;
        blocked = cross(P(a), P(b), P(q)) >= 0 && cross(P(b), P(c), P(q)) >= 0 &&
                  cross(P(c), P(a), P(q)) >= 0;
      }
      if (blocked) continue;
      out.push_back({a, b, c});
      idx.erase(idx.begin() + static_cast<std::ptrdiff_t>(i));
      start = i + 1;
      clipped = true;
    }
    if (!clipped) return false;
  }
  if (cross(P(idx[0]), P(idx[1]), P(idx[2])) > eps) {
    out.push_back({idx[0], idx[1], idx[2]});
    return true;
  }
  // The last three are collinear (collinear boundary points, e.g. along a flat face): the
  // middle one b lies on the diagonal (a, c); flip that diagonal with the triangle across it,
  // (a, c, d) → (a, b, d), (b, c, d).
  for (int r = 0; r < 3; ++r) {
    const std::int32_t a = idx[static_cast<std::size_t>(r)],
                       b = idx[static_cast<std::size_t>((r + 1) % 3)],
                       c = idx[static_cast<std::size_t>((r + 2) % 3)];
    const Eigen::Vector2d ac = P(c) - P(a);
    const double along = ac.dot(P(b) - P(a));
    if (!(along > 0 && along < ac.squaredNorm())) continue;  // b is not between a and c
    for (std::size_t t = first; t < out.size(); ++t)
      for (std::size_t k = 0; k < 3; ++k)
        if (out[t][k] == a && out[t][(k + 1) % 3] == c) {
          const std::int32_t d = out[t][(k + 2) % 3];
          if (cross(P(a), P(b), P(d)) <= eps || cross(P(b), P(c), P(d)) <= eps) return false;
          out[t] = {a, b, d};
          out.push_back({b, c, d});
          return true;
        }
  }
  return false;
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
void delaunay_flips(const Pts& p, std::vector<std::array<std::int32_t, 3>>& t, std::size_t first) {
  const std::size_t n = t.size() - first;
  if (n < 2) return;
  auto P = [&](std::int32_t i) -> const Eigen::Vector2d& { return p[static_cast<std::size_t>(i)]; };
  double scale = 0;
  for (std::size_t i = first; i < t.size(); ++i)
    for (auto v : t[i]) scale = std::max(scale, P(v).cwiseAbs().maxCoeff());
  const double eps_area = 1e-14 * scale * scale, eps_circle = 1e-12 * std::pow(scale, 4);
  EdgeMap where;  // directed edge → 3 · triangle + k
  where.reserve(3 * n);
  std::vector<std::int32_t> stack;
  for (std::size_t i = first; i < t.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const auto code = static_cast<std::int32_t>(3 * i + static_cast<std::size_t>(k));
      where.insert(t[i][static_cast<std::size_t>(k)], t[i][static_cast<std::size_t>((k + 1) % 3)],
                   code, true);
      stack.push_back(code);
    }
  auto incircle = [&](std::int32_t a, std::int32_t b, std::int32_t c, std::int32_t d) {
    const Eigen::Vector2d u = P(a) - P(d), v = P(b) - P(d), w = P(c) - P(d);
    return u.squaredNorm() * (v.x() * w.y() - v.y() * w.x()) -
           v.squaredNorm() * (u.x() * w.y() - u.y() * w.x()) +
           w.squaredNorm() * (u.x() * v.y() - u.y() * v.x());
  };
  std::size_t budget = 20 * n * n + 100;
  while (!stack.empty() && budget-- > 0) {
    const std::int32_t code = stack.back();
    stack.pop_back();
    const auto i = static_cast<std::size_t>(code / 3);
    const int k = code % 3;
    const std::int32_t a = t[i][static_cast<std::size_t>(k)],
                       b = t[i][static_cast<std::size_t>((k + 1) % 3)],
                       c = t[i][static_cast<std::size_t>((k + 2) % 3)];
    if (where.find(a, b) != code) continue;  // stale: this triangle changed since
    const std::int32_t other = where.find(b, a);
    if (other < 0) continue;  // a loop edge
    const auto j = static_cast<std::size_t>(other / 3);
    const std::int32_t d = t[j][static_cast<std::size_t>((other % 3 + 2) % 3)];
    if (!(incircle(a, b, c, d) > eps_circle)) continue;
    // (a, b, c) and (b, a, d) → (a, d, c) and (d, b, c), when both turn counter-clockwise.
    if (!(cross(P(a), P(d), P(c)) > eps_area) || !(cross(P(d), P(b), P(c)) > eps_area)) continue;
    where.erase(a, b, code);
    where.erase(b, a, other);
    t[i] = {a, d, c};
    t[j] = {d, b, c};
    for (const std::size_t x : {i, j})
      for (int m = 0; m < 3; ++m) {
        const auto cm = static_cast<std::int32_t>(3 * x + static_cast<std::size_t>(m));
        where.insert(t[x][static_cast<std::size_t>(m)], t[x][static_cast<std::size_t>((m + 1) % 3)],
                     cm, true);
        stack.push_back(cm);
      }
  }
}

bool ear_clip_section(const std::vector<Pts>& loops, SectionTriangulation& out) {
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
    if (!ear_clip(p, std::move(poly), out.triangles)) {
      out.problem = "a loop whose projection is not a simple polygon";
      return false;
    }
  }
  delaunay_flips(p, out.triangles, 0);
  return true;
}

}  // namespace

bool has_cgal_triangulator() {
  return detail::cdt_available();
}

SectionTriangulation triangulate_section(const std::vector<std::vector<Eigen::Vector2d>>& loops,
                                         SectionTriangulator method) {
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
  const bool ok = method == SectionTriangulator::ConstrainedDelaunay
                      ? detail::cdt_section(loops, out)
                      : ear_clip_section(loops, out);
  if (!ok) {
    out.triangles.clear();
    if (out.problem.empty()) out.problem = "the section could not be triangulated";
  }
  return out;
}

}  // namespace conform::mesh
