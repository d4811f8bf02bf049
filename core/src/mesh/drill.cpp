#include "conform/mesh/drill.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "drill_pinch.hpp"
#include "drill_region.hpp"
#include "drill_rim.hpp"
#include "drill_tube.hpp"

namespace conform::mesh {

double axis_distance_squared(const DrillTool& tool, const Eigen::Vector3d& x) {
  const Eigen::Vector3d u = (tool.tip - tool.base).normalized();
  const Eigen::Vector3d q = x - tool.base;
  return (q - q.dot(u) * u).squaredNorm();
}

namespace {

using namespace drilling;

void check_input(const SkinnedMesh& mesh, const Adjacency& adjacency, const DrillTool& tool) {
  if (!tool.tip.allFinite() || !tool.base.allFinite() || !std::isfinite(tool.radius))
    throw std::invalid_argument("drill: tip, base and radius must be finite");
  if (!(tool.radius > 0)) throw std::invalid_argument("drill: the radius must be positive");
  if (!((tool.tip - tool.base).norm() > 0))
    throw std::invalid_argument("drill: tip and base must differ");
  if (!adjacency.matches(mesh))
    throw std::invalid_argument("drill: the adjacency does not describe this mesh");
}

// Step 1: the faces pierced by the axis segment B→A.
std::vector<SegmentHit> pierced_faces(const SkinnedMesh& mesh, FaceIndex* index,
                                      const DrillTool& tool) {
  if (index) {
    index->ensure_fitted(mesh);
    return index->segment_hits(mesh, tool.base, tool.tip);
  }
  // No index kept by the caller: for one query a scan (O(F)) is cheaper than a build.
  return scan_segment_hits(mesh, tool.base, tool.tip);
}

// Step 2: the patches, one breadth-first walk from each pierced face not yet reached; where
// the axis pierces each first, and whether it enters the surface there.
std::vector<Patch> find_patches(Region& region, const SkinnedMesh& mesh, const Axis& axis,
                                const std::vector<std::int32_t>& seeds,
                                const std::vector<SegmentHit>& hits) {
  std::vector<Patch> patches;
  for (auto s : seeds) {
    if (region.loaded(s) >= 0) continue;
    region.walk(s, static_cast<std::int32_t>(patches.size()));
    patches.emplace_back();
  }
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
  return patches;
}

// The rim crossings of each patch's edges, each edge once (from its lower half-edge, or its
// only loaded one).
void count_crossings(const Region& region, std::vector<Patch>& patches) {
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
}

// Steps 3–4: refinement where the rim crosses: a face holding a chord of the rim polygon
// longer than the patch's limit is bisected (longest edge first, neighbours kept conforming).
// The inscribed polygon loses Σ r²(θ − sin θ)/2 ≈ πr² θ²/6 at most for chords of angle ≤ θ:
// the limit, 1.2 × the circumference / min_rim_points (θ ≈ 0.31 for 24), keeps that under
// 1.7 %; it shrinks while a patch has fewer than min_rim_points crossings. A face's depth
// counts its bisections; two halve a triangle as one 1-to-4 split does: `refinements` is
// depth / 2.
void refine_rim(Region& region, std::vector<Patch>& patches, const DrillTool& tool,
                const DrillOptions& options, DrillResult& result) {
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
    count_crossings(region, patches);
    bool again = false;
    for (auto& p : patches)
      if (p.crossings < min_rim && pass < max_depth) p.limit *= 0.75, again = true;
    if (!again) break;
  }
  for (const auto& p : patches)
    if (p.crossings > 0 && p.crossings < min_rim)
      result.message = "fewer rim points than min_rim_points after max_refinements";
}

// Step 5, the clipping: faces with a vertex inside are removed or, with one outside too,
// clipped (split triangles stay triangles; a clipped face's quad is split along the diagonal
// that keeps the larger smallest angle). Fills region.added (the faces replacing the modified
// original faces, in local vertices) and region.hole_edges (the hole's boundary half-edges,
// the surface on their left, per patch, for the tube).
class Clipper {
 public:
  Clipper(Region& region, std::vector<Patch>& patches, const Axis& axis, DrillResult& result)
      : region_(region), patches_(patches), axis_(axis), result_(result) {}

