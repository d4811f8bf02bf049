// The piece books: making the bodies (one per connected piece), moving a whole piece into a
// new body, detaching a vertex, and the bending links made again after a change.
#include <algorithm>
#include <new>
#include <span>

#include "bullet_surgery.hpp"
#include "conform/mesh/analysis.hpp"
#include "edge_key.hpp"
#include "skinned_soft_body_impl.hpp"

namespace conform::bullet {

/// One whole connected piece on its way into a new body (move_to_new_piece and its steps).
struct SkinnedSoftBody::Impl::PieceMove {
  std::span<const std::int32_t> moving;  // its vertices; node i of the new body is moving[i]
  std::vector<std::int32_t> sources;     // bodies the nodes leave (normally one)
  std::vector<std::int32_t> faces;       // mesh faces, each once
  std::vector<std::vector<std::uint8_t>> marks;  // per source body: per link, 1 if it moves
  std::size_t link_count = 0;                    // links marked
  std::int32_t into = -1;                        // the new body's index
};

SkinnedSoftBody::Impl::Piece& SkinnedSoftBody::Impl::new_piece(std::int32_t parent) {
  const auto slot = std::int32_t(pieces_.size());
  const Piece* from = parent >= 0 && pieces_[static_cast<std::size_t>(parent)] &&
                              pieces_[static_cast<std::size_t>(parent)]->body
                          ? pieces_[static_cast<std::size_t>(parent)].get()
                          : nullptr;
  auto piece = std::make_unique<Piece>();
  // This constructor (unlike the world-info-only one) creates the default material.
  piece->body = std::make_unique<PieceBody>(info_, &pieces_, slot);
  piece->settings = from ? from->settings : defaults_;
  piece->released = from && from->released;
  if (from) piece->release = from->release;
  btSoftBody& body = *piece->body;
  configure_body(body, from);
  link_.add(&body, piece->settings.collision_group, piece->settings.collision_mask);
  Piece& added = pieces_.add(std::move(piece), from ? parent : -1);
  ++stats_.new_pieces;
  return added;
}

void SkinnedSoftBody::Impl::configure_body(btSoftBody& body, const Piece* from) {
  // A split copies its parent's body settings as they are (the application may have changed
  // them); pieces made at construction take the template and the material.
  if (from) {
    const btSoftBody& old = *from->body;
    body.m_cfg = old.m_cfg;
    body.m_materials[0]->m_kLST = old.m_materials[0]->m_kLST;
    if (old.m_materials.size() > 1) body.appendMaterial()->m_kLST = old.m_materials[1]->m_kLST;
    body.m_pose.m_bvolume = old.m_pose.m_bvolume;
    body.getCollisionShape()->setMargin(old.getCollisionShape()->getMargin());
  } else {
    if (defaults_.config) body.m_cfg = *defaults_.config;
    // The membrane's links only carry the topology (inert, c0 = 0).
    body.m_materials[0]->m_kLST =
        membrane_model() ? btScalar(0) : btScalar(material_.link_stiffness);
    if (material_.bending_stiffness > 0)
      body.appendMaterial()->m_kLST = btScalar(material_.bending_stiffness);  // material 1
    // The membrane's damping is skin.attachment_damping, a viscosity in its own units; Bullet's
    // kDP would take a fixed fraction of the momentum every substep on top of it.
    body.m_cfg.kDP = membrane_model() ? btScalar(0) : btScalar(material_.damping);
    body.m_cfg.piterations = material_.position_iterations;
    body.getCollisionShape()->setMargin(btScalar(material_.margin));
  }
  body.setUserPointer(from ? from->settings.user : defaults_.user);
  body.setActivationState(DISABLE_DEACTIVATION);
  // A new btSoftBody asks for Bullet's whole-body reset at its first step; the plugin writes
  // every constant of what it adds (rest lengths, link constants, areas), so none is needed.
  body.m_bUpdateRtCst = false;
}

void SkinnedSoftBody::Impl::build(const mesh::SkinnedMesh& m) {
  reserve_books(m);
  index_faces(m);
  const mesh::Pieces labels = mesh::label_pieces(m);
  const std::vector<std::int32_t> body_of_piece = make_bodies(labels);
  place_nodes(m, labels, body_of_piece);
  place_faces_and_links(m);
  if (material_.bending_stiffness > 0)
    for (std::size_t f = 0; f < faces_.size(); ++f)
      for (int k = 0; k < 3; ++k) {
        const auto [a, b] = edge_key(faces_[f][k], faces_[f][(k + 1) % 3]);
        refresh_bending(a, b);
      }
  for (std::int32_t v = 0; v < m.vertex_count(); ++v)
    if (piece_of_[static_cast<std::size_t>(v)] >= 0) update_node_area(v);
  const auto n = static_cast<std::size_t>(m.vertex_count());
  area_mark_.assign(n, 0);
  seed_mark_.assign(n, 0);
  kept_.clear();
  bend_dirty_.clear();
  stats_ = {};
}

void SkinnedSoftBody::Impl::reserve_books(const mesh::SkinnedMesh& m) {
  // Room for edits to grow the per-vertex and per-face tables in place (a reallocation would
  // copy the whole table during an edit).
  const auto n = static_cast<std::size_t>(m.vertex_count());
  split_.reserve(std::int32_t(2 * n));
  split_.begin(std::int32_t(n));
  for (auto* table : {&piece_of_, &node_of_, &move_slot_}) table->reserve(2 * n);
  detached_.reserve(2 * n);
  for (auto* table : {&area_mark_, &seed_mark_, &pinned_, &kinematic_}) table->reserve(2 * n);
  mass_.reserve(2 * n);
  vertex_faces_.reserve(2 * n);
  faces_.reserve(2 * m.faces.size());
  face_piece_.reserve(2 * m.faces.size());
  face_slot_.reserve(2 * m.faces.size());
  for (auto* table : {&edge_faces_, &edge_link_}) table->reserve(3 * m.faces.size() / 2);
}

void SkinnedSoftBody::Impl::index_faces(const mesh::SkinnedMesh& m) {
  // The shadow faces, each vertex's faces and each edge's face count.
  const auto n = static_cast<std::size_t>(m.vertex_count());
  faces_ = m.faces;
  face_piece_.assign(faces_.size(), -1);
  face_slot_.assign(faces_.size(), -1);
  vertex_faces_.assign(n, {});
  piece_of_.assign(n, -1);
  node_of_.assign(n, -1);
  detached_.reset(n);
  for (std::size_t f = 0; f < faces_.size(); ++f) {
    for (const auto v : faces_[f])
      vertex_faces_[static_cast<std::size_t>(v)].push_back(std::int32_t(f));
    for (int k = 0; k < 3; ++k) {
      const auto [a, b] = edge_key(faces_[f][k], faces_[f][(k + 1) % 3]);
      ++edge_faces_.at(a, b, 0);
    }
  }
}

std::vector<std::int32_t> SkinnedSoftBody::Impl::make_bodies(const mesh::Pieces& labels) {
  // One empty body per piece; its index per piece label.
  std::vector<std::int32_t> piece_index(static_cast<std::size_t>(labels.count));
  std::vector<int> piece_faces(static_cast<std::size_t>(labels.count), 0);
  for (const auto p : labels.face_piece) ++piece_faces[static_cast<std::size_t>(p)];
  for (std::int32_t p = 0; p < labels.count; ++p) {
    btSoftBody& body = *new_piece().body;
    piece_index[static_cast<std::size_t>(p)] = std::int32_t(pieces_.size()) - 1;
    // Empty bodies: reserving moves nothing that is pointed to. Twice the size leaves room for
    // edits (a full array would be copied, and every node pointer re-pointed, when it grows).
    const int faces = piece_faces[static_cast<std::size_t>(p)];
    body.m_nodes.reserve(2 * (faces / 2 + 3));
    body.m_faces.reserve(2 * faces);
    const int links = 2 * (3 * faces / 2 + 3) * (material_.bending_stiffness > 0 ? 2 : 1);
    body.m_links.reserve(links);
    Piece& piece = *pieces_.back();
    piece.node_vertex.reserve(std::size_t(2 * (faces / 2 + 3)));
    piece.face_id.reserve(std::size_t(2 * faces));
    piece.rest.reserve(std::size_t(links));
    piece.link_key.reserve(std::size_t(links));
    piece.link_bend.reserve(std::size_t(links));
  }
  return piece_index;
}

void SkinnedSoftBody::Impl::place_nodes(const mesh::SkinnedMesh& m, const mesh::Pieces& labels,
                                        std::span<const std::int32_t> body_of_piece) {
  for (std::int32_t v = 0; v < m.vertex_count(); ++v) {
    const auto& vf = vertex_faces_[static_cast<std::size_t>(v)];
    if (vf.empty()) {  // no faces: not a node (its mass stays in the books)
      detached_.add(v, m.current.col(v), Eigen::Vector3d::Zero());
      continue;
    }
    add_node(
        body_of_piece[static_cast<std::size_t>(labels.face_piece[static_cast<std::size_t>(vf[0])])],
        v, m.current.col(v), Eigen::Vector3d::Zero());
  }
}

void SkinnedSoftBody::Impl::place_faces_and_links(const mesh::SkinnedMesh& m) {
  for (std::int32_t f = 0; f < std::int32_t(faces_.size()); ++f) {
    const std::int32_t p =
        piece_of_[static_cast<std::size_t>(faces_[static_cast<std::size_t>(f)][0])];
    add_face(p, f);
    for (int k = 0; k < 3; ++k) {
      const auto [a, b] = edge_key(faces_[static_cast<std::size_t>(f)][k],
                                   faces_[static_cast<std::size_t>(f)][(k + 1) % 3]);
      if (edge_link_.find(a, b) < 0)
        add_link(p, a, b,
                 (1 - material_.pretension) * (m.current.col(a) - m.current.col(b)).norm());
    }
  }
}

void SkinnedSoftBody::Impl::drop_empty_pieces() {
  // Pieces left without nodes leave the world.
  for (std::size_t slot = 0; slot < pieces_.size(); ++slot) {
    const auto& piece = pieces_[slot];
    if (!piece || !piece->body || piece->body->m_nodes.size() != 0) continue;
    link_.remove(piece->body.get());
    pieces_.remove(std::int32_t(slot));
  }
}

void SkinnedSoftBody::Impl::detach(std::int32_t v) {
  const Eigen::Vector3d x = position(v), vel = velocity(v);
  remove_node(v);
  detached_.add(v, x, vel);
  ++stats_.detached_nodes;
}

void SkinnedSoftBody::Impl::refresh_bending(std::int32_t a, std::int32_t b) {
  // A bending link across (a, b) iff exactly two faces use the edge, both in the same body;
  // it joins their third vertices. A link of the same vertices removed earlier in this change
  // (a face moved into another body) keeps its rest length.
  if (bend_link_.find(a, b) >= 0) return;
  std::int32_t found[2] = {-1, -1};
  int count = 0;
  for (const auto f : vertex_faces_[static_cast<std::size_t>(a)]) {
    const auto& tri = faces_[static_cast<std::size_t>(f)];
    if (tri[0] != b && tri[1] != b && tri[2] != b) continue;
    if (count < 2) found[count] = f;
    ++count;
  }
  if (count != 2) return;
  const std::int32_t p = face_piece_[static_cast<std::size_t>(found[0])];
  if (p < 0 || face_piece_[static_cast<std::size_t>(found[1])] != p) return;
  const std::int32_t c = third_vertex(faces_[static_cast<std::size_t>(found[0])], a, b),
                     d = third_vertex(faces_[static_cast<std::size_t>(found[1])], a, b);
  if (c < 0 || d < 0 || c == d) return;
  double rest = kept_.find(a, b, std::min(c, d), std::max(c, d), true);
  if (rest < 0) rest = (1 - material_.pretension) * (position(c) - position(d)).norm();
  add_bending(p, a, b, c, d, rest);
}

// --- Moving a whole piece into a new body ---
//
// Every face of a moving vertex moves (the vertices are a whole connected piece), and with them
// every edge and bending link touching them. Nodes, faces and links are copied whole, so that
// state, rest lengths, link constants and face areas carry over bit-exact, with their node
// pointers re-aimed; nothing is recomputed, and Bullet's append functions (which zero and copy
// every element, and set the whole-body reset) are not used.

std::int32_t SkinnedSoftBody::Impl::move_to_new_piece(std::span<const std::int32_t> moving,
                                                      std::int32_t joining,
                                                      std::int32_t added_faces) {
  PieceMove move;
  move.moving = moving;
  gather_move(move);
  mark_moving_links(move);
  open_new_body(move, joining, added_faces);
  copy_moving_nodes(move);
  move_faces(move);
  move_links(move);
  std::vector<btDbvtNode*> pool = leave_old_bodies(move);
  for (std::size_t i = 0; i < moving.size(); ++i) {
    const auto v = static_cast<std::size_t>(moving[i]);
    piece_of_[v] = move.into;
    node_of_[v] = std::int32_t(i);
    move_slot_[v] = -1;
  }
  build_node_tree(*pieces_[static_cast<std::size_t>(move.into)]->body, pool);
  stats_.moved_nodes += std::int32_t(moving.size());
  return move.into;
}

void SkinnedSoftBody::Impl::gather_move(PieceMove& move) {
  // Each moving vertex's slot in the new body, the bodies they leave, and their faces (each
  // once, taken at its first vertex).
  move_slot_.resize(piece_of_.size(), -1);
  for (std::size_t i = 0; i < move.moving.size(); ++i) {
    const auto v = static_cast<std::size_t>(move.moving[i]);
    move_slot_[v] = std::int32_t(i);
    if (std::find(move.sources.begin(), move.sources.end(), piece_of_[v]) == move.sources.end())
      move.sources.push_back(piece_of_[v]);
  }
  move.faces.reserve(2 * move.moving.size() + 16);
  for (const auto v : move.moving)
    for (const auto f : vertex_faces_[static_cast<std::size_t>(v)])
      if (faces_[static_cast<std::size_t>(f)][0] == v &&
          face_piece_[static_cast<std::size_t>(f)] >= 0)
        move.faces.push_back(f);
}

void SkinnedSoftBody::Impl::mark_moving_links(PieceMove& move) {
  // Links to move, marked per source body. Found through the faces' edges (two hash look-ups
  // per edge) or, when the moving nodes are a good part of their body, by one pass over its
  // links (a link moves iff it touches a moving node), which is then cheaper.
  const bool bending = material_.bending_stiffness > 0;
  move.marks.resize(move.sources.size());
  for (std::size_t s = 0; s < move.sources.size(); ++s) {
    const Piece& from = *pieces_[static_cast<std::size_t>(move.sources[s])];
    const btSoftBody& old = *from.body;
    auto& mark = move.marks[s];
    mark.assign(std::size_t(old.m_links.size()), 0);
    if (4 * move.moving.size() >= std::size_t(old.m_nodes.size())) {
      for (int li = 0; li < old.m_links.size(); ++li) {
        const auto w = from.node_vertex[std::size_t(old.m_links[li].m_n[0] - &old.m_nodes[0])];
        if (move_slot_[static_cast<std::size_t>(w)] >= 0)
          mark[std::size_t(li)] = 1, ++move.link_count;
      }
      continue;
    }
    auto take = [&](std::int32_t li) {
      if (li >= 0 && !mark[static_cast<std::size_t>(li)])
        mark[static_cast<std::size_t>(li)] = 1, ++move.link_count;
    };
    for (const auto f : move.faces) {
      if (face_piece_[static_cast<std::size_t>(f)] != move.sources[s]) continue;
      const auto& tri = faces_[static_cast<std::size_t>(f)];
      for (int k = 0; k < 3; ++k) {
        const auto [a, b] = edge_key(tri[k], tri[(k + 1) % 3]);
        take(edge_link_.find(a, b));
        if (bending) take(bend_link_.find(a, b));
      }
    }
  }
}

void SkinnedSoftBody::Impl::open_new_body(PieceMove& move, std::int32_t joining,
                                          std::int32_t added_faces) {
  Piece& into = new_piece(move.sources.empty() ? -1 : move.sources[0]);
  move.into = std::int32_t(pieces_.size()) - 1;
  btSoftBody& body = *into.body;
  // An empty body: reserving moves nothing that is pointed to. Room for what this change still
  // adds (new nodes joining, added faces and their links), little more: Bullet's allocator
  // zeroes every block it hands out (twice), so headroom is not free.
  const bool bending = material_.bending_stiffness > 0;
  const int node_room = int(move.moving.size()) + joining + 16,
            face_room = int(move.faces.size()) + added_faces + 16,
            link_room = int(move.link_count) + 3 * added_faces * (bending ? 2 : 1) + 16;
  // The arrays start in one block of our own: Bullet's allocator zeroes every block it hands
  // out, twice, and these are filled at once. Were they to grow later, Bullet moves them to
  // memory of its own and leaves this block alone.
  auto round = [](std::size_t bytes) { return (bytes + 15) / 16 * 16; };
  const std::size_t node_bytes = round(std::size_t(node_room) * sizeof(btSoftBody::Node)),
                    face_bytes = round(std::size_t(face_room) * sizeof(btSoftBody::Face)),
                    link_bytes = round(std::size_t(link_room) * sizeof(btSoftBody::Link));
  into.storage.reset(static_cast<std::byte*>(
      ::operator new[](node_bytes + face_bytes + link_bytes, std::align_val_t{16})));
  std::byte* at = into.storage.get();
  body.m_nodes.initializeFromBuffer(at, 0, node_room);
  body.m_faces.initializeFromBuffer(at + node_bytes, 0, face_room);
  body.m_links.initializeFromBuffer(at + node_bytes + face_bytes, 0, link_room);
  into.node_vertex.reserve(std::size_t(node_room));
  into.face_id.reserve(std::size_t(face_room));
  into.rest.reserve(std::size_t(link_room));
  into.link_key.reserve(std::size_t(link_room));
  into.link_bend.reserve(std::size_t(link_room));
}

void SkinnedSoftBody::Impl::copy_moving_nodes(PieceMove& move) {
  // Nodes (never reallocated: reserved above); node i is moving[i].
  Piece& into = *pieces_[static_cast<std::size_t>(move.into)];
  btSoftBody& body = *into.body;
  for (std::size_t i = 0; i < move.moving.size(); ++i) {
    const std::int32_t v = move.moving[i];
    body.m_nodes.push_back(body_of(v)->m_nodes[node_of_[static_cast<std::size_t>(v)]]);
    btSoftBody::Node& node = body.m_nodes[int(i)];
    node.m_leaf = nullptr;
    node.m_material = body.m_materials[0];
    into.node_vertex.push_back(v);
  }
}

void SkinnedSoftBody::Impl::move_faces(PieceMove& move) {
  // Faces: copied, then out of the old body (swap-with-last).
  Piece& into = *pieces_[static_cast<std::size_t>(move.into)];
  btSoftBody& body = *into.body;
  for (const auto f : move.faces) {
    const auto fi = static_cast<std::size_t>(f);
    body.m_faces.push_back(
        pieces_[static_cast<std::size_t>(face_piece_[fi])]->body->m_faces[face_slot_[fi]]);
    btSoftBody::Face& face = body.m_faces[body.m_faces.size() - 1];
    for (int k = 0; k < 3; ++k)
      face.m_n[k] = &body.m_nodes[move_slot_[static_cast<std::size_t>(faces_[fi][std::size_t(k)])]];
    face.m_leaf = nullptr;
    face.m_material = body.m_materials[0];
    remove_face_slot(f);
    face_piece_[fi] = move.into;
    face_slot_[fi] = body.m_faces.size() - 1;
    into.face_id.push_back(f);
  }
}

void SkinnedSoftBody::Impl::move_links(PieceMove& move) {
  // Links: copied, then out of the old body, highest index first (the tail is popped without
  // a swap). Their keys stay in the edge maps and get the new index once all have left.
  Piece& into = *pieces_[static_cast<std::size_t>(move.into)];
  btSoftBody& body = *into.body;
  btSoftBody::Material* const material = body.m_materials[0];
  btSoftBody::Material* const bending_material =
      body.m_materials.size() > 1 ? body.m_materials[1] : material;
  for (std::size_t s = 0; s < move.sources.size(); ++s) {
    const std::int32_t p = move.sources[s];
    const Piece& from = *pieces_[static_cast<std::size_t>(p)];
    for (auto li = std::int32_t(move.marks[s].size()); li-- > 0;) {
      if (!move.marks[s][static_cast<std::size_t>(li)]) continue;
      const auto l = static_cast<std::size_t>(li);
      body.m_links.push_back(from.body->m_links[li]);
      btSoftBody::Link& link = body.m_links[body.m_links.size() - 1];
      for (auto& node : link.m_n) {
        const auto w = from.node_vertex[static_cast<std::size_t>(node - &from.body->m_nodes[0])];
        node = &body.m_nodes[move_slot_[static_cast<std::size_t>(w)]];
      }
      link.m_material = from.link_bend[l] ? bending_material : material;
      into.rest.push_back(from.rest[l]);
      into.link_key.push_back(from.link_key[l]);
      into.link_bend.push_back(from.link_bend[l]);
      into.bending += from.link_bend[l];
      pop_link(p, li);  // its key stays, re-aimed below
    }
  }
  for (std::size_t i = 0; i < into.link_key.size(); ++i)
    (into.link_bend[i] ? bend_link_ : edge_link_)
        .insert(into.link_key[i].first, into.link_key[i].second, std::int32_t(i), true);
}

std::vector<btDbvtNode*> SkinnedSoftBody::Impl::leave_old_bodies(PieceMove& move) {
  // Node tree leaves: unlinked from the old trees (one refit pass each afterwards instead of
  // a refit walk per leaf) and kept, with their freed parents, for the new body's tree.
  std::vector<btDbvtNode*> pool;
  pool.reserve(2 * move.moving.size());
  for (const auto v : move.moving) {
    btSoftBody& old = *body_of(v);
    btSoftBody::Node& node = old.m_nodes[node_of_[static_cast<std::size_t>(v)]];
    if (node.m_leaf) unlink_leaf(old.m_ndbvt, node.m_leaf, pool);
    node.m_leaf = nullptr;
  }
  // Out of the old bodies, highest node first (read off the marks, no sort): the last nodes of
  // a body are popped without a swap.
  for (const auto p : move.sources) {
    const Piece& from = *pieces_[static_cast<std::size_t>(p)];
    for (auto i = std::int32_t(from.node_vertex.size()); i-- > 0;)
      if (i < std::int32_t(from.node_vertex.size()) &&
          move_slot_[static_cast<std::size_t>(from.node_vertex[static_cast<std::size_t>(i)])] >= 0)
        remove_node(from.node_vertex[static_cast<std::size_t>(i)]);
  }
  for (const auto p : move.sources)
    refit_tree(pieces_[static_cast<std::size_t>(p)]->body->m_ndbvt.m_root);
  return pool;
}

}  // namespace conform::bullet
