#include "cut_snap.hpp"

#include <algorithm>
#include <cmath>

#include "quad_split.hpp"

namespace conform::mesh::cutting {

double CutSnap::split_quality(const Face& f, const std::int8_t* s, bool* first_diagonal) const {
  const double snap = snap_;
  int zero = -1;
  for (int k = 0; k < 3; ++k)
    if (s[k] == 0) zero = k;
  if (zero >= 0) {
    const std::int32_t v0 = f[zero], v1 = f[(zero + 1) % 3], v2 = f[(zero + 2) % 3];
    const double t = crossing_t(v1, v2);
    if (t < snap || t > 1 - snap) return -1.0;
    const Eigen::Vector3d x = crossing_point(v1, v2);
    return std::min(smallest_angle_sin2(point(v0), point(v1), x),
                    smallest_angle_sin2(point(v0), x, point(v2)));
  }
  int lone = 0;
  for (int k = 0; k < 3; ++k)
    if (s[(k + 1) % 3] == s[(k + 2) % 3]) lone = k;
  const std::int32_t v0 = f[lone], v1 = f[(lone + 1) % 3], v2 = f[(lone + 2) % 3];
  const double t01 = crossing_t(v0, v1), t02 = crossing_t(v0, v2);
  if (t01 < snap || t01 > 1 - snap || t02 < snap || t02 > 1 - snap) return -1.0;
  const Eigen::Vector3d x01 = crossing_point(v0, v1), x20 = crossing_point(v2, v0);
  const Eigen::Vector3d p0 = point(v0), p1 = point(v1), p2 = point(v2);
  const QuadSplit quad = best_quad_split(
      x01, p1, p2, x20,
      [](const auto& a, const auto& b, const auto& c) { return smallest_angle_sin2(a, b, c); });
  if (first_diagonal) *first_diagonal = quad.first_diagonal;
  return std::min(smallest_angle_sin2(p0, x01, x20), quad.quality);
}

void CutSnap::snap() {
  const Face* const faces = mesh_.faces.data();
  const std::int8_t* const sd = sc_.side.data();
  std::vector<std::int32_t>&crossed = sc_.crossed, &evaluate = sc_.evaluate, &again = sc_.again,
  &snapped_now = sc_.snapped_now;
  crossed.clear(), evaluate.clear(), again.clear(), snapped_now.clear();
  for (const std::int32_t fi : sc_.work) {
    const Face& f = faces[fi];
    const std::int8_t s[3] = {sd[f[0]], sd[f[1]], sd[f[2]]};
    if (is_crossed(s)) crossed.push_back(fi);
  }
  sc_.diagonal.assign(crossed.size(), 1);
  for (std::size_t i = 0; i < crossed.size(); ++i) evaluate.push_back(static_cast<std::int32_t>(i));
  while (!evaluate.empty()) {
    snapped_now.clear();
    for (const std::int32_t ci : evaluate) snap_face(ci);
    // Faces touched by this round's snaps that are still crossed: evaluate them again.
    std::sort(snapped_now.begin(), snapped_now.end());
    again.clear();
    if (!snapped_now.empty())
      for (std::size_t ci = 0; ci < crossed.size(); ++ci) {
        const Face& f = faces[crossed[ci]];
        bool touched = false;
        for (auto v : f) touched |= std::binary_search(snapped_now.begin(), snapped_now.end(), v);
        const std::int8_t s[3] = {sd[f[0]], sd[f[1]], sd[f[2]]};
        if (touched && is_crossed(s)) again.push_back(static_cast<std::int32_t>(ci));
      }
    evaluate.swap(again);
  }
}

void CutSnap::snap_face(std::int32_t ci) {
  const Face& f = mesh_.faces[static_cast<std::size_t>(sc_.crossed[static_cast<std::size_t>(ci)])];
  std::int8_t* const sd = sc_.side.data();
  std::int8_t s[3] = {sd[f[0]], sd[f[1]], sd[f[2]]};
  if (!is_crossed(s)) return;
  bool first_diagonal = true;
  const double quality = split_quality(f, s, &first_diagonal);
  sc_.diagonal[static_cast<std::size_t>(ci)] = first_diagonal;
  if (quality >= floor_sin2_) return;  // the bound is never above the floor
  const double bound = sliver_bound_sin2(point(f[0]), point(f[1]), point(f[2]), options_.min_angle);
  if (quality >= bound) return;
  // Taking two of its vertices as on the plane always makes the face acceptable (it is no
  // longer crossed), so the nearest alone if that suffices, else the second nearest alone
  // if that does, else both.
  // A vertex a snap would pinch (compute_cut's later rounds) is never taken: it sorts last,
  // and the face keeps its sliver when only such vertices would do.
  const std::vector<std::int32_t>& barred = sc_.unsnappable;
  auto snappable = [&](int k) {
    return barred.empty() || !std::binary_search(barred.begin(), barred.end(), f[k]);
  };
  int order[3] = {0, 1, 2};
  std::sort(order, order + 3, [&](int i, int j) {
    const double di = s[i] == 0 ? -1 : snappable(i) ? std::abs(dist(f[i])) : INFINITY;
    const double dj = s[j] == 0 ? -1 : snappable(j) ? std::abs(dist(f[j])) : INFINITY;
    return di < dj || (di == dj && i < j);
  });
  const int first = s[order[0]] == 0 ? 1 : 0;  // skip a vertex already on the plane
  if (!snappable(order[first])) return;
  auto acceptable_without = [&](int k) {
    const std::int8_t keep = s[k];
    s[k] = 0;
    const bool ok = !is_crossed(s) || split_quality(f, s, nullptr) >= bound;
    s[k] = keep;
    return ok;
  };
  auto snap_vertex = [&](std::int32_t v) {
    sd[v] = 0;
    ++result_.snapped_vertices;
    sc_.snapped_now.push_back(v);
    if (!(sc_.code[static_cast<std::size_t>(v)] & 16)) outside_work_ = true;
  };
  const bool second = first == 0 && snappable(order[1]);
  if (acceptable_without(order[first])) {
    snap_vertex(f[order[first]]);
  } else if (second && acceptable_without(order[1])) {
    snap_vertex(f[order[1]]);
  } else {
    snap_vertex(f[order[first]]);
    if (second) snap_vertex(f[order[1]]);
  }
}

void CutSnap::add_faces_around_far_snaps() {
  std::vector<std::int32_t>& work = sc_.work;
  const std::uint8_t* const cd = sc_.code.data();
  const std::int8_t* const sd = sc_.side.data();
  const auto before = work.size();
  for (std::size_t fi = 0; fi < static_cast<std::size_t>(nf0_); ++fi) {
    const Face& f = mesh_.faces[fi];
    const int fc = cd[f[0]] | cd[f[1]] | cd[f[2]];
    if (!(fc == 2 || fc == 8)) continue;  // already in work
    if (sd[f[0]] == 0 || sd[f[1]] == 0 || sd[f[2]] == 0)
      work.push_back(static_cast<std::int32_t>(fi));
  }
  std::inplace_merge(work.begin(), work.begin() + static_cast<std::ptrdiff_t>(before), work.end());
}

}  // namespace conform::mesh::cutting