  void run() {
    mark_fates();
    for (std::size_t f = 0; f < region_.faces.size(); ++f) {
      const Region::LocalFace& lf = region_.faces[f];
      const std::uint8_t fate = region_.fate[f];
      if (fate == kKept) {
        if (region_.origins[std::size_t(lf.origin)].modified) region_.added.push_back(lf.v);
      } else if (fate == kRemoved) {
        remove_face(f);
      } else {
        clip_face(lf);
      }
    }
  }

 private:
  static constexpr std::uint8_t kKept = 0, kClipped = 1, kRemoved = 2;

  // Faces with a vertex inside are removed (2) or, with one outside too, clipped (1).
  void mark_fates() {
    auto& fate = region_.fate;
    fate.assign(region_.faces.size(), kKept);
    for (std::size_t f = 0; f < region_.faces.size(); ++f) {
      const Region::LocalFace& lf = region_.faces[f];
      bool in = false, out = false;
      for (auto v : lf.v) {
        in = in || region_.verts[std::size_t(v)].side < 0;
        out = out || region_.verts[std::size_t(v)].side > 0;
      }
      if (!in) continue;
      fate[f] = out ? kClipped : kRemoved;
      region_.origins[std::size_t(lf.origin)].modified = true;
      patches_[std::size_t(lf.patch)].cut = true;
      ++result_.removed_area_faces;
    }
  }

  // The rim vertex on edge (u, w), made once for both faces.
  std::int32_t cross_vertex(std::int32_t u, std::int32_t w) {
    const std::int32_t a = std::min(u, w), b = std::max(u, w);
    const std::int32_t made = static_cast<std::int32_t>(region_.verts.size());
    const std::int32_t id = region_.crossing_vertex.at(a, b, made);
    if (id == made)
      region_.verts[std::size_t(region_.between(a, b, rim_crossing_t(region_, axis_, a, b)))].rim =
          true;
    return id;
  }
  double area(std::int32_t a, std::int32_t b, std::int32_t c) const {
    const Eigen::Vector3d &pa = region_.verts[std::size_t(a)].x,
                          &pb = region_.verts[std::size_t(b)].x,
                          &pc = region_.verts[std::size_t(c)].x;
    return 0.5 * (pb - pa).cross(pc - pa).norm();
  }

  // A removed face: its area goes, and an edge shared with a kept face (both ends on the rim)
  // borders the hole.
  void remove_face(std::size_t f) {
    const Region::LocalFace& lf = region_.faces[f];
    const auto& t = lf.v;
    result_.removed_area += area(t[0], t[1], t[2]);
    for (int k = 0; k < 3; ++k) {
      const std::int32_t tw = lf.twin[k];
      if (tw == Region::kBoundary || (tw >= 0 && region_.fate[std::size_t(tw / 3)] != kKept))
        continue;
      region_.hole_edges.push_back({lf.patch, t[(k + 1) % 3], t[k]});
    }
  }

  // A clipped face: the pieces outside stay, the rest of its area goes.
  void clip_face(const Region::LocalFace& lf) {
    const auto t = lf.v;
    const double a0 = area(t[0], t[1], t[2]);
    const int s[3] = {region_.verts[std::size_t(t[0])].side, region_.verts[std::size_t(t[1])].side,
                      region_.verts[std::size_t(t[2])].side};
    const std::int32_t patch = lf.patch;
    double kept = 0;
    auto keep = [&](std::int32_t a, std::int32_t b, std::int32_t c) {
      region_.added.push_back({a, b, c});
      kept += area(a, b, c);
    };
    auto cut = [&](std::int32_t from, std::int32_t to) {
      region_.hole_edges.push_back({patch, from, to});
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
        const auto& X = region_.verts;
        if (drill_quad_split(X[std::size_t(x01)].x, X[std::size_t(v1)].x, X[std::size_t(v2)].x,
                             X[std::size_t(x20)].x)
                .first_diagonal)
          keep(x01, v1, v2), keep(x01, v2, x20);
        else
          keep(x01, v1, x20), keep(v1, v2, x20);
        cut(x20, x01);
      }
    }
    result_.removed_area += a0 - kept;
  }

