#include "conform/mesh/tear.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "change_flips.hpp"
#include "tear_opening.hpp"

namespace conform::mesh {

namespace tearing {

void TearAdvance::run() {
  if (!make_plane()) return;
  if (!walk()) return;
  if (!split_along_path()) return;
  open_left_side();
  record();
}

bool TearAdvance::split_along_path() {
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
        // No room inside the face for a tip. The lips: on the edge crossing behind the blade,
        // however far, or else on the one ahead, where that makes no sliver. Otherwise the
        // face is in the old tip's fan: on the track's edge ahead or behind (past the fan).
        const std::string message = tear_.message_;
        path_.back().out = blade;
        off_track_ = false;
        if (smooth && split_with_tip_on_edge(std::numeric_limits<double>::infinity(), true)) break;
        if (!smooth && split_with_tip_past_fan()) break;
        tear_.message_ = message;
        return false;
      }
      split_face(c);
    }
  }
  if (smooth) flip_beside_path();
  std::sort(split_.removed_faces.begin(), split_.removed_faces.end());
  split_.removed_faces.erase(std::unique(split_.removed_faces.begin(), split_.removed_faces.end()),
                             split_.removed_faces.end());
  tear_.commit(std::move(split_), step_);
  return true;
}

void TearAdvance::record() {
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

}  // namespace tearing

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
  // The walk and the splits measure positions: a NaN makes its crossings meaningless, and the
  // splits could then leave a non-manifold vertex.
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
  if (!exact) ch = fan_change(tearing::place_tip(bary, a, b, c, {a, b, c}, options_.min_angle));
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
  tearing::TearAdvance(*this, s, step).run();
  previous_ = s;
  return step;
}

void Tear::adopt_growth(std::int32_t end, std::int32_t duplicate, std::int32_t new_tip) {
  const bool at_tip = path_.size() >= 2 && end == tip_;
  const bool at_start = path_.size() >= 2 && end == path_.front().right;
  if (!at_tip && !at_start)
    throw std::invalid_argument("tear: vertex " + std::to_string(end) +
                                " is not an end of the tear");
  // The end's copy on the right border is the one sharing a face with the neighbouring point's
  // right copy; the normal points from the right copy's faces toward the left one's.
  const PathVertex& next = at_tip ? path_[path_.size() - 2] : path_[1];
  const auto shares_face = [&](std::int32_t u, std::int32_t v) {
    return adjacency_.find(u, v) >= 0 || adjacency_.find(v, u) >= 0;
  };
  const std::int32_t right = shares_face(next.right, duplicate) ? duplicate : end;
  const std::int32_t left = right == duplicate ? end : duplicate;
  const auto centroid = [&](std::int32_t v) {  // of the faces around v
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    int n = 0;
    for (const Face& f : mesh_.faces)
      if (f[0] == v || f[1] == v || f[2] == v) {
        c += mesh_.current.col(f[0]) + mesh_.current.col(f[1]) + mesh_.current.col(f[2]);
        n += 3;
      }
    return Eigen::Vector3d(c / std::max(n, 1));
  };
  const Eigen::Vector3d along = mesh_.current.col(new_tip) - mesh_.current.col(end);
  Eigen::Vector3d normal = centroid(left) - centroid(right);
  normal -= normal.dot(along) / along.squaredNorm() * along;
  const PathVertex grown{right, left, normal.normalized()};
  if (at_tip) {
    path_.back() = grown;
    path_.push_back({new_tip, -1, Eigen::Vector3d::Zero()});
    tip_ = new_tip;
    tip_neighbor_ = right;
    tip_target_ = mesh_.current.col(new_tip);
    tip_off_track_ = false;
  } else {
    path_.front() = grown;
    path_.insert(path_.begin(), {new_tip, -1, Eigen::Vector3d::Zero()});
  }
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

}  // namespace conform::mesh
