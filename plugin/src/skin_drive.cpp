// The skin drive: pose source → skinned targets (SkinDrive), and the per-substep update that
// drives the Bullet nodes toward them (Impl::update).
#include "skin_drive.hpp"

#include <algorithm>

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "bullet_surgery.hpp"
#include "skinned_soft_body_impl.hpp"

namespace conform::bullet {

// --- Pose sources ---

void SkinDrive::set_pose(const skin::Pose& pose) {
  if (pose.local.size() != skeleton_->joints.size())
    throw std::invalid_argument("set_pose: the pose has " + std::to_string(pose.local.size()) +
                                " joints, the skeleton " +
                                std::to_string(skeleton_->joints.size()));
  source_ = [pose](double, skin::Pose& out) { out = pose; };
}

void SkinDrive::play(const skin::Animation& animation, skin::Blend blend, bool loop) {
  source_ = [skeleton = skeleton_, animation, blend, loop](double time, skin::Pose& out) {
    const double d = animation.duration();
    const double t = loop && d > 0 ? std::fmod(time, d) : time;
    animation.sample(*skeleton, t, blend, out);
  };
}

void SkinDrive::set_keyframes(skin::PoseTrack track, skin::Blend blend) {
  source_ = [track = std::move(track), blend](double time, skin::Pose& out) {
    track.sample(time, blend, out);
  };
}

void SkinDrive::set_pose_source(std::function<void(double, skin::Pose&)> source) {
  source_ = std::move(source);
}

void SkinDrive::set_threads(int threads) {
  threads_ = threads;
  if (skinner_) skinner_->set_threads(threads);
}

// --- Skinned targets ---

void SkinDrive::start(const mesh::SkinnedMesh& mesh) {
  pose_ = skin::Pose::rest(*skeleton_);
  skinner_.emplace(*skeleton_, mesh.rest, skin::Influences<double>::from_mesh(mesh));
  skinner_->set_threads(threads_);
  rebuild_inputs(mesh);
  skin(mesh, 0);
  previous_ = target_;
}

Eigen::Matrix3Xd SkinDrive::bind_pose(const mesh::SkinnedMesh& mesh) const {
  skin::Skinner<double> skinner(*skeleton_, mesh.rest, skin::Influences<double>::from_mesh(mesh));
  skin::SoaPoints<double> bind;
  skinner.skin(skin::Pose::rest(*skeleton_), skin::SkinMode::cga, bind);
  Eigen::Matrix3Xd out(3, mesh.vertex_count());
  double apart = 0;
  for (Eigen::Index v = 0; v < out.cols(); ++v) {
    const auto i = static_cast<std::size_t>(v);
    out.col(v) << bind.x[i], bind.y[i], bind.z[i];
    apart = std::max(apart, (out.col(v) - mesh.rest.col(v)).norm());
  }
  if (mesh.vertex_count() == 0) return out;
  const double size = (mesh.rest.rowwise().maxCoeff() - mesh.rest.rowwise().minCoeff()).norm();
  return apart <= 1e-9 * size ? Eigen::Matrix3Xd() : out;
}

void SkinDrive::rebuild_inputs(const mesh::SkinnedMesh& mesh) {
  const auto n = static_cast<std::size_t>(mesh.vertex_count());
  if (skinner_->vertex_count() != n)
    skinner_->set_points(mesh.rest, skin::Influences<double>::from_mesh(mesh));
  const std::size_t old = previous_.size();
  target_.resize(n);
  previous_.resize(n);
  for (std::size_t v = old; v < n; ++v)
    previous_.x[v] = previous_.y[v] = previous_.z[v] = std::nan("");
  fill_previous_ = true;
}

void SkinDrive::skin(const mesh::SkinnedMesh& mesh, double time) {
  if (target_.size() != static_cast<std::size_t>(mesh.vertex_count())) rebuild_inputs(mesh);
  if (source_) source_(time, pose_);
  if (pose_.local.size() != skeleton_->joints.size())  // a source's pose of another skeleton
    throw std::invalid_argument("SkinnedSoftBody: the pose source gave " +
                                std::to_string(pose_.local.size()) +
                                " joints at t = " + std::to_string(time) + " s, the skeleton has " +
                                std::to_string(skeleton_->joints.size()));
  skinner_->skin(pose_, skin::SkinMode::cga, target_);
  place();
}

void SkinDrive::place() {
  if (transform_.matrix() == Eigen::Matrix4d::Identity()) return;
  for (std::size_t v = 0; v < target_.size(); ++v) {
    const Eigen::Vector3d t =
        transform_ * Eigen::Vector3d(target_.x[v], target_.y[v], target_.z[v]);
    target_.x[v] = t.x(), target_.y[v] = t.y(), target_.z[v] = t.z();
  }
}

void SkinDrive::extend(const mesh::SkinnedMesh& mesh) {
  if (target_.size() == static_cast<std::size_t>(mesh.vertex_count())) return;
  const std::size_t old = target_.size();
  rebuild_inputs(mesh);
  skinner_->skin(pose_, skin::SkinMode::cga, target_);
  place();
  for (std::size_t v = old; v < target_.size(); ++v)
    previous_.x[v] = target_.x[v], previous_.y[v] = target_.y[v], previous_.z[v] = target_.z[v];
  fill_previous_ = false;
}

void SkinDrive::advance(const mesh::SkinnedMesh& mesh, double time) {
  std::swap(previous_, target_);
  skin(mesh, time);  // resizes both after vertices were added (new previous entries NaN)
  if (!fill_previous_) return;
  for (std::size_t v = 0; v < target_.size(); ++v)
    if (std::isnan(previous_.x[v]))
      previous_.x[v] = target_.x[v], previous_.y[v] = target_.y[v], previous_.z[v] = target_.z[v];
  fill_previous_ = false;
}

// --- The per-substep drive ---

void SkinnedSoftBody::Impl::update(double dt, double time) {
  if (!pieces_.lost().empty())
    throw std::logic_error("SkinnedSoftBody: cannot step: " + pieces_.lost());
  if (!(dt > 0)) return;
  time_ = time, last_dt_ = dt;
  if (!started_) {
    // The first substep starts on the pose source's pose at its start time, not on the bind
    // pose the body was built in: no jump (a speed spike) towards the first pose.
    started_ = true;
    if (source_chosen_) {
      if (!clock_) clock_now_ = time - dt;
      place_on_pose();
    }
  }
  if (clock_) {
    if (!clock_->paused) clock_now_ += clock_->speed * dt;
  } else {
    clock_now_ = time;
  }
  drive_.advance(mesh_, clock_now_);
  for (std::int32_t slot = 0; slot < detached_.count(); ++slot) {
    // A detached vertex rides its target.
    const auto v = static_cast<std::size_t>(detached_.vertex(slot));
    const Eigen::Vector3d t = drive_.target(std::int32_t(v)), tp = drive_.previous_target(v);
    detached_.set(slot, t, (t - tp) / dt);
  }
  hold_released_volumes(dt);
  if (membrane_model()) {
    step_membrane(dt);
    return;
  }
  for (auto& piece : pieces_) {
    if (!piece) continue;
    if (!piece->released) drive_nodes(*piece, dt);  // a released piece is Bullet's alone
    reapply_rest_lengths(*piece);
  }
}

// The membrane's substep: kinematic nodes on their targets, then one membrane step of the
// others (membrane_drive.hpp).
void SkinnedSoftBody::Impl::step_membrane(double dt) {
  const skin::SoaPoints<double>& target = drive_.targets();
  const skin::SoaPoints<double>& previous = drive_.previous_targets();
  const auto n = static_cast<std::size_t>(mesh_.vertex_count());
  vertex_node_.assign(n, nullptr);
  target_matrix_.resize(3, Eigen::Index(n));
  previous_matrix_.resize(3, Eigen::Index(n));
  for (std::size_t v = 0; v < n; ++v) {
    target_matrix_.col(Eigen::Index(v)) << target.x[v], target.y[v], target.z[v];
    previous_matrix_.col(Eigen::Index(v)) << previous.x[v], previous.y[v], previous.z[v];
  }
  for (auto& piece : pieces_) {
    if (!piece || piece->released) continue;  // released: the membrane leaves it alone
    btSoftBody& body = *piece->body;
    for (int i = 0; i < body.m_nodes.size(); ++i) {
      btSoftBody::Node& node = body.m_nodes[i];
      const auto v = static_cast<std::size_t>(piece->node_vertex[static_cast<std::size_t>(i)]);
      vertex_node_[v] = &node;
      if (!kinematic_[v]) continue;
      const btVector3 t(btScalar(target.x[v]), btScalar(target.y[v]), btScalar(target.z[v]));
      node.m_x = t;  // after Bullet's prediction: on the target; Bullet derives the velocity
      node.m_v = (t - node.m_q) / btScalar(dt);
    }
  }
  membrane_.step(mesh_, skin_rest(), material_.skin, material_.solver, vertex_node_, kinematic_,
                 mass_, target_matrix_, previous_matrix_, dt);
}

void SkinnedSoftBody::Impl::drive_nodes(Piece& piece, double dt) {
  const skin::SoaPoints<double>& target = drive_.targets();
  const skin::SoaPoints<double>& previous = drive_.previous_targets();
  const double k = material_.target_stiffness, c = material_.target_damping;
  const double dt2 = dt * dt, denom = 1 + c * dt + k * dt2;
  const bool pull = k > 0 || c > 0;
  btSoftBody& body = *piece.body;
  for (int i = 0; i < body.m_nodes.size(); ++i) {
    btSoftBody::Node& node = body.m_nodes[i];
    const auto v = static_cast<std::size_t>(piece.node_vertex[static_cast<std::size_t>(i)]);
    const btVector3 t(btScalar(target.x[v]), btScalar(target.y[v]), btScalar(target.z[v]));
    if (kinematic_[v]) {
      // After Bullet's prediction: place the node on its target; Bullet derives the velocity.
      node.m_x = t;
      node.m_v = (t - node.m_q) / btScalar(dt);
    } else if (pull) {
      // An implicit spring–damper toward the target, relative to the target's velocity.
      const btVector3 tp(btScalar(previous.x[v]), btScalar(previous.y[v]), btScalar(previous.z[v]));
      const btVector3 target_velocity = (t - tp) / btScalar(dt);
      const btVector3 error = t - node.m_x;
      const btVector3 relative = (node.m_x - node.m_q) / btScalar(dt) - target_velocity;
      node.m_x += (error * btScalar(k) - relative * btScalar(c)) * btScalar(dt2 / denom);
    }
  }
}

void SkinnedSoftBody::Impl::reapply_rest_lengths(Piece& piece) {
  // Bullet resets every rest length at once (updateConstants, after any edit); one link
  // tells whether it happened since we last wrote them, and then ours (with pretension) win.
  btSoftBody& body = *piece.body;
  if (!piece.reapply &&
      (body.m_links.size() == 0 || body.m_links[0].m_rl == btScalar(piece.rest[0])))
    return;
  piece.reapply = false;
  for (int i = 0; i < body.m_links.size(); ++i) {
    const double r = piece.rest[static_cast<std::size_t>(i)];
    body.m_links[i].m_rl = btScalar(r);
    body.m_links[i].m_c1 = btScalar(r * r);
  }
}

void SkinnedSoftBody::Impl::set_clock(const Clock& clock) {
  if (!std::isfinite(clock.start) || !std::isfinite(clock.speed))
    throw std::invalid_argument(
        "SkinnedSoftBody::set_clock: start = " + std::to_string(clock.start) +
        " s, speed = " + std::to_string(clock.speed) + ": both must be finite");
  clock_ = clock;
  clock_now_ = clock.start;
}

void SkinnedSoftBody::Impl::snap_to_pose() {
  check_editable("snap_to_pose");
  started_ = true;
  place_on_pose();
}

void SkinnedSoftBody::Impl::place_on_pose() {
  drive_.settle(mesh_, clock_now_);
  for (auto& piece : pieces_) {
    if (!piece || !piece->body || piece->released) continue;
    btSoftBody& body = *piece->body;
    for (int i = 0; i < body.m_nodes.size(); ++i) {
      btSoftBody::Node& node = body.m_nodes[i];
      node.m_x = node.m_q = to_bt(drive_.target(piece->node_vertex[static_cast<std::size_t>(i)]));
      node.m_v = btVector3(0, 0, 0);
      if (node.m_leaf)
        node.m_leaf->volume = btDbvtVolume::FromCR(node.m_x, body.getCollisionShape()->getMargin());
    }
    refit_tree(body.m_ndbvt.m_root);  // the leaves moved: their ancestors follow
  }
  for (std::int32_t slot = 0; slot < detached_.count(); ++slot)
    detached_.set(slot, drive_.target(detached_.vertex(slot)), Eigen::Vector3d::Zero());
  membrane_.invalidate();  // its carried solution is of the old positions
}

void SkinnedSoftBody::Impl::skin_targets(double time) {
  drive_.skin(mesh_, time);
}

void SkinnedSoftBody::Impl::set_pinned(std::span<const std::int32_t> vertices) {
  check_editable("set_pinned");
  for (const auto v : vertices)
    if (v < 0 || v >= vertex_count())
      throw std::invalid_argument("SkinnedSoftBody::set_pinned: vertex " + std::to_string(v) +
                                  " out of range [0, " + std::to_string(vertex_count()) + ")");
  std::fill(pinned_.begin(), pinned_.end(), 0);
  for (const auto v : vertices) pinned_.at(static_cast<std::size_t>(v)) = 1;
  for (std::int32_t v = 0; v < vertex_count(); ++v) {
    const auto i = static_cast<std::size_t>(v);
    const std::int32_t p = piece_of_[i];
    if (p >= 0 && pieces_[static_cast<std::size_t>(p)]->released) continue;  // free for good
    const bool k = pinned_[i] || is_kinematic_by_weight(v);
    if (k == bool(kinematic_[i])) continue;
    kinematic_[i] = k;
    set_node_mass(v);  // and the constants of its links
  }
}

}  // namespace conform::bullet
