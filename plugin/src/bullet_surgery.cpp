// Bullet surgery: the free edits of a body's node tree (bullet_surgery.hpp), and the books-aware
// edits of nodes, faces and links. Removals are swap-with-last with local re-pointing (found
// through the mesh faces of the moved element). None sets Bullet's whole-body reset
// (m_bUpdateRtCst): the constants of what changed are written here.
#include "bullet_surgery.hpp"

#include <algorithm>
#include <cstring>
#include <new>

#include "edge_key.hpp"
#include "skinned_soft_body_impl.hpp"

namespace conform::bullet {

namespace {

// Spreads the low 10 bits of x to every third bit (Morton code helper).
std::uint32_t spread_bits(std::uint32_t x) {
  x &= 0x3ffu;
  x = (x | (x << 16)) & 0x030000ffu;
  x = (x | (x << 8)) & 0x0300f00fu;
  x = (x | (x << 4)) & 0x030c30c3u;
  x = (x | (x << 2)) & 0x09249249u;
  return x;
}

}  // namespace

void unlink_leaf(btDbvt& tree, btDbvtNode* leaf, std::vector<btDbvtNode*>& pool) {
  pool.push_back(leaf);
  --tree.m_leaves;
  if (leaf == tree.m_root) {
    tree.m_root = nullptr;
    return;
  }
  btDbvtNode* parent = leaf->parent;
  btDbvtNode* sibling = parent->childs[parent->childs[0] == leaf ? 1 : 0];
  btDbvtNode* grand = parent->parent;
  sibling->parent = grand;
  if (grand)
    grand->childs[grand->childs[1] == parent ? 1 : 0] = sibling;
  else
    tree.m_root = sibling;
  pool.push_back(parent);
}

btDbvtNode* insert_leaf_beside(btDbvt& tree, btDbvtNode* beside, const btDbvtVolume& volume,
                               void* data) {
  auto* leaf = new (btAlignedAlloc(sizeof(btDbvtNode), 16)) btDbvtNode();
  leaf->volume = volume;
  leaf->data = data;
  leaf->childs[1] = nullptr;
  auto* node = new (btAlignedAlloc(sizeof(btDbvtNode), 16)) btDbvtNode();
  btDbvtNode* up = beside->parent;
  node->parent = up;
  Merge(volume, beside->volume, node->volume);
  node->childs[0] = beside;
  node->childs[1] = leaf;
  beside->parent = node;
  leaf->parent = node;
  ++tree.m_leaves;
  if (!up) {
    tree.m_root = node;
    return leaf;
  }
  up->childs[up->childs[1] == beside ? 1 : 0] = node;
  for (btDbvtNode* child = node; up && !up->volume.Contain(child->volume);
       child = up, up = up->parent)
    Merge(up->childs[0]->volume, up->childs[1]->volume, up->volume);
  return leaf;
}

void refit_tree(btDbvtNode* node) {
  if (!node || node->isleaf()) return;
  refit_tree(node->childs[0]);
  refit_tree(node->childs[1]);
  Merge(node->childs[0]->volume, node->childs[1]->volume, node->volume);
}

void build_node_tree(btSoftBody& body, std::vector<btDbvtNode*>& pool) {
  const int n = body.m_nodes.size();
  if (n > 0) {
    const btScalar margin = body.getCollisionShape()->getMargin();
    btVector3 lo = body.m_nodes[0].m_x, hi = lo;
    for (int i = 1; i < n; ++i) {
      lo.setMin(body.m_nodes[i].m_x);
      hi.setMax(body.m_nodes[i].m_x);
    }
    const btVector3 extent = hi - lo;
    const btScalar size = std::max({extent.x(), extent.y(), extent.z(), btScalar(1e-9)});
    const btScalar scale = btScalar(1023) / size;
    std::vector<std::pair<std::uint32_t, int>> order(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
      const btVector3 q = (body.m_nodes[i].m_x - lo) * scale;
      order[static_cast<std::size_t>(i)] = {spread_bits(std::uint32_t(q.x())) |
                                                (spread_bits(std::uint32_t(q.y())) << 1) |
                                                (spread_bits(std::uint32_t(q.z())) << 2),
                                            i};
    }
    std::sort(order.begin(), order.end());
    auto make = [&](btDbvtNode* parent) {
      btDbvtNode* node;
      if (pool.empty()) {
        node = new (btAlignedAlloc(sizeof(btDbvtNode), 16)) btDbvtNode();
      } else {
        node = pool.back();
        pool.pop_back();
      }
      node->parent = parent;
      return node;
    };
    auto build = [&](auto&& self, int first, int count, btDbvtNode* parent) -> btDbvtNode* {
      btDbvtNode* node = make(parent);
      if (count == 1) {
        btSoftBody::Node& leaf = body.m_nodes[order[static_cast<std::size_t>(first)].second];
        node->volume = btDbvtVolume::FromCR(leaf.m_x, margin);
        node->data = &leaf;
        node->childs[1] = nullptr;
        leaf.m_leaf = node;
        return node;
      }
      const int half = count / 2;
      node->childs[0] = self(self, first, half, node);
      node->childs[1] = self(self, first + half, count - half, node);
      Merge(node->childs[0]->volume, node->childs[1]->volume, node->volume);
      return node;
    };
    btDbvt& tree = body.m_ndbvt;
    tree.m_root = build(build, 0, n, nullptr);
    tree.m_leaves = n;
  }
  for (btDbvtNode* spare : pool) btAlignedFree(spare);
  pool.clear();
}

void SkinnedSoftBody::Impl::set_node_mass(std::int32_t v) {
  const auto i = static_cast<std::size_t>(v);
  if (piece_of_[i] < 0) return;
  btSoftBody::Node& node = body_of(v)->m_nodes[node_of_[i]];
  const btScalar im = kinematic_[i] ? btScalar(0) : btScalar(1 / mass_[i]);
  if (im == node.m_im) return;  // e.g. a kinematic node: its links' constants stand
  node.m_im = im;
  update_link_constants(v);
}

void SkinnedSoftBody::Impl::update_link_constants(std::int32_t v) {
  btSoftBody& body = *body_of(v);
  const btSoftBody::Node* node = &body.m_nodes[node_of_[static_cast<std::size_t>(v)]];
  auto touch = [&](std::int32_t li) {
    if (li < 0 || li >= body.m_links.size()) return;
    btSoftBody::Link& l = body.m_links[li];
    if (l.m_n[0] == node || l.m_n[1] == node) link_constant(l);
  };
  for (const auto f : vertex_faces_[static_cast<std::size_t>(v)]) {
    const auto& tri = faces_[static_cast<std::size_t>(f)];
    for (int k = 0; k < 3; ++k) {
      const auto [a, b] = edge_key(tri[k], tri[(k + 1) % 3]);
      touch(a == v || b == v ? edge_link_.find(a, b) : bend_link_.find(a, b));
    }
  }
}

void SkinnedSoftBody::Impl::update_node_area(std::int32_t v) {
  const auto i = static_cast<std::size_t>(v);
  if (piece_of_[i] < 0) return;
  btSoftBody& body = *body_of(v);
  btScalar sum = 0;
  int count = 0;
  for (const auto f : vertex_faces_[i])
    if (face_piece_[static_cast<std::size_t>(f)] == piece_of_[i])
      sum += btFabs(body.m_faces[face_slot_[static_cast<std::size_t>(f)]].m_ra), ++count;
  body.m_nodes[node_of_[i]].m_area = count ? sum / btScalar(count) : btScalar(0);
}

void SkinnedSoftBody::Impl::add_node(std::int32_t p, std::int32_t v, const Eigen::Vector3d& x,
                                     const Eigen::Vector3d& vel, std::int32_t near) {
  Piece& piece = *pieces_[static_cast<std::size_t>(p)];
  btSoftBody& body = *piece.body;
  btDbvtNode* beside = near >= 0 && piece_of_[static_cast<std::size_t>(near)] == p
                           ? body.m_nodes[node_of_[static_cast<std::size_t>(near)]].m_leaf
                           : nullptr;
  if (beside && body.m_nodes.size() < body.m_nodes.capacity()) {
    // appendNode's node, with its tree leaf placed beside the leaf of a node next to it
    // instead of by a walk down from the root (the array has room: nothing is re-pointed).
    body.m_nodes.push_back(btSoftBody::Node());
    btSoftBody::Node& node = body.m_nodes[body.m_nodes.size() - 1];
    std::memset(static_cast<void*>(&node), 0, sizeof(node));
    node.m_x = node.m_q = to_bt(x);
    node.m_material = body.m_materials[0];
    node.m_leaf = insert_leaf_beside(
        body.m_ndbvt, beside, btDbvtVolume::FromCR(node.m_x, body.getCollisionShape()->getMargin()),
        &node);
  } else {
    body.appendNode(to_bt(x), 1);
  }
  btSoftBody::Node& node = body.m_nodes[body.m_nodes.size() - 1];
  node.m_v = to_bt(vel);
  const auto i = static_cast<std::size_t>(v);
  piece_of_[i] = p;
  node_of_[i] = body.m_nodes.size() - 1;
  piece.node_vertex.push_back(v);
  node.m_im = kinematic_[i] ? btScalar(0) : btScalar(1 / mass_[i]);
}

void SkinnedSoftBody::Impl::remove_node(std::int32_t v) {
  // Swap-with-last: the last node moves into the hole and the faces and links that point to
  // it (found through its mesh faces) are re-pointed. v's own faces and links must be gone.
  const auto iv = static_cast<std::size_t>(v);
  const std::int32_t p = piece_of_[iv];
  Piece& piece = *pieces_[static_cast<std::size_t>(p)];
  btSoftBody& body = *piece.body;
  const int i = node_of_[iv], last = body.m_nodes.size() - 1;
  if (body.m_nodes[i].m_leaf) body.m_ndbvt.remove(body.m_nodes[i].m_leaf);
  if (i != last) {
    btSoftBody::Node* from = &body.m_nodes[last];
    btSoftBody::Node* to = &body.m_nodes[i];
    *to = *from;
    if (to->m_leaf) to->m_leaf->data = to;
    const std::int32_t w = piece.node_vertex[static_cast<std::size_t>(last)];
    piece.node_vertex[static_cast<std::size_t>(i)] = w;
    node_of_[static_cast<std::size_t>(w)] = i;
    auto repoint_link = [&](std::int32_t li) {
      if (li < 0 || li >= body.m_links.size()) return;
      for (auto& n : body.m_links[li].m_n)
        if (n == from) n = to;
    };
    for (const auto f : vertex_faces_[static_cast<std::size_t>(w)]) {
      const auto fi = static_cast<std::size_t>(f);
      if (face_piece_[fi] == p)
        for (auto& n : body.m_faces[face_slot_[fi]].m_n)
          if (n == from) n = to;
      const auto& tri = faces_[fi];
      for (int k = 0; k < 3; ++k) {
        const auto [a, b] = edge_key(tri[k], tri[(k + 1) % 3]);
        repoint_link(a == w || b == w ? edge_link_.find(a, b) : bend_link_.find(a, b));
      }
    }
  }
  body.m_nodes.pop_back();
  piece.node_vertex.pop_back();
  piece_of_[iv] = -1;
  node_of_[iv] = -1;
}

void SkinnedSoftBody::Impl::add_face(std::int32_t p, std::int32_t f) {
  Piece& piece = *pieces_[static_cast<std::size_t>(p)];
  btSoftBody& body = *piece.body;
  const auto& tri = faces_[static_cast<std::size_t>(f)];
  const bool reset = body.m_bUpdateRtCst;
  body.appendFace(node_of_[static_cast<std::size_t>(tri[0])],
                  node_of_[static_cast<std::size_t>(tri[1])],
                  node_of_[static_cast<std::size_t>(tri[2])]);
  body.m_bUpdateRtCst = reset;
  btSoftBody::Face& face = body.m_faces[body.m_faces.size() - 1];
  face.m_ra = face_ra(face);
  face_piece_[static_cast<std::size_t>(f)] = p;
  face_slot_[static_cast<std::size_t>(f)] = body.m_faces.size() - 1;
  piece.face_id.push_back(f);
}

void SkinnedSoftBody::Impl::remove_face_from_bullet(std::int32_t f) {
  const std::int32_t p = face_piece_[static_cast<std::size_t>(f)];
  if (p < 0) return;
  if (material_.bending_stiffness > 0) {
    // A bending link needs both faces of its edge.
    const auto& tri = faces_[static_cast<std::size_t>(f)];
    for (int k = 0; k < 3; ++k) {
      const auto [a, b] = edge_key(tri[k], tri[(k + 1) % 3]);
      remove_bending(a, b);
      bend_dirty_.emplace_back(a, b);
    }
  }
  remove_face_slot(f);
  ++stats_.removed_faces;
}

void SkinnedSoftBody::Impl::remove_face_slot(std::int32_t f) {
  const std::int32_t p = face_piece_[static_cast<std::size_t>(f)];
  Piece& piece = *pieces_[static_cast<std::size_t>(p)];
  btSoftBody& body = *piece.body;
  const int slot = face_slot_[static_cast<std::size_t>(f)], last = body.m_faces.size() - 1;
  if (body.m_faces[slot].m_leaf) body.m_fdbvt.remove(body.m_faces[slot].m_leaf);
  if (slot != last) {
    body.m_faces[slot] = body.m_faces[last];
    if (body.m_faces[slot].m_leaf) body.m_faces[slot].m_leaf->data = &body.m_faces[slot];
    piece.face_id[static_cast<std::size_t>(slot)] = piece.face_id[static_cast<std::size_t>(last)];
    face_slot_[static_cast<std::size_t>(piece.face_id[static_cast<std::size_t>(slot)])] = slot;
  }
  body.m_faces.pop_back();
  piece.face_id.pop_back();
  face_piece_[static_cast<std::size_t>(f)] = -1;
  face_slot_[static_cast<std::size_t>(f)] = -1;
}

void SkinnedSoftBody::Impl::add_link(std::int32_t p, std::int32_t u, std::int32_t v, double rest) {
  Piece& piece = *pieces_[static_cast<std::size_t>(p)];
  btSoftBody& body = *piece.body;
  const bool reset = body.m_bUpdateRtCst;
  body.appendLink(node_of_[static_cast<std::size_t>(u)], node_of_[static_cast<std::size_t>(v)],
                  nullptr, false);
  body.m_bUpdateRtCst = reset;
  btSoftBody::Link& link = body.m_links[body.m_links.size() - 1];
  link.m_rl = btScalar(rest);
  link.m_c1 = btScalar(rest * rest);
  link_constant(link);
  piece.rest.push_back(rest);
  const auto key = edge_key(u, v);
  piece.link_key.push_back(key);
  piece.link_bend.push_back(0);
  edge_link_.insert(key.first, key.second, body.m_links.size() - 1, true);
  ++stats_.added_links;
}

void SkinnedSoftBody::Impl::add_bending(std::int32_t p, std::int32_t a, std::int32_t b,
                                        std::int32_t c, std::int32_t d, double rest) {
  Piece& piece = *pieces_[static_cast<std::size_t>(p)];
  btSoftBody& body = *piece.body;
  const bool reset = body.m_bUpdateRtCst;
  body.appendLink(node_of_[static_cast<std::size_t>(c)], node_of_[static_cast<std::size_t>(d)],
                  body.m_materials[1], false);
  body.m_bUpdateRtCst = reset;
  btSoftBody::Link& link = body.m_links[body.m_links.size() - 1];
  link.m_bbending = 1;
  link.m_rl = btScalar(rest);
  link.m_c1 = btScalar(rest * rest);
  link_constant(link);
  piece.rest.push_back(rest);
  piece.link_key.emplace_back(a, b);
  piece.link_bend.push_back(1);
  ++piece.bending;
  bend_link_.insert(a, b, body.m_links.size() - 1, true);
  ++stats_.added_bending;
}

void SkinnedSoftBody::Impl::remove_bending(std::int32_t a, std::int32_t b) {
  const std::int32_t li = bend_link_.find(a, b);
  if (li < 0) return;
  const std::int32_t p = piece_of_[static_cast<std::size_t>(a)];
  Piece& piece = *pieces_[static_cast<std::size_t>(p)];
  btSoftBody& body = *piece.body;
  const btSoftBody::Link& l = body.m_links[li];
  const std::int32_t c = piece.node_vertex[static_cast<std::size_t>(l.m_n[0] - &body.m_nodes[0])],
                     d = piece.node_vertex[static_cast<std::size_t>(l.m_n[1] - &body.m_nodes[0])];
  kept_.keep(a, b, std::min(c, d), std::max(c, d), piece.rest[static_cast<std::size_t>(li)], true);
  remove_link(p, li);
  --stats_.removed_links;
  ++stats_.removed_bending;
}

void SkinnedSoftBody::Impl::remove_link(std::int32_t p, std::int32_t li) {
  Piece& piece = *pieces_[static_cast<std::size_t>(p)];
  const auto [a, b] = piece.link_key[static_cast<std::size_t>(li)];
  (piece.link_bend[static_cast<std::size_t>(li)] ? bend_link_ : edge_link_).erase(a, b, li);
  pop_link(p, li);
  ++stats_.removed_links;
}

void SkinnedSoftBody::Impl::pop_link(std::int32_t p, std::int32_t li) {
  // Swap-with-last; the key of the link that fills the hole is updated, li's own is left to
  // the caller.
  Piece& piece = *pieces_[static_cast<std::size_t>(p)];
  btSoftBody& body = *piece.body;
  const int last = body.m_links.size() - 1;
  const auto l = static_cast<std::size_t>(li), e = static_cast<std::size_t>(last);
  piece.bending -= piece.link_bend[l];
  if (li != last) {
    body.m_links[li] = body.m_links[last];
    piece.rest[l] = piece.rest[e];
    piece.link_key[l] = piece.link_key[e];
    piece.link_bend[l] = piece.link_bend[e];
    const auto [a, b] = piece.link_key[l];
    (piece.link_bend[l] ? bend_link_ : edge_link_).insert(a, b, li, true);
  }
  body.m_links.pop_back();
  piece.rest.pop_back();
  piece.link_key.pop_back();
  piece.link_bend.pop_back();
}

void SkinnedSoftBody::Impl::remove_nodes_highest_first(std::span<const std::int32_t> vertices) {
  // The last nodes of a body are popped without a swap (and without re-pointing).
  std::vector<std::int32_t> order(vertices.begin(), vertices.end());
  std::sort(order.begin(), order.end(), [&](std::int32_t x, std::int32_t y) {
    return node_of_[static_cast<std::size_t>(x)] > node_of_[static_cast<std::size_t>(y)];
  });
  for (const auto v : order) remove_node(v);
}

}  // namespace conform::bullet
