#include "conform/mesh/drill.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
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
  std::vector<std::int32_t> faces;
  double t = 2;                                // where the axis pierces it, from B (0) to A (1)
  bool entering = false;                       // its pierced face's normal points against B→A
  std::size_t added_begin = 0, added_end = 0;  // its faces in the hole change's added_faces
  std::vector<std::int32_t> removed;           // its removed faces
  std::vector<std::int32_t> rim;               // its rim loop, in boundary order; empty: none
  bool cut = false;
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

// The boundary loop the hole change `ch` (not yet applied) leaves around `hole`, as rim
// vertices in boundary order (the surface on the left), or empty when the boundary there is
// not one simple loop of rim vertices (new vertices on the cylinder, or snapped ones).
template <class SideOf>
std::vector<std::int32_t> rim_loop(const SkinnedMesh& mesh, const Adjacency& adjacency,
                                   const TopologyChange& ch, const Patch& hole,
                                   const SideOf& side_of) {
  auto removed = [&](std::int32_t f) {
    return std::binary_search(ch.removed_faces.begin(), ch.removed_faces.end(), f);
  };
  EdgeMap added;
  for (std::size_t k = hole.added_begin; k < hole.added_end; ++k)
    for (int e = 0; e < 3; ++e)
      added.insert(ch.added_faces[k][e], ch.added_faces[k][(e + 1) % 3], 1);
  EdgeMap next;  // (0, u) → v for the boundary half-edge u → v
  std::size_t count = 0;
  std::int32_t start = -1;
  bool simple = true;
  auto boundary = [&](std::int32_t u, std::int32_t v) {
    simple = simple && next.insert(0, u, v);
    ++count;
    start = u;
  };
  // Half-edges of the clipped faces with no surviving twin, and half-edges of surviving faces
  // whose twin was removed without replacement.
  for (std::size_t k = hole.added_begin; k < hole.added_end; ++k)
    for (int e = 0; e < 3; ++e) {
      const std::int32_t u = ch.added_faces[k][e], v = ch.added_faces[k][(e + 1) % 3];
      if (added.find(v, u) >= 0) continue;
      const std::int32_t h = adjacency.find(v, u);
      if (h >= 0 && !removed(h / 3)) continue;
      boundary(u, v);
    }
  for (auto g : hole.removed) {
    const Face& t = mesh.faces[static_cast<std::size_t>(g)];
    for (int e = 0; e < 3; ++e) {
      const std::int32_t a = t[e], b = t[(e + 1) % 3];
      const std::int32_t h = adjacency.find(b, a);
      if (h < 0 || removed(h / 3) || added.find(a, b) >= 0) continue;
      boundary(b, a);
    }
  }
  if (!simple || count < 3) return {};
  std::vector<std::int32_t> loop;
  std::int32_t v = start;
  do {
    if (!(v >= ch.base_vertex_count || side_of(v) == 0)) return {};  // not a rim vertex
    loop.push_back(v);
    v = next.find(0, v);
    if (v < 0) return {};
  } while (v != start && loop.size() <= count);
  if (loop.size() != count) return {};  // more than one loop
  return loop;
}

