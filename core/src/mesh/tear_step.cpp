#include "tear_step.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace conform::mesh::tearing {

namespace {

// The edge parameters t (from x to y) at which a point of edge (x, y) is seen from the vertex
// opposite the edge, in each face holding it, at least `angle` of that face away from both
// ends (angle: the face's sliver bound). A point in that range splits those faces, from their
// opposite vertices, into triangles that keep the bound; an empty range gives its middle.
std::pair<double, double> safe_range(const SkinnedMesh& mesh, const Adjacency& adj, std::int32_t x,
                                     std::int32_t y, double floor) {
  double lo = 0, hi = 1;
  const Eigen::Vector3d px = mesh.current.col(x), py = mesh.current.col(y);
  const double len = (py - px).norm();
  if (!(len > 0)) return {0.5, 0.5};
  for (const std::int32_t h : {adj.find(x, y), adj.find(y, x)}) {
    if (h < 0) continue;
    const Face& f = mesh.faces[static_cast<std::size_t>(h / 3)];
    const std::int32_t o = f[(h % 3 + 2) % 3];
    const Eigen::Vector3d po = mesh.current.col(o);
    auto angle = [](const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
      return std::atan2(u.cross(v).norm(), u.dot(v));
    };
    const double ax = angle(py - px, po - px), ay = angle(px - py, po - py);
    // The split angle at o: at least min(floor, half of it) on each side (for an input face,
    // at least its sliver bound; for a face the tear made, no less than it can be).
    const double b = std::min(floor, (std::numbers::pi - ax - ay) / 2);
    // Sine rule in (o, x, q) with the angle b at o: |x q| = |o x| sin b / sin(ax + b).
    const double sx = std::sin(ax + b), sy = std::sin(ay + b);
    if (sx > 0) lo = std::max(lo, (po - px).norm() * std::sin(b) / sx / len);
    if (sy > 0) hi = std::min(hi, 1 - (po - py).norm() * std::sin(b) / sy / len);
  }
  if (lo > hi) lo = hi = (lo + hi) / 2;
  return {lo, hi};
}

}  // namespace

bool StepPlane::make_plane() {
  tip_ = mesh_.current.col(tear_.tip_);
  // A tip moved off the blade's track (its fan) leaves Π on the track: through the hit it
  // stands for, so that the path's next points do not take on its offset.
  const Eigen::Vector3d from = tear_.tip_off_track_ ? tear_.tip_target_ : tip_;
  const auto plane = cga::Plane<double>::through(from, s_.a, s_.b);
  if (!plane) {
    tear_.message_ = "the blade is collinear with the tip: no plane";
    return false;
  }
  plane_ = *plane;
  n_ = plane_.normal();
  const double scale = std::max({(s_.a - tip_).norm(), (s_.b - tip_).norm(), 1e-300});
  zero_ = 1e-12 * scale;
  const Eigen::Vector3d ab = s_.b - s_.a;
  const double u = std::clamp((tip_ - s_.a).dot(ab) / std::max(ab.squaredNorm(), 1e-300), 0.0, 1.0);
  toward_ = s_.a + u * ab - tip_;
  sweep_ = {tip_, tear_.previous_.a, tear_.previous_.b, s_.a, s_.b};
  return true;
}

Eigen::Vector3d StepPlane::pos(const PathPoint& p, std::int32_t face) const {
  if (p.kind == PathPoint::Vertex) return mesh_.current.col(p.v);
  if (p.kind == PathPoint::Edge)
    return (1 - p.t) * mesh_.current.col(p.a) + p.t * mesh_.current.col(p.b);
  const Face& f = mesh_.faces[static_cast<std::size_t>(face)];
  return p.bary[0] * mesh_.current.col(f[0]) + p.bary[1] * mesh_.current.col(f[1]) +
         p.bary[2] * mesh_.current.col(f[2]);
}