  Region& region_;
  std::vector<Patch>& patches_;
  const Axis& axis_;
  DrillResult& result_;
};

// The change: new vertices that the added faces use (refinement's first, then the rim's),
// each one combination of original vertices; the modified original faces out. With the tube,
// region.new_x gets the new vertices' positions.
TopologyChange start_change(Region& region, const SkinnedMesh& mesh, bool tube,
                            DrillResult& result) {
  TopologyChange ch;
  ch.base_vertex_count = mesh.vertex_count();
  ch.edit = EditKind::drill;
  ch.base_face_count = mesh.face_count();
  for (const Face& t : region.added)
    for (auto v : t)
      if (region.verts[std::size_t(v)].index < 0) region.verts[std::size_t(v)].index = -2;
  for (auto& v : region.verts)
    if (v.index == -2) {
      v.index = ch.base_vertex_count + static_cast<std::int32_t>(ch.new_vertices.size());
      ch.new_vertices.push_back(v.def.new_vertex());
      if (tube) region.new_x.push_back(v.x);
      result.rim_vertices += v.rim;
    }
  for (const auto& o : region.origins)
    if (o.modified) ch.removed_faces.push_back(o.face);
  std::sort(ch.removed_faces.begin(), ch.removed_faces.end());
  return ch;
}

// Steps 5–5b: the clipping and the change's vertices and removed faces, clipped again without
// each rim vertex it would pinch (drill_pinch.hpp), un-snapped back to its own side of the
// cylinder. Every round un-snaps at least one vertex for good, so the rounds end. False when
// the drill removes nothing.
bool clip_unpinched(Region& region, std::vector<Patch>& patches, const SkinnedMesh& mesh,
                    const Adjacency& adjacency, const Axis& axis, bool tube, DrillResult& result,
                    TopologyChange& ch) {
  // What the clipping and start_change write, to start each round from.
  const std::size_t verts_before = region.verts.size();
  thread_local std::vector<bool> modified_before;  // kept per thread, as the Region is
  modified_before.clear();
  for (const auto& o : region.origins) modified_before.push_back(o.modified);
  const std::vector<Patch> patches_before = patches;
  const DrillResult result_before = result;
  int unsnapped = 0;
  for (;;) {
    Clipper(region, patches, axis, result).run();
    for (const auto& p : patches) result.holes += p.cut;
    if (result.holes == 0) return false;
    ch = start_change(region, mesh, tube, result);
    if (result.snapped_rim_vertices == unsnapped) break;  // no snapped vertex left to pinch at
    const std::vector<std::int32_t> pinched = pinched_rim_vertices(region, mesh, adjacency, ch);
    if (pinched.empty()) break;
    for (const std::int32_t v : pinched) {
      auto& x = region.verts[std::size_t(v)];
      x.side = region.inside(x.q) ? -1 : 1;
    }
    unsnapped += int(pinched.size());
    region.verts.resize(verts_before);
    for (auto& v : region.verts)
      if (v.index >= ch.base_vertex_count) v.index = -1;
    for (std::size_t o = 0; o < region.origins.size(); ++o)
      region.origins[o].modified = modified_before[o];
    patches = patches_before;
    result = result_before;
    region.added.clear(), region.hole_edges.clear(), region.new_x.clear();
    region.crossing_vertex.clear();
  }
  result.snapped_rim_vertices -= unsnapped;
  result.unsnapped_rim_vertices = unsnapped;
  return true;
}

