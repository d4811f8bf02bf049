#include "tear_walk.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace conform::mesh::tearing {

namespace {

double segment_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                        const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double l2 = ab.squaredNorm();
  const double u = l2 > 0 ? std::clamp((p - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return (a + u * ab - p).norm();
}

// Distance from p to triangle (a, b, c): to its plane where p projects inside it, else to its
// nearest edge (also when the triangle is degenerate).
double triangle_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                         const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double n2 = n.squaredNorm();
  if (n2 > 0 && n.dot((b - a).cross(p - a)) >= 0 && n.dot((c - b).cross(p - b)) >= 0 &&
      n.dot((a - c).cross(p - c)) >= 0)
    return std::abs(n.dot(p - a)) / std::sqrt(n2);
  return std::min(
      {segment_distance(p, a, b), segment_distance(p, b, c), segment_distance(p, c, a)});
}

double signed_volume(const std::array<Eigen::Vector3d, 4>& t) {
  return (t[1] - t[0]).cross(t[2] - t[0]).dot(t[3] - t[0]);
}

// Distance from p to the convex hull of five points (0 inside). By Carathéodory the hull is the
// union of the tetrahedra on four of the points, and its boundary lies on triangles of three
// (which also covers a flat or collinear hull).
double hull_distance(const Eigen::Vector3d& p, const std::array<Eigen::Vector3d, 5>& q) {
  for (std::size_t skip = 0; skip < q.size(); ++skip) {
    std::array<Eigen::Vector3d, 4> t;
    for (std::size_t i = 0, k = 0; i < q.size(); ++i)
      if (i != skip) t[k++] = q[i];
    const double v = signed_volume(t);
    if (v == 0) continue;
    bool inside = true;
    for (std::size_t f = 0; f < t.size() && inside; ++f) {
      auto u = t;
      u[f] = p;  // p on the same side of the face opposite t[f] as t[f]
      inside = signed_volume(u) * v >= 0;
    }
    if (inside) return 0;
  }
  double d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < q.size(); ++i)
    for (std::size_t j = i + 1; j < q.size(); ++j)
      for (std::size_t k = j + 1; k < q.size(); ++k)
        d = std::min(d, triangle_distance(p, q[i], q[j], q[k]));
  return d;
}

// The faces around vertex v, starting from half-edge h out of v (CCW, then CW from h if a
// boundary stops the first sweep).
std::vector<std::int32_t> fan(const Adjacency& adj, std::int32_t h) {
  std::vector<std::int32_t> out;
  std::int32_t g = h;
  for (int guard = 0; guard < 4096; ++guard) {
    out.push_back(g);
    const std::int32_t prev = 3 * (g / 3) + (g % 3 + 2) % 3;
    const std::int32_t o = adj.twin(prev);
    if (o < 0) break;
    if (o == h) return out;
    g = o;
  }
  // Open fan: the other way from h.
  g = h;
  for (int guard = 0; guard < 4096; ++guard) {
    const std::int32_t o = adj.twin(g);
    if (o < 0) break;
    g = 3 * (o / 3) + (o % 3 + 1) % 3;
    if (g == h) break;
    out.push_back(g);
  }
  return out;
}

}  // namespace

bool TearWalk::within_sweep(const Crossing& c) {
  const double tolerance = tear_.options_.sweep_tolerance;
  if (std::isinf(tolerance)) return true;
  const Face& f = mesh_.faces[static_cast<std::size_t>(c.face)];
  double edge = 0;
  for (int k = 0; k < 3; ++k)
    edge = std::max(edge, (mesh_.current.col(f[(k + 1) % 3]) - mesh_.current.col(f[k])).norm());
  const double d = hull_distance(pos(c.out, c.face), sweep_);
  if (d <= tolerance * edge) return true;
  if (beyond_ < 0) beyond_ = d;
  return false;
}

std::vector<TearWalk::Move> TearWalk::moves_from(std::int32_t v, std::int32_t any_neighbor,
                                                 const Eigen::Vector3d& dir,
                                                 std::vector<std::int32_t>& fan_faces) const {
  std::vector<Move> moves;
  std::int32_t h = adjacency_.find(v, any_neighbor);
  if (h < 0) {
    const std::int32_t g = adjacency_.find(any_neighbor, v);
    if (g < 0) return moves;
    h = 3 * (g / 3) + (g % 3 + 1) % 3;
  }
  fan_faces.clear();
  for (auto he : fan(adjacency_, h)) {
    const std::int32_t face = he / 3;
    fan_faces.push_back(face);
    PathPoint out;
    if (!exit_opposite(face, he % 3, out)) continue;
    const Eigen::Vector3d e = pos(out, face) - mesh_.current.col(v);
    const double len = e.norm() * dir.norm();
    moves.push_back({face, out, len > 0 ? e.dot(dir) / len : -1});
  }
  std::sort(moves.begin(), moves.end(),
            [](const Move& a, const Move& b) { return a.cosine > b.cosine; });
  return moves;
}

