#include "tear_face_split.hpp"

#include <algorithm>

#include "quad_split.hpp"

namespace conform::mesh::tearing {

std::int32_t PathSplit::id_of(const PathPoint& p, std::int32_t face) {
  if (p.kind == PathPoint::Vertex) return p.v;
  if (p.kind == PathPoint::Edge) {
    const std::int32_t lo = std::min(p.a, p.b), hi = std::max(p.a, p.b);
    std::int32_t id = edge_ids_.find(lo, hi);
    if (id < 0) {
      id = nv0_ + static_cast<std::int32_t>(split_.new_vertices.size());
      split_.new_vertices.push_back(NewVertex::on_edge(p.a, p.b, p.t));
      edge_ids_.insert(lo, hi, id);
    }
    return id;
  }
  if (tip_id_ < 0) {
    const Face& f = mesh_.faces[static_cast<std::size_t>(face)];
    tip_id_ = nv0_ + static_cast<std::int32_t>(split_.new_vertices.size());
    split_.new_vertices.push_back(
        NewVertex::in_face(f[0], f[1], f[2], p.bary[0], p.bary[1], p.bary[2]));
  }
  return tip_id_;
}

Eigen::Vector3d PathSplit::position_of(std::int32_t id) const {
  if (id < nv0_) return mesh_.current.col(id);
  const NewVertex& nv = split_.new_vertices[static_cast<std::size_t>(id - nv0_)];
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  for (int k = 0; k < 3; ++k)
    if (nv.parents[k] >= 0) x += nv.coefficients[k] * mesh_.current.col(nv.parents[k]);
  return x;
}

void PathSplit::restart_split() {
  split_.new_vertices.clear();
  split_.removed_faces.clear();
  split_.added_faces.clear();
  edge_ids_ = EdgeMap();
  points_.clear();
  tip_id_ = -1;
  target_ = tear_.tip_target_;
}

void PathSplit::split_face(const Crossing& c) {
  const Face& f = mesh_.faces[static_cast<std::size_t>(c.face)];
  const std::int32_t in = id_of(c.in, c.face), out = id_of(c.out, c.face);
  points_.push_back(out);
  std::vector<std::int32_t> poly;
  for (int k = 0; k < 3; ++k) {
    poly.push_back(f[k]);
    for (const PathPoint* p : {&c.in, &c.out})
      if (on_edge(*p, f[k], f[(k + 1) % 3])) poly.push_back(id_of(*p, c.face));
  }
  TopologyChange& a = split_;
  a.removed_faces.push_back(c.face);
  const auto m = poly.size();
  if (c.out.kind == PathPoint::Inside) {
    for (std::size_t i = 0; i < m; ++i) a.added_faces.push_back({poly[i], poly[(i + 1) % m], out});
    return;
  }
  const auto i_in =
      static_cast<std::size_t>(std::find(poly.begin(), poly.end(), in) - poly.begin());
  const auto i_out =
      static_cast<std::size_t>(std::find(poly.begin(), poly.end(), out) - poly.begin());
  if ((i_in + 1) % m == i_out || (i_out + 1) % m == i_in) {
    a.removed_faces.pop_back();  // along an existing edge: the face stays
    return;
  }
  for (auto [from, to] : {std::pair{i_in, i_out}, std::pair{i_out, i_in}}) {
    std::vector<std::int32_t> sub;
    for (std::size_t i = from;; i = (i + 1) % m) {
      sub.push_back(poly[i]);
      if (i == to) break;
    }
    if (sub.size() == 3) {
      a.added_faces.push_back({sub[0], sub[1], sub[2]});
      continue;
    }
    const QuadSplit quad = best_quad_split(
        position_of(sub[0]), position_of(sub[1]), position_of(sub[2]), position_of(sub[3]),
        [](const auto& x, const auto& y, const auto& z) { return smallest_angle_sin2(x, y, z); });
    if (quad.first_diagonal) {
      a.added_faces.push_back({sub[0], sub[1], sub[2]});
      a.added_faces.push_back({sub[0], sub[2], sub[3]});
    } else {
      a.added_faces.push_back({sub[0], sub[1], sub[3]});
      a.added_faces.push_back({sub[1], sub[2], sub[3]});
    }
  }
}

void PathSplit::split_from_opposite(std::int32_t face, const PathPoint& p) {
  const Face& f = mesh_.faces[static_cast<std::size_t>(face)];
  const std::int32_t mid = id_of(p, face);
  for (int k = 0; k < 3; ++k)
    if (on_edge(p, f[k], f[(k + 1) % 3])) {
      const std::int32_t x = f[k], y = f[(k + 1) % 3], z = f[(k + 2) % 3];
      split_.removed_faces.push_back(face);
      split_.added_faces.push_back({x, mid, z});
      split_.added_faces.push_back({mid, y, z});
      return;
    }
}

}  // namespace conform::mesh::tearing
