// The piece slots and their ids, events and per-piece settings (piece_handles.hpp).
#include "piece_handles.hpp"

#include <stdexcept>
#include <string>

namespace conform::bullet {

PieceBody::~PieceBody() {
  if (owner) owner->body_deleted(slot);
}

Piece& PieceHandles::add(std::unique_ptr<Piece> piece, std::int32_t parent) {
  const auto slot = std::int32_t(pieces_.size());
  pieces_.push_back(std::move(piece));
  generation_.push_back(1);
  events_.push_back(
      {PieceEvent::Kind::created, id_of(slot), parent >= 0 ? id_of(parent) : PieceId{}});
  return *pieces_.back();
}

void PieceHandles::remove(std::int32_t slot) {
  const auto s = static_cast<std::size_t>(slot);
  events_.push_back({PieceEvent::Kind::removed, id_of(slot), {}});
  pieces_[s].reset();
  ++generation_[s];  // every id of it is stale from now on
}

void PieceHandles::body_deleted(std::int32_t slot) {
  auto& piece = pieces_[static_cast<std::size_t>(slot)];
  (void)piece->body.release();  // being deleted by the application: never ours to delete
  ++generation_[static_cast<std::size_t>(slot)];
  if (lost_.empty())
    lost_ = "the btSoftBody of piece " + std::to_string(slot) +
            " was deleted by the application (Bullet's teardown) while its skinned body "
            "lives; destroy the plugin or the skinned body (Plugin::remove_skinned_body)";
}

std::vector<PieceId> PieceHandles::ids() const {
  std::vector<PieceId> out;
  for (std::size_t s = 0; s < pieces_.size(); ++s)
    if (pieces_[s] && pieces_[s]->body) out.push_back(id_of(std::int32_t(s)));
  return out;
}

bool PieceHandles::valid(PieceId id) const {
  if (id.index < 0 || std::size_t(id.index) >= pieces_.size()) return false;
  const auto s = static_cast<std::size_t>(id.index);
  return generation_[s] == id.generation && pieces_[s] && pieces_[s]->body;
}

btSoftBody* PieceHandles::body(PieceId id) const {
  return valid(id) ? pieces_[static_cast<std::size_t>(id.index)]->body.get() : nullptr;
}

Piece& PieceHandles::live(PieceId id, const char* what) const {
  if (!valid(id))
    throw std::invalid_argument(std::string("SkinnedSoftBody::") + what + ": piece id (slot " +
                                std::to_string(id.index) + ", generation " +
                                std::to_string(id.generation) +
                                ") is stale or null: its piece was removed by an edit, or never "
                                "existed");
  return *pieces_[static_cast<std::size_t>(id.index)];
}

void PieceHandles::set_user(PieceId id, void* user) {
  Piece& piece = live(id, "set_piece_user");
  piece.settings.user = user;
  piece.body->setUserPointer(user);
}

void PieceHandles::listen(std::function<void(const PieceEvent&)> listener) {
  if (listener) listeners_.push_back(std::move(listener));
}

void PieceHandles::deliver() {
  // Swapped out first: a listener's own queries never see a half-delivered queue.
  std::vector<PieceEvent> events;
  events.swap(events_);
  for (const auto& event : events)
    for (auto& listener : listeners_) listener(event);
}

void PieceHandles::destroyed() {
  events_.clear();
  for (auto& listener : listeners_) listener({PieceEvent::Kind::body_destroyed, {}, {}});
}

}  // namespace conform::bullet
