#include "drill_pinch.hpp"

#include <algorithm>

#include "conform/mesh/detail/union_find.hpp"

namespace conform::mesh::drilling {

namespace {

// One face around a vertex, as the edge (a, b) of the vertex's link: its other two corners,
// in mesh indices. A vertex is manifold when its link is one path or one cycle.
struct LinkEdge {
  std::int32_t centre;  // the rim vertex, local id
  std::int32_t a, b;
};

// The number of connected components of a link (few nodes: looked up linearly).
int link_components(const std::vector<std::pair<std::int32_t, std::int32_t>>& edges) {
  thread_local std::vector<std::int32_t> node, parent;  // kept: drills run at haptic rates
  node.clear(), parent.clear();
  auto id = [&](std::int32_t v) {
    for (std::size_t i = 0; i < node.size(); ++i)
      if (node[i] == v) return std::int32_t(i);
    node.push_back(v), parent.push_back(std::int32_t(parent.size()));
    return std::int32_t(node.size() - 1);
  };
  for (const auto& [a, b] : edges) {
    const std::int32_t ia = id(a), ib = id(b);
    detail::unite(parent.data(), ia, ib);
  }
  int components = 0;
  for (std::size_t i = 0; i < node.size(); ++i)
    components += detail::find_root(parent.data(), std::int32_t(i)) == std::int32_t(i);
  return components;
}

int corner_of(const Face& t, std::int32_t g) {
  return t[0] == g ? 0 : t[1] == g ? 1 : 2;
}

// The faces of the mesh around original vertex g, from face `start` (which holds it): rotated
// one way across the edges into g, then, if that meets a boundary, the other way.
void original_fan(const SkinnedMesh& mesh, const Adjacency& adjacency, std::int32_t g,
                  std::int32_t start, std::vector<std::int32_t>& fan) {
  fan.clear();
  fan.push_back(start);
  const auto limit = std::size_t(adjacency.face_count());
  for (std::int32_t f = start;;) {  // across the half-edge that ends at g
    const std::int32_t t =
        adjacency.twin(3 * f + (corner_of(mesh.faces[std::size_t(f)], g) + 2) % 3);
    if (t < 0) break;
    f = t / 3;
    if (f == start || fan.size() > limit) return;  // closed around g
    fan.push_back(f);
  }
  for (std::int32_t f = start;;) {  // open: across the half-edge that leaves g
    const std::int32_t t = adjacency.twin(3 * f + corner_of(mesh.faces[std::size_t(f)], g));
    if (t < 0 || fan.size() > limit) return;
    f = t / 3;
    fan.push_back(f);
  }
}

// The link edges of the rim vertices from the added faces, and, for the original ones, a
// face of the mesh that holds each (to start its original fan from).
void rim_links(const Region& region, std::vector<LinkEdge>& links,
               std::vector<std::pair<std::int32_t, std::int32_t>>& starts) {
  const auto& X = region.verts;
  for (const Face& t : region.added)
    for (int k = 0; k < 3; ++k)
      if (X[std::size_t(t[k])].side == 0)
        links.push_back(
            {t[k], X[std::size_t(t[(k + 1) % 3])].index, X[std::size_t(t[(k + 2) % 3])].index});
  for (const Region::LocalFace& lf : region.faces)
    for (const std::int32_t v : lf.v)
      if (X[std::size_t(v)].side == 0 && X[std::size_t(v)].def.count == 1)
        starts.emplace_back(v, region.origins[std::size_t(lf.origin)].face);
  auto by_centre = [](const LinkEdge& l, const LinkEdge& r) { return l.centre < r.centre; };
  std::sort(links.begin(), links.end(), by_centre);
  std::sort(starts.begin(), starts.end());
  starts.erase(std::unique(starts.begin(), starts.end(),
                           [](const auto& l, const auto& r) { return l.first == r.first; }),
               starts.end());
}

}  // namespace

std::vector<std::int32_t> pinched_rim_vertices(const Region& region, const SkinnedMesh& mesh,
                                               const Adjacency& adjacency,
                                               const TopologyChange& ch) {
  // The scratch is kept per thread between drills, as the Region is.
  thread_local std::vector<LinkEdge> links;
  thread_local std::vector<std::pair<std::int32_t, std::int32_t>> starts;  // (vertex, face)
  thread_local std::vector<std::int32_t> centres, fan;
  thread_local std::vector<std::pair<std::int32_t, std::int32_t>> link;
  links.clear(), starts.clear(), centres.clear();
  rim_links(region, links, starts);
  for (const LinkEdge& l : links) centres.push_back(l.centre);
  for (const auto& s : starts) centres.push_back(s.first);
  std::sort(centres.begin(), centres.end());
  centres.erase(std::unique(centres.begin(), centres.end()), centres.end());

  std::vector<std::int32_t> pinched;  // empty (no allocation) but where the hole would pinch
  auto next_link = links.begin();
  auto next_start = starts.begin();
  for (const std::int32_t c : centres) {
    link.clear();
    for (; next_link != links.end() && next_link->centre == c; ++next_link)
      link.emplace_back(next_link->a, next_link->b);
    if (next_start != starts.end() && next_start->first == c) {
      // An original vertex: its faces that the change keeps.
      const std::int32_t g = region.verts[std::size_t(c)].index;
      original_fan(mesh, adjacency, g, next_start->second, fan);
      for (const std::int32_t f : fan) {
        if (std::binary_search(ch.removed_faces.begin(), ch.removed_faces.end(), f)) continue;
        const Face& t = mesh.faces[std::size_t(f)];
        const int k = corner_of(t, g);
        link.emplace_back(t[(k + 1) % 3], t[(k + 2) % 3]);
      }
      ++next_start;
    }
    if (link_components(link) > 1) pinched.push_back(c);
  }
  return pinched;
}

}  // namespace conform::mesh::drilling
