#include "conform/bullet/skinned_soft_body.hpp"

#include <BulletSoftBody/btSoftBody.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <ctime>
#include <limits>
#include <new>
#include <stdexcept>
#include <string>
#include <tuple>

#include "conform/bullet/convert.hpp"
#include "conform/mesh/analysis.hpp"
#include "skinned_soft_body_impl.hpp"

namespace conform::bullet {

namespace {

std::pair<std::int32_t, std::int32_t> edge_key(std::int32_t a, std::int32_t b) {
  return a < b ? std::pair{a, b} : std::pair{b, a};
}

Eigen::Vector3d to_eigen(const btVector3& v) {
  return {v.x(), v.y(), v.z()};
}
btVector3 to_btv(const Eigen::Vector3d& v) {
  return btVector3(btScalar(v.x()), btScalar(v.y()), btScalar(v.z()));
}

void erase_value(std::vector<std::int32_t>& list, std::int32_t value) {
  const auto it = std::find(list.begin(), list.end(), value);
  if (it != list.end()) {
    *it = list.back();
    list.pop_back();
  }
}

}  // namespace

struct SkinnedSoftBody::Impl::Piece {
  // Memory the body's node, face and link arrays start in (see move_to_new_piece); declared
  // first, so it outlives the body (which never frees memory it does not own).
  struct Release {
    void operator()(std::byte* p) const { ::operator delete[](p, std::align_val_t{16}); }
  };
  std::unique_ptr<std::byte[], Release> storage;
  std::unique_ptr<btSoftBody> body;
  std::vector<std::int32_t> node_vertex;  // node index → mesh vertex
  std::vector<double> rest;               // link index → our rest length (Bullet resets its own)
  std::vector<std::pair<std::int32_t, std::int32_t>> link_key;  // link → its key edge (min, max)
  std::vector<std::uint8_t> link_bend;                          // link → 1 for a bending link
  std::vector<std::int32_t> face_id;                            // Bullet face slot → mesh face
  std::int32_t bending = 0;                                     // bending links in this body
  bool reapply = true;  // rest lengths to write at the next update (set when built)
};

namespace {

// Phase timings: CPU time of the calling thread (steadier than wall time on a shared machine;
// the edits run on the caller's thread).
struct Clock {
  using time_point = double;
  static double now() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
  }
};
double seconds_since(double& t) {
  const double now = Clock::now();
  const double s = now - t;
  t = now;
  return s;
}

// Bullet's link constant c0 = (1/m_a + 1/m_b) / kLST (what its updateLinkConstants writes).
// A material with kLST = 0 (the membrane's links) gets c0 = 0, which Bullet's link solve skips.
void link_constant(btSoftBody::Link& l) {
  const btScalar k = l.m_material->m_kLST;
  l.m_c0 = k > 0 ? (l.m_n[0]->m_im + l.m_n[1]->m_im) / k : btScalar(0);
}

// Bullet's face m_ra: twice the triangle's area (its AreaOf).
btScalar face_ra(const btSoftBody::Face& f) {
  return btCross(f.m_n[1]->m_x - f.m_n[0]->m_x, f.m_n[2]->m_x - f.m_n[0]->m_x).length();
}

std::int32_t third_vertex(const mesh::Face& f, std::int32_t a, std::int32_t b) {
  for (const auto v : f)
    if (v != a && v != b) return v;
  return -1;
}

// Spreads the low 10 bits of x to every third bit (Morton code helper).
std::uint32_t spread_bits(std::uint32_t x) {
  x &= 0x3ffu;
  x = (x | (x << 16)) & 0x030000ffu;
  x = (x | (x << 8)) & 0x0300f00fu;
  x = (x | (x << 4)) & 0x030c30c3u;
  x = (x | (x << 2)) & 0x09249249u;
  return x;
}

// Takes a leaf out of its tree without freeing anything: its parent (now redundant, its
// other child takes its place) and the leaf itself go to `pool`, for the tree of another body.
// Unlike btDbvt::remove, no ancestor is refitted here (see refit_tree).
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

// btDbvt::insert without its walk down from the root: the new leaf becomes the sibling of
// `beside` (a leaf of the same tree, e.g. a neighbouring node's), and the ancestors grow as
// btDbvt's own insert grows them.
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

// Recomputes every internal volume from its children (after many leaves were unlinked: one
// pass over the tree instead of a refit walk per leaf).
void refit_tree(btDbvtNode* node) {
  if (!node || node->isleaf()) return;
  refit_tree(node->childs[0]);
  refit_tree(node->childs[1]);
  Merge(node->childs[0]->volume, node->childs[1]->volume, node->volume);
}

// Builds the node tree (m_ndbvt) of a body whose nodes have no leaves yet, in one pass: leaves
// as appendNode makes them (the node's position, the body's margin), joined in Morton order
// into a balanced tree. One insert per node walks the growing tree and costs several times
// more. Tree nodes come from `pool` (nodes unlinked from another tree) and then from
// btAlignedAlloc, as btDbvt's own (it frees them); what the pool has left over is freed.
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

}  // namespace

SkinnedSoftBody::Impl::Impl(btSoftBodyWorldInfo& info, std::function<void(btSoftBody*)> add,
                            std::function<void(btSoftBody*)> remove, const mesh::SkinnedMesh& mesh,
                            const skin::Skeleton& skeleton, const Material& material)
    : info_(&info),
      add_(std::move(add)),
      remove_(std::move(remove)),
      mesh_(mesh),
      skeleton_(skeleton),
      material_(material) {
  const std::int32_t n = mesh_.vertex_count();
  if (n == 0) throw std::invalid_argument("SkinnedSoftBody: empty mesh");
  if (mesh_.current.cols() != n || mesh_.bones.cols() != n || mesh_.weights.cols() != n)
    throw std::invalid_argument(
        "SkinnedSoftBody: current, bones and weights need one column per vertex");
  if (skeleton_.bone_count() == 0) throw std::invalid_argument("SkinnedSoftBody: no bones");
  for (const auto& f : mesh_.faces)
    for (const auto v : f)
      if (v < 0 || v >= n) throw std::invalid_argument("SkinnedSoftBody: face index out of range");
  for (std::int32_t v = 0; v < n; ++v)
    for (int k = 0; k < mesh::kMaxInfluences; ++k)
      if (mesh_.weights(k, v) != 0 &&
          (mesh_.bones(k, v) < 0 || mesh_.bones(k, v) >= skeleton_.bone_count()))
        throw std::invalid_argument("SkinnedSoftBody: bone id out of range at vertex " +
                                    std::to_string(v));
  if (!(material_.pretension >= 0 && material_.pretension < 1))
    throw std::invalid_argument("SkinnedSoftBody: pretension must be in [0, 1)");
  if (!(material_.density > 0)) throw std::invalid_argument("SkinnedSoftBody: density must be > 0");
  if (membrane_model()) {
    material_.skin.validate();  // throws naming the field
    material_.solver.validate();
    material_.density = material_.skin.areal_density;  // the books' masses are the membrane's
  }
  if (!(material_.link_stiffness > 0 && material_.link_stiffness <= 1))
    throw std::invalid_argument("SkinnedSoftBody: link_stiffness must be in (0, 1]");
  if (!(material_.bending_stiffness >= 0 && material_.bending_stiffness <= 1))
    throw std::invalid_argument("SkinnedSoftBody: bending_stiffness must be in [0, 1]");
  adjacency_.build(mesh_);
  face_index_.build(mesh_);
  pose_ = skin::Pose::rest(skeleton_);
  global_.resize(static_cast<std::size_t>(skeleton_.joint_count()));
  versors_.resize(static_cast<std::size_t>(skeleton_.bone_count()));
  kernels_.resize(versors_.size());

  // Masses: a third of each face's area to each of its vertices.
  mass_.assign(static_cast<std::size_t>(n), 0.0);
  for (const auto& f : mesh_.faces) {
    const Eigen::Vector3d a = mesh_.current.col(f[0]), b = mesh_.current.col(f[1]),
                          c = mesh_.current.col(f[2]);
    const double m = material_.density * 0.5 * (b - a).cross(c - a).norm() / 3;
    for (const auto v : f) mass_[static_cast<std::size_t>(v)] += m;
  }
  double sum = 0;
  int count = 0;
  for (const double m : mass_)
    if (m > 0) sum += m, ++count;
  const double fallback = count ? sum / count : material_.density * 1e-6;
  for (double& m : mass_)
    if (!(m > 0)) m = fallback;  // vertices without faces still carry some mass

  pinned_.assign(static_cast<std::size_t>(n), 0);
  kinematic_.resize(static_cast<std::size_t>(n));
  for (std::int32_t v = 0; v < n; ++v)
    kinematic_[static_cast<std::size_t>(v)] = is_kinematic_by_weight(v);
  rebuild_skin_inputs();
  skin_targets(0);
  previous_target_ = target_;
  build(mesh_);
}

