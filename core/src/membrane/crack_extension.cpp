#include "conform/membrane/crack_extension.hpp"

#include <algorithm>
#include <map>
#include <numeric>
#include <set>

#include "conform/membrane/energy_release.hpp"

namespace conform::membrane {
namespace {

// Face `f` turned so that its corner `k` comes first (the winding kept).
mesh::Face from_corner(const mesh::Face& f, int k) {
  return {f[std::size_t(k)], f[std::size_t((k + 1) % 3)], f[std::size_t((k + 2) % 3)]};
}

int corner_of(const mesh::Face& f, std::int32_t v) {
  for (int k = 0; k < 3; ++k)
    if (f[std::size_t(k)] == v) return k;
  return -1;
}

// The face other than `skip` holding the edge (b, c), or -1 on the border.
std::int32_t face_across(const mesh::SkinnedMesh& m, std::int32_t skip, std::int32_t b,
                         std::int32_t c) {
  for (std::int32_t g = 0; g < m.face_count(); ++g)
    if (g != skip && corner_of(m.faces[std::size_t(g)], b) >= 0 &&
        corner_of(m.faces[std::size_t(g)], c) >= 0)
      return g;
  return -1;
}

struct LocalFace {
  std::int32_t origin;  // the face of the mesh it replaces (or is)
  mesh::Face face;
};

// T's faces split into the parts that meet across an edge T-v (v != cut): union-find.
std::vector<int> fan_parts(const std::vector<LocalFace>& fan, std::int32_t tip, std::int32_t cut) {
  std::vector<int> part(fan.size());
  std::iota(part.begin(), part.end(), 0);
  const auto root = [&](int i) {
    while (part[std::size_t(i)] != i) i = part[std::size_t(i)];
    return i;
  };
  std::map<std::int32_t, int> first_with_edge;
  for (std::size_t i = 0; i < fan.size(); ++i)
    for (const std::int32_t v : fan[i].face) {
      if (v == tip || v == cut) continue;
      const auto [it, fresh] = first_with_edge.emplace(v, int(i));
      if (!fresh) part[std::size_t(root(int(i)))] = root(it->second);
    }
  for (std::size_t i = 0; i < fan.size(); ++i) part[i] = root(int(i));
  return part;
}

}  // namespace

CrackExtension crack_extension(const mesh::SkinnedMesh& m, const std::vector<std::uint8_t>& fixed,
                               std::int32_t tip, const Eigen::Vector3d& direction,
                               double snap_fraction) {
  CrackExtension out;
  const Eigen::Vector3d normal = sheet_normal(m, tip), at = m.rest.col(tip);
  const Eigen::Vector3d d = (direction - direction.dot(normal) * normal).normalized();
  const Eigen::Vector3d side = normal.cross(d);  // +: left of the path
  // The fan face the ray enters: b right of d (or on it), c left of it.
  std::int32_t f = -1;
  mesh::Face turned{};
  double yb = 0, yc = 0;
  for (std::int32_t g = 0; g < m.face_count() && f < 0; ++g) {
    const int k = corner_of(m.faces[std::size_t(g)], tip);
    if (k < 0) continue;
    const mesh::Face t = from_corner(m.faces[std::size_t(g)], k);
    const Eigen::Vector3d pb = m.rest.col(t[1]) - at, pc = m.rest.col(t[2]) - at;
    if (pb.dot(side) <= 0 && pc.dot(side) >= 0 && (pb + pc).dot(d) > 0)
      f = g, turned = t, yb = pb.dot(side), yc = pc.dot(side);
  }
  if (f < 0) {
    out.message = "no face of the tip's fan lies ahead along the direction";
    return out;
  }
  const std::int32_t b = turned[1], c = turned[2];
  const double t = yc - yb > 0 ? -yb / (yc - yb) : 0.5;  // Q = b + t (c - b)
  const bool split = t >= snap_fraction && t <= 1 - snap_fraction;
  const std::int32_t g = split ? face_across(m, f, b, c) : -1;
  const std::int32_t base = m.vertex_count();
  const std::int32_t q = split ? base : (t < snap_fraction ? b : c);
  if ((split && (g < 0 || (fixed[std::size_t(b)] && fixed[std::size_t(c)]))) ||
      (!split && fixed[std::size_t(q)])) {
    out.reached_border = true;
    out.message = "the crack reached the border";
    return out;
  }
  // T's fan after the split, and the split face across (b, c).
  std::vector<LocalFace> fan, across;
  for (std::int32_t h = 0; h < m.face_count(); ++h) {
    if (corner_of(m.faces[std::size_t(h)], tip) < 0) continue;
    if (split && h == f) {
      fan.push_back({f, {tip, b, q}});
      fan.push_back({f, {tip, q, c}});
    } else {
      fan.push_back({h, m.faces[std::size_t(h)]});
    }
  }
  if (split) {
    const mesh::Face w =
        from_corner(m.faces[std::size_t(g)], corner_of(m.faces[std::size_t(g)], c));
    across = {{g, {c, q, w[2]}}, {g, {q, b, w[2]}}};
  }
  const std::vector<int> part = fan_parts(fan, tip, q);
  const std::set<int> parts(part.begin(), part.end());
  if (parts.size() != 2) {
    out.message = "the tip is not the end of a crack (its fan has " + std::to_string(parts.size()) +
                  " parts around the path)";
    return out;
  }
  // The part left of the path (the one holding c's side of f) takes T's duplicate.
  int left = -1;
  for (std::size_t i = 0; i < fan.size(); ++i)
    if (fan[i].origin == f && corner_of(fan[i].face, c) >= 0) left = part[i];
  const std::int32_t duplicate = base + (split ? 1 : 0);
  mesh::TopologyChange& ch = out.change;
  ch.base_vertex_count = base;
  ch.base_face_count = m.face_count();
  if (split) ch.new_vertices.push_back(mesh::NewVertex::on_edge(b, c, t));
  ch.new_vertices.push_back(mesh::NewVertex::duplicate(tip));
  std::set<std::int32_t> removed;
  if (split) removed = {f, g};
  for (std::size_t i = 0; i < fan.size(); ++i)
    if (part[i] == left) removed.insert(fan[i].origin);
  ch.removed_faces.assign(removed.begin(), removed.end());
  for (std::size_t i = 0; i < fan.size(); ++i) {
    if (!removed.count(fan[i].origin)) continue;
    mesh::Face face = fan[i].face;
    if (part[i] == left) std::replace(face.begin(), face.end(), tip, duplicate);
    ch.added_faces.push_back(face);
  }
  for (const LocalFace& a : across) ch.added_faces.push_back(a.face);
  out.new_tip = q;
  out.duplicate = duplicate;
  return out;
}

void extend_columns(Eigen::Matrix3Xd& x, const mesh::TopologyChange& change) {
  const auto base = static_cast<Eigen::Index>(change.base_vertex_count);
  x.conservativeResize(3, base + static_cast<Eigen::Index>(change.new_vertices.size()));
  for (std::size_t i = 0; i < change.new_vertices.size(); ++i) {
    const mesh::NewVertex& nv = change.new_vertices[i];
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k)
      if (nv.parents[std::size_t(k)] >= 0)
        p += nv.coefficients[std::size_t(k)] * x.col(nv.parents[std::size_t(k)]);
    x.col(base + static_cast<Eigen::Index>(i)) = p;
  }
}

}  // namespace conform::membrane
