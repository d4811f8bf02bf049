#include "tear_tip_placement.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace conform::mesh::tearing {

std::array<double, 3> place_tip(const std::array<double, 3>& bary, const Eigen::Vector3d& a,
                                const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                                const std::vector<Eigen::Vector3d>& poly, double floor,
                                double* achieved, double target) {
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

const std::array<TipPlacement::Strategy, 6> TipPlacement::kOnTrack{{
    {"at the blade's hit, joined by flips", &TipPlacement::tip_at_hit},
    {"on the edge the hit lies next to, joined by flips", &TipPlacement::tip_on_edge_of_hit},
    {"on the edge crossing just behind the hit", &TipPlacement::tip_on_crossing_behind},
    {"on a corner of the hit's face on the track", &TipPlacement::split_with_tip_on_corner},
    {"on the nearer edge crossing behind or ahead", &TipPlacement::split_with_nearer_crossing},
    {"at the hit moved toward the incenter, joined by flips",
     &TipPlacement::split_with_recovered_shifted},
}};

bool TipPlacement::split_on_track() {
  for (const Strategy& strategy : kOnTrack)
    if ((this->*strategy.split)()) return true;
  return false;
}

bool TipPlacement::split_with_recovered_edges(bool on_edge, double lambda) {
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

bool TipPlacement::split_with_tip_past_fan() {
  const double inf = std::numeric_limits<double>::infinity();
  return split_with_tip_on_edge(0, true, true) || split_with_tip_on_edge(inf, false, true);
}

bool TipPlacement::split_with_tip_on_edge(double behind, bool ahead, bool past_fan) {
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
  if (!at_vertex && !past_fan && !roomy(last.face)) return false;
  if (near) {
    tip = last.in;
    if (!at_vertex) beyond = last.face;
    path.pop_back();  // the path ends at the tip
  } else if (ahead &&
             exit_ahead(last, hit, tip, past_fan ? snap_ * mean_edge(last.face) : 0, past_fan)) {
    path.back().out = tip;
    if (tip.kind == PathPoint::Vertex) {  // past a fan: the tip on that vertex, nothing beyond
      if (on_border(last.face, corner_of(last.face, tip.v))) return false;
    } else {
      const std::int32_t e = adjacency_.find(tip.a, tip.b), g = adjacency_.find(tip.b, tip.a);
      const std::int32_t o = e >= 0 && e / 3 == last.face ? g : e;
      if (o < 0) return false;  // a boundary edge
      beyond = o / 3;
    }
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
  // Past a fan the faces made must be as roomy as the blade's face (up to twice the floor): a
  // later split of one keeps what a split of that face would have kept.
  const double min_angle = tear_.options_.min_angle;
  const Face& blade_face = mesh_.faces[static_cast<std::size_t>(path_.back().face)];
  const double kept =
      past_fan ? std::clamp(smallest_angle(position_of(blade_face[0]), position_of(blade_face[1]),
                                           position_of(blade_face[2])),
                            min_angle, 2 * min_angle)
               : min_angle;
  const double floor2 = std::pow(std::sin(kept), 2);
  for (std::size_t i = first_checked; i < split_.added_faces.size(); ++i) {
    const Face& f = split_.added_faces[i];
    if (smallest_angle_sin2(position_of(f[0]), position_of(f[1]), position_of(f[2])) < floor2)
      return false;
  }
  path_ = std::move(path);
  target_ = hit;
  return true;
}

bool TipPlacement::insert_tip_on_edge(std::int32_t face, const std::array<double, 3>& bary) {
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

bool TipPlacement::split_with_tip_on_corner() {
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

bool TipPlacement::split_with_nearer_crossing() {
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

bool TipPlacement::place_new_tip(Crossing& c) {
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

std::vector<Eigen::Vector3d> TipPlacement::tip_ring(const Crossing& c) const {
  const Face& f = mesh_.faces[static_cast<std::size_t>(c.face)];
  std::vector<Eigen::Vector3d> ring;
  for (int k = 0; k < 3; ++k) {
    ring.push_back(mesh_.current.col(f[k]));
    if (c.in.kind == PathPoint::Edge && on_edge(c.in, f[k], f[(k + 1) % 3]))
      ring.push_back(pos(c.in, c.face));
  }
  return ring;
}

}  // namespace conform::mesh::tearing
