#include "conform/mesh/drill.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <deque>
#include <numbers>
#include <stdexcept>

#include "conform/mesh/refine.hpp"

namespace conform::mesh {

namespace {

struct Axis {
  Eigen::Vector3d b, u;  // base and unit direction towards the tip
  double length = 0, r2 = 0;
  Eigen::Vector3d radial(const Eigen::Vector3d& x) const {
    const Eigen::Vector3d q = x - b;
    return q - q.dot(u) * u;
  }
};

// Segment p→q against triangle (a, b, c), Möller–Trumbore; true when they meet.
bool segment_hits(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& a,
                  const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d d = q - p, e1 = b - a, e2 = c - a;
  const Eigen::Vector3d h = d.cross(e2);
  const double det = e1.dot(h);
  if (std::abs(det) < 1e-300) return false;
  const double inv = 1 / det;
  const Eigen::Vector3d s = p - a;
  const double u = inv * s.dot(h);
  if (u < 0 || u > 1) return false;
  const Eigen::Vector3d qv = s.cross(e1);
  const double v = inv * d.dot(qv);
  if (v < 0 || u + v > 1) return false;
  const double t = inv * e2.dot(qv);
  return t >= 0 && t <= 1;
}

// The roots α in [0, 1] of |μ + α(ν − μ)|² = r² (eqs 18–20 with α from μ), ascending.
int edge_roots(const Eigen::Vector3d& mu, const Eigen::Vector3d& nu, double r2, double out[2]) {
  const Eigen::Vector3d d = nu - mu;
  const double k = d.squaredNorm(), l = 2 * mu.dot(d), n = mu.squaredNorm() - r2;
  if (!(k > 0)) return 0;  // the edge is parallel to the axis: its projection is a point
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

}  // namespace

double axis_distance_squared(const DrillTool& tool, const Eigen::Vector3d& x) {
  const Eigen::Vector3d u = (tool.tip - tool.base).normalized();
  const Eigen::Vector3d q = x - tool.base;
  return (q - q.dot(u) * u).squaredNorm();
}

DrillResult drill(SkinnedMesh& mesh, Adjacency& adjacency, const DrillTool& tool,
                  const DrillOptions& options) {
  if (!tool.tip.allFinite() || !tool.base.allFinite() || !std::isfinite(tool.radius))
    throw std::invalid_argument("drill: tip, base and radius must be finite");
  if (!(tool.radius > 0)) throw std::invalid_argument("drill: the radius must be positive");
  const double len = (tool.tip - tool.base).norm();
  if (!(len > 0)) throw std::invalid_argument("drill: tip and base must differ");
  if (!adjacency.matches(mesh))
    throw std::invalid_argument("drill: the adjacency does not describe this mesh");
  if (!mesh.current.allFinite()) throw std::invalid_argument("drill: non-finite positions");
  Axis axis{tool.base, (tool.tip - tool.base) / len, len, tool.radius * tool.radius};
  DrillResult result;

  auto pierced = [&](std::int32_t f) {
    const Face& t = mesh.faces[static_cast<std::size_t>(f)];
    return segment_hits(tool.base, tool.tip, mesh.current.col(t[0]), mesh.current.col(t[1]),
                        mesh.current.col(t[2]));
  };
  std::vector<std::int32_t> seeds;
  for (std::int32_t f = 0; f < mesh.face_count(); ++f)
    if (pierced(f)) seeds.push_back(f);
  if (seeds.empty()) {
    result.message = "the drill's axis does not pierce the surface";
    return result;
  }
  auto inside = [&](std::int32_t v) {
    return axis.radial(mesh.current.col(v)).squaredNorm() < axis.r2;
  };
  // An edge comes within r of the axis: an end inside, or its projection's closest point.
  auto edge_near = [&](std::int32_t a, std::int32_t b) {
    const Eigen::Vector3d mu = axis.radial(mesh.current.col(a)),
                          nu = axis.radial(mesh.current.col(b));
    if (mu.squaredNorm() < axis.r2 || nu.squaredNorm() < axis.r2) return true;
    double roots[2];
    return edge_roots(mu, nu, axis.r2, roots) == 2;
  };
  // Breadth-first patches from the seeds; patch[i] lists the faces of hole i.
  std::vector<std::vector<std::int32_t>> patches;
  auto walk = [&]() {
    patches.clear();
    EdgeMap seen;
    for (auto s : seeds) {
      if (seen.find(s, 0) >= 0) continue;
      std::vector<std::int32_t> patch;
      std::deque<std::int32_t> queue{s};
      seen.insert(s, 0, 1);
      while (!queue.empty()) {
        const std::int32_t f = queue.front();
        queue.pop_front();
        patch.push_back(f);
        for (int k = 0; k < 3; ++k) {
          const std::int32_t g = adjacency.neighbor(f, k);
          if (g < 0 || seen.find(g, 0) >= 0) continue;
          const Face& t = mesh.faces[static_cast<std::size_t>(g)];
          bool near = false;
          for (int e = 0; e < 3 && !near; ++e) near = edge_near(t[e], t[(e + 1) % 3]);
          if (!near) continue;
          seen.insert(g, 0, 1);
          queue.push_back(g);
        }
      }
      std::sort(patch.begin(), patch.end());
      patches.push_back(std::move(patch));
    }
  };

  // Refine until every patch has enough crossings and no edge enters and leaves the disc.
  for (;;) {
    walk();
    std::vector<EdgeSplit> splits;
    for (const auto& patch : patches) {
      int crossings = 0;
      double longest = 0;  // the longest edge of a face the rim crosses
      std::vector<EdgeSplit> patch_edges;
      for (auto f : patch) {
        const Face& t = mesh.faces[static_cast<std::size_t>(f)];
        for (int k = 0; k < 3; ++k) {
          const std::int32_t a = t[k], b = t[(k + 1) % 3];
          const std::int32_t twin = adjacency.find(b, a);
          // Count each edge once: from the face with the lower half-edge, or on a boundary.
          const bool counted_here = twin < 0 || 3 * f + k < twin;
          const Eigen::Vector3d mu = axis.radial(mesh.current.col(a)),
                                nu = axis.radial(mesh.current.col(b));
          const bool ia = mu.squaredNorm() < axis.r2, ib = nu.squaredNorm() < axis.r2;
          if (ia != ib) {
            crossings += counted_here;
            for (int e = 0; e < 3; ++e)
              longest = std::max(
                  longest, (mesh.current.col(t[e]) - mesh.current.col(t[(e + 1) % 3])).norm());
          } else if (!ia) {
            double roots[2];
            if (edge_roots(mu, nu, axis.r2, roots) == 2) {
              splits.push_back({a, b, 0.5 * (roots[0] + roots[1])});  // the point nearest the axis
              crossings += 2 * counted_here;
            }
          }
          patch_edges.push_back({a, b, 0.5});
        }
      }
      // Enough rim points, and chords short enough for the area (≈ 2π²/3n² short for n even
      // chords): faces on the rim no longer than 1.5 × the circumference / min_rim_points.
      const double chord = 1.5 * 2 * std::numbers::pi * tool.radius / options.min_rim_points;
      if (crossings < options.min_rim_points || longest > chord) {
        if (result.refinements < options.max_refinements)
          splits.insert(splits.end(), patch_edges.begin(), patch_edges.end());
        else
          result.message = "fewer rim points than min_rim_points after max_refinements";
      }
    }
    if (splits.empty()) break;
    // Beyond the refinement limit only two-root splits continue, for a bounded number of passes.
    if (result.refinements >= options.max_refinements + 2) break;
    TopologyChange ch = split_edges(mesh, adjacency, splits);
    if (ch.empty()) break;
    // The new seeds: pierced faces among the added ones and the untouched old seeds (adding
    // at least as many faces as are removed moves no face).
    std::vector<std::int32_t> candidates = added_face_indices(ch);
    for (auto s : seeds)
      if (!std::binary_search(ch.removed_faces.begin(), ch.removed_faces.end(), s))
        candidates.push_back(s);
    apply(mesh, ch, &adjacency);
    result.changes.push_back(std::move(ch));
    ++result.refinements;
    seeds.clear();
    for (auto f : candidates)
      if (pierced(f)) seeds.push_back(f);
    std::sort(seeds.begin(), seeds.end());
    seeds.erase(std::unique(seeds.begin(), seeds.end()), seeds.end());
  }

  // Classify the patches' vertices: +1 outside, −1 inside, 0 on the cylinder (snapped).
  EdgeMap side;  // (vertex, 0) → side + 1
  auto side_of = [&](std::int32_t v) { return side.find(v, 0) - 1; };
  for (const auto& patch : patches)
    for (auto f : patch)
      for (auto v : mesh.faces[static_cast<std::size_t>(f)])
        if (side.find(v, 0) < 0) side.insert(v, 0, inside(v) ? 0 : 2);
  const std::int32_t nv0 = mesh.vertex_count();
  TopologyChange ch;
  ch.base_vertex_count = nv0;
  ch.base_face_count = mesh.face_count();
  auto crossing_t = [&](std::int32_t a, std::int32_t b) {
    double roots[2];
    const int n = edge_roots(axis.radial(mesh.current.col(a)), axis.radial(mesh.current.col(b)),
                             axis.r2, roots);
    return n > 0 ? roots[0] : 0.5;
  };
  for (const auto& patch : patches)
    for (auto f : patch) {
      const Face& t = mesh.faces[static_cast<std::size_t>(f)];
      for (int k = 0; k < 3; ++k) {
        const std::int32_t a = std::min(t[k], t[(k + 1) % 3]), b = std::max(t[k], t[(k + 1) % 3]);
        const int sa = side_of(a), sb = side_of(b);
        if (sa * sb >= 0) continue;
        const double tt = crossing_t(a, b);
        if (tt < options.snap_fraction)
          side.insert(a, 0, 1, true), ++result.snapped_rim_vertices;
        else if (tt > 1 - options.snap_fraction)
          side.insert(b, 0, 1, true), ++result.snapped_rim_vertices;
      }
    }
  EdgeMap xmap;
  auto cross_vertex = [&](std::int32_t u, std::int32_t w) {
    const std::int32_t a = std::min(u, w), b = std::max(u, w);
    std::int32_t id = xmap.find(a, b);
    if (id >= 0) return id;
    id = nv0 + static_cast<std::int32_t>(ch.new_vertices.size());
    ch.new_vertices.push_back(NewVertex::on_edge(a, b, crossing_t(a, b)));
    xmap.insert(a, b, id);
    return id;
  };
  auto area = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    return 0.5 * (b - a).cross(c - a).norm();
  };
  auto pos = [&](std::int32_t v) -> Eigen::Vector3d {
    if (v < nv0) return mesh.current.col(v);
    const NewVertex& n = ch.new_vertices[static_cast<std::size_t>(v - nv0)];
    return n.coefficients[0] * mesh.current.col(n.parents[0]) +
           n.coefficients[1] * mesh.current.col(n.parents[1]);
  };
  std::vector<std::int32_t> removed;
  for (const auto& patch : patches) {
    bool cut_any = false;
    for (auto f : patch) {
      const Face& t = mesh.faces[static_cast<std::size_t>(f)];
      const int s[3] = {side_of(t[0]), side_of(t[1]), side_of(t[2])};
      const bool has_in = s[0] < 0 || s[1] < 0 || s[2] < 0;
      if (!has_in) continue;
      const bool has_out = s[0] > 0 || s[1] > 0 || s[2] > 0;
      removed.push_back(f);
      cut_any = true;
      const double a0 = area(pos(t[0]), pos(t[1]), pos(t[2]));
      double kept = 0;
      auto keep = [&](std::int32_t a, std::int32_t b, std::int32_t c) {
        ch.added_faces.push_back({a, b, c});
        kept += area(pos(a), pos(b), pos(c));
      };
      if (has_out) {
        int zero = -1;
        for (int k = 0; k < 3; ++k)
          if (s[k] == 0) zero = k;
        if (zero >= 0) {
          const std::int32_t v0 = t[zero], v1 = t[(zero + 1) % 3], v2 = t[(zero + 2) % 3];
          const std::int32_t x = cross_vertex(v1, v2);
          if (s[(zero + 1) % 3] > 0)
            keep(v0, v1, x);
          else
            keep(v0, x, v2);
        } else {
          int lone = 0;
          for (int k = 0; k < 3; ++k)
            if (s[(k + 1) % 3] == s[(k + 2) % 3]) lone = k;
          const std::int32_t v0 = t[lone], v1 = t[(lone + 1) % 3], v2 = t[(lone + 2) % 3];
          const std::int32_t x01 = cross_vertex(v0, v1), x20 = cross_vertex(v2, v0);
          if (s[lone] > 0) {
            keep(v0, x01, x20);
          } else if ((pos(x01) - pos(v2)).squaredNorm() <= (pos(v1) - pos(x20)).squaredNorm()) {
            keep(x01, v1, v2), keep(x01, v2, x20);
          } else {
            keep(x01, v1, x20), keep(v1, v2, x20);
          }
        }
      }
      result.removed_area += a0 - kept;
    }
    result.holes += cut_any;
  }
  result.removed_area_faces = static_cast<std::int32_t>(removed.size());
  result.rim_vertices = static_cast<std::int32_t>(ch.new_vertices.size());
  std::sort(removed.begin(), removed.end());
  ch.removed_faces = std::move(removed);
  if (result.holes == 0) {
    result.message = "the drill pierces the surface but removes nothing";
    return result;
  }
  apply(mesh, ch, &adjacency);
  result.changes.push_back(std::move(ch));
  return result;
}

}  // namespace conform::mesh
