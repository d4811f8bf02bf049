#include "conform/mesh/tear.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numbers>
#include <stdexcept>

#include "change_flips.hpp"
#include "conform/cga/plane.hpp"
#include "conform/mesh/analysis.hpp"
#include "quad_split.hpp"

namespace conform::mesh {

namespace {

// A point of the tear's path: a vertex, a point on an edge, or a point inside a face.
struct PathPoint {
  enum Kind { Vertex, Edge, Inside } kind = Vertex;
  std::int32_t v = -1;          // Vertex
  std::int32_t a = -1, b = -1;  // Edge: (1 − t) a + t b
  double t = 0;
  std::array<double, 3> bary{0, 0, 0};  // Inside: barycentric in the crossing's face
};

struct Crossing {
  std::int32_t face;
  PathPoint in, out;
};

// Segment p→q against triangle (a, b, c); on a hit, the barycentric coordinates of the hit.
bool segment_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& a,
                      const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                      std::array<double, 3>& bary) {
  double t = 0;
  return conform::mesh::segment_triangle(p, q, a, b, c, t, bary);
}

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

// A point inside the polygon `poly` (a face with at most one edge point) for the fan of
// triangles (poly[i], poly[i + 1], tip): the barycentric `bary` in the face (a, b, c) moved
// toward the face's incenter, by the first of a few steps that gives every fan triangle its
// smallest angle's sin² ≥ `target` (default: the face's sliver bound), else the step with the
// best fan; `achieved` gets that fan's quality.
std::array<double, 3> place_tip(const std::array<double, 3>& bary, const Eigen::Vector3d& a,
                                const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                                const std::vector<Eigen::Vector3d>& poly, double floor,
                                double* achieved = nullptr, double target = -1) {
  const double la = (c - b).norm(), lb = (a - c).norm(), lc = (b - a).norm(), p = la + lb + lc;
  if (!(p > 0)) return bary;
  const std::array<double, 3> in{la / p, lb / p, lc / p};
  const double bound = target >= 0 ? target : sliver_bound_sin2(a, b, c, floor);
  std::array<double, 3> best = bary;
  double best_q = -1;
  for (const double lambda : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    std::array<double, 3> w;
    for (int k = 0; k < 3; ++k) w[k] = (1 - lambda) * bary[k] + lambda * in[k];
    const Eigen::Vector3d tip = w[0] * a + w[1] * b + w[2] * c;
    double q = 1;
    for (std::size_t i = 0; i < poly.size(); ++i)
      q = std::min(q, smallest_angle_sin2(poly[i], poly[(i + 1) % poly.size()], tip));
    if (q > best_q) best_q = q, best = w;
    if (q >= bound) break;
  }
  if (achieved) *achieved = best_q;
  return best;
}

// Step 6's direction at each interior path point: Π's normal of the step that made it (toward
// the left side), averaged along the path with Gaussian weights exp(−Δs² / 2σ²) of the arc
// length between points, without its component along the path's tangent (averaged alike).
// Π leans along the path where the tip was off the blade's track, and a direction that turns
// faster than the opening is wide folds one lip over itself where the path bends: an offset
// curve loops once its offset exceeds the radius of curvature. With σ at least the opening's
// width, each lip is an offset of the path smoothed over σ.
std::vector<Eigen::Vector3d> opening_directions(const std::vector<Eigen::Vector3d>& points,
                                                const std::vector<Eigen::Vector3d>& normals,
                                                double sigma) {
  const std::size_t n = points.size();
  std::vector<double> s(n, 0.0);
  for (std::size_t i = 1; i < n; ++i) s[i] = s[i - 1] + (points[i] - points[i - 1]).norm();
  std::vector<Eigen::Vector3d> out(normals);
  for (std::size_t i = 1; i + 1 < n; ++i) {
    Eigen::Vector3d d = Eigen::Vector3d::Zero(), t = Eigen::Vector3d::Zero();
    for (std::size_t j = 0; j < n; ++j) {
      const double u = (s[j] - s[i]) / sigma;
      if (std::abs(u) > 4) continue;
      const double w = std::exp(-0.5 * u * u);
      d += w * normals[j];
      if (j + 1 < n) t += w * (points[j + 1] - points[j]);  // the segment's direction × length
    }
    if (t.norm() > 0) t.normalize();
    if (t.allFinite()) d -= d.dot(t) * t;
    if (d.norm() > 1e-6 && d.allFinite()) out[i] = d.normalized();
  }
  return out;
}

}  // namespace

// One sample of Tear::advance after the start: steps 1–3 of tear.hpp over the tear's state.
// Each step is one member; what they hand on (the plane, the path, the new points) is below.
class TearAdvance {
 public:
  TearAdvance(Tear& tear, const ScalpelSample& s, TearStep& step)
      : tear_(tear),
        mesh_(tear.mesh_),
        adjacency_(tear.adjacency_),
        s_(s),
        step_(step),
        snap_(tear.options_.snap_fraction) {}

  void run() {
    if (!make_plane()) return;
    if (!walk()) return;
    if (!split_along_path()) return;
    open_left_side();
    record();
  }

 private:
  // Candidate first moves from a vertex: (face, exit, cosine).
  struct Move {
    std::int32_t face;
    PathPoint out;
    double cosine;
  };

  // Step 1: the plane Π through the tip and the blade, and the direction to walk in (toward
  // the blade's point nearest the tip).
  bool make_plane() {
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
    const double u =
        std::clamp((tip_ - s_.a).dot(ab) / std::max(ab.squaredNorm(), 1e-300), 0.0, 1.0);
    toward_ = s_.a + u * ab - tip_;
    sweep_ = {tip_, tear_.previous_.a, tear_.previous_.b, s_.a, s_.b};
    return true;
  }