bool StepPlane::blade_barycentrics(const Face& f, double floor, std::array<double, 3>& bary) const {
  if (!segment_triangle(s_.a, s_.b, mesh_.current.col(f[0]), mesh_.current.col(f[1]),
                        mesh_.current.col(f[2]), bary))
    return false;
  for (auto& x : bary) x = std::max(x, floor);
  const double sum = bary[0] + bary[1] + bary[2];
  for (auto& x : bary) x /= sum;
  return true;
}

bool StepPlane::blade_hit(std::int32_t face, PathPoint& out) const {
  const Face& f = mesh_.faces[static_cast<std::size_t>(face)];
  std::array<double, 3> bary{};
  if (!blade_barycentrics(f, snap_, bary)) return false;
  out.kind = PathPoint::Inside;
  out.bary = bary;
  return true;
}

bool StepPlane::exit_opposite(std::int32_t face, int corner, PathPoint& out) const {
  const Face& f = mesh_.faces[static_cast<std::size_t>(face)];
  const std::int32_t x = f[(corner + 1) % 3], y = f[(corner + 2) % 3];
  const double dx = delta(x), dy = delta(y);
  if (dx == 0) return out = {PathPoint::Vertex, x}, true;
  if (dy == 0) return out = {PathPoint::Vertex, y}, true;
  if (!(dx * dy < 0)) return false;
  const double t = dx / (dx - dy);
  if (t < snap_) return out = {PathPoint::Vertex, x}, true;
  if (t > 1 - snap_) return out = {PathPoint::Vertex, y}, true;
  out = edge_point(x, y, t);
  return true;
}

bool StepPlane::on_border(std::int32_t face, int k) const {
  const std::int32_t h0 = 3 * face + k;  // out of the corner
  std::int32_t h = h0;
  for (int guard = 0; guard < 4096; ++guard) {
    const std::int32_t prev = 3 * (h / 3) + (h % 3 + 2) % 3;  // into the corner
    const std::int32_t o = adjacency_.twin(prev);
    if (o < 0 || adjacency_.twin(h) < 0) return true;
    if (o == h0) return false;
    h = o;
  }
  return true;
}

double StepPlane::mean_edge(std::int32_t face) const {
  const Face& f = mesh_.faces[static_cast<std::size_t>(face)];
  double sum = 0;
  for (int k = 0; k < 3; ++k)
    sum += (mesh_.current.col(f[(k + 1) % 3]) - mesh_.current.col(f[k])).norm();
  return sum / 3;
}

bool StepPlane::exit_ahead(const Crossing& c, const Eigen::Vector3d& hit, PathPoint& out,
                           double slack, bool through_vertex) const {
  const Face& f = mesh_.faces[static_cast<std::size_t>(c.face)];
  const Eigen::Vector3d from = pos(c.in, c.face);
  for (int corner = 0; corner < 3; ++corner) {
    const std::int32_t x = f[(corner + 1) % 3], y = f[(corner + 2) % 3];
    if (on_edge(c.in, x, y) || (c.in.kind == PathPoint::Vertex && (c.in.v == x || c.in.v == y)))
      continue;
    PathPoint e;
    if (!exit_opposite(c.face, corner, e)) continue;
    if (e.kind != PathPoint::Edge && !(through_vertex && e.kind == PathPoint::Vertex)) continue;
    if ((pos(e, c.face) - hit).dot((hit - from).normalized()) <= -slack) continue;
    out = e;
    return true;
  }
  return false;
}

PathPoint StepPlane::edge_point(std::int32_t x, std::int32_t y, double t) const {
  const auto [lo, hi] = safe_range(mesh_, adjacency_, x, y, tear_.options_.min_angle);
  t = std::clamp(t, std::max(lo, snap_), std::max(std::min(hi, 1 - snap_), std::max(lo, snap_)));
  return {PathPoint::Edge, -1, x, y, t};
}

}  // namespace conform::mesh::tearing
