#include "lip_refine.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>

#include "change_flips.hpp"
#include "conform/mesh/analysis.hpp"

namespace conform::mesh {

namespace {

Eigen::Vector3d at(const SkinnedMesh& mesh, std::int32_t v) {
  return mesh.current.col(v);
}

// The faces around the corner of half-edge h (out of its vertex), both ways from h.
std::vector<std::int32_t> ring(const Adjacency& adj, std::int32_t h) {
  std::vector<std::int32_t> out;
  std::int32_t g = h;
  for (int guard = 0; guard < 64; ++guard) {
    out.push_back(g / 3);
    const std::int32_t o = adj.twin(3 * (g / 3) + (g % 3 + 2) % 3);
    if (o < 0 || o == h) break;
    g = o;
  }
  g = h;
  for (int guard = 0; guard < 64; ++guard) {
    const std::int32_t o = adj.twin(g);
    if (o < 0) break;
    g = 3 * (o / 3) + (o % 3 + 1) % 3;
    if (g == h) break;
    out.push_back(g / 3);
  }
  return out;
}

// A face around a corner of `face` that holds p (projected on its plane) with every barycentric
// coordinate at least `margin`; −1 if none.
std::int32_t locate(const SkinnedMesh& mesh, const Adjacency& adj, std::int32_t face,
                    const Eigen::Vector3d& p, double margin, std::array<double, 3>& bary) {
  for (int k = 0; k < 3; ++k)
    for (const std::int32_t g : ring(adj, 3 * face + k)) {
      const Face& f = mesh.faces[static_cast<std::size_t>(g)];
      const Eigen::Vector3d a = at(mesh, f[0]), b = at(mesh, f[1]), c = at(mesh, f[2]);
      const Eigen::Vector3d n = (b - a).cross(c - a);
      const double n2 = n.squaredNorm();
      if (!(n2 > 0)) continue;
      bary = {(c - b).cross(p - b).dot(n) / n2, (a - c).cross(p - c).dot(n) / n2, 0};
      bary[2] = 1 - bary[0] - bary[1];
      if (*std::min_element(bary.begin(), bary.end()) >= margin) return g;
    }
  return -1;
}

// The smallest angle's sin² over the faces `ch` adds (or over those it removes).
double worst(const SkinnedMesh& mesh, const TopologyChange& ch, bool added) {
  const std::int32_t base = ch.base_vertex_count;
  auto pos = [&](std::int32_t v) {
    if (v < base) return at(mesh, v);
    const NewVertex& nv = ch.new_vertices[static_cast<std::size_t>(v - base)];
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k)
      if (nv.parents[k] >= 0) x += nv.coefficients[k] * at(mesh, nv.parents[k]);
    return x;
  };
  double q = 1;
  if (added)
    for (const Face& f : ch.added_faces)
      q = std::min(q, smallest_angle_sin2(pos(f[0]), pos(f[1]), pos(f[2])));
  else
    for (const std::int32_t s : ch.removed_faces) {
      const Face& f = mesh.faces[static_cast<std::size_t>(s)];
      q = std::min(q, smallest_angle_sin2(at(mesh, f[0]), at(mesh, f[1]), at(mesh, f[2])));
    }
  return q;
}

// The change that puts a Steiner point at the apex of the equilateral triangle on edge (u, v)
// of face `cap`, on the side of its third vertex `apex` (or, `halfway`, midway between the
// edge's middle and `apex`: where that vertex is the apex of a fan over several short path
// edges, the point halves the fan's distance to the path), and flips around it (the path's edges
// `fixed`); empty unless it removes `cap`, raises the smallest angle and keeps the floor.
TopologyChange steiner(const SkinnedMesh& mesh, const Adjacency& adj, std::int32_t cap,
                       std::int32_t u, std::int32_t v, std::int32_t apex, bool halfway,
                       const std::vector<std::array<std::int32_t, 2>>& fixed, double floor) {
  TopologyChange ch;
  const Eigen::Vector3d pu = at(mesh, u), pv = at(mesh, v), pa = at(mesh, apex);
  const Eigen::Vector3d n = (pv - pu).cross(pa - pu), e = pv - pu;
  Eigen::Vector3d side = n.cross(e).normalized();
  if (side.dot(pa - pu) < 0) side = -side;
  if (!side.allFinite()) return ch;
  const Eigen::Vector3d mid = 0.5 * (pu + pv);
  const Eigen::Vector3d s = halfway ? Eigen::Vector3d(0.5 * (mid + pa))
                                    : Eigen::Vector3d(mid + std::sqrt(3.0) / 2 * e.norm() * side);
  std::array<double, 3> bary{};
  const std::int32_t face = locate(mesh, adj, cap, s, 0.02, bary);
  if (face < 0) return ch;
  const Face f = mesh.faces[static_cast<std::size_t>(face)];
  ch.base_vertex_count = mesh.vertex_count();
  ch.base_face_count = mesh.face_count();
  const std::int32_t id = mesh.vertex_count();
  ch.new_vertices.push_back(NewVertex::in_face(f[0], f[1], f[2], bary[0], bary[1], bary[2]));
  ch.removed_faces = {face};
  ch.added_faces = {{f[0], f[1], id}, {f[1], f[2], id}, {f[2], f[0], id}};
  flip_for_angles(mesh, adj, ch, fixed);
  const bool removes_cap =
      std::find(ch.removed_faces.begin(), ch.removed_faces.end(), cap) != ch.removed_faces.end();
  const double after = worst(mesh, ch, true), floor2 = std::pow(std::sin(floor), 2);
  if (!removes_cap || after < floor2 || !(after > worst(mesh, ch, false))) return TopologyChange{};
  return ch;
}

}  // namespace