  // The walk's latest point lies within sweep_tolerance (in edge lengths of its face) of the
  // region the blade swept; else the first distance beyond it is kept for the message.
  bool within_sweep(const Crossing& c) {
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

  double delta(std::int32_t v) const {
    const double d = plane_.signed_distance(mesh_.current.col(v));
    return std::abs(d) <= zero_ ? 0.0 : d;
  }
  Eigen::Vector3d pos(const PathPoint& p, std::int32_t face) const {
    if (p.kind == PathPoint::Vertex) return mesh_.current.col(p.v);
    if (p.kind == PathPoint::Edge)
      return (1 - p.t) * mesh_.current.col(p.a) + p.t * mesh_.current.col(p.b);
    const Face& f = mesh_.faces[static_cast<std::size_t>(face)];
    return p.bary[0] * mesh_.current.col(f[0]) + p.bary[1] * mesh_.current.col(f[1]) +
           p.bary[2] * mesh_.current.col(f[2]);
  }
  // Where the blade crosses `face`, as barycentrics each at least `floor` (then normalized);
  // false when it does not cross it.
  bool blade_barycentrics(const Face& f, double floor, std::array<double, 3>& bary) const {
    if (!segment_triangle(s_.a, s_.b, mesh_.current.col(f[0]), mesh_.current.col(f[1]),
                          mesh_.current.col(f[2]), bary))
      return false;
    for (auto& x : bary) x = std::max(x, floor);
    const double sum = bary[0] + bary[1] + bary[2];
    for (auto& x : bary) x /= sum;
    return true;
  }
  // The blade crosses `face`: `out` is the hit, kept snap_fraction inside the face.
  bool blade_hit(std::int32_t face, PathPoint& out) const {
    const Face& f = mesh_.faces[static_cast<std::size_t>(face)];
    std::array<double, 3> bary{};
    if (!blade_barycentrics(f, snap_, bary)) return false;
    out.kind = PathPoint::Inside;
    out.bary = bary;
    return true;
  }
  // A crossing of edge (x, y) at t from x, off Π if need be, into the range where it makes no
  // sliver on either side.
  PathPoint edge_point(std::int32_t x, std::int32_t y, double t) const {
    const auto [lo, hi] = safe_range(mesh_, adjacency_, x, y, tear_.options_.min_angle);
    t = std::clamp(t, std::max(lo, snap_), std::max(std::min(hi, 1 - snap_), std::max(lo, snap_)));
    return {PathPoint::Edge, -1, x, y, t};
  }
  // Where Π leaves face `face` through the edge opposite its corner `corner` (x = next,
  // y = after): a vertex, or a point on the edge; false when Π does not cross that edge.
  bool exit_opposite(std::int32_t face, int corner, PathPoint& out) const {
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
  // The moves out of vertex v across the faces around it (found from any neighbour), best
  // aligned with `dir` first; `fan_faces` gets those faces.
  std::vector<Move> moves_from(std::int32_t v, std::int32_t any_neighbor,
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
  std::int32_t corner_of(std::int32_t face, std::int32_t v) const {
    const Face& f = mesh_.faces[static_cast<std::size_t>(face)];
    return f[0] == v ? 0 : (f[1] == v ? 1 : 2);
  }

  // Step 2: walk from the tip along Π ∩ M; the first candidate direction that reaches the
  // blade gives the path.
  bool walk() {
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

  // The blade meets a face around the tip: the path is that one face, unless the blade is
  // where it was (true: nothing to tear yet).
  bool blade_next_to_tip(const std::vector<std::int32_t>& fan_faces) {
    for (auto face : fan_faces) {
      PathPoint hit;
      if (!blade_hit(face, hit)) continue;
      const Face& f = mesh_.faces[static_cast<std::size_t>(face)];
      const double size = (mesh_.current.col(f[1]) - mesh_.current.col(f[0])).norm();
      std::array<double, 3> raw{};
      segment_triangle(s_.a, s_.b, mesh_.current.col(f[0]), mesh_.current.col(f[1]),
                       mesh_.current.col(f[2]), raw);
      const Eigen::Vector3d at = raw[0] * mesh_.current.col(f[0]) +
                                 raw[1] * mesh_.current.col(f[1]) +
                                 raw[2] * mesh_.current.col(f[2]);
      // Where the blade was, not the placed tip.
      if ((at - tear_.tip_target_).norm() <= snap_ * size) return true;
      path_.push_back({face, {PathPoint::Vertex, tear_.tip_}, hit});
      return false;
    }
    return false;
  }

  // A tip put ahead of the blade's hit (on the edge crossing past it, TearOptions::smooth_lips)
  // and a blade still behind it: a walk toward the blade would turn the path back on itself.
  bool blade_behind_a_leading_tip() const {
    const auto& path = tear_.path_;
    if (!tear_.options_.smooth_lips || path.size() < 2) return false;
    const Eigen::Vector3d along = tip_ - mesh_.current.col(path[path.size() - 2].right);
    return (tear_.tip_target_ - tip_).dot(along) < 0 && toward_.dot(along) < 0;
  }

  // The walk that leaves the tip by move m; on reaching the blade it becomes the path.
  void walk_from(const Move& m) {
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

  // With smooth_lips, a walk that reaches a vertex on a border (the tear's own lips, where a
  // stroke turns about) stops there like one that meets a boundary: a path through it would
  // pinch the border (two fans of faces on one vertex).
  bool at_border_vertex(const Crossing& c) const {
    return tear_.options_.smooth_lips && c.out.kind == PathPoint::Vertex &&
           on_border(c.face, corner_of(c.face, c.out.v));
  }

  enum class WalkStep { Moved, Reached, Failed };

  // The walk is on an edge: into the face across it, which the blade crosses (reached) or
  // which Π leaves through an edge at its third vertex z (not back through the edge).
  WalkStep cross_edge(std::vector<Crossing>& trial, std::vector<std::int32_t>& visited) const {
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

  // The walk is at a vertex: the blade may be in a face around it, else it continues
  // straight on through the best aligned face not yet visited.
  WalkStep pass_vertex(std::vector<Crossing>& trial, std::vector<std::int32_t>& visited) const {
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

  // The id of path point p of face `face` in the change: a vertex, the edge point's new
  // vertex (one per edge), or the new tip.
  std::int32_t id_of(const PathPoint& p, std::int32_t face) {
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
  Eigen::Vector3d position_of(std::int32_t id) const {
    if (id < nv0_) return mesh_.current.col(id);
    const NewVertex& nv = split_.new_vertices[static_cast<std::size_t>(id - nv0_)];
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k)
      if (nv.parents[k] >= 0) x += nv.coefficients[k] * mesh_.current.col(nv.parents[k]);
    return x;
  }
  static bool on_edge(const PathPoint& p, std::int32_t u, std::int32_t w) {
    return p.kind == PathPoint::Edge && ((p.a == u && p.b == w) || (p.b == u && p.a == w));
  }

  // Step 3, first change: split the crossed faces along S_i, Q_1 … Q_m, S_i+1. False (and
  // the mesh unchanged) when the new tip would be in a face too thin for it.
  bool split_along_path() {
    if (path_through_border_vertex()) {
      tear_.message_ = "the path crosses a vertex on a border; the tear stops before it";
      return false;
    }
    split_.base_vertex_count = nv0_ = mesh_.vertex_count();
    split_.base_face_count = mesh_.face_count();
    const bool smooth = tear_.options_.smooth_lips;
    const PathPoint blade = path_.back().out;
    if (!(smooth && split_on_track())) {
      off_track_ = smooth;
      restart_split();
      points_.push_back(tear_.tip_);
      for (std::size_t i = 0; i < path_.size(); ++i) {
        Crossing& c = path_[i];
        if (c.out.kind == PathPoint::Inside && !place_new_tip(c)) {
          // No room inside the face for a tip: on the edge crossing behind the blade, however
          // far, or else on the one ahead, where that makes no sliver.
          const std::string message = tear_.message_;
          path_.back().out = blade;
          off_track_ = false;
          if (smooth && split_with_tip_on_edge(std::numeric_limits<double>::infinity(), true))
            break;
          tear_.message_ = message;
          return false;
        }
        split_face(c);
      }
    }
    if (smooth) flip_beside_path();
    std::sort(split_.removed_faces.begin(), split_.removed_faces.end());
    split_.removed_faces.erase(
        std::unique(split_.removed_faces.begin(), split_.removed_faces.end()),
        split_.removed_faces.end());
    tear_.commit(std::move(split_), step_);
    return true;
  }

  // The lips (TearOptions::smooth_lips): the first of these splits that keeps the new tip on the
  // blade's track and every face it makes at or above min_angle. Else the tip is moved off the
  // track toward its face's middle (place_new_tip) and the next step's Π passes through the hit.
  bool split_on_track() {
    return split_with_recovered_edges() || split_with_recovered_edges(true) ||
           split_with_tip_on_edge(kLipBehind) || split_with_tip_on_corner() ||
           split_with_nearer_crossing() || split_with_recovered_shifted();
  }
  // The recovered tip moved toward its face's incenter by the first of a few steps that keeps
  // the floor: off the track by less than place_tip's tip (whose step is coarser and whose faces
  // are not flipped); the next step's Π goes through the hit.
  bool split_with_recovered_shifted() {
    for (const double lambda : {0.1, 0.2, 0.35, 0.5})
      if (split_with_recovered_edges(false, lambda)) return true;
    return false;
  }

  void restart_split() {
    split_.new_vertices.clear();
    split_.removed_faces.clear();
    split_.added_faces.clear();
    edge_ids_ = EdgeMap();
    points_.clear();
    tip_id_ = -1;
    target_ = tear_.tip_target_;
  }

  double mean_edge(std::int32_t face) const {
    const Face& f = mesh_.faces[static_cast<std::size_t>(face)];
    double sum = 0;
    for (int k = 0; k < 3; ++k)
      sum += (mesh_.current.col(f[(k + 1) % 3]) - mesh_.current.col(f[k])).norm();
    return sum / 3;
  }

  // The lips' spacing (TearOptions::smooth_lips): a blade hit just past the last edge crossing
  // (within `behind` of the face's mean edge, kLipBehind) leaves the new tip on that crossing,
  // and the blade's face is split from its vertex opposite that edge. A tip inside the face
  // would make a pair of path points that close, and a fan of thin triangles on the face's far
  // vertex; the tip lags the blade by at most that much. With `ahead`, a hit too far from the
  // crossing (or one in a face beside the tip) puts the tip where Π leaves the blade's face
  // instead, and splits the face beyond. False (nothing kept) when neither applies or the
  // faces it makes would be thinner than min_angle.
  static constexpr double kLipBehind = 0.4;
  bool split_with_tip_on_edge(double behind, bool ahead = false) {
    const Crossing& last = path_.back();
    if (last.out.kind != PathPoint::Inside) return false;
    const Eigen::Vector3d hit = pos(last.out, last.face);
    std::vector<Crossing> path = path_;
    PathPoint tip;
    std::int32_t beyond = -1;  // the face split from the tip: not on the rest of the walk
    const bool near = path.size() >= 2 && last.in.kind != PathPoint::Inside &&
                      (hit - pos(last.in, last.face)).norm() < behind * mean_edge(last.face);
    // Past a vertex the walk reached, the tip stays on it and no face is split beyond: an inside
    // tip there would be pushed off the vertex toward the face's middle (its fan), behind the
    // vertex on the path, a lip that doubles back. Past an edge crossing, the blade's face is
    // split from its vertex opposite that edge, which needs a roomy face.
    const bool at_vertex = near && last.in.kind == PathPoint::Vertex;
    if (!at_vertex && !roomy(last.face)) return false;
    if (near) {
      tip = last.in;
      if (!at_vertex) beyond = last.face;
      path.pop_back();  // the path ends at the tip
    } else if (ahead && exit_ahead(last, hit, tip)) {
      path.back().out = tip;
      const std::int32_t e = adjacency_.find(tip.a, tip.b), g = adjacency_.find(tip.b, tip.a);
      const std::int32_t o = e >= 0 && e / 3 == last.face ? g : e;
      if (o < 0) return false;  // a boundary edge
      beyond = o / 3;
    } else {
      return false;
    }
    restart_split();
    points_.push_back(tear_.tip_);
    std::size_t first_checked = 0;  // the faces beside the tip, which differ from an inside tip's
    for (std::size_t i = 0; i < path.size(); ++i) {
      if (i + 1 == path.size() && path.size() == path_.size())
        first_checked = split_.added_faces.size();
      split_face(path[i]);
    }
    if (path.size() < path_.size()) first_checked = split_.added_faces.size();
    if (beyond >= 0) {
      if (std::find(split_.removed_faces.begin(), split_.removed_faces.end(), beyond) !=
          split_.removed_faces.end())
        return false;
      split_from_opposite(beyond, tip);
    }
    const double floor2 = std::pow(std::sin(tear_.options_.min_angle), 2);
    for (std::size_t i = first_checked; i < split_.added_faces.size(); ++i) {
      const Face& f = split_.added_faces[i];
      if (smallest_angle_sin2(position_of(f[0]), position_of(f[1]), position_of(f[2])) < floor2)
        return false;
    }
    path_ = std::move(path);
    target_ = hit;
    return true;
  }

  // The lips evenly spaced on the blade's track (TearOptions::smooth_lips): the new tip exactly
  // at the blade's hit, joined to the old tip (through the vertices the walk went through) by
  // edges that flips make (change_flips.hpp) instead of a chain of edge crossings, which would
  // be moved off the track where they come near a vertex, to keep the sliver floor. Then flips
  // for the smallest angle, the path's edges kept. False (nothing kept) where an edge cannot be
  // made or a face would be thinner than min_angle.
  bool split_with_recovered_edges(bool on_edge = false, double lambda = 0) {
    Crossing& last = path_.back();
    if (last.out.kind != PathPoint::Inside) return false;
    const std::int32_t face = last.face;
    const Face f = mesh_.faces[static_cast<std::size_t>(face)];
    // A path that comes back beside the tear's own border (a stroke that turns about) is left to
    // the crossing splits: a tip joined to that border would pinch it.
    for (int k = 0; k < 3; ++k)
      if (f[k] != tear_.tip_ && on_border(face, k)) return false;
    std::array<double, 3> raw{};
    if (!blade_barycentrics(f, kExactMargin, raw)) return false;
    const Eigen::Vector3d pa = mesh_.current.col(f[0]), pb = mesh_.current.col(f[1]),
                          pc = mesh_.current.col(f[2]);
    const Eigen::Vector3d hit = raw[0] * pa + raw[1] * pb + raw[2] * pc;
    if (lambda > 0) {  // toward the incenter
      const double la = (pc - pb).norm(), lb = (pa - pc).norm(), lc = (pb - pa).norm();
      const double p = la + lb + lc;
      const std::array<double, 3> in{la / p, lb / p, lc / p};
      for (int k = 0; k < 3; ++k) raw[k] = (1 - lambda) * raw[k] + lambda * in[k];
    }
    restart_split();
    std::vector<std::int32_t> slots;
    points_.push_back(tear_.tip_);
    for (const Crossing& c : path_) {
      slots.push_back(c.face);
      if (c.out.kind == PathPoint::Vertex) points_.push_back(c.out.v);
    }
    const std::int32_t tip = nv0_;
    if (on_edge) {
      if (!insert_tip_on_edge(face, raw)) return false;
    } else {
      split_.new_vertices.push_back(NewVertex::in_face(f[0], f[1], f[2], raw[0], raw[1], raw[2]));
      split_.removed_faces.push_back(face);
      for (int k = 0; k < 3; ++k) split_.added_faces.push_back({f[k], f[(k + 1) % 3], tip});
    }
    points_.push_back(tip);
    const Eigen::Vector3d blade = s_.b - s_.a;
    for (std::size_t i = 0; i + 1 < points_.size(); ++i) {
      const Eigen::Vector3d n =
          (position_of(points_[i + 1]) - position_of(points_[i])).cross(blade).normalized();
      if (!n.allFinite() ||
          !flip_to_edge(mesh_, adjacency_, split_, points_[i], points_[i + 1], n, slots))
        return false;
    }
    flip_beside_path();
    const double floor2 = std::pow(std::sin(tear_.options_.min_angle), 2);
    for (const Face& g : split_.added_faces)
      if (smallest_angle_sin2(position_of(g[0]), position_of(g[1]), position_of(g[2])) < floor2)
        return false;
    tip_id_ = tip;
    target_ = hit;
    off_track_ = lambda > 0;
    return true;
  }

  // The path goes through a vertex on a border (a boundary, a hole's rim, the tear's own lips):
  // whichever split made it, that vertex would stay joined across the opened path, a pinch (two
  // fans at one vertex). The walks stop at such a vertex; a path may still reach one.
  bool path_through_border_vertex() const {
    for (const Crossing& c : path_)
      if (c.out.kind == PathPoint::Vertex && on_border(c.face, corner_of(c.face, c.out.v)))
        return true;
    return false;
  }

  // Corner k of `face` is on a border of the mesh (the tear's slit or a boundary): a face
  // around it has an edge without a twin.
  bool on_border(std::int32_t face, int k) const {
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

  // A blade hit within kEdgeTip (barycentric) of an edge of its face, where a tip inside the
  // face would make a sliver that no flip removes (the edge on a fold of the surface): the tip on
  // that edge, at the hit's projection, both faces of the edge split from their third vertex.
  static constexpr double kEdgeTip = 0.05;
  bool insert_tip_on_edge(std::int32_t face, const std::array<double, 3>& bary) {
    const Face& f = mesh_.faces[static_cast<std::size_t>(face)];
    const int k = static_cast<int>(std::min_element(bary.begin(), bary.end()) - bary.begin());
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    if (!(bary[k] < kEdgeTip)) return false;
    const double t = bary[j] / (bary[i] + bary[j]);
    const std::int32_t x = f[i], y = f[j], z = f[k], tip = nv0_;
    if (t < snap_ || t > 1 - snap_) return false;  // at a vertex: the corner snap's
    split_.new_vertices.push_back(NewVertex::on_edge(x, y, t));
    split_.removed_faces.push_back(face);
    split_.added_faces.push_back({z, x, tip});
    split_.added_faces.push_back({z, tip, y});
    const std::int32_t h = adjacency_.find(y, x);
    if (h < 0) return true;  // a border edge
    const std::int32_t w = mesh_.faces[static_cast<std::size_t>(h / 3)][(h % 3 + 2) % 3];
    split_.removed_faces.push_back(h / 3);
    split_.added_faces.push_back({w, y, tip});
    split_.added_faces.push_back({w, tip, x});
    return true;
  }

  // The recovered tip's least barycentric coordinate in its face.
  static constexpr double kExactMargin = 0.01;

  // A blade hit within kLipSnapReach of its face's mean edge from a corner of the face that
  // lies within kLipSnap of Π (on the blade's track) puts the tip on that corner, where a tip at
  // the hit would make a sliver with it: the face is split along the chord from the path's last
  // crossing to it.
  static constexpr double kLipSnap = 0.05, kLipSnapReach = 0.3;
  bool split_with_tip_on_corner() {
    const Crossing& last = path_.back();
    if (last.out.kind != PathPoint::Inside) return false;
    const Face& f = mesh_.faces[static_cast<std::size_t>(last.face)];
    const Eigen::Vector3d hit = pos(last.out, last.face);
    int best = -1;
    const double edge = mean_edge(last.face);
    double nearest = kLipSnapReach * edge;
    for (int k = 0; k < 3; ++k) {
      const double d = (mesh_.current.col(f[k]) - hit).norm();
      // Not the corner the path came in by, nor an end of the edge it came in through (the
      // chord would run along that edge).
      const bool behind =
          (last.in.kind == PathPoint::Vertex && last.in.v == f[k]) ||
          (last.in.kind == PathPoint::Edge && (last.in.a == f[k] || last.in.b == f[k]));
      if (d < nearest && std::abs(delta(f[k])) <= kLipSnap * edge && !behind) nearest = d, best = k;
    }
    if (best < 0) return false;
    std::vector<Crossing> path = path_;
    path.back().out = {PathPoint::Vertex, f[best]};
    restart_split();
    points_.push_back(tear_.tip_);
    for (const Crossing& c : path) split_face(c);
    const double floor2 = std::pow(std::sin(tear_.options_.min_angle), 2);
    for (const Face& g : split_.added_faces)
      if (smallest_angle_sin2(position_of(g[0]), position_of(g[1]), position_of(g[2])) < floor2)
        return false;
    path_ = std::move(path);
    target_ = hit;
    return true;
  }

  // Edge flips among the faces the split adds and those beside them, the path's edges kept.
  void flip_beside_path() {
    std::vector<std::array<std::int32_t, 2>> path_edges;
    for (std::size_t i = 0; i + 1 < points_.size(); ++i)
      path_edges.push_back({points_[i], points_[i + 1]});
    flip_for_angles(mesh_, adjacency_, split_, path_edges);
  }

  // Where the tip cannot be at the blade's hit (its faces would be slivers however flipped),
  // it goes on the nearer of the edge crossings behind and ahead of the hit, within kLipReach of
  // that edge: an edge crossing lies on Π, so on the track.
  static constexpr double kLipReach = 0.6;
  bool split_with_nearer_crossing() {
    const Crossing& last = path_.back();
    const Eigen::Vector3d hit = pos(last.out, last.face);
    const double inf = std::numeric_limits<double>::infinity();
    const double reach = kLipReach * mean_edge(last.face);
    PathPoint exit;
    const double back = last.in.kind != PathPoint::Inside && path_.size() >= 2
                            ? (hit - pos(last.in, last.face)).norm()
                            : inf;
    const double ahead = exit_ahead(last, hit, exit) ? (pos(exit, last.face) - hit).norm() : inf;
    if (std::min(back, ahead) > reach) return false;
    if (ahead < back)
      return split_with_tip_on_edge(0, true) || (back <= reach && split_with_tip_on_edge(inf));
    return split_with_tip_on_edge(inf) || (ahead <= reach && split_with_tip_on_edge(0, true));
  }

  // The polygon around a new tip in crossing c's face: its corners, with the path's edge point.
  std::vector<Eigen::Vector3d> tip_ring(const Crossing& c) const {
    const Face& f = mesh_.faces[static_cast<std::size_t>(c.face)];
    std::vector<Eigen::Vector3d> ring;
    for (int k = 0; k < 3; ++k) {
      ring.push_back(mesh_.current.col(f[k]));
      if (c.in.kind == PathPoint::Edge && on_edge(c.in, f[k], f[(k + 1) % 3]))
        ring.push_back(pos(c.in, c.face));
    }
    return ring;
  }

  // A face whose corners, split once more, keep the sliver floor (smallest angle ≥ 2 min_angle):
  // in a thinner face (a real model's) the halves would be split again below the bound of the
  // face they lie in (mesh_real_models_test found one without this check).
  bool roomy(std::int32_t face) const {
    const Face& f = mesh_.faces[static_cast<std::size_t>(face)];
    return smallest_angle(mesh_.current.col(f[0]), mesh_.current.col(f[1]),
                          mesh_.current.col(f[2])) >= 2 * tear_.options_.min_angle;
  }

  // Where Π leaves the blade's face (crossing c) ahead of the hit, on an edge other than the
  // one it came in by: false if there is none (or Π leaves it through a vertex).
  bool exit_ahead(const Crossing& c, const Eigen::Vector3d& hit, PathPoint& out) const {
    const Face& f = mesh_.faces[static_cast<std::size_t>(c.face)];
    const Eigen::Vector3d from = pos(c.in, c.face);
    for (int corner = 0; corner < 3; ++corner) {
      const std::int32_t x = f[(corner + 1) % 3], y = f[(corner + 2) % 3];
      if (on_edge(c.in, x, y) || (c.in.kind == PathPoint::Vertex && (c.in.v == x || c.in.v == y)))
        continue;
      PathPoint e;
      if (!exit_opposite(c.face, corner, e) || e.kind != PathPoint::Edge) continue;
      if ((pos(e, c.face) - hit).dot(hit - from) <= 0) continue;
      out = e;
      return true;
    }
    return false;
  }

  // Face `face`, which holds edge point p's edge, split in two from its vertex opposite it.
  void split_from_opposite(std::int32_t face, const PathPoint& p) {
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

  // The new tip in crossing c's face, moved so that its fan makes no sliver.
  bool place_new_tip(Crossing& c) {
    const Face& f = mesh_.faces[static_cast<std::size_t>(c.face)];
    const Eigen::Vector3d fa = mesh_.current.col(f[0]), fb = mesh_.current.col(f[1]),
                          fc = mesh_.current.col(f[2]);
    const std::vector<Eigen::Vector3d> ring = tip_ring(c);
    target_ = pos(c.out, c.face);
    // Aim at the floor itself. A face the tear made (it holds a vertex the tear added), e.g.
    // in the old tip's fan after a short step, whose fan cannot keep the floor is not split:
    // the step waits for the blade to move on (splitting it anyway would halve its thin
    // corners step after step). An input face needs only its own bound.
    const double min_angle = tear_.options_.min_angle;
    const double floor2 = std::pow(std::sin(min_angle), 2);
    double achieved = 0;
    c.out.bary = place_tip(c.out.bary, fa, fb, fc, ring, min_angle, &achieved, floor2);
    const std::int32_t first_new = tear_.first_new_vertex_;
    const bool made_by_tear = f[0] >= first_new || f[1] >= first_new || f[2] >= first_new;
    if (achieved < floor2 && made_by_tear) {
      tear_.message_ = "the blade is in a face too thin for a new tip: waiting for it to move on";
      return false;
    }
    return true;
  }

  // Crossing c's face as a polygon with the path's edge points inserted, split along the
  // path: a fan around the new tip, or the two sides of the chord (quads along the diagonal
  // with the larger smallest angle); a face crossed along an existing edge stays.
  void split_face(const Crossing& c) {
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
      for (std::size_t i = 0; i < m; ++i)
        a.added_faces.push_back({poly[i], poly[(i + 1) % m], out});
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

  // Step 3, second change: duplicate the interior points for the faces on the path's left,
  // found by turning counter-clockwise around each from the outgoing path edge to the
  // incoming one (or to the open slit, at the old tip).
  void open_left_side() {
    TopologyChange b;
    b.base_vertex_count = mesh_.vertex_count();
    b.base_face_count = mesh_.face_count();
    std::map<std::int32_t, Face> remapped;
    const auto& path = tear_.path_;
    const std::int32_t prev_tip = path.size() >= 2 ? path[path.size() - 2].right : -1;
    dups_.assign(points_.size(), -1);
    left_dir_.assign(points_.size(), n_);
    std::vector<std::int32_t> faces;
    for (std::size_t j = 0; j + 1 < points_.size(); ++j) {
      if (j == 0 && path.size() == 1) continue;  // the start of the tear stays one point
      const std::int32_t p = points_[j];
      const std::int32_t prev = j == 0 ? prev_tip : points_[j - 1];
      if (!left_faces(p, points_[j + 1], prev, faces))
        continue;  // no incoming edge around: leave this point joined
      const std::int32_t dup =
          b.base_vertex_count + static_cast<std::int32_t>(b.new_vertices.size());
      b.new_vertices.push_back(NewVertex::duplicate(p));
      dups_[j] = dup;
      Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
      for (auto fi : faces) {
        auto it = remapped.try_emplace(fi, mesh_.faces[static_cast<std::size_t>(fi)]).first;
        for (auto& v : it->second)
          if (v == p) v = dup;
        const Face& f = mesh_.faces[static_cast<std::size_t>(fi)];
        centroid +=
            (mesh_.current.col(f[0]) + mesh_.current.col(f[1]) + mesh_.current.col(f[2])) / 3;
      }
      centroid /= static_cast<double>(faces.size());
      left_dir_[j] = (centroid - mesh_.current.col(p)).dot(n_) >= 0 ? n_ : Eigen::Vector3d(-n_);
    }
    for (const auto& [fi, f] : remapped) {
      b.removed_faces.push_back(fi);
      b.added_faces.push_back(f);
    }
    if (!b.empty()) tear_.commit(std::move(b), step_);
  }

  // The faces counter-clockwise around path point p from the outgoing edge (p, next) to the
  // incoming one from `prev` (or a boundary); false when there is no incoming edge around.
  bool left_faces(std::int32_t p, std::int32_t next, std::int32_t prev,
                  std::vector<std::int32_t>& faces) const {
    faces.clear();
    const std::int32_t h0 = adjacency_.find(p, next);
    if (h0 < 0) return false;
    std::int32_t h = h0;
    for (int guard = 0;; ++guard) {
      faces.push_back(h / 3);
      const std::int32_t pv = 3 * (h / 3) + (h % 3 + 2) % 3;
      const std::int32_t o = adjacency_.twin(pv);
      if (o < 0) return true;
      const Face& of = mesh_.faces[static_cast<std::size_t>(o / 3)];
      if (of[(o % 3 + 1) % 3] == prev) return true;  // reached the incoming path edge
      if (o == h0 || guard > 4096) return false;
      h = o;
    }
  }

  // The path recorded: the old tip becomes interior, then the Q_j, then the new tip.
  void record() {
    auto& path = tear_.path_;
    path.back().left = dups_[0];
    path.back().normal = left_dir_[0];
    for (std::size_t j = 1; j < points_.size(); ++j)
      path.push_back({points_[j], j + 1 < points_.size() ? dups_[j] : -1, left_dir_[j]});
    tear_.tip_neighbor_ = points_[points_.size() - 2];
    tear_.tip_ = points_.back();
    tear_.tip_target_ = target_;
    tear_.tip_off_track_ = off_track_;
    ++tear_.steps_;
    step_.extended = true;
    tear_.message_.clear();
  }

  Tear& tear_;
  SkinnedMesh& mesh_;
  Adjacency& adjacency_;
  const ScalpelSample& s_;
  TearStep& step_;
  const double snap_;
  // Step 1
  Eigen::Vector3d tip_, n_, toward_;
  cga::Plane<double> plane_;
  double zero_ = 0;                       // |distance to Π| taken as on it
  std::array<Eigen::Vector3d, 5> sweep_;  // the tip and both blades: their hull is the sweep
  double beyond_ = -1;                    // how far a walk left the sweep (−1: none did)
  // Step 2
  std::vector<Crossing> path_;
  // Step 3
  TopologyChange split_;
  std::int32_t nv0_ = 0;
  EdgeMap edge_ids_;  // edge → its new vertex
  std::int32_t tip_id_ = -1;
  std::vector<std::int32_t> points_;  // S_i, Q_1 … Q_m, S_i+1
  Eigen::Vector3d target_;            // the blade's hit the new tip stands for
  std::vector<std::int32_t> dups_;    // per point, its copy for the left, or −1
  std::vector<Eigen::Vector3d> left_dir_;
  bool off_track_ = false;  // the new tip was moved off the blade's hit (its fan)
};

Tear::Tear(SkinnedMesh& mesh, Adjacency& adjacency, const TearOptions& options)
    : mesh_(mesh),
      adjacency_(adjacency),
      options_(options),
      first_new_vertex_(mesh.vertex_count()) {
  if (!adjacency.matches(mesh))
    throw std::invalid_argument("tear: the adjacency does not describe this mesh");
  if (!(options.snap_fraction > 0 && options.snap_fraction < 0.25) ||
      !(options.min_angle >= 0 && options.min_angle < 0.5))
    throw std::invalid_argument(
        "tear: snap_fraction must be in (0, 0.25) and min_angle in [0, 0.5)");
  if (!(options.sweep_tolerance >= 0))
    throw std::invalid_argument("tear: sweep_tolerance must be ≥ 0 (infinity: unbounded)");
  // The walk and the splits measure positions: a NaN makes its crossings meaningless (the fuzzer
  // found a tear on such a mesh leaving a non-manifold vertex).
  if (!mesh.current.allFinite() || !mesh.rest.allFinite())
    throw std::invalid_argument("tear: the mesh has non-finite positions");
}

Tear::Tear(SkinnedMesh& mesh, Adjacency& adjacency, FaceIndex& index, const TearOptions& options)
    : Tear(mesh, adjacency, options) {
  if (!index.matches(mesh))
    throw std::invalid_argument("tear: the face index does not describe this mesh");
  index_ = &index;
}

void Tear::commit(TopologyChange&& change, TearStep& step) {
  change.edit = EditKind::tear;
  apply(mesh_, change, &adjacency_);
  if (index_) index_->update(mesh_, change);
  step.changes.push_back(std::move(change));
}

bool Tear::start(const ScalpelSample& s, TearStep& step) {
  SegmentHit first;
  if (index_) {
    if (!index_->matches(mesh_))
      throw std::invalid_argument("tear: the face index does not describe this mesh");
    index_->ensure_fitted(mesh_);
    first = index_->first_hit(mesh_, s.a, s.b);
  } else {  // no index kept by the caller: for one query a scan is cheaper than a build
    const auto hits = scan_segment_hits(mesh_, s.a, s.b);
    if (!hits.empty()) first = hits.front();
  }
  const std::int32_t hit = first.face;
  std::array<double, 3> bary = first.bary;
  if (hit < 0) {
    message_ = "the scalpel does not meet the surface";
    return false;
  }
  // Keep the start point off the face's edges (no slivers).
  const double m = options_.snap_fraction;
  for (auto& x : bary) x = std::max(x, m);
  const double sum = bary[0] + bary[1] + bary[2];
  for (auto& x : bary) x /= sum;
  const Face f = mesh_.faces[static_cast<std::size_t>(hit)];
  const Eigen::Vector3d a = mesh_.current.col(f[0]), b = mesh_.current.col(f[1]),
                        c = mesh_.current.col(f[2]);
  tip_target_ = bary[0] * a + bary[1] * b + bary[2] * c;
  const std::int32_t s0 = mesh_.vertex_count();
  auto fan_change = [&](const std::array<double, 3>& w) {
    TopologyChange ch;
    ch.base_vertex_count = mesh_.vertex_count();
    ch.base_face_count = mesh_.face_count();
    ch.new_vertices.push_back(NewVertex::in_face(f[0], f[1], f[2], w[0], w[1], w[2]));
    ch.removed_faces = {hit};
    ch.added_faces = {{f[0], f[1], s0}, {f[1], f[2], s0}, {f[2], f[0], s0}};
    return ch;
  };
  // smooth_lips: the start at the hit, the slivers of its fan flipped away (change_flips.hpp);
  // else (or where flips leave a face below the floor) moved toward the face's incenter.
  TopologyChange ch = fan_change(bary);
  bool exact = options_.smooth_lips;
  if (exact) {
    flip_for_angles(mesh_, adjacency_, ch, {});
    auto at = [&](std::int32_t v) {
      return v == s0 ? tip_target_ : Eigen::Vector3d(mesh_.current.col(v));
    };
    const double floor2 = std::pow(std::sin(options_.min_angle), 2);
    for (const Face& g : ch.added_faces)
      exact = exact && smallest_angle_sin2(at(g[0]), at(g[1]), at(g[2])) >= floor2;
  }
  if (!exact) ch = fan_change(place_tip(bary, a, b, c, {a, b, c}, options_.min_angle));
  commit(std::move(ch), step);
  tip_ = s0;
  tip_off_track_ = options_.smooth_lips && !exact;
  tip_neighbor_ = f[0];
  path_.push_back({s0, -1, Eigen::Vector3d::Zero()});
  message_.clear();
  return true;
}

TearStep Tear::advance(const ScalpelSample& s) {
  if (!std::isfinite(s.t) || !s.a.allFinite() || !s.b.allFinite())
    throw std::invalid_argument("tear: non-finite scalpel sample");
  TearStep step;
  if (tip_ < 0) {
    start(s, step);
    previous_ = s;
    return step;
  }
  // The index inserts only the faces that survive both phases of the step.
  struct Batch {
    FaceIndex* index;
    const SkinnedMesh& mesh;
    ~Batch() {
      if (index) index->end_batch(mesh);
    }
  } batch{index_, mesh_};
  if (index_) index_->begin_batch();
  TearAdvance(*this, s, step).run();
  previous_ = s;
  return step;
}

double Tear::length() const {
  double l = 0;
  for (std::size_t i = 1; i < path_.size(); ++i)
    l += (mesh_.current.col(path_[i].right) - mesh_.current.col(path_[i - 1].right)).norm();
  return l;
}

std::vector<std::int32_t> Tear::left_border() const {
  std::vector<std::int32_t> out;
  for (const auto& p : path_) out.push_back(p.left >= 0 ? p.left : p.right);
  return out;
}

std::vector<std::int32_t> Tear::right_border() const {
  std::vector<std::int32_t> out;
  for (const auto& p : path_) out.push_back(p.right);
  return out;
}

std::vector<std::pair<std::int32_t, Eigen::Vector3d>> Tear::open(double amount) {
  if (!std::isfinite(amount) || amount < 0)
    throw std::invalid_argument("tear: the opening must be finite and ≥ 0");
  std::vector<std::pair<std::int32_t, Eigen::Vector3d>> out;
  const double total = length();
  if (path_.size() < 3 || !(total > 0) || amount == 0) return out;
  std::vector<Eigen::Vector3d> direction;
  for (const auto& p : path_) direction.push_back(p.normal);
  if (options_.smooth_lips) {
    std::vector<Eigen::Vector3d> points;
    for (const auto& p : path_) points.push_back(mesh_.current.col(p.right));
    const double mean_segment = total / static_cast<double>(path_.size() - 1);
    direction = opening_directions(points, direction, std::max(amount, mean_segment));
  }
  std::vector<Eigen::Vector3d> delta(path_.size(), Eigen::Vector3d::Zero());
  double s = 0;
  for (std::size_t i = 1; i + 1 < path_.size(); ++i) {
    s += (mesh_.current.col(path_[i].right) - mesh_.current.col(path_[i - 1].right)).norm();
    if (path_[i].left < 0) continue;
    delta[i] = 0.5 * amount * std::sin(std::numbers::pi * s / total) * direction[i];
  }
  for (std::size_t i = 1; i + 1 < path_.size(); ++i) {
    if (path_[i].left < 0) continue;
    mesh_.current.col(path_[i].left) += delta[i];
    mesh_.current.col(path_[i].right) -= delta[i];
    out.emplace_back(path_[i].left, delta[i]);
    out.emplace_back(path_[i].right, -delta[i]);
  }
  if (index_ && !out.empty()) index_->mark_moved();
  return out;
}

}  // namespace conform::mesh
