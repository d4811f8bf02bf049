// Releasing a piece from skinning: its nodes leave the skin drive (no target, no membrane, not
// kinematic) and become an ordinary Bullet soft body that falls and collides, its shape held by
// Bullet's own links at the lengths it has when released and, for a closed piece, by the
// plugin's implicit volume step (released_volume.cpp), not Bullet's explicit kVC and kPR.
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "bullet_surgery.hpp"
#include "skinned_soft_body_impl.hpp"

namespace conform::bullet {

namespace {

void require(bool ok, const char* field, double value, const char* range) {
  if (ok) return;
  std::ostringstream out;
  out << "SkinnedSoftBody::release_piece: " << field << " = " << value << " is out of range ("
      << range << ")";
  throw std::invalid_argument(out.str());
}

}  // namespace

void SkinnedSoftBody::Impl::release_piece(PieceId id, const ReleaseOptions& options) {
  check_editable("release_piece");
  Piece& piece = pieces_.live(id, "release_piece");
  const auto finite = [](double v) { return std::isfinite(v); };
  require(
      finite(options.link_stiffness) && options.link_stiffness > 0 && options.link_stiffness <= 1,
      "link_stiffness", options.link_stiffness, "(0, 1]");
  require(finite(options.volume_modulus) && options.volume_modulus >= 0, "volume_modulus",
          options.volume_modulus, ">= 0 Pa");
  require(finite(options.pressure) && options.pressure >= 0, "pressure", options.pressure,
          ">= 0 Pa");
  btSoftBody& body = *piece.body;
  if (options.volume_modulus > 0 || options.pressure > 0)
    require(body.getVolume() > 0, "the piece's volume (for volume_modulus or pressure)",
            double(body.getVolume()), "> 0 m^3: a closed, outward-oriented piece");
  piece.released = true;
  piece.release = options;
  body.m_materials[0]->m_kLST = btScalar(options.link_stiffness);
  release_nodes(piece);
  // The shape at release is the rest shape from now on (what Bullet's own reset would give).
  for (int i = 0; i < body.m_links.size(); ++i) {
    btSoftBody::Link& link = body.m_links[i];
    const double rest = double((link.m_n[0]->m_x - link.m_n[1]->m_x).length());
    piece.rest[static_cast<std::size_t>(i)] = rest;
    link.m_rl = btScalar(rest);
    link.m_c1 = btScalar(rest * rest);
    link_constant(link);
  }
  piece.reapply = true;
  body.m_pose.m_wgh.clear();  // refresh_released captures the volume now
  refresh_released();
}

void SkinnedSoftBody::Impl::release_nodes(Piece& piece) {
  btSoftBody& body = *piece.body;
  for (int i = 0; i < body.m_nodes.size(); ++i) {
    const auto v = static_cast<std::size_t>(piece.node_vertex[static_cast<std::size_t>(i)]);
    kinematic_[v] = 0;
    pinned_[v] = 0;
    body.m_nodes[i].m_im = btScalar(1 / mass_[v]);
  }
  for (int i = 0; i < body.m_links.size(); ++i) link_constant(body.m_links[i]);
}

void SkinnedSoftBody::Impl::refresh_released() {
  for (auto& piece : pieces_) {
    if (!piece || !piece->body || !piece->released) continue;
    btSoftBody& body = *piece->body;
    if (body.m_pose.m_wgh.size() == body.m_nodes.size()) continue;  // nodes unchanged
    release_nodes(*piece);
    // The volume force is ours (hold_released_volumes, implicit): Bullet's own (kVC, kPR) is
    // explicit and blows up above a modulus set by the step. m_wgh's size records the node
    // count the volume was taken at (pose matching, which reads it, is off: m_bframe false).
    const double volume = double(body.getVolume());
    piece->release_volume = volume > 0 ? volume : 0;
    body.m_pose.m_bvolume = false;
    body.m_cfg.kVC = 0;
    body.m_cfg.kPR = 0;
    body.m_pose.m_wgh.resize(body.m_nodes.size(), btScalar(0));
  }
}

}  // namespace conform::bullet
