// The pieces of one skinned body: a slot per piece ever made, each holding its Bullet body and
// the books of what that body's nodes, faces and links mirror (filled by the plugin's edits),
// named to the application by generation-checked ids, with the events an edit queues for it.
// Invariant: an id is valid iff its slot holds a piece whose body lives and the id's
// generation is the slot's; a slot's generation changes whenever its piece leaves (emptied by
// an edit, or its body deleted by the application), so an id never names a later piece. Events
// reach the listeners only at deliver() (after an edit), never halfway through one.
#pragma once

#include <BulletSoftBody/btSoftBody.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include "conform/bullet/piece.hpp"

namespace conform::bullet {

class PieceHandles;

/// A piece's btSoftBody. It tells its handles when the application deletes it (Bullet's
/// standard teardown deletes every soft body of the world), so that the plugin neither deletes
/// nor touches it again. `owner` is null when the plugin deletes it itself.
struct PieceBody final : btSoftBody {
  PieceBody(btSoftBodyWorldInfo* info, PieceHandles* handles, std::int32_t piece_slot)
      : btSoftBody(info, 0, nullptr, nullptr), owner(handles), slot(piece_slot) {}
  ~PieceBody() override;  // piece_handles.cpp
  PieceBody(const PieceBody&) = delete;
  PieceBody& operator=(const PieceBody&) = delete;
  PieceHandles* owner;
  std::int32_t slot;
};

/// One piece: its body and, per node, face and link, the mesh element it mirrors.
struct Piece {
  Piece() = default;
  Piece(const Piece&) = delete;
  Piece& operator=(const Piece&) = delete;
  ~Piece() {
    if (body) body->owner = nullptr;  // deleted by the plugin: no notice
  }
  // Memory the body's node, face and link arrays start in (see move_to_new_piece); declared
  // first, so it outlives the body (which never frees memory it does not own).
  struct Release {
    void operator()(std::byte* p) const { ::operator delete[](p, std::align_val_t{16}); }
  };
  std::unique_ptr<std::byte[], Release> storage;
  std::unique_ptr<PieceBody> body;        // null once the application deleted it
  std::vector<std::int32_t> node_vertex;  // node index → mesh vertex
  std::vector<double> rest;               // link index → our rest length (Bullet resets its own)
  std::vector<std::pair<std::int32_t, std::int32_t>> link_key;  // link → its key edge (min, max)
  std::vector<std::uint8_t> link_bend;                          // link → 1 for a bending link
  std::vector<std::int32_t> face_id;                            // Bullet face slot → mesh face
  std::int32_t bending = 0;                                     // bending links in this body
  bool reapply = true;        // rest lengths to write at the next update (set when built)
  PieceSettings settings;     // inherited by the pieces split from it
  bool released = false;      // released from skinning (release_piece): not driven
  ReleaseOptions release{};   // how, when released
  double release_volume = 0;  // V0, m³: the closed piece's volume at release (0: open)
};

class PieceHandles {
 public:
  using Slot = std::unique_ptr<Piece>;  // null once its piece left
  // --- Slots (a piece's index; its body and books are the plugin's to edit) ---
  std::size_t size() const { return pieces_.size(); }
  const Slot& operator[](std::size_t slot) const { return pieces_[slot]; }
  const Slot& back() const { return pieces_.back(); }
  auto begin() const { return pieces_.cbegin(); }
  auto end() const { return pieces_.cend(); }
  /// Adds `piece` (its body made for the next slot) and queues its `created` event; `parent`
  /// is the slot it split from (−1: none).
  Piece& add(std::unique_ptr<Piece> piece, std::int32_t parent);
  /// Empties `slot` (its body already out of the world) and queues its `removed` event.
  void remove(std::int32_t slot);
  /// The slot's piece's body was deleted by the application: it is never touched again, and
  /// the body is unusable from now on (lost()).
  void body_deleted(std::int32_t slot);
  /// Why the body is unusable (a piece's body deleted by the application), else empty.
  const std::string& lost() const { return lost_; }

  // --- Ids ---
  PieceId id_of(std::int32_t slot) const {
    return {slot, generation_[static_cast<std::size_t>(slot)]};
  }
  std::vector<PieceId> ids() const;
  bool valid(PieceId id) const;
  btSoftBody* body(PieceId id) const;
  /// The live piece `id` names; throws std::invalid_argument naming `what` when stale.
  Piece& live(PieceId id, const char* what) const;
  const PieceSettings& settings(PieceId id) const { return live(id, "piece_settings").settings; }
  void set_user(PieceId id, void* user);
  bool released(PieceId id) const { return live(id, "piece_released").released; }

  // --- Events ---
  void listen(std::function<void(const PieceEvent&)> listener);
  /// Hands the queued events to the listeners.
  void deliver();
  /// Forgets the queued events (the pieces made with the body are not announced).
  void drop_events() { events_.clear(); }
  /// Tells the listeners the body is gone; queued events are dropped.
  void destroyed();

 private:
  std::vector<Slot> pieces_;
  std::vector<std::uint32_t> generation_;  // per slot; changes when its piece leaves
  std::vector<std::function<void(const PieceEvent&)>> listeners_;
  std::vector<PieceEvent> events_;  // queued during an edit, delivered after it
  std::string lost_;
};

}  // namespace conform::bullet