// Joins consecutive holes along the axis, where the drill enters then leaves the surface, with
// a strip of triangles between their rim loops (see drill.hpp, step 6).
template <class Commit>
void join_holes(const SkinnedMesh& mesh, const Adjacency& adjacency, const Axis& axis,
                const std::vector<Patch>& patches, DrillResult& result, Commit& commit) {
  std::vector<const Patch*> cut;
  for (const auto& p : patches)
    if (p.cut) cut.push_back(&p);
  std::sort(cut.begin(), cut.end(), [](const Patch* a, const Patch* b) { return a->t < b->t; });
  // An orthonormal frame about the axis, for the rim vertices' angles.
  int k0 = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(axis.u[k]) < std::abs(axis.u[k0])) k0 = k;
  const Eigen::Vector3d e1 = Eigen::Vector3d::Unit(k0).cross(axis.u).normalized();
  const Eigen::Vector3d e2 = axis.u.cross(e1);
  auto angle = [&](std::int32_t v) {
    const Eigen::Vector3d r = axis.radial(mesh.current.col(v));
    return std::atan2(r.dot(e2), r.dot(e1));
  };
  constexpr double pi = std::numbers::pi;
  auto wrap = [](double a) { return std::remainder(a, 2 * pi); };
  // Cumulative turning along a closed loop from its first vertex (loop.size() + 1 values).
  auto turning = [&](const std::vector<std::int32_t>& loop) {
    std::vector<double> cum(loop.size() + 1, 0.0);
    for (std::size_t k = 0; k < loop.size(); ++k)
      cum[k + 1] = cum[k] + wrap(angle(loop[(k + 1) % loop.size()]) - angle(loop[k]));
    return cum;
  };
  auto fail = [&](const std::string& why) {
    if (!result.message.empty()) result.message += "; ";
    result.message += why;
  };
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
    const double ta = alpha.back(), tb = beta.back();
    if (std::abs(std::abs(ta) - 2 * pi) > 1e-6 || std::abs(ta - tb) > 1e-6) {
      fail("tube: the rims do not wind once around the axis in matching directions");
      continue;
    }
    const double sign = ta > 0 ? 1 : -1, delta = wrap(angle(B[0]) - a0);
    const std::size_t n = A.size(), m = B.size();
    std::vector<Face> faces;
    faces.reserve(n + m);
    for (std::size_t ia = 0, jb = 0; ia < n || jb < m;) {
      const bool along_a =
          jb == m || (ia < n && sign * alpha[ia + 1] <= sign * (delta + beta[jb + 1]));
      if (along_a) {
        faces.push_back({A[ia], A[(ia + 1) % n], B[jb % m]});
        ++ia;
      } else {
        faces.push_back({B[(jb + 1) % m], B[jb], A[ia % n]});
        ++jb;
      }
    }
    // The strip must only add edges: along the rims the reverse of a boundary half-edge, across
    // the tube edges that do not exist yet.
    EdgeMap in_a;
    for (auto v : A) in_a.insert(0, v, 1);
    bool ok = true;
    for (auto v : B) ok = ok && in_a.find(0, v) < 0;
    for (const Face& f : faces)
      for (int e = 0; e < 3 && ok; ++e) {
        const std::int32_t x = f[e], y = f[(e + 1) % 3];
        const bool across = (in_a.find(0, x) >= 0) != (in_a.find(0, y) >= 0);
        ok = adjacency.find(x, y) < 0 && (!across || adjacency.find(y, x) < 0);
      }
    if (!ok) {
      fail("tube: the rims share vertices or edges");
      continue;
    }
    TopologyChange tube;
    tube.base_vertex_count = mesh.vertex_count();
    tube.base_face_count = mesh.face_count();
    tube.added_faces = std::move(faces);
    result.tube_faces += static_cast<std::int32_t>(tube.added_faces.size());
    ++result.tubes;
    commit(std::move(tube));
  }
}