TopologyChange refine_beside_path(const SkinnedMesh& mesh, const Adjacency& adjacency,
                                  const std::vector<std::int32_t>& path, double thin,
                                  double floor) {
  std::vector<std::array<std::int32_t, 2>> fixed;
  for (std::size_t i = 0; i + 1 < path.size(); ++i) fixed.push_back({path[i], path[i + 1]});
  const double thin2 = std::pow(std::sin(thin), 2);
  for (const auto& [p, q] : fixed)
    for (const std::int32_t h : {adjacency.find(p, q), adjacency.find(q, p)}) {
      if (h < 0) continue;
      const std::int32_t face = h / 3;
      const Face& f = mesh.faces[static_cast<std::size_t>(face)];
      const std::int32_t u = f[h % 3], v = f[(h % 3 + 1) % 3], apex = f[(h % 3 + 2) % 3];
      if (std::find(path.begin(), path.end(), apex) != path.end()) continue;
      if (smallest_angle_sin2(at(mesh, u), at(mesh, v), at(mesh, apex)) >= thin2) continue;
      for (const bool halfway : {false, true}) {
        TopologyChange ch = steiner(mesh, adjacency, face, u, v, apex, halfway, fixed, floor);
        if (!ch.empty()) return ch;
      }
    }
  // A face on a path vertex thin at a vertex off the path: the short side opposite it joins the
  // path to a vertex just off the track; the Steiner point goes across that side from the path.
  // Not around the new tip, whose faces the next step re-triangulates.
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    const std::int32_t h = adjacency.find(path[i], path[i + 1]);
    if (h < 0) continue;
    for (const std::int32_t face : ring(adjacency, h)) {
      const Face& f = mesh.faces[static_cast<std::size_t>(face)];
      std::array<double, 3> len;  // the side opposite each corner: the thinnest faces the shortest
      for (int i = 0; i < 3; ++i)
        len[i] = (at(mesh, f[(i + 2) % 3]) - at(mesh, f[(i + 1) % 3])).norm();
      const int k = static_cast<int>(std::min_element(len.begin(), len.end()) - len.begin());
      const std::int32_t w = f[k], u = f[(k + 1) % 3], v = f[(k + 2) % 3];
      if (std::find(path.begin(), path.end(), w) != path.end()) continue;
      if (smallest_angle_sin2(at(mesh, u), at(mesh, v), at(mesh, w)) >= thin2) continue;
      for (const bool halfway : {false, true}) {
        TopologyChange ch = steiner(mesh, adjacency, face, u, v, w, halfway, fixed, floor);
        if (!ch.empty()) return ch;
      }
    }
  }
  return {};
}

}  // namespace conform::mesh
