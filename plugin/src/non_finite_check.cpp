// The per-substep finiteness check (non_finite_state.hpp): one pass over every piece's nodes.
#include <cmath>
#include <sstream>

#include "skinned_soft_body_impl.hpp"

namespace conform::bullet {

namespace {

bool finite(const btVector3& v) {
  // A finite sum means three finite terms (a NaN or infinite one makes it NaN or infinite); the
  // sum of large finite terms may overflow, so only then are they tested one by one.
  return std::isfinite(v.x() + v.y() + v.z()) ||
         (std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()));
}

}  // namespace

// The node's speed past its bone's: its velocity less its skinned target's over the last
// substep. A skin riding an animation that sweeps it at 100 m/s (a 120 m chain of boxes turning
// full circles) is not running away; a released piece has no target and counts whole.
Eigen::Vector3d SkinnedSoftBody::Impl::own_velocity(const Piece& piece, int node) const {
  const btVector3& v = piece.body->m_nodes[node].m_v;
  const Eigen::Vector3d velocity(double(v.x()), double(v.y()), double(v.z()));
  const auto vertex = static_cast<std::size_t>(piece.node_vertex[static_cast<std::size_t>(node)]);
  if (piece.released || !(last_dt_ > 0) || vertex >= drive_.targets().x.size()) return velocity;
  const Eigen::Vector3d carried =
      (drive_.target(std::int32_t(vertex)) - drive_.previous_target(vertex)) / last_dt_;
  return carried.allFinite() ? Eigen::Vector3d(velocity - carried) : velocity;
}

std::optional<NonFiniteNode> SkinnedSoftBody::Impl::first_non_finite_node() const {
  const double max_speed2 = material_.max_speed * material_.max_speed;  // inf: no bound
  for (std::size_t slot = 0; slot < pieces_.size(); ++slot) {
    const Piece* piece = pieces_[slot].get();
    if (!piece || !piece->body) continue;
    const btSoftBody& body = *piece->body;
    for (int i = 0; i < body.m_nodes.size(); ++i) {
      const btSoftBody::Node& n = body.m_nodes[i];
      const bool x = finite(n.m_x), v = finite(n.m_v);
      const bool runaway =
          x && v && std::isfinite(max_speed2) && own_velocity(*piece, i).squaredNorm() > max_speed2;
      if (x && v && !runaway) continue;
      const btVector3& bad = x ? n.m_v : n.m_x;
      return NonFiniteNode{
          static_cast<std::int32_t>(slot),
          i,
          piece->node_vertex[static_cast<std::size_t>(i)],
          !x,
          runaway,
          runaway ? own_velocity(*piece, i)
                  : Eigen::Vector3d(double(bad.x()), double(bad.y()), double(bad.z()))};
    }
  }
  return std::nullopt;
}

namespace {

std::string describe(long long substep, double time, std::size_t body, const NonFiniteNode& n) {
  std::ostringstream s;
  if (n.runaway) {
    s << "the simulation ran away at substep " << substep << " (t = " << time
      << " s): skinned body " << body << ", piece " << n.piece << ", node " << n.node
      << " (mesh vertex " << n.vertex << ") moves at " << n.value.norm()
      << " m/s past its skinned target, faster than its Material::max_speed, at the start of that "
         "substep; too large a "
         "time step, force or stiffness for the material?";
    return s.str();
  }
  s << "the simulation went non-finite at substep " << substep << " (t = " << time
    << " s): skinned body " << body << ", piece " << n.piece << ", node " << n.node
    << " (mesh vertex " << n.vertex << ") has " << (n.position ? "position" : "velocity") << " ("
    << n.value.x() << ", " << n.value.y() << ", " << n.value.z()
    << ") at the start of that substep (what the one before and Bullet's prediction left); too "
       "large a time step, force or stiffness for the material?";
  return s.str();
}

}  // namespace

NonFiniteState::NonFiniteState(long long substep, double time, std::size_t body,
                               const NonFiniteNode& node)
    : std::runtime_error(describe(substep, time, body, node)),
      substep_(substep),
      time_(time),
      body_(body),
      node_(node) {}

}  // namespace conform::bullet