DrillResult drill_impl(SkinnedMesh& mesh, Adjacency& adjacency, FaceIndex* index,
                       const DrillTool& tool, const DrillOptions& options,
                       const std::vector<SegmentHit>& hits) {
  const double len = (tool.tip - tool.base).norm();
  Axis axis{tool.base, (tool.tip - tool.base) / len, len, tool.radius * tool.radius};
  DrillResult result;
  // The index inserts only the faces that survive all the drill's changes.
  struct Batch {
    FaceIndex* index;
    const SkinnedMesh& mesh;
    ~Batch() {
      if (index) index->end_batch(mesh);
    }
  } batch{index, mesh};
  if (index) index->begin_batch();
  auto commit = [&](TopologyChange&& ch) {
    apply(mesh, ch, &adjacency);
    if (index) index->update(mesh, ch);
    result.changes.push_back(std::move(ch));
  };
  // The axis parameter where it pierces face f, or −1.
  auto pierced = [&](std::int32_t f) {
    const Face& t = mesh.faces[static_cast<std::size_t>(f)];
    double at = -1;
    std::array<double, 3> bary{};
    if (!segment_triangle(tool.base, tool.tip, mesh.current.col(t[0]), mesh.current.col(t[1]),
                          mesh.current.col(t[2]), at, bary))
      return -1.0;
    return at;
  };
  std::vector<std::int32_t> seeds;
  std::vector<double> seed_t;
  for (const SegmentHit& h : hits) seeds.push_back(h.face);
  std::sort(seeds.begin(), seeds.end());
  seeds.erase(std::unique(seeds.begin(), seeds.end()), seeds.end());
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
  // Breadth-first patches from the seeds; patches[i].faces lists the faces of hole i.
  std::vector<Patch> patches;
  auto walk = [&]() {
    patches.clear();
    EdgeMap seen;  // (0, face) → its patch (keys (0, x): EdgeMap hashes u poorly)
    for (auto s : seeds) {
      if (seen.find(0, s) >= 0) continue;
      const auto id = static_cast<std::int32_t>(patches.size());
      std::vector<std::int32_t> patch;
      std::deque<std::int32_t> queue{s};
      seen.insert(0, s, id);
      while (!queue.empty()) {
        const std::int32_t f = queue.front();
        queue.pop_front();
        patch.push_back(f);
        for (int k = 0; k < 3; ++k) {
          const std::int32_t g = adjacency.neighbor(f, k);
          if (g < 0 || seen.find(0, g) >= 0) continue;
          const Face& t = mesh.faces[static_cast<std::size_t>(g)];
          bool near = false;
          for (int e = 0; e < 3 && !near; ++e) near = edge_near(t[e], t[(e + 1) % 3]);
          if (!near) continue;
          seen.insert(0, g, id);
          queue.push_back(g);
        }
      }
      std::sort(patch.begin(), patch.end());
      Patch hole;
      hole.faces = std::move(patch);
      patches.push_back(std::move(hole));
    }
    // Where the axis pierces each patch first, and whether it enters the surface there.
    for (auto s : seeds) {
      Patch& p = patches[static_cast<std::size_t>(seen.find(0, s))];
      const double at = pierced(s);
      if (at < 0 || at >= p.t) continue;
      p.t = at;
      const Face& t = mesh.faces[static_cast<std::size_t>(s)];
      const Eigen::Vector3d n = (mesh.current.col(t[1]) - mesh.current.col(t[0]))
                                    .cross(mesh.current.col(t[2]) - mesh.current.col(t[0]));
      p.entering = n.dot(axis.u) < 0;
    }
  };

  // Refine until every patch has enough crossings and no edge enters and leaves the disc.
  for (bool first = true;; first = false) {
    walk();
    if (first)  // only the positions the drill reads are checked (a whole-mesh check is O(V))
      for (const auto& hole : patches)
        for (auto f : hole.faces)
          for (auto v : mesh.faces[static_cast<std::size_t>(f)])
            if (!mesh.current.col(v).allFinite())
              throw std::invalid_argument("drill: non-finite positions");
    std::vector<EdgeSplit> splits;
    for (const auto& hole : patches) {
      const auto& patch = hole.faces;
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
    commit(std::move(ch));
    ++result.refinements;
    seeds.clear();
    for (auto f : candidates)
      if (pierced(f) >= 0) seeds.push_back(f);
    std::sort(seeds.begin(), seeds.end());
    seeds.erase(std::unique(seeds.begin(), seeds.end()), seeds.end());
  }

  // Classify the patches' vertices: +1 outside, −1 inside, 0 on the cylinder (snapped).
  EdgeMap side;  // (0, vertex) → side + 1
  auto side_of = [&](std::int32_t v) { return side.find(0, v) - 1; };
  for (const auto& hole : patches)
    for (auto f : hole.faces)
      for (auto v : mesh.faces[static_cast<std::size_t>(f)])
        if (side.find(0, v) < 0) side.insert(0, v, inside(v) ? 0 : 2);
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
  for (const auto& hole : patches)
    for (auto f : hole.faces) {
      const Face& t = mesh.faces[static_cast<std::size_t>(f)];
      for (int k = 0; k < 3; ++k) {
        const std::int32_t a = std::min(t[k], t[(k + 1) % 3]), b = std::max(t[k], t[(k + 1) % 3]);
        const int sa = side_of(a), sb = side_of(b);
        if (sa * sb >= 0) continue;
        const double tt = crossing_t(a, b);
        if (tt < options.snap_fraction)
          side.insert(0, a, 1, true), ++result.snapped_rim_vertices;
        else if (tt > 1 - options.snap_fraction)
          side.insert(0, b, 1, true), ++result.snapped_rim_vertices;
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
  for (auto& hole : patches) {
    bool cut_any = false;
    hole.added_begin = ch.added_faces.size();
    for (auto f : hole.faces) {
      const Face& t = mesh.faces[static_cast<std::size_t>(f)];
      const int s[3] = {side_of(t[0]), side_of(t[1]), side_of(t[2])};
      const bool has_in = s[0] < 0 || s[1] < 0 || s[2] < 0;
      if (!has_in) continue;
      const bool has_out = s[0] > 0 || s[1] > 0 || s[2] > 0;
      removed.push_back(f);
      hole.removed.push_back(f);
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
    hole.added_end = ch.added_faces.size();
    hole.cut = cut_any;
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
  if (options.tube) {
    for (auto& hole : patches)
      if (hole.cut) hole.rim = rim_loop(mesh, adjacency, ch, hole, side_of);
  }
  commit(std::move(ch));
  if (options.tube) join_holes(mesh, adjacency, axis, patches, result, commit);
  return result;
}

}  // namespace

}  // namespace conform::mesh