SkinnedSoftBody::Impl::~Impl() {
  for (auto& piece : pieces_)
    if (piece) remove_(piece->body.get());
}

bool SkinnedSoftBody::Impl::is_kinematic_by_weight(std::int32_t v) const {
  return !membrane_model() && mesh_.weights(0, v) >= material_.kinematic_weight;
}

SkinnedSoftBody::Impl::Piece& SkinnedSoftBody::Impl::new_piece() {
  auto piece = std::make_unique<Piece>();
  // This constructor (unlike the world-info-only one) creates the default material.
  piece->body = std::make_unique<btSoftBody>(info_, 0, nullptr, nullptr);
  btSoftBody& body = *piece->body;
  // The membrane's links only carry the topology (inert, c0 = 0).
  body.m_materials[0]->m_kLST = membrane_model() ? btScalar(0) : btScalar(material_.link_stiffness);
  if (material_.bending_stiffness > 0)
    body.appendMaterial()->m_kLST = btScalar(material_.bending_stiffness);  // material 1
  body.m_cfg.kDP = btScalar(material_.damping);
  body.m_cfg.piterations = material_.position_iterations;
  body.getCollisionShape()->setMargin(btScalar(material_.margin));
  body.setActivationState(DISABLE_DEACTIVATION);
  // A new btSoftBody asks for Bullet's whole-body reset at its first step; the plugin writes
  // every constant of what it adds (rest lengths, link constants, areas), so none is needed.
  body.m_bUpdateRtCst = false;
  add_(&body);
  pieces_.push_back(std::move(piece));
  ++stats_.new_pieces;
  return *pieces_.back();
}

void SkinnedSoftBody::Impl::build(const mesh::SkinnedMesh& m) {
  const auto n = static_cast<std::size_t>(m.vertex_count());
  // Room for edits to grow the per-vertex and per-face tables in place (a reallocation would
  // copy the whole table during an edit).
  for (auto* table :
       {&piece_of_, &node_of_, &detached_slot_, &search_label_, &move_slot_, &seed_slot_})
    table->reserve(2 * n);
  for (auto* table : {&area_mark_, &seed_mark_, &pinned_, &kinematic_}) table->reserve(2 * n);
  mass_.reserve(2 * n);
  vertex_faces_.reserve(2 * n);
  faces_.reserve(2 * m.faces.size());
  face_piece_.reserve(2 * m.faces.size());
  face_slot_.reserve(2 * m.faces.size());
  for (auto* table : {&edge_faces_, &edge_link_}) table->reserve(3 * m.faces.size() / 2);
  faces_ = m.faces;
  face_piece_.assign(faces_.size(), -1);
  face_slot_.assign(faces_.size(), -1);
  vertex_faces_.assign(n, {});
  piece_of_.assign(n, -1);
  node_of_.assign(n, -1);
  detached_slot_.assign(n, -1);
  search_label_.assign(n, -1);
  for (std::size_t f = 0; f < faces_.size(); ++f) {
    for (const auto v : faces_[f])
      vertex_faces_[static_cast<std::size_t>(v)].push_back(std::int32_t(f));
    for (int k = 0; k < 3; ++k) {
      const auto [a, b] = edge_key(faces_[f][k], faces_[f][(k + 1) % 3]);
      ++edge_faces_.at(a, b, 0);
    }
  }
  const mesh::Pieces labels = mesh::label_pieces(m);
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
  for (std::int32_t v = 0; v < m.vertex_count(); ++v) {
    const auto& vf = vertex_faces_[static_cast<std::size_t>(v)];
    if (vf.empty()) {  // no faces: not a node (its mass stays in the books)
      detached_slot_[static_cast<std::size_t>(v)] = std::int32_t(detached_state_.size());
      detached_state_.emplace_back(m.current.col(v), Eigen::Vector3d::Zero());
      detached_vertex_.push_back(v);
      ++detached_count_;
      continue;
    }
    add_node(
        piece_index[static_cast<std::size_t>(labels.face_piece[static_cast<std::size_t>(vf[0])])],
        v, m.current.col(v), Eigen::Vector3d::Zero());
  }
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
  if (material_.bending_stiffness > 0)
    for (std::size_t f = 0; f < faces_.size(); ++f)
      for (int k = 0; k < 3; ++k) {
        const auto [a, b] = edge_key(faces_[f][k], faces_[f][(k + 1) % 3]);
        refresh_bending(a, b);
      }
  for (std::int32_t v = 0; v < m.vertex_count(); ++v)
    if (piece_of_[static_cast<std::size_t>(v)] >= 0) update_node_area(v);
  area_mark_.assign(n, 0);
  seed_mark_.assign(n, 0);
  seed_slot_.assign(n, -1);
  clear_kept();
  bend_dirty_.clear();
  stats_ = {};
}

// --- Bullet edits. None sets Bullet's whole-body reset (m_bUpdateRtCst): the constants of
// what changed are written here. ---

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
    node.m_x = node.m_q = to_btv(x);
    node.m_material = body.m_materials[0];
    node.m_leaf = insert_leaf_beside(
        body.m_ndbvt, beside, btDbvtVolume::FromCR(node.m_x, body.getCollisionShape()->getMargin()),
        &node);
  } else {
    body.appendNode(to_btv(x), 1);
  }
  btSoftBody::Node& node = body.m_nodes[body.m_nodes.size() - 1];
  node.m_v = to_btv(vel);
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