// The rim loops, for the tube: per cut patch, the hole's boundary half-edges chained into one
// loop of rim vertices, in mesh indices (empty when they are not one simple loop).
void find_rim_loops(Region& region, std::vector<Patch>& patches) {
  for (std::size_t p = 0; p < patches.size(); ++p) {
    if (!patches[p].cut) continue;
    auto& next = region.next;
    next.clear();
    std::size_t count = 0;
    std::int32_t start = -1;
    bool simple = true;
    for (const auto& [patch, from, to] : region.hole_edges) {
      if (patch != std::int32_t(p)) continue;
      simple = simple && next.at(0, from, to) == to;
      ++count, start = from;
    }
    std::vector<std::int32_t> loop;
    for (std::int32_t v = start; simple && count >= 3;) {
      const auto& x = region.verts[std::size_t(v)];
      if (!(x.rim || x.side == 0)) break;
      loop.push_back(v);
      v = next.find(0, v);
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
}

// The added faces, in mesh indices; with the tube, their half-edges between rim vertices
// (the only ones the tube's checks need) go to region.rim_edges.
void add_faces(Region& region, bool tube, TopologyChange& ch) {
  ch.added_faces.reserve(region.added.size());
  for (const Face& t : region.added) {
    const auto &a = region.verts[std::size_t(t[0])], &b = region.verts[std::size_t(t[1])],
               &c = region.verts[std::size_t(t[2])];
    ch.added_faces.push_back({a.index, b.index, c.index});
    if (tube) {
      if (a.loop && b.loop) region.rim_edges.insert(a.index, b.index, 1);
      if (b.loop && c.loop) region.rim_edges.insert(b.index, c.index, 1);
      if (c.loop && a.loop) region.rim_edges.insert(c.index, a.index, 1);
    }
  }
}

// Algorithm 3 after the search: steps 2–6 on a copy of the patches, applied as one change.
DrillResult drill_impl(SkinnedMesh& mesh, Adjacency& adjacency, FaceIndex* index,
                       const DrillTool& tool, const DrillOptions& options,
                       const std::vector<SegmentHit>& hits) {
  const Axis axis(tool);
  DrillResult result;
  std::vector<std::int32_t> seeds;
  for (const SegmentHit& h : hits) seeds.push_back(h.face);
  std::sort(seeds.begin(), seeds.end());
  seeds.erase(std::unique(seeds.begin(), seeds.end()), seeds.end());
  if (seeds.empty()) {
    result.message = "the drill's axis does not pierce the surface";
    return result;
  }
  thread_local Region region;
  region.reset(mesh, adjacency, axis);
  std::vector<Patch> patches = find_patches(region, mesh, axis, seeds, hits);
  refine_rim(region, patches, tool, options, result);
  classify_rim(region, patches, mesh, axis, options, result);
  TopologyChange ch;
  if (!clip_unpinched(region, patches, mesh, adjacency, axis, options.tube, result, ch)) {
    result.message = "the drill pierces the surface but removes nothing";
    return result;
  }
  if (options.tube) find_rim_loops(region, patches);
  add_faces(region, options.tube, ch);
  // 6. The tube walls join the rims in the same change.
  if (options.tube) {
    const Outcome out{mesh, adjacency, ch, region.new_x, region.rim_edges};
    add_tubes(out, axis, patches, options.tube_ring_spacing, ch, region.new_x, region.rim_edges,
              region.in_a, result);
  }
  // The drill's one change: applied to the mesh, its adjacency and the index.
  apply(mesh, ch, &adjacency);
  if (index) index->update(mesh, ch);
  result.changes.push_back(std::move(ch));
  return result;
}

}  // namespace

DrillResult drill(SkinnedMesh& mesh, Adjacency& adjacency, const DrillTool& tool,
                  const DrillOptions& options) {
  check_input(mesh, adjacency, tool);
  return drill_impl(mesh, adjacency, nullptr, tool, options, pierced_faces(mesh, nullptr, tool));
}

DrillResult drill(SkinnedMesh& mesh, Adjacency& adjacency, FaceIndex& index, const DrillTool& tool,
                  const DrillOptions& options) {
  check_input(mesh, adjacency, tool);
  if (!index.matches(mesh))
    throw std::invalid_argument("drill: the face index does not describe this mesh");
  return drill_impl(mesh, adjacency, &index, tool, options, pierced_faces(mesh, &index, tool));
}

}  // namespace conform::mesh
