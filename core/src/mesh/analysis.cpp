#include "conform/mesh/analysis.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <tuple>

#include "conform/mesh/detail/union_find.hpp"

namespace conform::mesh {

namespace {

template <class Fn>
void for_faces(const SkinnedMesh& mesh, std::span<const std::int32_t> faces, Fn fn) {
  if (faces.empty()) {
    for (const Face& f : mesh.faces) fn(f);
  } else {
    for (auto i : faces) fn(mesh.faces[static_cast<std::size_t>(i)]);
  }
}

}  // namespace

double surface_area(const SkinnedMesh& mesh, std::span<const std::int32_t> faces) {
  double a = 0;
  for_faces(mesh, faces, [&](const Face& f) {
    const Eigen::Vector3d p = mesh.current.col(f[0]);
    a += 0.5 * (mesh.current.col(f[1]) - p).cross(mesh.current.col(f[2]) - p).norm();
  });
  return a;
}

double signed_volume(const SkinnedMesh& mesh, std::span<const std::int32_t> faces) {
  double v = 0;
  for_faces(mesh, faces, [&](const Face& f) {
    const Eigen::Vector3d a = mesh.current.col(f[0]), b = mesh.current.col(f[1]),
                          c = mesh.current.col(f[2]);
    v += a.dot(b.cross(c));
  });
  return v / 6;
}

double bounding_diagonal(const SkinnedMesh& mesh) {
  const Eigen::Index n = mesh.current.cols();
  if (n == 0) return 0;
  // One pass over the columns (Eigen's rowwise reductions walk the 3 × N matrix row by row).
  const double* p = mesh.current.data();
  double lo[3] = {p[0], p[1], p[2]}, hi[3] = {p[0], p[1], p[2]};
  for (Eigen::Index i = 1; i < n; ++i) {
    const double* q = p + 3 * i;
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], q[k]), hi[k] = std::max(hi[k], q[k]);
  }
  return std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                   (hi[2] - lo[2]) * (hi[2] - lo[2]));
}

double smallest_angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                      const Eigen::Vector3d& c) {
  auto at = [](const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& r) {
    const Eigen::Vector3d u = q - p, v = r - p;
    return std::atan2(u.cross(v).norm(), u.dot(v));
  };
  return std::min({at(a, b, c), at(b, c, a), at(c, a, b)});
}

double sliver_bound_sin2(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         const Eigen::Vector3d& c, double floor) {
  const double s = std::sin(floor);
  // sin²(α/2) = (1 − cos α) / 2 for the smallest angle α, the one between the longer sides.
  const double ab = (b - a).squaredNorm(), bc = (c - b).squaredNorm(), ca = (a - c).squaredNorm();
  double l1 = ab, l2 = bc, shortest = ca;  // the two longer sides and the shortest
  if (ab < shortest) std::swap(l1, shortest);
  if (bc < shortest) std::swap(l2, shortest);
  if (!(l1 > 0 && l2 > 0)) return 0;
  const double cosine = std::clamp((l1 + l2 - shortest) / (2 * std::sqrt(l1 * l2)), -1.0, 1.0);
  return std::min(s * s, (1 - cosine) / 2);
}

std::string MeshReport::summary() const {
  return std::string(indices_valid ? "" : "invalid indices; ") +
         (finite ? "" : "non-finite positions; ") + "tiny faces " + std::to_string(tiny_faces) +
         ", boundary edges " + std::to_string(boundary_edges) + ", overused edges " +
         std::to_string(overused_edges) + ", misoriented edges " +
         std::to_string(misoriented_edges) + ", non-manifold vertices " +
         std::to_string(nonmanifold_vertices);
}

