// The piece books: one Bullet body per connected piece of the mesh, and for each the mesh
// vertex, face and edge that its nodes, faces and links mirror. Also the small keys every part
// of the plugin uses (an undirected edge, the third vertex of a face).
#pragma once

#include <BulletSoftBody/btSoftBody.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "conform/bullet/convert.hpp"
#include "skinned_soft_body_impl.hpp"

namespace conform::bullet {

/// An undirected edge as the books key it: (min, max).
inline std::pair<std::int32_t, std::int32_t> edge_key(std::int32_t a, std::int32_t b) {
  return a < b ? std::pair{a, b} : std::pair{b, a};
}

/// The vertex of `f` that is neither a nor b (−1 if none).
inline std::int32_t third_vertex(const mesh::Face& f, std::int32_t a, std::int32_t b) {
  for (const auto v : f)
    if (v != a && v != b) return v;
  return -1;
}

/// One whole connected piece on its way into a new body (move_to_new_piece and its steps).
struct SkinnedSoftBody::Impl::PieceMove {
  std::span<const std::int32_t> moving;  // its vertices; node i of the new body is moving[i]
  std::vector<std::int32_t> sources;     // bodies the nodes leave (normally one)
  std::vector<std::int32_t> faces;       // mesh faces, each once
  std::vector<std::vector<std::uint8_t>> marks;  // per source body: per link, 1 if it moves
  std::size_t link_count = 0;                    // links marked
  std::int32_t into = -1;                        // the new body's index
};

inline btSoftBody* SkinnedSoftBody::Impl::body_of(std::int32_t v) const {
  const std::int32_t p = piece_of_[static_cast<std::size_t>(v)];
  return p < 0 ? nullptr : pieces_[static_cast<std::size_t>(p)]->body.get();
}

// The node of an attached vertex (its body deleted by the application: refused).
inline const btSoftBody::Node& SkinnedSoftBody::Impl::node(std::int32_t v) const {
  const btSoftBody* body = body_of(v);
  if (!body) throw std::logic_error("SkinnedSoftBody: " + pieces_.lost());
  return body->m_nodes[node_of_[static_cast<std::size_t>(v)]];
}

inline Eigen::Vector3d SkinnedSoftBody::Impl::position(std::int32_t v) const {
  const auto i = static_cast<std::size_t>(v);
  if (piece_of_[i] < 0) return detached_.position(v);
  return from_bt(node(v).m_x);
}

inline Eigen::Vector3d SkinnedSoftBody::Impl::velocity(std::int32_t v) const {
  const auto i = static_cast<std::size_t>(v);
  if (piece_of_[i] < 0) return detached_.velocity(v);
  return from_bt(node(v).m_v);
}

}  // namespace conform::bullet