void SkinnedSoftBody::Impl::detach(std::int32_t v) {
  const auto i = static_cast<std::size_t>(v);
  const Eigen::Vector3d x = position(v), vel = velocity(v);
  remove_node(v);
  detached_slot_[i] = std::int32_t(detached_state_.size());
  detached_state_.emplace_back(x, vel);
  detached_vertex_.push_back(v);
  ++detached_count_;
  ++stats_.detached_nodes;
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
  keep_rest(a, b, std::min(c, d), std::max(c, d), piece.rest[static_cast<std::size_t>(li)], true);
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

void SkinnedSoftBody::Impl::keep_rest(std::int32_t a, std::int32_t b, std::int32_t c,
                                      std::int32_t d, double rest, bool bending) {
  (bending ? relink_bend_ : relink_edge_).insert(a, b, std::int32_t(relink_.size()), true);
  relink_.emplace_back(a, b, c, d, rest);
}

double SkinnedSoftBody::Impl::kept_rest(std::int32_t a, std::int32_t b, std::int32_t c,
                                        std::int32_t d, bool bending) const {
  const std::int32_t i = (bending ? relink_bend_ : relink_edge_).find(a, b);
  if (i < 0) return -1;
  const auto& [ka, kb, kc, kd, rest] = relink_[static_cast<std::size_t>(i)];
  return kc == c && kd == d ? rest : -1;
}

void SkinnedSoftBody::Impl::clear_kept() {
  for (std::size_t i = 0; i < relink_.size(); ++i) {
    const auto& [a, b, c, d, rest] = relink_[i];
    const bool bending = !(a == c && b == d);
    (bending ? relink_bend_ : relink_edge_).erase(a, b, std::int32_t(i));
  }
  relink_.clear();
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
  double rest = kept_rest(a, b, std::min(c, d), std::max(c, d), true);
  if (rest < 0) rest = (1 - material_.pretension) * (position(c) - position(d)).norm();
  add_bending(p, a, b, c, d, rest);
}

void SkinnedSoftBody::Impl::remove_nodes_highest_first(std::span<const std::int32_t> vertices) {
  // The last nodes of a body are popped without a swap (and without re-pointing).
  std::vector<std::int32_t> order(vertices.begin(), vertices.end());
  std::sort(order.begin(), order.end(), [&](std::int32_t x, std::int32_t y) {
    return node_of_[static_cast<std::size_t>(x)] > node_of_[static_cast<std::size_t>(y)];
  });
  for (const auto v : order) remove_node(v);
}

std::int32_t SkinnedSoftBody::Impl::move_to_new_piece(std::span<const std::int32_t> moving,
                                                      std::int32_t joining,
                                                      std::int32_t added_faces) {
  // Every face of a moving vertex moves (the vertices are a whole connected piece), and with
  // them every edge and bending link touching them. Nodes, faces and links are copied whole,
  // so that state, rest lengths, link constants and face areas carry over bit-exact, with their
  // node pointers re-aimed; nothing is recomputed, and Bullet's append functions (which zero
  // and copy every element, and set the whole-body reset) are not used.
  const auto n = static_cast<int>(moving.size());
  move_slot_.resize(piece_of_.size(), -1);
  std::vector<std::int32_t> sources;  // bodies the nodes leave (normally one)
  for (int i = 0; i < n; ++i) {
    const auto v = static_cast<std::size_t>(moving[std::size_t(i)]);
    move_slot_[v] = i;
    if (std::find(sources.begin(), sources.end(), piece_of_[v]) == sources.end())
      sources.push_back(piece_of_[v]);
  }
  std::vector<std::int32_t> faces;  // mesh faces, each once (taken at its first vertex)
  faces.reserve(std::size_t(2 * n + 16));
  for (const auto v : moving)
    for (const auto f : vertex_faces_[static_cast<std::size_t>(v)])
      if (faces_[static_cast<std::size_t>(f)][0] == v &&
          face_piece_[static_cast<std::size_t>(f)] >= 0)
        faces.push_back(f);
  // Links to move, marked per source body. Found through the faces' edges (two hash look-ups
  // per edge) or, when the moving nodes are a good part of their body, by one pass over its
  // links (a link moves iff it touches a moving node), which is then cheaper.
  const bool bending = material_.bending_stiffness > 0;
  std::vector<std::vector<std::uint8_t>> marks(sources.size());
  std::size_t link_count = 0;
  for (std::size_t s = 0; s < sources.size(); ++s) {
    const Piece& from = *pieces_[static_cast<std::size_t>(sources[s])];
    const btSoftBody& old = *from.body;
    auto& mark = marks[s];
    mark.assign(std::size_t(old.m_links.size()), 0);
    if (4 * std::size_t(n) >= std::size_t(old.m_nodes.size())) {
      for (int li = 0; li < old.m_links.size(); ++li) {
        const auto w = from.node_vertex[std::size_t(old.m_links[li].m_n[0] - &old.m_nodes[0])];
        if (move_slot_[static_cast<std::size_t>(w)] >= 0) mark[std::size_t(li)] = 1, ++link_count;
      }
      continue;
    }
    auto take = [&](std::int32_t li) {
      if (li >= 0 && !mark[static_cast<std::size_t>(li)])
        mark[static_cast<std::size_t>(li)] = 1, ++link_count;
    };
    for (const auto f : faces) {
      if (face_piece_[static_cast<std::size_t>(f)] != sources[s]) continue;
      const auto& tri = faces_[static_cast<std::size_t>(f)];
      for (int k = 0; k < 3; ++k) {
        const auto [a, b] = edge_key(tri[k], tri[(k + 1) % 3]);
        take(edge_link_.find(a, b));
        if (bending) take(bend_link_.find(a, b));
      }
    }
  }

  Piece& into = new_piece();
  const auto into_index = std::int32_t(pieces_.size()) - 1;
  btSoftBody& body = *into.body;
  // An empty body: reserving moves nothing that is pointed to. Room for what this change still
  // adds (new nodes joining, added faces and their links), little more: Bullet's allocator
  // zeroes every block it hands out (twice), so headroom is not free.
  const int node_room = n + joining + 16, face_room = int(faces.size()) + added_faces + 16,
            link_room = int(link_count) + 3 * added_faces * (bending ? 2 : 1) + 16;
  {
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
  }
  into.node_vertex.reserve(std::size_t(node_room));
  into.face_id.reserve(std::size_t(face_room));
  into.rest.reserve(std::size_t(link_room));
  into.link_key.reserve(std::size_t(link_room));
  into.link_bend.reserve(std::size_t(link_room));
  btSoftBody::Material* const material = body.m_materials[0];
  btSoftBody::Material* const bending_material =
      body.m_materials.size() > 1 ? body.m_materials[1] : material;

  // Nodes (never reallocated: reserved above); node i is moving[i].
  for (int i = 0; i < n; ++i) {
    const auto v = static_cast<std::size_t>(moving[std::size_t(i)]);
    body.m_nodes.push_back(body_of(moving[std::size_t(i)])->m_nodes[node_of_[v]]);
    btSoftBody::Node& node = body.m_nodes[i];
    node.m_leaf = nullptr;
    node.m_material = material;
    into.node_vertex.push_back(moving[std::size_t(i)]);
  }
  // Faces: copied, then out of the old body (swap-with-last).
  for (const auto f : faces) {
    const auto fi = static_cast<std::size_t>(f);
    body.m_faces.push_back(
        pieces_[static_cast<std::size_t>(face_piece_[fi])]->body->m_faces[face_slot_[fi]]);
    btSoftBody::Face& face = body.m_faces[body.m_faces.size() - 1];
    for (int k = 0; k < 3; ++k)
      face.m_n[k] = &body.m_nodes[move_slot_[static_cast<std::size_t>(faces_[fi][std::size_t(k)])]];
    face.m_leaf = nullptr;
    face.m_material = material;
    remove_face_slot(f);
    face_piece_[fi] = into_index;
    face_slot_[fi] = body.m_faces.size() - 1;
    into.face_id.push_back(f);
  }
  // Links: copied, then out of the old body, highest index first (the tail is popped without
  // a swap). Their keys stay in the edge maps and get the new index once all have left.
  for (std::size_t s = 0; s < sources.size(); ++s) {
    const std::int32_t p = sources[s];
    const Piece& from = *pieces_[static_cast<std::size_t>(p)];
    for (auto li = std::int32_t(marks[s].size()); li-- > 0;) {
      if (!marks[s][static_cast<std::size_t>(li)]) continue;
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
  // Node tree leaves: unlinked from the old trees (one refit pass each afterwards instead of
  // a refit walk per leaf) and reused, with their freed parents, for the new body's tree.
  std::vector<btDbvtNode*> pool;
  pool.reserve(std::size_t(2 * n));
  for (const auto v : moving) {
    btSoftBody& old = *body_of(v);
    btSoftBody::Node& node = old.m_nodes[node_of_[static_cast<std::size_t>(v)]];
    if (node.m_leaf) unlink_leaf(old.m_ndbvt, node.m_leaf, pool);
    node.m_leaf = nullptr;
  }
  // Out of the old bodies, highest node first (read off the marks, no sort): the last nodes of
  // a body are popped without a swap.
  for (const auto p : sources) {
    const Piece& from = *pieces_[static_cast<std::size_t>(p)];
    for (auto i = std::int32_t(from.node_vertex.size()); i-- > 0;)
      if (i < std::int32_t(from.node_vertex.size()) &&
          move_slot_[static_cast<std::size_t>(from.node_vertex[static_cast<std::size_t>(i)])] >= 0)
        remove_node(from.node_vertex[static_cast<std::size_t>(i)]);
  }
  for (const auto p : sources)
    refit_tree(pieces_[static_cast<std::size_t>(p)]->body->m_ndbvt.m_root);
  for (int i = 0; i < n; ++i) {
    const auto v = static_cast<std::size_t>(moving[std::size_t(i)]);
    piece_of_[v] = into_index;
    node_of_[v] = i;
    move_slot_[v] = -1;
  }
  build_node_tree(body, pool);
  stats_.moved_nodes += n;
  return into_index;
}

void SkinnedSoftBody::Impl::mirror(const mesh::TopologyChange& change) {
  membrane_.invalidate();
  auto clock = Clock::now();
  auto& sec = stats_.seconds;
  const std::int32_t v0 = change.base_vertex_count;
  if (v0 != std::int32_t(piece_of_.size()) || change.base_face_count != std::int32_t(faces_.size()))
    throw std::logic_error("SkinnedSoftBody: change does not match the mirrored mesh");
  const auto nnew = static_cast<std::int32_t>(change.new_vertices.size());
  const auto total = static_cast<std::size_t>(v0 + nnew);
  if (mesh_.vertex_count() < v0 + nnew)
    throw std::logic_error("SkinnedSoftBody: mesh lacks the change's new vertices");
  const bool bending = material_.bending_stiffness > 0;
  clear_kept();
  bend_dirty_.clear();

  // 1. New vertices: x and v interpolated from the parents; mass taken from the parents in
  // proportion to the same coefficients, so Σm and Σm·v are unchanged exactly.
  std::vector<Eigen::Vector3d> nx(static_cast<std::size_t>(nnew)),
      nv(static_cast<std::size_t>(nnew));
  piece_of_.resize(total, -1);
  node_of_.resize(total, -1);
  detached_slot_.resize(total, -1);
  search_label_.resize(total, -1);
  mass_.resize(total, 0);
  pinned_.resize(total, 0);
  kinematic_.resize(total, 0);
  vertex_faces_.resize(total);
  for (std::size_t v = std::size_t(v0); v < total; ++v)
    vertex_faces_[v].reserve(8);      // one allocation
  std::vector<std::int32_t> touched;  // old vertices whose mass changed
  auto pos = [&](std::int32_t p) {
    return p < v0 ? position(p) : nx[static_cast<std::size_t>(p - v0)];
  };
  auto vel = [&](std::int32_t p) {
    return p < v0 ? velocity(p) : nv[static_cast<std::size_t>(p - v0)];
  };
  for (std::int32_t i = 0; i < nnew; ++i) {
    const auto& nvx = change.new_vertices[static_cast<std::size_t>(i)];
    const std::int32_t id = v0 + i;
    Eigen::Vector3d x = nvx.displacement, v = Eigen::Vector3d::Zero();
    double share = std::numeric_limits<double>::infinity();
    bool pinned = false;
    for (int j = 0; j < 3; ++j) {
      const std::int32_t p = nvx.parents[static_cast<std::size_t>(j)];
      const double c = nvx.coefficients[static_cast<std::size_t>(j)];
      if (p < 0) continue;
      x += c * pos(p);
      v += c * vel(p);
      if (c > 0) share = std::min(share, mass_[static_cast<std::size_t>(p)] / c);
      pinned = pinned || (pinned_[static_cast<std::size_t>(p)] && c > 0);
    }
    const double mu = std::isfinite(share) ? 0.5 * share : 0.0;
    for (int j = 0; j < 3; ++j) {
      const std::int32_t p = nvx.parents[static_cast<std::size_t>(j)];
      const double c = nvx.coefficients[static_cast<std::size_t>(j)];
      if (p < 0 || !(c > 0)) continue;
      mass_[static_cast<std::size_t>(p)] -= c * mu;
      if (p < v0) touched.push_back(p);
    }
    mass_[static_cast<std::size_t>(id)] = mu;
    nx[static_cast<std::size_t>(i)] = x;
    nv[static_cast<std::size_t>(i)] = v;
    // A new vertex between pinned vertices (e.g. on a pinned border) stays pinned.
    pinned_[static_cast<std::size_t>(id)] = pinned;
    kinematic_[static_cast<std::size_t>(id)] = pinned || is_kinematic_by_weight(id);
  }
  sec.vertices += seconds_since(clock);

  // 2. Removed faces leave Bullet; edges no face uses any more lose their link (kept aside:
  // an edge that comes back in the same change keeps its rest length).
  std::vector<std::int32_t> seeds;  // vertices around the change (their pieces may split)
  seed_mark_.resize(total, 0);
  seed_slot_.resize(total, -1);
  auto seed = [&](std::int32_t v) {
    auto& slot = seed_slot_[static_cast<std::size_t>(v)];
    if (slot < 0) slot = std::int32_t(seeds.size()), seeds.push_back(v);
  };
  // Clusters of removed faces (sharing vertices), over the seeds they make: a union-find.
  std::vector<std::int32_t> cluster;
  auto cluster_root = [&](std::int32_t i) {
    while (cluster[static_cast<std::size_t>(i)] != i)
      i = cluster[static_cast<std::size_t>(i)] =
          cluster[static_cast<std::size_t>(cluster[static_cast<std::size_t>(i)])];
    return i;
  };
  std::vector<std::pair<std::int32_t, std::int32_t>> dropped;
  for (const auto f : change.removed_faces) {
    const auto tri = faces_[static_cast<std::size_t>(f)];
    remove_face_from_bullet(f);
    std::int32_t first = -1;
    for (int k = 0; k < 3; ++k) {
      erase_value(vertex_faces_[static_cast<std::size_t>(tri[k])], f);
      seed(tri[k]);
      cluster.resize(seeds.size(), -1);
      const std::int32_t slot = seed_slot_[static_cast<std::size_t>(tri[k])];
      if (cluster[static_cast<std::size_t>(slot)] < 0)
        cluster[static_cast<std::size_t>(slot)] = slot;
      if (first < 0)
        first = cluster_root(slot);
      else
        cluster[static_cast<std::size_t>(cluster_root(slot))] = first;
      const auto [a, b] = edge_key(tri[k], tri[(k + 1) % 3]);
      std::int32_t& count = edge_faces_.at(a, b, 0);
      if (--count <= 0) {
        edge_faces_.erase(a, b, count);
        dropped.emplace_back(a, b);
      }
    }
  }
  for (const auto& [a, b] : dropped) {
    const std::int32_t li = edge_link_.find(a, b);
    if (li < 0) continue;
    const std::int32_t p = piece_of_[static_cast<std::size_t>(a)];
    keep_rest(a, b, a, b, pieces_[static_cast<std::size_t>(p)]->rest[std::size_t(li)], false);
    remove_link(p, li);
  }

  // 3. The face slots, exactly as mesh::apply does them (topology_change.hpp).
  std::vector<std::int32_t> pending;  // mesh faces to add to Bullet
  const std::size_t nr = change.removed_faces.size(), na = change.added_faces.size(),
                    nk = std::min(nr, na);
  for (std::size_t i = 0; i < nk; ++i) {
    const std::int32_t f = change.removed_faces[i];
    faces_[static_cast<std::size_t>(f)] = change.added_faces[i];
    pending.push_back(f);
  }
  for (std::size_t i = nk; i < na; ++i) {
    faces_.push_back(change.added_faces[i]);
    face_piece_.push_back(-1);
    face_slot_.push_back(-1);
    pending.push_back(std::int32_t(faces_.size()) - 1);
  }
  for (std::size_t i = nr; i-- > nk;) {
    const std::int32_t slot = change.removed_faces[i];
    const std::int32_t last = std::int32_t(faces_.size()) - 1;
    if (slot != last) {
      const auto s = static_cast<std::size_t>(slot), l = static_cast<std::size_t>(last);
      faces_[s] = faces_[l];
      face_piece_[s] = face_piece_[l];
      face_slot_[s] = face_slot_[l];
      if (face_piece_[s] >= 0)
        pieces_[static_cast<std::size_t>(face_piece_[s])]
            ->face_id[static_cast<std::size_t>(face_slot_[s])] = slot;
      for (const auto v : faces_[s]) {
        auto& list = vertex_faces_[static_cast<std::size_t>(v)];
        std::replace(list.begin(), list.end(), last, slot);
      }
    }
    faces_.pop_back();
    face_piece_.pop_back();
    face_slot_.pop_back();
  }
  // Per pending face, a bit per edge that no face used until now: only such an edge lacks a
  // link (an edge that kept a face kept its link), so only these are looked up again below.
  std::vector<std::uint8_t> new_edges(pending.size(), 0);
  for (std::size_t i = 0; i < pending.size(); ++i) {
    const auto& tri = faces_[static_cast<std::size_t>(pending[i])];
    for (int k = 0; k < 3; ++k) {
      vertex_faces_[static_cast<std::size_t>(tri[k])].push_back(pending[i]);
      seed(tri[k]);
      const auto [a, b] = edge_key(tri[k], tri[(k + 1) % 3]);
      if (++edge_faces_.at(a, b, 0) == 1) new_edges[i] |= std::uint8_t(1u << k);
    }
  }
  stats_.added_faces += std::int32_t(pending.size());
  stats_.new_nodes += nnew;
  for (std::int32_t i = 0; i < nnew; ++i) seed(v0 + i);
  for (const auto v : seeds) seed_slot_[static_cast<std::size_t>(v)] = -1;
  sec.faces += seconds_since(clock);

  // 4. Connected pieces around the change. A piece can only split where faces changed, so one
  // search starts at every changed vertex; searches that meet merge into a group, and they
  // advance in turn, one vertex each, until at most one group is still growing. The exhausted
  // groups are complete pieces (no larger than the growing one, up to the turn order); the
  // growing one is the rest of its body, which keeps its btSoftBody unexplored. Only if that
  // group reaches vertices of two bodies (a merge) or of none is it explored to the end.
  struct Search {
    std::vector<std::int32_t> queue;  // the vertices it labelled, in order
    std::size_t head = 0;             // queue[head..] are still to expand
    std::int32_t root;
  };
  std::vector<Search> searches;
  auto root_of = [&](std::int32_t s) {
    while (searches[static_cast<std::size_t>(s)].root != s) {
      auto& r = searches[static_cast<std::size_t>(s)].root;
      r = searches[static_cast<std::size_t>(r)].root;
      s = r;
    }
    return s;
  };
  for (const auto v : seeds) {
    const auto i = static_cast<std::size_t>(v);
    if (vertex_faces_[i].empty() || search_label_[i] >= 0) continue;
    search_label_[i] = std::int32_t(searches.size());
    searches.push_back({{v}, 0, std::int32_t(searches.size())});
  }
  std::vector<std::int32_t> active;
  for (std::size_t s = 0; s < searches.size(); ++s) active.push_back(std::int32_t(s));
  // Per root: its searches that still have vertices to expand; groups with any.
  std::vector<std::int32_t> pending_in(searches.size(), 1);
  auto growing = std::int32_t(searches.size());
  std::int32_t open_root = -1, open_piece = -1;
  bool to_the_end = false;
  // A shorter proof that nothing split, for changes inside one body (say a drill through both
  // walls of the arm, whose two holes' searches would only meet by growing around it): the body
  // was connected, and an old path can only have used removed faces within one cluster of
  // them (removed faces sharing vertices), entering and leaving at vertices of that cluster
  // that keep faces. So once each cluster's surviving vertices are in one group, every old
  // vertex that keeps faces is still connected to all others; groups that hold one are the
  // body, and a group of new vertices only is a piece of its own once exhausted (until then
  // the proof waits).
  std::vector<std::uint8_t> has_old(searches.size(), 0);
  std::int32_t only_piece = -1;
  bool one_body = true;
  for (std::size_t s = 0; s < searches.size(); ++s) {
    const std::int32_t v = searches[s].queue[0];
    if (v >= v0) continue;
    has_old[s] = 1;
    const std::int32_t p = piece_of_[static_cast<std::size_t>(v)];
    if (p < 0 || (only_piece >= 0 && p != only_piece)) one_body = false;
    only_piece = p;
  }
  one_body = one_body && only_piece >= 0;
  std::vector<std::int32_t> boundary;  // seed indices of removed faces' vertices that keep faces
  for (std::size_t i = 0; i < cluster.size(); ++i)
    if (!vertex_faces_[static_cast<std::size_t>(seeds[i])].empty())
      boundary.push_back(std::int32_t(i));
  std::vector<std::int32_t> cluster_group(cluster.size(), -1);
  // The proof needs each cluster in one group, so it is only tried with no more groups growing
  // than there are clusters (a cut's single ring never: the search must end the other way).
  std::int32_t clusters = 0;
  for (const auto i : boundary) {
    auto& g = cluster_group[static_cast<std::size_t>(cluster_root(i))];
    if (g < 0) g = 0, ++clusters;
  }
  for (const auto i : boundary) cluster_group[static_cast<std::size_t>(cluster_root(i))] = -1;
  auto body_unbroken = [&]() {
    bool proven = true;
    for (const auto i : boundary) {
      auto& g = cluster_group[static_cast<std::size_t>(cluster_root(i))];
      const std::int32_t r =
          root_of(search_label_[static_cast<std::size_t>(seeds[static_cast<std::size_t>(i)])]);
      if (g < 0) g = r;
      if (g != r) {
        proven = false;
        break;
      }
    }
    for (const auto i : boundary) cluster_group[static_cast<std::size_t>(cluster_root(i))] = -1;
    for (std::size_t k = 0; k < active.size() && proven; ++k)
      proven = has_old[static_cast<std::size_t>(root_of(active[k]))];
    return proven;
  };
  bool merged = false;
  while (!active.empty()) {
    if (merged && one_body && !to_the_end && growing > 1 && growing <= clusters &&
        body_unbroken()) {
      // One group for the body: every group holding an old vertex.
      open_piece = only_piece;
      for (std::size_t s = 0; s < searches.size(); ++s) {
        const std::int32_t r = root_of(std::int32_t(s));
        if (!has_old[static_cast<std::size_t>(r)]) continue;
        if (open_root < 0) open_root = r;
        searches[static_cast<std::size_t>(r)].root = open_root;
      }
      break;
    }
    merged = false;
    if (growing == 1 && !to_the_end) {
      // Which bodies does the growing group touch so far?
      const std::int32_t root = root_of(active[0]);
      std::int32_t piece = -1;
      bool several = false;
      for (std::size_t s = 0; s < searches.size() && !several; ++s) {
        if (root_of(std::int32_t(s)) != root) continue;
        for (const auto v : searches[s].queue) {
          const std::int32_t p = piece_of_[static_cast<std::size_t>(v)];
          if (p < 0) continue;
          if (piece >= 0 && p != piece) several = true;
          piece = p;
        }
      }
      if (piece >= 0 && !several) {
        open_root = root;
        open_piece = piece;
        break;
      }
      to_the_end = true;
    }
    std::size_t kept = 0;
    for (const auto s : active) {
      auto& search = searches[static_cast<std::size_t>(s)];
      const std::int32_t u = search.queue[search.head++];
      std::int32_t rs = root_of(s);
      // Only the vertex after u in each of its faces: a face's vertices form a cycle under
      // "next", so its others are reached (and any other group labelling one of them is met)
      // from there, a third of the look-ups of all three.
      for (const auto f : vertex_faces_[static_cast<std::size_t>(u)]) {
        const auto& tri = faces_[static_cast<std::size_t>(f)];
        const std::int32_t w = tri[0] == u ? tri[1] : tri[1] == u ? tri[2] : tri[0];
        std::int32_t& label = search_label_[static_cast<std::size_t>(w)];
        if (label < 0) {
          label = s;
          auto& grow = searches[static_cast<std::size_t>(s)];
          grow.queue.push_back(w);
          if (w < v0) has_old[static_cast<std::size_t>(rs)] = 1;
          continue;
        }
        if (label == s) continue;
        const std::int32_t rw = root_of(label);
        if (rw == rs) continue;
        const std::int32_t r = std::min(rw, rs), o = std::max(rw, rs);
        merged = true;
        has_old[static_cast<std::size_t>(r)] |= has_old[static_cast<std::size_t>(o)];
        auto& pr = pending_in[static_cast<std::size_t>(r)];
        auto& po = pending_in[static_cast<std::size_t>(o)];
        if (pr > 0 && po > 0) --growing;
        pr += po;
        po = 0;
        searches[static_cast<std::size_t>(o)].root = r;
        rs = r;
      }
      if (searches[static_cast<std::size_t>(s)].head <
          searches[static_cast<std::size_t>(s)].queue.size())
        active[kept++] = s;
      else if (--pending_in[static_cast<std::size_t>(rs)] == 0)
        --growing;
    }
    active.resize(kept);
  }
  // Complete groups, as lists of vertices.
  std::vector<std::int32_t> group_of_root(searches.size(), -1);
  std::vector<std::vector<std::int32_t>> components;
  for (std::size_t s = 0; s < searches.size(); ++s) {
    stats_.searched_vertices += std::int32_t(searches[s].queue.size());
    const std::int32_t r = root_of(std::int32_t(s));
    if (r == open_root) continue;
    auto& g = group_of_root[static_cast<std::size_t>(r)];
    if (g < 0) {
      g = std::int32_t(components.size());
      components.emplace_back();
    }
    auto& list = components[static_cast<std::size_t>(g)];
    list.insert(list.end(), searches[s].queue.begin(), searches[s].queue.end());
  }

  // The growing group keeps its body. Each other body goes to the complete group holding most
  // of its nodes; a group wanted by two bodies (a merge) goes to the one with more nodes there;
  // the remaining groups become new bodies.
  std::vector<std::int32_t> owner(components.size(), -1), owner_count(components.size(), 0);
  {
    std::vector<std::pair<std::int32_t, std::int32_t>> best;  // per piece: (component, count)
    std::vector<std::int32_t> pieces_seen;
    for (std::size_t c = 0; c < components.size(); ++c) {
      std::vector<std::pair<std::int32_t, std::int32_t>> counts;
      for (const auto v : components[c]) {
        const std::int32_t p = piece_of_[static_cast<std::size_t>(v)];
        if (p < 0 || p == open_piece) continue;
        auto it = std::find_if(counts.begin(), counts.end(), [&](auto& e) { return e.first == p; });
        if (it == counts.end())
          counts.emplace_back(p, 1);
        else
          ++it->second;
      }
      for (const auto& [p, n] : counts) {
        auto it = std::find(pieces_seen.begin(), pieces_seen.end(), p);
        if (it == pieces_seen.end()) {
          pieces_seen.push_back(p);
          best.emplace_back(std::int32_t(c), n);
        } else {
          auto& b = best[static_cast<std::size_t>(it - pieces_seen.begin())];
          if (n > b.second) b = {std::int32_t(c), n};
        }
      }
    }
    for (std::size_t i = 0; i < pieces_seen.size(); ++i) {
      const auto [c, n] = best[i];
      if (n > owner_count[static_cast<std::size_t>(c)]) {
        owner[static_cast<std::size_t>(c)] = pieces_seen[i];
        owner_count[static_cast<std::size_t>(c)] = n;
      }
    }
  }
  sec.pieces += seconds_since(clock);

  // 5. Moves (splits and merges): the moving nodes' faces and links leave their old body, the
  // nodes follow with x, v and mass exactly, and the faces and links are rebuilt in the new one.
  std::vector<std::int32_t> moved_faces;
  std::vector<std::tuple<std::int32_t, std::int32_t, double>> moved_links;  // (a, b, rest)
  for (std::size_t c = 0; c < components.size(); ++c) {
    std::vector<std::int32_t> moving;
    for (const auto v : components[c]) {
      const std::int32_t p = piece_of_[static_cast<std::size_t>(v)];
      if (p >= 0 && p != owner[c]) moving.push_back(v);
    }
    if (moving.empty()) continue;
    if (owner[c] < 0) {
      // A piece of its own: copied whole into a new body.
      owner[c] = move_to_new_piece(moving, std::int32_t(components[c].size() - moving.size()),
                                   std::int32_t(pending.size()));
      continue;
    }
    std::vector<btSoftBody::Node> state;
    for (const auto v : moving) {
      for (const auto f : vertex_faces_[static_cast<std::size_t>(v)]) {
        if (face_piece_[static_cast<std::size_t>(f)] < 0) continue;
        const auto tri = faces_[static_cast<std::size_t>(f)];
        remove_face_from_bullet(f);
        --stats_.removed_faces;  // re-added below: counted as moved, not removed
        moved_faces.push_back(f);
        for (int k = 0; k < 3; ++k) {
          const auto [a, b] = edge_key(tri[k], tri[(k + 1) % 3]);
          const std::int32_t li = edge_link_.find(a, b);
          if (li < 0) continue;  // moved already (from the face across)
          const std::int32_t lp = piece_of_[static_cast<std::size_t>(a)];
          moved_links.emplace_back(
              a, b, pieces_[static_cast<std::size_t>(lp)]->rest[static_cast<std::size_t>(li)]);
          remove_link(lp, li);
          --stats_.removed_links;
        }
      }
      state.push_back(body_of(v)->m_nodes[node_of_[static_cast<std::size_t>(v)]]);
    }
    remove_nodes_highest_first(moving);
    for (std::size_t i = 0; i < moving.size(); ++i) {
      add_node(owner[c], moving[i], to_eigen(state[i].m_x), to_eigen(state[i].m_v));
      // Bit-exact copy (the double round trip is exact, but say so in code).
      btSoftBody::Node& node =
          body_of(moving[i])->m_nodes[node_of_[static_cast<std::size_t>(moving[i])]];
      node.m_x = state[i].m_x;
      node.m_q = state[i].m_q;
      node.m_v = state[i].m_v;
    }
    stats_.moved_nodes += std::int32_t(moving.size());
  }
  sec.split += seconds_since(clock);

  // 6. Old vertices left without faces leave Bullet; new nodes join their group's body (a new
  // vertex without faces is detached at once).
  for (const auto v : seeds)
    if (v < v0 && piece_of_[static_cast<std::size_t>(v)] >= 0 &&
        vertex_faces_[static_cast<std::size_t>(v)].empty())
      detach(v);
  for (std::int32_t i = 0; i < nnew; ++i) {
    const std::int32_t id = v0 + i;
    const std::int32_t label = search_label_[static_cast<std::size_t>(id)];
    if (label < 0) {
      detached_slot_[static_cast<std::size_t>(id)] = std::int32_t(detached_state_.size());
      detached_state_.emplace_back(nx[static_cast<std::size_t>(i)],
                                   nv[static_cast<std::size_t>(i)]);
      detached_vertex_.push_back(id);
      ++detached_count_;
      ++stats_.detached_nodes;
      continue;
    }
    const std::int32_t r = root_of(label);
    std::int32_t p = open_piece;
    if (r != open_root) {
      auto& o = owner[static_cast<std::size_t>(group_of_root[static_cast<std::size_t>(r)])];
      if (o < 0) {
        new_piece();
        o = std::int32_t(pieces_.size()) - 1;
      }
      p = o;
    }
    std::int32_t near = -1;  // a parent in the same body, whose tree leaf it joins
    for (const auto q : change.new_vertices[static_cast<std::size_t>(i)].parents)
      if (q >= 0 && piece_of_[static_cast<std::size_t>(q)] == p) {
        near = q;
        break;
      }
    add_node(p, id, nx[static_cast<std::size_t>(i)], nv[static_cast<std::size_t>(i)], near);
  }
  for (const auto& s : searches)
    for (const auto v : s.queue) search_label_[static_cast<std::size_t>(v)] = -1;
  for (const auto v : touched) {  // once each (seed_mark_ is clear here)
    auto& mark = seed_mark_[static_cast<std::size_t>(v)];
    if (!mark) mark = 1, set_node_mass(v);
  }
  for (const auto v : touched) seed_mark_[static_cast<std::size_t>(v)] = 0;

  // 7. Faces and links into Bullet; a moved link keeps its rest length, a new one gets
  // (1 − s) × its current length. Then bending links of the edges whose faces changed.
  for (const auto f : moved_faces)
    add_face(piece_of_[static_cast<std::size_t>(faces_[static_cast<std::size_t>(f)][0])], f);
  for (const auto& [a, b, rest] : moved_links) {
    add_link(piece_of_[static_cast<std::size_t>(a)], a, b, rest);
    --stats_.added_links;
  }
  if (bending)
    for (const auto f : moved_faces) {
      const auto& tri = faces_[static_cast<std::size_t>(f)];
      for (int k = 0; k < 3; ++k) bend_dirty_.push_back(edge_key(tri[k], tri[(k + 1) % 3]));
    }
  for (std::size_t i = 0; i < pending.size(); ++i) {
    const std::int32_t f = pending[i];
    if (face_piece_[static_cast<std::size_t>(f)] >= 0) continue;
    const auto tri = faces_[static_cast<std::size_t>(f)];
    const std::int32_t p = piece_of_[static_cast<std::size_t>(tri[0])];
    add_face(p, f);
    for (int k = 0; k < 3; ++k) {
      const auto [a, b] = edge_key(tri[k], tri[(k + 1) % 3]);
      if (bending) bend_dirty_.emplace_back(a, b);
      if (!(new_edges[i] >> k & 1u)) continue;  // it has its link
      const double kept = kept_rest(a, b, a, b, false);
      if (kept >= 0) {
        add_link(p, a, b, kept);
        --stats_.added_links;
      } else {
        add_link(p, a, b, (1 - material_.pretension) * (position(a) - position(b)).norm());
      }
    }
  }
  if (bending) {
    std::sort(bend_dirty_.begin(), bend_dirty_.end());
    bend_dirty_.erase(std::unique(bend_dirty_.begin(), bend_dirty_.end()), bend_dirty_.end());
    for (const auto& [a, b] : bend_dirty_) refresh_bending(a, b);
  }
  area_mark_.resize(total, 0);
  auto area = [&](std::int32_t v) {
    auto& mark = area_mark_[static_cast<std::size_t>(v)];
    if (!mark) mark = 1, update_node_area(v);
  };
  for (const auto v : seeds) area(v);
  for (const auto f : pending)
    for (const auto v : faces_[static_cast<std::size_t>(f)]) area(v);
  for (const auto v : seeds) area_mark_[static_cast<std::size_t>(v)] = 0;
  for (const auto f : moved_faces)
    for (const auto v : faces_[static_cast<std::size_t>(f)]) area(v);
  for (const auto f : moved_faces)
    for (const auto v : faces_[static_cast<std::size_t>(f)])
      area_mark_[static_cast<std::size_t>(v)] = 0;
  for (const auto f : pending)
    for (const auto v : faces_[static_cast<std::size_t>(f)])
      area_mark_[static_cast<std::size_t>(v)] = 0;

  // Pieces left without nodes leave the world.
  for (auto& piece : pieces_)
    if (piece && piece->body->m_nodes.size() == 0) {
      remove_(piece->body.get());
      piece.reset();
    }
  clear_kept();
  bend_dirty_.clear();
  sec.insert += seconds_since(clock);
}

void SkinnedSoftBody::Impl::apply(const mesh::TopologyChange& change) {
  stats_ = {};
  auto clock = Clock::now();
  mesh::apply(mesh_, change, &adjacency_);
  face_index_.update(mesh_, change);
  stats_.seconds.mesh += seconds_since(clock);
  mirror(change);
}

void SkinnedSoftBody::Impl::sync_mesh() {
  for (std::int32_t v = 0; v < mesh_.vertex_count(); ++v) mesh_.current.col(v) = position(v);
  face_index_.mark_moved();
}

mesh::CutResult SkinnedSoftBody::Impl::cut(const cga::Plane<double>& plane,
                                           const mesh::CutOptions& options) {
  stats_ = {};
  auto clock = Clock::now();
  sync_mesh();
  const double sync = seconds_since(clock);
  mesh::CutResult result = mesh::compute_cut(mesh_, plane, options);
  const double compute = seconds_since(clock);
  if (result.status == mesh::CutStatus::Cut) apply(result.change);
  stats_.seconds.sync = sync;
  stats_.seconds.mesh += compute;
  return result;
}

mesh::DrillResult SkinnedSoftBody::Impl::drill(const mesh::DrillTool& tool,
                                               const mesh::DrillOptions& options) {
  stats_ = {};
  auto clock = Clock::now();
  sync_mesh();
  stats_.seconds.sync = seconds_since(clock);
  mesh::DrillResult result = mesh::drill(mesh_, adjacency_, face_index_, tool, options);
  stats_.seconds.mesh = seconds_since(clock);
  for (const auto& change : result.changes) mirror(change);
  return result;
}

void SkinnedSoftBody::Impl::begin_tear(const mesh::TearOptions& options) {
  tear_ = std::make_unique<mesh::Tear>(mesh_, adjacency_, face_index_, options);
}

mesh::TearStep SkinnedSoftBody::Impl::tear_advance(const mesh::ScalpelSample& sample) {
  if (!tear_) begin_tear();
  stats_ = {};
  auto clock = Clock::now();
  sync_mesh();
  stats_.seconds.sync = seconds_since(clock);
  mesh::TearStep step = tear_->advance(sample);
  stats_.seconds.mesh = seconds_since(clock);
  for (const auto& change : step.changes) mirror(change);
  return step;
}

// --- Pose and skinning ---

void SkinnedSoftBody::Impl::set_pose(const skin::Pose& pose) {
  if (pose.local.size() != global_.size())
    throw std::invalid_argument("set_pose: wrong joint count");
  source_ = [pose](double, skin::Pose& out) { out = pose; };
}

void SkinnedSoftBody::Impl::play(const skin::Animation& animation, skin::Blend blend, bool loop) {
  source_ = [this, animation, blend, loop](double time, skin::Pose& out) {
    const double d = animation.duration();
    const double t = loop && d > 0 ? std::fmod(time, d) : time;
    animation.sample(skeleton_, t, blend, out);
  };
}

void SkinnedSoftBody::Impl::set_keyframes(skin::PoseTrack track, skin::Blend blend) {
  source_ = [track = std::move(track), blend](double time, skin::Pose& out) {
    track.sample(time, blend, out);
  };
}

void SkinnedSoftBody::Impl::set_pose_source(std::function<void(double, skin::Pose&)> source) {
  source_ = std::move(source);
}

void SkinnedSoftBody::Impl::set_pinned(std::span<const std::int32_t> vertices) {
  std::fill(pinned_.begin(), pinned_.end(), 0);
  for (const auto v : vertices) pinned_.at(static_cast<std::size_t>(v)) = 1;
  for (std::int32_t v = 0; v < vertex_count(); ++v) {
    const auto i = static_cast<std::size_t>(v);
    const bool k = pinned_[i] || is_kinematic_by_weight(v);
    if (k == bool(kinematic_[i])) continue;
    kinematic_[i] = k;
    set_node_mass(v);  // and the constants of its links
  }
}

void SkinnedSoftBody::Impl::pose_at(double time, skin::Pose& pose) {
  if (source_) source_(time, pose);
}

void SkinnedSoftBody::Impl::rebuild_skin_inputs() {
  const auto n = static_cast<std::size_t>(mesh_.vertex_count());
  rest_soa_ = skin::SoaPoints<double>::from(mesh_.rest);
  soa_bones_.resize(n * mesh::kMaxInfluences);
  soa_weights_.resize(n * mesh::kMaxInfluences);
  for (std::size_t v = 0; v < n; ++v)
    for (std::size_t k = 0; k < std::size_t(mesh::kMaxInfluences); ++k) {
      soa_bones_[k * n + v] = mesh_.bones(Eigen::Index(k), Eigen::Index(v));
      soa_weights_[k * n + v] = mesh_.weights(Eigen::Index(k), Eigen::Index(v));
    }
  const std::size_t old = previous_target_.size();
  target_.resize(n);
  previous_target_.resize(n);
  for (std::size_t v = old; v < n; ++v)
    previous_target_.x[v] = previous_target_.y[v] = previous_target_.z[v] = std::nan("");
  fill_previous_ = true;
}

void SkinnedSoftBody::Impl::skin_targets(double time) {
  if (rest_soa_.size() != static_cast<std::size_t>(mesh_.vertex_count())) rebuild_skin_inputs();
  pose_at(time, pose_);
  skin::global_versors(skeleton_, pose_, global_);
  skin::skinning_versors(skeleton_, global_, versors_);
  skin::versor_kernels<double>(versors_, kernels_);
  skin::CgaSkinningJob<double> job;
  job.kernels = kernels_;
  job.input = {rest_soa_.x,          rest_soa_.y, rest_soa_.z,
               mesh::kMaxInfluences, soa_bones_,  soa_weights_};
  job.output = {target_.x, target_.y, target_.z};
  job.threads = skin_threads_;
  job.run();
}

void SkinnedSoftBody::Impl::update(double dt, double time) {
  if (!(dt > 0)) return;
  std::swap(previous_target_, target_);
  skin_targets(time);  // resizes both after vertices were added (new previous entries NaN)
  if (fill_previous_) {
    for (std::size_t v = 0; v < target_.size(); ++v)
      if (std::isnan(previous_target_.x[v]))
        previous_target_.x[v] = target_.x[v], previous_target_.y[v] = target_.y[v],
        previous_target_.z[v] = target_.z[v];
    fill_previous_ = false;
  }
  for (std::size_t slot = 0; slot < detached_vertex_.size(); ++slot) {
    const auto v = static_cast<std::size_t>(detached_vertex_[slot]);
    const Eigen::Vector3d t(target_.x[v], target_.y[v], target_.z[v]),
        tp(previous_target_.x[v], previous_target_.y[v], previous_target_.z[v]);
    detached_state_[slot] = {t, (t - tp) / dt};
  }
  if (membrane_model()) {
    step_membrane(dt);
    return;
  }
  const double k = material_.target_stiffness, c = material_.target_damping;
  const double dt2 = dt * dt, denom = 1 + c * dt + k * dt2;
  const bool pull = k > 0 || c > 0;
  for (auto& piece : pieces_) {
    if (!piece) continue;
    btSoftBody& body = *piece->body;
    for (int i = 0; i < body.m_nodes.size(); ++i) {
      btSoftBody::Node& node = body.m_nodes[i];
      const auto v = static_cast<std::size_t>(piece->node_vertex[static_cast<std::size_t>(i)]);
      const btVector3 t(btScalar(target_.x[v]), btScalar(target_.y[v]), btScalar(target_.z[v]));
      if (kinematic_[v]) {
        // After Bullet's prediction: place the node on its target; Bullet derives the velocity.
        node.m_x = t;
        node.m_v = (t - node.m_q) / btScalar(dt);
      } else if (pull) {
        const btVector3 tp(btScalar(previous_target_.x[v]), btScalar(previous_target_.y[v]),
                           btScalar(previous_target_.z[v]));
        const btVector3 target_velocity = (t - tp) / btScalar(dt);
        const btVector3 error = t - node.m_x;
        const btVector3 relative = (node.m_x - node.m_q) / btScalar(dt) - target_velocity;
        node.m_x += (error * btScalar(k) - relative * btScalar(c)) * btScalar(dt2 / denom);
      }
    }
    // Bullet resets every rest length at once (updateConstants, after any edit); one link
    // tells whether it happened since we last wrote them, and then ours (with pretension) win.
    if (!piece->reapply &&
        (body.m_links.size() == 0 || body.m_links[0].m_rl == btScalar(piece->rest[0])))
      continue;
    piece->reapply = false;
    for (int i = 0; i < body.m_links.size(); ++i) {
      const double r = piece->rest[static_cast<std::size_t>(i)];
      body.m_links[i].m_rl = btScalar(r);
      body.m_links[i].m_c1 = btScalar(r * r);
    }
  }
}

// Kinematic nodes on their targets; then the membrane's step for the others (membrane_drive.hpp).
void SkinnedSoftBody::Impl::step_membrane(double dt) {
  const auto n = static_cast<std::size_t>(mesh_.vertex_count());
  vertex_node_.assign(n, nullptr);
  target_matrix_.resize(3, Eigen::Index(n));
  previous_matrix_.resize(3, Eigen::Index(n));
  for (std::size_t v = 0; v < n; ++v) {
    target_matrix_.col(Eigen::Index(v)) << target_.x[v], target_.y[v], target_.z[v];
    previous_matrix_.col(Eigen::Index(v)) << previous_target_.x[v], previous_target_.y[v],
        previous_target_.z[v];
  }
  for (auto& piece : pieces_) {
    if (!piece) continue;
    btSoftBody& body = *piece->body;
    for (int i = 0; i < body.m_nodes.size(); ++i) {
      btSoftBody::Node& node = body.m_nodes[i];
      const auto v = static_cast<std::size_t>(piece->node_vertex[static_cast<std::size_t>(i)]);
      vertex_node_[v] = &node;
      if (!kinematic_[v]) continue;
      const btVector3 t(btScalar(target_.x[v]), btScalar(target_.y[v]), btScalar(target_.z[v]));
      node.m_x = t;  // after Bullet's prediction: on the target; Bullet derives the velocity
      node.m_v = (t - node.m_q) / btScalar(dt);
    }
  }
  membrane_.step(mesh_, material_.skin, material_.solver, vertex_node_, kinematic_, mass_,
                 target_matrix_, previous_matrix_, dt);
}

// --- Queries ---

const membrane::SolveReport& SkinnedSoftBody::last_solve() const {
  return impl_->membrane_.last_report();
}

std::int32_t SkinnedSoftBody::Impl::piece_count() const {
  return std::int32_t(std::count_if(pieces_.begin(), pieces_.end(),
                                    [](auto& p) { return p && p->body->m_faces.size() > 0; }));
}

std::vector<btSoftBody*> SkinnedSoftBody::Impl::pieces() const {
  std::vector<btSoftBody*> out;
  for (const auto& p : pieces_)
    if (p) out.push_back(p->body.get());
  return out;
}

btSoftBody* SkinnedSoftBody::Impl::body_of(std::int32_t v) const {
  const std::int32_t p = piece_of_[static_cast<std::size_t>(v)];
  return p < 0 ? nullptr : pieces_[static_cast<std::size_t>(p)]->body.get();
}

std::int32_t SkinnedSoftBody::Impl::vertex_of(const btSoftBody* body, int node) const {
  for (const auto& p : pieces_)
    if (p && p->body.get() == body)
      return node >= 0 && std::size_t(node) < p->node_vertex.size()
                 ? p->node_vertex[std::size_t(node)]
                 : -1;
  return -1;
}

Eigen::Vector3d SkinnedSoftBody::Impl::position(std::int32_t v) const {
  const auto i = static_cast<std::size_t>(v);
  if (piece_of_[i] < 0) return detached_state_[static_cast<std::size_t>(detached_slot_[i])].first;
  return to_eigen(body_of(v)->m_nodes[node_of_[i]].m_x);
}

Eigen::Vector3d SkinnedSoftBody::Impl::velocity(std::int32_t v) const {
  const auto i = static_cast<std::size_t>(v);
  if (piece_of_[i] < 0) return detached_state_[static_cast<std::size_t>(detached_slot_[i])].second;
  return to_eigen(body_of(v)->m_nodes[node_of_[i]].m_v);
}

Eigen::Vector3d SkinnedSoftBody::Impl::target(std::int32_t v) const {
  const auto i = static_cast<std::size_t>(v);
  return {target_.x.at(i), target_.y.at(i), target_.z.at(i)};
}

double SkinnedSoftBody::Impl::total_mass() const {
  double m = 0;
  for (const double x : mass_) m += x;
  return m;
}

Eigen::Vector3d SkinnedSoftBody::Impl::momentum() const {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (std::int32_t v = 0; v < vertex_count(); ++v)
    p += mass_[static_cast<std::size_t>(v)] * velocity(v);
  return p;
}

double SkinnedSoftBody::Impl::momentum_scale() const {
  double s = 0;
  for (std::int32_t v = 0; v < vertex_count(); ++v)
    s += mass_[static_cast<std::size_t>(v)] * velocity(v).norm();
  return s;
}

double SkinnedSoftBody::Impl::rest_length(std::int32_t u, std::int32_t v) const {
  const auto [a, b] = edge_key(u, v);
  const std::int32_t li = edge_link_.find(a, b);
  const std::int32_t p = piece_of_[static_cast<std::size_t>(a)];
  if (li < 0 || p < 0) return -1;
  return pieces_[static_cast<std::size_t>(p)]->rest[static_cast<std::size_t>(li)];
}

double SkinnedSoftBody::Impl::bending_rest_length(std::int32_t u, std::int32_t v) const {
  const auto [a, b] = edge_key(u, v);
  const std::int32_t li = bend_link_.find(a, b);
  const std::int32_t p = piece_of_[static_cast<std::size_t>(a)];
  if (li < 0 || p < 0) return -1;
  return pieces_[static_cast<std::size_t>(p)]->rest[static_cast<std::size_t>(li)];
}

std::int32_t SkinnedSoftBody::Impl::link_count() const {
  std::int32_t n = 0;
  for (const auto& p : pieces_)
    if (p) n += p->body->m_links.size() - p->bending;
  return n;
}

std::int32_t SkinnedSoftBody::Impl::bending_link_count() const {
  std::int32_t n = 0;
  for (const auto& p : pieces_)
    if (p) n += p->bending;
  return n;
}

// --- SkinnedSoftBody: forwards to its Impl ---

SkinnedSoftBody::SkinnedSoftBody(btSoftBodyWorldInfo& info, std::function<void(btSoftBody*)> add,
                                 std::function<void(btSoftBody*)> remove,
                                 const mesh::SkinnedMesh& mesh, const skin::Skeleton& skeleton,
                                 const Material& material)
    : impl_(std::make_unique<Impl>(info, std::move(add), std::move(remove), mesh, skeleton,
                                   material)) {}
SkinnedSoftBody::~SkinnedSoftBody() = default;

void SkinnedSoftBody::set_pose(const skin::Pose& pose) {
  impl_->set_pose(pose);
}
void SkinnedSoftBody::play(const skin::Animation& animation, skin::Blend blend, bool loop) {
  impl_->play(animation, blend, loop);
}
void SkinnedSoftBody::set_keyframes(skin::PoseTrack track, skin::Blend blend) {
  impl_->set_keyframes(std::move(track), blend);
}
void SkinnedSoftBody::set_pose_source(std::function<void(double, skin::Pose&)> source) {
  impl_->set_pose_source(std::move(source));
}
void SkinnedSoftBody::set_skin_threads(int threads) {
  impl_->set_skin_threads(threads);
}
void SkinnedSoftBody::set_pinned(std::span<const std::int32_t> vertices) {
  impl_->set_pinned(vertices);
}

mesh::CutResult SkinnedSoftBody::cut(const cga::Plane<double>& plane,
                                     const mesh::CutOptions& options) {
  return impl_->cut(plane, options);
}
mesh::DrillResult SkinnedSoftBody::drill(const mesh::DrillTool& tool,
                                         const mesh::DrillOptions& options) {
  return impl_->drill(tool, options);
}
void SkinnedSoftBody::begin_tear(const mesh::TearOptions& options) {
  impl_->begin_tear(options);
}
mesh::TearStep SkinnedSoftBody::tear_advance(const mesh::ScalpelSample& sample) {
  return impl_->tear_advance(sample);
}
const mesh::Tear* SkinnedSoftBody::tear() const {
  return impl_->tear();
}
void SkinnedSoftBody::apply(const mesh::TopologyChange& change) {
  impl_->apply(change);
}
const ApplyStats& SkinnedSoftBody::last_apply() const {
  return impl_->last_apply();
}

const mesh::SkinnedMesh& SkinnedSoftBody::mesh() const {
  return impl_->mesh();
}
const skin::Skeleton& SkinnedSoftBody::skeleton() const {
  return impl_->skeleton();
}
const Material& SkinnedSoftBody::material() const {
  return impl_->material();
}
void SkinnedSoftBody::sync_mesh() {
  impl_->sync_mesh();
}
std::int32_t SkinnedSoftBody::vertex_count() const {
  return impl_->vertex_count();
}
std::int32_t SkinnedSoftBody::piece_count() const {
  return impl_->piece_count();
}
std::vector<btSoftBody*> SkinnedSoftBody::pieces() const {
  return impl_->pieces();
}
Eigen::Vector3d SkinnedSoftBody::position(std::int32_t vertex) const {
  return impl_->position(vertex);
}
Eigen::Vector3d SkinnedSoftBody::velocity(std::int32_t vertex) const {
  return impl_->velocity(vertex);
}
double SkinnedSoftBody::mass(std::int32_t vertex) const {
  return impl_->mass(vertex);
}
bool SkinnedSoftBody::kinematic(std::int32_t vertex) const {
  return impl_->kinematic(vertex);
}
btSoftBody* SkinnedSoftBody::body_of(std::int32_t vertex) const {
  return impl_->body_of(vertex);
}
std::int32_t SkinnedSoftBody::vertex_of(const btSoftBody* body, int node) const {
  return impl_->vertex_of(body, node);
}
std::int32_t SkinnedSoftBody::node_of(std::int32_t vertex) const {
  return impl_->node_of(vertex);
}
Eigen::Vector3d SkinnedSoftBody::target(std::int32_t vertex) const {
  return impl_->target(vertex);
}
double SkinnedSoftBody::total_mass() const {
  return impl_->total_mass();
}
Eigen::Vector3d SkinnedSoftBody::momentum() const {
  return impl_->momentum();
}
double SkinnedSoftBody::momentum_scale() const {
  return impl_->momentum_scale();
}
double SkinnedSoftBody::rest_length(std::int32_t u, std::int32_t v) const {
  return impl_->rest_length(u, v);
}
std::int32_t SkinnedSoftBody::link_count() const {
  return impl_->link_count();
}
std::int32_t SkinnedSoftBody::bending_link_count() const {
  return impl_->bending_link_count();
}
double SkinnedSoftBody::bending_rest_length(std::int32_t u, std::int32_t v) const {
  return impl_->bending_rest_length(u, v);
}
bool SkinnedSoftBody::detached(std::int32_t vertex) const {
  return impl_->detached(vertex);
}
std::int32_t SkinnedSoftBody::detached_count() const {
  return impl_->detached_count();
}

void SkinnedSoftBody::update(double dt, double time) {
  impl_->update(dt, time);
}
void SkinnedSoftBody::skin_targets(double time) {
  impl_->skin_targets(time);
}

}  // namespace conform::bullet
