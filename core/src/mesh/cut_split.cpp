#include "cut_split.hpp"

#include <algorithm>

namespace conform::mesh::cutting {

std::int32_t CutSplit::cross_vertex(std::int32_t u, std::int32_t w) {
  const std::int32_t a = std::min(u, w), b = std::max(u, w);
  std::int32_t id = sc_.crossing.find(a, b);
  if (id >= 0) return id;
  const double da = dist(a), db = dist(b);
  const double t = da / (da - db);
  TopologyChange& ch = result_.change;
  id = nv0_ + static_cast<std::int32_t>(ch.new_vertices.size());
  ch.new_vertices.push_back(NewVertex::on_edge(a, b, t));
  sc_.xpos.push_back((1 - t) * mesh_.current.col(a) + t * mesh_.current.col(b));
  sc_.crossing.insert(a, b, id);
  ++result_.crossed_edges;
  return id;
}

bool CutSplit::split_crossed_faces() {
  const std::size_t work_size = sc_.work.size();
  sc_.crossing.clear();
  sc_.crossing.reserve(2 * work_size);
  result_.change.new_vertices.reserve(2 * work_size);
  sc_.xpos.clear();
  sc_.xpos.reserve(work_size);
  sc_.pending.clear();
  sc_.pending.reserve(3 * work_size);
  sc_.on_plane.clear();  // (vertex on the plane, pending index)
  split_.reserve(work_size);
  std::size_t next_crossed = 0;  // walks `crossed` along with `work` (both increasing)
  for (const std::int32_t fi : sc_.work) {
    const Face& f = mesh_.faces[static_cast<std::size_t>(fi)];
    const std::int8_t s[3] = {sc_.side[static_cast<std::size_t>(f[0])],
                              sc_.side[static_cast<std::size_t>(f[1])],
                              sc_.side[static_cast<std::size_t>(f[2])]};
    if (!is_crossed(s)) {
      keep_face(fi, s);
      continue;
    }
    face_pos_ = face_neg_ = true;
    split_.push_back(fi);
    split_face(fi, s, next_crossed);
  }
  return face_pos_ && face_neg_;
}

void CutSplit::keep_face(std::int32_t fi, const std::int8_t* s) {
  const Face& f = mesh_.faces[static_cast<std::size_t>(fi)];
  std::int8_t fs = s[0] != 0 ? s[0] : (s[1] != 0 ? s[1] : s[2]);
  if (fs == 0) {
    const Eigen::Vector3d a = mesh_.current.col(f[0]);
    const Eigen::Vector3d normal = (mesh_.current.col(f[1]) - a).cross(mesh_.current.col(f[2]) - a);
    fs = normal.dot(plane_.normal()) > 0 ? -1 : 1;
  }
  (fs > 0 ? face_pos_ : face_neg_) = true;
  if (s[0] != 0 && s[1] != 0 && s[2] != 0) return;
  const auto idx = static_cast<std::int32_t>(sc_.pending.size());
  sc_.pending.push_back({f, f, fs, fi});
  for (int k = 0; k < 3; ++k)
    if (s[k] == 0) sc_.on_plane.emplace_back(f[k], idx);
}

void CutSplit::split_face(std::int32_t fi, const std::int8_t* s, std::size_t& next_crossed) {
  const Face& f = mesh_.faces[static_cast<std::size_t>(fi)];
  std::vector<Pending>& pending = sc_.pending;
  int zero = -1;
  for (int k = 0; k < 3; ++k)
    if (s[k] == 0) zero = k;
  if (zero >= 0) {
    const std::int32_t v0 = f[zero], v1 = f[(zero + 1) % 3], v2 = f[(zero + 2) % 3];
    const std::int32_t x = cross_vertex(v1, v2);
    const auto idx = static_cast<std::int32_t>(pending.size());
    pending.push_back({{v0, v1, x}, {v0, v1, x}, s[(zero + 1) % 3], -1});
    pending.push_back({{v0, x, v2}, {v0, x, v2}, s[(zero + 2) % 3], -1});
    sc_.on_plane.emplace_back(v0, idx);
    sc_.on_plane.emplace_back(v0, idx + 1);
    return;
  }
  int lone = 0;
  for (int k = 0; k < 3; ++k)
    if (s[(k + 1) % 3] == s[(k + 2) % 3]) lone = k;
  const std::int32_t v0 = f[lone], v1 = f[(lone + 1) % 3], v2 = f[(lone + 2) % 3];
  const std::int32_t x01 = cross_vertex(v0, v1), x20 = cross_vertex(v2, v0);
  const std::int8_t s0 = s[lone];
  const auto s1 = static_cast<std::int8_t>(-s0);
  pending.push_back({{v0, x01, x20}, {v0, x01, x20}, s0, -1});
  // The diagonal step 2 chose for this face (its last evaluation saw these sides).
  while (sc_.crossed[next_crossed] != fi) ++next_crossed;
  if (sc_.diagonal[next_crossed]) {
    pending.push_back({{x01, v1, v2}, {x01, v1, v2}, s1, -1});
    pending.push_back({{x01, v2, x20}, {x01, v2, x20}, s1, -1});
  } else {
    pending.push_back({{x01, v1, x20}, {x01, v1, x20}, s1, -1});
    pending.push_back({{v1, v2, x20}, {v1, v2, x20}, s1, -1});
  }
}

void CutSplit::emit_faces() {
  TopologyChange& ch = result_.change;
  for (const Pending& p : sc_.pending) {
    if (p.original >= 0) {
      if (!p.remapped) continue;
      split_.push_back(p.original);
    }
    ch.added_faces.push_back(p.v);
    result_.added_side.push_back(p.side);
  }
  std::sort(split_.begin(), split_.end());
  ch.removed_faces = std::move(split_);
}

}  // namespace conform::mesh::cutting
