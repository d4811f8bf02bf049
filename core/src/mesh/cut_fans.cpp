#include "cut_fans.hpp"

#include <algorithm>
#include <numeric>

#include "conform/mesh/detail/union_find.hpp"

namespace conform::mesh::cutting {

void CutFans::separate_fans() {
  auto& on_plane = sc_.on_plane;
  std::sort(on_plane.begin(), on_plane.end());
  for (std::size_t i = 0; i < on_plane.size();) {
    std::size_t j = i;
    while (j < on_plane.size() && on_plane[j].first == on_plane[i].first) ++j;
    separate_fans_at(i, j);
    i = j;
  }
}

void CutFans::separate_fans_at(std::size_t i, std::size_t j) {
  const std::int32_t v = sc_.on_plane[i].first;
  const auto m = static_cast<std::int32_t>(j - i);
  std::vector<std::int32_t>& parent = sc_.parent;
  parent.resize(static_cast<std::size_t>(m));
  std::iota(parent.begin(), parent.end(), 0);
  std::int32_t* const par = parent.data();
  for (std::int32_t a = 0; a < m; ++a)
    for (std::int32_t b = a + 1; b < m; ++b) {
      const Pending& pa = pending_at(i + static_cast<std::size_t>(a));
      const Pending& pb = pending_at(i + static_cast<std::size_t>(b));
      if (pa.side != pb.side) continue;
      bool shared = false;
      for (auto x : pa.pre)
        if (x != v && (x == pb.pre[0] || x == pb.pre[1] || x == pb.pre[2])) shared = true;
      if (shared) detail::unite(par, a, b);
    }
  std::int32_t keeper = -1;
  for (std::int32_t a = 0; a < m && keeper < 0; ++a)
    if (pending_at(i + static_cast<std::size_t>(a)).side > 0) keeper = detail::find_root(par, a);
  if (keeper < 0) keeper = detail::find_root(par, 0);
  TopologyChange& ch = result_.change;
  std::vector<std::pair<std::int32_t, std::int32_t>> copies;  // (fan root, copy id)
  for (std::int32_t a = 0; a < m; ++a) {
    const std::int32_t r = detail::find_root(par, a);
    if (r == keeper) continue;
    std::int32_t id = -1;
    for (const auto& c : copies)
      if (c.first == r) id = c.second;
    if (id < 0) {
      id = nv0_ + static_cast<std::int32_t>(ch.new_vertices.size());
      ch.new_vertices.push_back(NewVertex::duplicate(v));
      copies.emplace_back(r, id);
    }
    Pending& p =
        sc_.pending[static_cast<std::size_t>(sc_.on_plane[i + static_cast<std::size_t>(a)].second)];
    for (auto& x : p.v)
      if (x == v) x = id;
    p.remapped = true;
  }
}

void CutFans::separate_crossings() {
  TopologyChange& ch = result_.change;
  nx_ = static_cast<std::int32_t>(sc_.xpos.size());
  std::vector<std::int32_t>& xcopy = sc_.xcopy;
  xcopy.resize(static_cast<std::size_t>(nx_));
  for (std::int32_t k = 0; k < nx_; ++k) {
    xcopy[static_cast<std::size_t>(k)] = nv0_ + static_cast<std::int32_t>(ch.new_vertices.size());
    ch.new_vertices.push_back(NewVertex::duplicate(nv0_ + k));
  }
  for (Pending& p : sc_.pending)
    if (p.side < 0)
      for (auto& x : p.v)
        if (x >= nv0_ && x < nv0_ + nx_) x = xcopy[static_cast<std::size_t>(x - nv0_)];
}

}  // namespace conform::mesh::cutting
