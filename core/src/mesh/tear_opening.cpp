#include <cmath>
#include <map>
#include <numbers>
#include <stdexcept>

#include "tear_opening.hpp"

namespace conform::mesh {

namespace {

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

namespace tearing {

void TearOpening::open_left_side() {
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
    const std::int32_t dup = b.base_vertex_count + static_cast<std::int32_t>(b.new_vertices.size());
    b.new_vertices.push_back(NewVertex::duplicate(p));
    dups_[j] = dup;
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (auto fi : faces) {
      auto it = remapped.try_emplace(fi, mesh_.faces[static_cast<std::size_t>(fi)]).first;
      for (auto& v : it->second)
        if (v == p) v = dup;
      const Face& f = mesh_.faces[static_cast<std::size_t>(fi)];
      centroid += (mesh_.current.col(f[0]) + mesh_.current.col(f[1]) + mesh_.current.col(f[2])) / 3;
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

bool TearOpening::left_faces(std::int32_t p, std::int32_t next, std::int32_t prev,
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

}  // namespace tearing

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
