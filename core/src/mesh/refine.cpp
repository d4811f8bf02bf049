#include "conform/mesh/refine.hpp"

#include <algorithm>
#include <utility>

namespace conform::mesh {

TopologyChange split_edges(const SkinnedMesh& mesh, const Adjacency& adjacency,
                           std::span<const EdgeSplit> edges) {
  TopologyChange ch;
  ch.base_vertex_count = mesh.vertex_count();
  ch.base_face_count = mesh.face_count();
  const std::int32_t nv0 = mesh.vertex_count();
  EdgeMap mid;  // (min, max) → new vertex
  std::vector<std::int32_t> faces;
  for (const EdgeSplit& e : edges) {
    const std::int32_t lo = std::min(e.a, e.b), hi = std::max(e.a, e.b);
    if (lo == hi || mid.find(lo, hi) >= 0) continue;
    const std::int32_t h1 = adjacency.find(e.a, e.b), h2 = adjacency.find(e.b, e.a);
    if (h1 < 0 && h2 < 0) continue;
    const double t = std::clamp(e.t, 1e-6, 1 - 1e-6);
    mid.insert(lo, hi, nv0 + static_cast<std::int32_t>(ch.new_vertices.size()));
    ch.new_vertices.push_back(NewVertex::on_edge(e.a, e.b, t));
    if (h1 >= 0) faces.push_back(h1 / 3);
    if (h2 >= 0) faces.push_back(h2 / 3);
  }
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  auto pos = [&](std::int32_t v) -> Eigen::Vector3d {
    if (v < nv0) return mesh.current.col(v);
    const NewVertex& n = ch.new_vertices[static_cast<std::size_t>(v - nv0)];
    return n.coefficients[0] * mesh.current.col(n.parents[0]) +
           n.coefficients[1] * mesh.current.col(n.parents[1]);
  };
  for (auto fi : faces) {
    const Face& f = mesh.faces[static_cast<std::size_t>(fi)];
    std::int32_t m[3];
    int count = 0;
    for (int k = 0; k < 3; ++k) {
      m[k] = mid.find(std::min(f[k], f[(k + 1) % 3]), std::max(f[k], f[(k + 1) % 3]));
      count += m[k] >= 0;
    }
    ch.removed_faces.push_back(fi);
    if (count == 3) {
      ch.added_faces.push_back({f[0], m[0], m[2]});
      ch.added_faces.push_back({m[0], f[1], m[1]});
      ch.added_faces.push_back({m[2], m[1], f[2]});
      ch.added_faces.push_back({m[0], m[1], m[2]});
    } else if (count == 1) {
      int k = 0;
      while (m[k] < 0) ++k;
      const std::int32_t a = f[k], b = f[(k + 1) % 3], c = f[(k + 2) % 3];
      ch.added_faces.push_back({a, m[k], c});
      ch.added_faces.push_back({m[k], b, c});
    } else {
      int k = 0;  // the unsplit edge is k: (a, b); split edges (b, c) and (c, a)
      while (m[k] >= 0) ++k;
      const std::int32_t a = f[k], b = f[(k + 1) % 3], c = f[(k + 2) % 3];
      const std::int32_t mbc = m[(k + 1) % 3], mca = m[(k + 2) % 3];
      ch.added_faces.push_back({mca, mbc, c});
      if ((pos(a) - pos(mbc)).squaredNorm() <= (pos(b) - pos(mca)).squaredNorm()) {
        ch.added_faces.push_back({a, b, mbc});
        ch.added_faces.push_back({a, mbc, mca});
      } else {
        ch.added_faces.push_back({a, b, mca});
        ch.added_faces.push_back({b, mbc, mca});
      }
    }
  }
  return ch;
}

std::vector<std::int32_t> added_face_indices(const TopologyChange& change) {
  struct Collect {
    std::vector<std::int32_t> out;
    void fill(std::int32_t slot, std::size_t) { out.push_back(slot); }
    void append(std::int32_t slot, std::size_t) { out.push_back(slot); }
    void move(std::int32_t, std::int32_t) {}  // never an added face (visit_face_slots)
    void pop(std::int32_t) {}
  } collect;
  visit_face_slots(change, collect);
  return std::move(collect.out);
}

}  // namespace conform::mesh
