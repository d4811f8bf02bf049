#include "cut_caps.hpp"

#include <algorithm>

namespace conform::mesh::cutting {

void CutCaps::cap() {
  index_loop_vertices();
  chain_boundary();
  std::vector<std::string> problems;
  std::vector<std::vector<Eigen::Vector2d>> loops2 = closed_loops(problems);
  if (!loops2.empty()) add_cap_faces(loops2, forbidden_diagonals(), problems);
  if (!problems.empty()) result_.message = "not capped: " + problems.front();
}

void CutCaps::index_loop_vertices() {
  std::vector<std::int32_t>& plane_vertices = sc_.plane_vertices;
  plane_vertices.clear();
  plane_vertices.reserve(sc_.on_plane.size());
  for (const auto& [v, unused] : sc_.on_plane)
    if (plane_vertices.empty() || plane_vertices.back() != v) plane_vertices.push_back(v);
  nloop_ = static_cast<std::size_t>(nx_) + plane_vertices.size();
  const std::vector<Pending>& pending = sc_.pending;
  auto& pending_local = sc_.pending_local;
  pending_local.resize(pending.size());
  for (std::size_t i = 0; i < pending.size(); ++i)
    for (int k = 0; k < 3; ++k) pending_local[i][k] = local(pending[i].pre[k]);
  sc_.copy_plus.assign(nloop_, -1), sc_.copy_minus.assign(nloop_, -1);
  sc_.ambiguous.assign(nloop_, 0);
  for (std::size_t i = 0; i < pending.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const std::int32_t l = pending_local[i][k];
      if (l < 0) continue;
      std::int32_t& id =
          (pending[i].side > 0 ? sc_.copy_plus : sc_.copy_minus)[static_cast<std::size_t>(l)];
      if (id < 0)
        id = pending[i].v[k];
      else if (id != pending[i].v[k])
        sc_.ambiguous[static_cast<std::size_t>(l)] = 1;
    }
}

void CutCaps::chain_boundary() {
  auto edge_key = [](std::int32_t u, std::int32_t w) {
    return (std::uint64_t(std::uint32_t(u)) << 32) | std::uint32_t(w);
  };
  std::vector<std::uint64_t>& plus_edges = sc_.plus_edges;
  plus_edges.clear();
  plus_edges.reserve(sc_.pending.size());
  for (std::size_t i = 0; i < sc_.pending.size(); ++i)
    if (sc_.pending[i].side > 0)
      for (int k = 0; k < 3; ++k) {
        const std::int32_t u = sc_.pending_local[i][k], w = sc_.pending_local[i][(k + 1) % 3];
        if (u >= 0 && w >= 0) plus_edges.push_back(edge_key(u, w));
      }
  std::sort(plus_edges.begin(), plus_edges.end());
  sc_.next.assign(nloop_, -1);
  sc_.starts.clear();
  for (const std::uint64_t e : plus_edges) {
    const auto u = static_cast<std::int32_t>(e >> 32),
               w = static_cast<std::int32_t>(e & 0xffffffffu);
    if (std::binary_search(plus_edges.begin(), plus_edges.end(), edge_key(w, u))) continue;
    std::int32_t& to = sc_.next[static_cast<std::size_t>(u)];
    if (to >= 0) {
      branching_ = true;
      note_pinch(u);
    } else {
      to = w;
    }
    sc_.starts.push_back(u);
  }
}

ForbiddenDiagonals CutCaps::forbidden_diagonals() const {
  auto edge_key = [](std::int32_t u, std::int32_t w) {
    return (std::uint64_t(std::uint32_t(u)) << 32) | std::uint32_t(w);
  };
  std::vector<std::int32_t> at(nloop_, -1);  // local id → index in sc_.ids
  for (std::size_t i = 0; i < sc_.ids.size(); ++i)
    at[static_cast<std::size_t>(sc_.ids[i])] = static_cast<std::int32_t>(i);
  ForbiddenDiagonals out;
  for (const int side : {1, -1}) {
    std::vector<std::uint64_t> edges;
    for (std::size_t i = 0; i < sc_.pending.size(); ++i)
      if (sc_.pending[i].side == side)
        for (int k = 0; k < 3; ++k) {
          const std::int32_t u = sc_.pending_local[i][k], w = sc_.pending_local[i][(k + 1) % 3];
          if (u >= 0 && w >= 0) edges.push_back(edge_key(u, w));
        }
    std::sort(edges.begin(), edges.end());
    for (const std::uint64_t e : edges) {
      const auto u = static_cast<std::int32_t>(e >> 32),
                 w = static_cast<std::int32_t>(e & 0xffffffffu);
      const std::int32_t a = at[static_cast<std::size_t>(u)], b = at[static_cast<std::size_t>(w)];
      if (u < w && a >= 0 && b >= 0 &&
          std::binary_search(edges.begin(), edges.end(), edge_key(w, u)))
        out.push_back({a, b});
    }
  }
  return out;
}

std::vector<std::vector<Eigen::Vector2d>> CutCaps::closed_loops(
    std::vector<std::string>& problems) {
  std::vector<std::uint8_t>& visited = sc_.visited;
  visited.assign(nloop_, 0);
  const Eigen::Vector3d n = plane_.normal();
  const Eigen::Vector3d e1 = n.unitOrthogonal(), e2 = n.cross(e1);
  std::vector<std::vector<Eigen::Vector2d>> loops2;
  sc_.ids.clear();
  std::vector<std::int32_t>& loop = sc_.loop;
  for (auto s0 : sc_.starts) {
    if (visited[static_cast<std::size_t>(s0)]) continue;
    loop.clear();
    std::int32_t u = s0;
    bool closed = false;
    while (u >= 0 && !visited[static_cast<std::size_t>(u)]) {
      visited[static_cast<std::size_t>(u)] = 1;
      loop.push_back(u);
      u = sc_.next[static_cast<std::size_t>(u)];
      if (u == s0) closed = true;
    }
    if (!closed) {
      problems.push_back("an open cut curve (the surface has a boundary there)");
      continue;
    }
    ++result_.loops;
    bool amb = branching_;
    for (auto v : loop) {
      if (!sc_.ambiguous[static_cast<std::size_t>(v)]) continue;
      amb = true;
      note_pinch(v);
    }
    if (amb) {
      problems.push_back(
          "a cut loop through a vertex where the surface touches the plane in several fans");
      continue;
    }
    auto& p2 = loops2.emplace_back();
    p2.reserve(loop.size());
    for (auto v : loop) {
      const Eigen::Vector3d x = pos(global(v));
      p2.emplace_back(x.dot(e1), x.dot(e2));
    }
    sc_.ids.insert(sc_.ids.end(), loop.begin(), loop.end());
  }
  return loops2;
}

void CutCaps::add_cap_faces(const std::vector<std::vector<Eigen::Vector2d>>& loops2,
                            const ForbiddenDiagonals& forbidden,
                            std::vector<std::string>& problems) {
  const detail::OrientedSections section =
      detail::oriented_sections(loops2, options_.cap_triangulator, forbidden);
  if (!section.problem.empty()) {
    problems.push_back(section.problem);
    return;
  }
  result_.capped_loops = section.capped_loops;
  result_.nested_loops = section.nested_loops;
  result_.inside_out_loops = section.inside_out_loops;
  TopologyChange& ch = result_.change;
  ch.added_faces.reserve(ch.added_faces.size() + 2 * section.triangles.size());
  const auto first = static_cast<std::int32_t>(ch.added_faces.size());
  for (const auto& t : section.triangles) {
    Face plus, minus;
    for (int k = 0; k < 3; ++k) {
      const auto v = static_cast<std::size_t>(
          sc_.ids[static_cast<std::size_t>(t[static_cast<std::size_t>(k)])]);
      plus[2 - k] = sc_.copy_plus[v];
      minus[k] = sc_.copy_minus[v];
    }
    if (plus[0] >= 0 && plus[1] >= 0 && plus[2] >= 0) {
      ch.added_faces.push_back(plus);
      result_.added_side.push_back(1);
    }
    if (minus[0] >= 0 && minus[1] >= 0 && minus[2] >= 0) {
      ch.added_faces.push_back(minus);
      result_.added_side.push_back(-1);
    }
    ++result_.cap_faces;
  }
  const auto count = static_cast<std::int32_t>(ch.added_faces.size()) - first;
  if (count > 0) ch.new_surface.push_back({first, count, FaceKind::cap});
}

}  // namespace conform::mesh::cutting
