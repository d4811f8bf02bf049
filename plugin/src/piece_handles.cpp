// Pieces as the application sees them: generation-checked ids over the piece slots, the events
// queued by an edit and delivered after it, the settings a split inherits, and the guard that
// refuses an edit inside a step or after the application deleted a piece's body.
#include <stdexcept>
#include <string>

#include "piece_books.hpp"

namespace conform::bullet {

PieceId SkinnedSoftBody::Impl::id_of_slot(std::int32_t slot) const {
  return {slot, generation_[static_cast<std::size_t>(slot)]};
}

std::vector<PieceId> SkinnedSoftBody::Impl::piece_ids() const {
  std::vector<PieceId> out;
  for (std::size_t s = 0; s < pieces_.size(); ++s)
    if (pieces_[s] && pieces_[s]->body) out.push_back(id_of_slot(std::int32_t(s)));
  return out;
}

bool SkinnedSoftBody::Impl::piece_valid(PieceId id) const {
  if (id.index < 0 || std::size_t(id.index) >= pieces_.size()) return false;
  const auto s = static_cast<std::size_t>(id.index);
  return generation_[s] == id.generation && pieces_[s] && pieces_[s]->body;
}

btSoftBody* SkinnedSoftBody::Impl::piece_body(PieceId id) const {
  return piece_valid(id) ? pieces_[static_cast<std::size_t>(id.index)]->body.get() : nullptr;
}

PieceId SkinnedSoftBody::Impl::piece_of(std::int32_t vertex) const {
  if (vertex < 0 || vertex >= vertex_count())
    throw std::out_of_range("SkinnedSoftBody::piece_of: vertex " + std::to_string(vertex) +
                            " out of range [0, " + std::to_string(vertex_count()) + ")");
  const std::int32_t p = piece_of_[static_cast<std::size_t>(vertex)];
  return p < 0 ? PieceId{} : id_of_slot(p);
}

void SkinnedSoftBody::Impl::on_piece_event(std::function<void(const PieceEvent&)> listener) {
  if (listener) listeners_.push_back(std::move(listener));
}

SkinnedSoftBody::Impl::Piece& SkinnedSoftBody::Impl::live_piece(PieceId id,
                                                                const char* what) const {
  if (!piece_valid(id))
    throw std::invalid_argument(std::string("SkinnedSoftBody::") + what + ": piece id (slot " +
                                std::to_string(id.index) + ", generation " +
                                std::to_string(id.generation) +
                                ") is stale or null: its piece was removed by an edit, or never "
                                "existed");
  return *pieces_[static_cast<std::size_t>(id.index)];
}

const PieceSettings& SkinnedSoftBody::Impl::piece_settings(PieceId id) const {
  return live_piece(id, "piece_settings").settings;
}

void SkinnedSoftBody::Impl::set_piece_user(PieceId id, void* user) {
  Piece& piece = live_piece(id, "set_piece_user");
  piece.settings.user = user;
  piece.body->setUserPointer(user);
}

void SkinnedSoftBody::Impl::set_piece_collision(PieceId id, int group, int mask) {
  check_editable("set_piece_collision");
  Piece& piece = live_piece(id, "set_piece_collision");
  piece.settings.collision_group = group;
  piece.settings.collision_mask = mask;
  // Bullet reads the filter when it makes the broadphase proxy: out of the world and back in.
  link_.remove(piece.body.get());
  link_.add(piece.body.get(), group, mask);
}

bool SkinnedSoftBody::Impl::piece_released(PieceId id) const {
  return live_piece(id, "piece_released").released;
}

void SkinnedSoftBody::Impl::check_editable(const char* what) const {
  if (link_.stepping && link_.stepping())
    throw std::logic_error(std::string("SkinnedSoftBody::") + what +
                           ": called inside stepSimulation (from a step hook or other code the "
                           "step runs); Bullet's contacts hold node pointers until the step "
                           "ends, so edit between stepSimulation calls");
  if (!lost_.empty())
    throw std::logic_error(std::string("SkinnedSoftBody::") + what + ": " + lost_);
}

void SkinnedSoftBody::Impl::deliver_events() {
  // Swapped out first: a listener's own queries never see a half-delivered queue.
  std::vector<PieceEvent> events;
  events.swap(events_);
  for (const auto& event : events)
    for (auto& listener : listeners_) listener(event);
}

void SkinnedSoftBody::Impl::body_deleted_by_app(std::int32_t slot) {
  auto& piece = pieces_[static_cast<std::size_t>(slot)];
  (void)piece->body.release();  // being deleted by the application: never ours to delete
  ++generation_[static_cast<std::size_t>(slot)];
  if (lost_.empty())
    lost_ = "the btSoftBody of piece " + std::to_string(slot) +
            " was deleted by the application (Bullet's teardown) while its skinned body "
            "lives; destroy the plugin or the skinned body (Plugin::remove_skinned_body)";
}

}  // namespace conform::bullet