MeshReport check_mesh(const SkinnedMesh& mesh, double min_area) {
  MeshReport r;
  const std::int32_t nv = mesh.vertex_count();
  r.finite = mesh.current.allFinite();
  for (const Face& f : mesh.faces)
    for (auto v : f)
      if (v < 0 || v >= nv) r.indices_valid = false;
  for (const Face& f : mesh.faces)
    if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2]) r.indices_valid = false;
  if (!r.indices_valid) return r;
  for (const Face& f : mesh.faces) {
    const Eigen::Vector3d p = mesh.current.col(f[0]);
    const double a = 0.5 * (mesh.current.col(f[1]) - p).cross(mesh.current.col(f[2]) - p).norm();
    if (!(a > min_area)) ++r.tiny_faces;
  }
  // Undirected edges with their direction counts.
  std::vector<std::tuple<std::int32_t, std::int32_t, int>> e;  // (min, max, +1 if min→max)
  e.reserve(mesh.faces.size() * 3);
  for (const Face& f : mesh.faces)
    for (int k = 0; k < 3; ++k) {
      const std::int32_t u = f[k], v = f[(k + 1) % 3];
      e.emplace_back(std::min(u, v), std::max(u, v), u < v ? 1 : 0);
    }
  std::sort(e.begin(), e.end());
  for (std::size_t i = 0; i < e.size();) {
    std::size_t j = i;
    int forward = 0;
    while (j < e.size() && std::get<0>(e[j]) == std::get<0>(e[i]) &&
           std::get<1>(e[j]) == std::get<1>(e[i]))
      forward += std::get<2>(e[j]), ++j;
    const auto n = static_cast<int>(j - i);
    if (n == 1) ++r.boundary_edges;
    if (n > 2) ++r.overused_edges;
    if (n == 2 && forward != 1) ++r.misoriented_edges;
    i = j;
  }
  // Vertex fans: faces around a vertex joined through shared edges must form one group.
  std::vector<std::int32_t> start(static_cast<std::size_t>(nv) + 1, 0);
  for (const Face& f : mesh.faces)
    for (auto v : f) ++start[static_cast<std::size_t>(v) + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<std::int32_t> inc(static_cast<std::size_t>(start.back()));
  std::vector<std::int32_t> fill(start.begin(), start.end() - 1);
  for (std::size_t fi = 0; fi < mesh.faces.size(); ++fi)
    for (auto v : mesh.faces[fi])
      inc[static_cast<std::size_t>(fill[static_cast<std::size_t>(v)]++)] =
          static_cast<std::int32_t>(fi);
  std::vector<std::int32_t> parent;
  for (std::int32_t v = 0; v < nv; ++v) {
    const auto b = static_cast<std::size_t>(start[static_cast<std::size_t>(v)]);
    const auto n = static_cast<std::int32_t>(start[static_cast<std::size_t>(v) + 1] -
                                             start[static_cast<std::size_t>(v)]);
    if (n <= 1) continue;
    parent.resize(static_cast<std::size_t>(n));
    std::iota(parent.begin(), parent.end(), 0);
    for (std::int32_t i = 0; i < n; ++i)
      for (std::int32_t j = i + 1; j < n; ++j) {
        const Face& a = mesh.faces[static_cast<std::size_t>(inc[b + static_cast<std::size_t>(i)])];
        const Face& c = mesh.faces[static_cast<std::size_t>(inc[b + static_cast<std::size_t>(j)])];
        // Share an edge through v: a common vertex other than v.
        bool shared = false;
        for (auto x : a)
          if (x != v && (x == c[0] || x == c[1] || x == c[2])) shared = true;
        if (shared) detail::unite(parent.data(), i, j);
      }
    int groups = 0;
    for (std::int32_t i = 0; i < n; ++i) groups += detail::find_root(parent.data(), i) == i;
    if (groups > 1) ++r.nonmanifold_vertices;
  }
  return r;
}

std::vector<std::int32_t> Pieces::faces_of(std::int32_t p) const {
  std::vector<std::int32_t> out;
  for (std::size_t f = 0; f < face_piece.size(); ++f)
    if (face_piece[f] == p) out.push_back(static_cast<std::int32_t>(f));
  return out;
}

Pieces label_pieces(const SkinnedMesh& mesh) {
  // Union–find over the vertices where every root is the lowest vertex of its set: linking
  // always hangs the higher roots under the lowest, r, and compression only points a vertex at
  // an ancestor, so parent[v] < v for every non-root v. Each face also points its own
  // vertices straight at r (full compression of the paths just walked: the next faces around
  // them find r in one or two loads). One increasing pass then compresses every path. The
  // scratch arrays are kept per thread between calls (no allocation at haptic rates).
  const auto nv = static_cast<std::size_t>(mesh.vertex_count());
  thread_local std::vector<std::int32_t> parent, label;
  if (parent.size() < nv) parent.resize(nv), label.resize(nv);
  std::int32_t* const par = parent.data();
  std::iota(par, par + nv, 0);
  auto find = [par](std::int32_t x) { return detail::find_root(par, x); };
  for (const Face& f : mesh.faces) {
    // Three independent loads settle the usual face, whose vertices already share a parent.
    const std::int32_t p0 = par[f[0]];
    if (p0 == par[f[1]] && p0 == par[f[2]]) continue;
    const std::int32_t a = find(f[0]), b = find(f[1]), c = find(f[2]);
    if (a == b && b == c) continue;
    const std::int32_t r = std::min(a, std::min(b, c));
    par[a] = r, par[b] = r, par[c] = r;
    par[f[0]] = r, par[f[1]] = r, par[f[2]] = r;
  }
  for (std::size_t v = 0; v < nv; ++v) par[v] = par[par[v]];
  Pieces p;
  p.face_piece.resize(mesh.faces.size());
  std::int32_t* const lab = label.data();
  std::fill(lab, lab + nv, -1);
  std::int32_t* const out = p.face_piece.data();
  std::int32_t count = 0;
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    std::int32_t& l = lab[par[mesh.faces[f][0]]];
    if (l < 0) l = count++;
    out[f] = l;
  }
  p.count = count;
  return p;
}

}  // namespace conform::mesh
