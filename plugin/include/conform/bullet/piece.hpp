// Pieces of a skinned soft body as an application sees them: stable, generation-checked
// handles (Box2D v3 style ids), the events of their life, the settings every piece carries and
// hands on to the pieces a split makes from it, and the options of releasing one from skinning.
//
// Ownership: every piece's btSoftBody is made, added to the world, removed and deleted by the
// plugin. An application may read and write a piece's body between steps (its m_cfg, its
// materials, its nodes' state) but must not keep the raw pointer across an edit: an edit can
// empty a piece and delete its body. Keep a PieceId instead; SkinnedSoftBody::piece_body(id)
// gives the body while the piece lives and null once it is gone (the id is then stale, and
// SkinnedSoftBody::piece_valid says so, instead of a use-after-free).
#pragma once

#include "conform/bullet/precision.hpp"  // the package's Bullet precision, checked

#include <BulletCollision/BroadphaseCollision/btBroadphaseProxy.h>
#include <BulletSoftBody/btSoftBody.h>

#include <cstdint>
#include <optional>

namespace conform::bullet {

/// A piece's handle: its slot in its skinned body and the slot's generation. Slots are never
/// handed to another piece while the id could still name the old one: the generation of a
/// slot changes when its piece is removed, so an old id is detected, never resolved to
/// another piece. Default-constructed ids are null (never valid).
struct PieceId {
  std::int32_t index = -1;
  std::uint32_t generation = 0;
  bool is_null() const { return index < 0; }
  friend bool operator==(const PieceId&, const PieceId&) = default;
};

/// What happened to a piece. Delivered to SkinnedSoftBody::on_piece_event listeners after the
/// edit that caused it has been mirrored completely (so every query is valid in the listener),
/// or from the body's destructor for body_destroyed. Listeners must not edit the body.
struct PieceEvent {
  enum class Kind {
    /// A new piece: at construction (parent null) or made by a split (parent = the piece whose
    /// nodes it took; its settings were inherited from there).
    created,
    /// An edit left the piece without nodes: its btSoftBody left the world and was deleted.
    removed,
    /// The skinned body is being destroyed: every piece id of it is now stale (piece null).
    body_destroyed,
  };
  Kind kind = Kind::created;
  PieceId piece{};
  PieceId parent{};
};

/// Settings of a piece that the pieces split from it inherit (copied at the split).
struct PieceSettings {
  /// The application's pointer (also set as the btSoftBody's user pointer).
  void* user = nullptr;
  /// Broadphase filter of the piece's btSoftBody (btSoftRigidDynamicsWorld::addSoftBody).
  int collision_group = btBroadphaseProxy::DefaultFilter;
  int collision_mask = btBroadphaseProxy::AllFilter;
  /// A template for the pieces' btSoftBody::Config (collision flags, kCHR, kDF, kVC, ...).
  /// Material::damping and Material::position_iterations replace its kDP and piterations.
  /// Unset: Bullet's defaults. A split copies its parent's m_cfg as it is at the time.
  /// Bullet's Config constructor leaves its fields uninitialized: start a template from a
  /// body's m_cfg (btSoftBody(&world_info, 0, nullptr, nullptr).m_cfg).
  std::optional<btSoftBody::Config> config{};
};

/// Releasing a piece from skinning (SkinnedSoftBody::release_piece): its nodes are no longer
/// driven toward their skinned targets (nor kinematic); the piece falls under gravity and
/// collides as a free Bullet soft body, its shape held by Bullet's own links.
struct ReleaseOptions {
  /// kLST of the piece's links, in (0, 1]: their rest lengths become the lengths at release.
  double link_stiffness = 0.9;
  /// Keeps the volume the piece has at release: a bulk modulus K in Pa (>= 0; 0 = off), the
  /// pressure K (V0 − V) / V0 pushing on the closed surface. The plugin integrates it
  /// implicitly, interleaved with the links' lengths, so every K is stable at any step (unlike
  /// Bullet's own explicit kVC). Needs a closed piece (e.g. a capped cut). Below about 9 × the
  /// skin's weight per area (1.1 kg/m² × g, about 100 Pa) the piece sags under its own weight.
  /// Measured figures: docs/notes/plugin.md.
  double volume_modulus = 0.0;
  /// An inner pressure in Pa at the release volume (>= 0; 0 = off), following Boyle's law
  /// (p V = p0 V0), integrated implicitly as the modulus is. Needs a closed piece. Unlike the
  /// modulus it pushes at V0 too, and the links (solved by position) must carry its tension
  /// p R / 2. Keep it within about 10 × the skin's weight per area, or keep the volume with
  /// volume_modulus (docs/notes/plugin.md).
  double pressure = 0.0;
};

}  // namespace conform::bullet