bool TearWalk::walk() {
  // Any neighbour of the tip: the vertices of a face holding it, found through the last
  // path point or the start face.
  const auto& path = tear_.path_;
  const std::int32_t tip = tear_.tip_;
  std::int32_t neighbor = path.size() >= 2 ? path[path.size() - 2].right : -1;
  if (neighbor < 0 || (adjacency_.find(tip, neighbor) < 0 && adjacency_.find(neighbor, tip) < 0))
    neighbor = tear_.tip_neighbor_;
  std::vector<std::int32_t> fan_faces;
  const std::vector<Move> first = moves_from(tip, neighbor, toward_, fan_faces);
  if (blade_next_to_tip(fan_faces)) {
    tear_.message_ = "the blade has not moved away from the tip";
    return false;
  }
  if (blade_behind_a_leading_tip()) {
    tear_.message_ = "the blade has not caught up with the tip: waiting for it";
    return false;
  }
  for (const Move& m : first) {
    if (!path_.empty()) break;
    if (m.cosine <= 0) break;
    walk_from(m);
  }
  if (path_.empty() && beyond_ >= 0) {
    char text[128];
    std::snprintf(text, sizeof text,
                  "the walk left the region the blade swept (%.3g m beyond it): waiting for "
                  "the blade",
                  beyond_);
    tear_.message_ = text;
    return false;
  }
  if (path_.empty()) {
    tear_.message_ =
        "the walk from the tip did not reach the blade (outside the mesh, unmoved, or past a "
        "boundary)";
    return false;
  }
  return true;
}

bool TearWalk::blade_next_to_tip(const std::vector<std::int32_t>& fan_faces) {
  for (auto face : fan_faces) {
    PathPoint hit;
    if (!blade_hit(face, hit)) continue;
    const Face& f = mesh_.faces[static_cast<std::size_t>(face)];
    const double size = (mesh_.current.col(f[1]) - mesh_.current.col(f[0])).norm();
    std::array<double, 3> raw{};
    segment_triangle(s_.a, s_.b, mesh_.current.col(f[0]), mesh_.current.col(f[1]),
                     mesh_.current.col(f[2]), raw);
    const Eigen::Vector3d at = raw[0] * mesh_.current.col(f[0]) + raw[1] * mesh_.current.col(f[1]) +
                               raw[2] * mesh_.current.col(f[2]);
    // Where the blade was, not the placed tip.
    if ((at - tear_.tip_target_).norm() <= snap_ * size) return true;
    path_.push_back({face, {PathPoint::Vertex, tear_.tip_}, hit});
    return false;
  }
  return false;
}

void TearWalk::walk_from(const Move& m) {
  std::vector<Crossing> trial{{m.face, {PathPoint::Vertex, tear_.tip_}, m.out}};
  std::vector<std::int32_t> visited{m.face};
  if (!within_sweep(trial.back()) || at_border_vertex(trial.back())) return;
  for (int guard = 0; guard < tear_.options_.max_walk_faces; ++guard) {
    const WalkStep next = trial.back().out.kind == PathPoint::Edge ? cross_edge(trial, visited)
                                                                   : pass_vertex(trial, visited);
    if (next == WalkStep::Failed) return;
    if (next == WalkStep::Moved && !within_sweep(trial.back())) return;  // left the sweep
    if (next == WalkStep::Moved && at_border_vertex(trial.back())) return;
    if (next == WalkStep::Reached) {
      path_ = std::move(trial);
      return;
    }
  }
}

TearWalk::WalkStep TearWalk::cross_edge(std::vector<Crossing>& trial,
                                        std::vector<std::int32_t>& visited) const {
  const Crossing& last = trial.back();
  const PathPoint at = last.out;
  std::int32_t h = adjacency_.find(at.a, at.b);
  if (h < 0 || h / 3 != last.face) h = adjacency_.find(at.b, at.a);
  const std::int32_t o = h >= 0 ? adjacency_.twin(h) : -1;
  if (o < 0) return WalkStep::Failed;  // a boundary: this direction fails
  const std::int32_t g = o / 3;
  if (std::find(visited.begin(), visited.end(), g) != visited.end()) return WalkStep::Failed;
  visited.push_back(g);
  PathPoint out;
  if (blade_hit(g, out)) {
    trial.push_back({g, at, out});
    return WalkStep::Reached;
  }
  const int cz = (o % 3 + 2) % 3;
  const std::int32_t z = mesh_.faces[static_cast<std::size_t>(g)][cz];
  const double dz = delta(z);
  const std::int32_t w = delta(at.a) * dz < 0 ? at.a : at.b;  // the end across Π from z
  if (dz == 0) {
    out = {PathPoint::Vertex, z};
  } else {
    const double dw = delta(w);
    const double t = dz / (dz - dw);  // from z towards w
    out = t < snap_ ? PathPoint{PathPoint::Vertex, z} : edge_point(z, w, t);
  }
  trial.push_back({g, at, out});
  return WalkStep::Moved;
}

TearWalk::WalkStep TearWalk::pass_vertex(std::vector<Crossing>& trial,
                                         std::vector<std::int32_t>& visited) const {
  const Crossing& last = trial.back();
  const PathPoint at = last.out;
  const Eigen::Vector3d dir = Eigen::Vector3d(mesh_.current.col(at.v)) - pos(last.in, last.face);
  const Face& lf = mesh_.faces[static_cast<std::size_t>(last.face)];
  const std::int32_t nb = lf[(corner_of(last.face, at.v) + 1) % 3];
  std::vector<std::int32_t> around;
  const std::vector<Move> next = moves_from(at.v, nb, dir, around);
  for (auto face : around) {
    if (std::find(visited.begin(), visited.end(), face) != visited.end()) continue;
    PathPoint hit;
    if (blade_hit(face, hit)) {
      trial.push_back({face, at, hit});
      return WalkStep::Reached;
    }
  }
  for (const Move& mv : next) {
    if (mv.cosine <= 0) break;
    if (std::find(visited.begin(), visited.end(), mv.face) != visited.end()) continue;
    visited.push_back(mv.face);
    trial.push_back({mv.face, at, mv.out});
    return WalkStep::Moved;
  }
  return WalkStep::Failed;
}

}  // namespace conform::mesh::tearing
