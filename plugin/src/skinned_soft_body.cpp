#include "conform/bullet/skinned_soft_body.hpp"

#include <BulletSoftBody/btSoftBody.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>

#include "conform/bullet/convert.hpp"
#include "conform/mesh/analysis.hpp"

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

struct SkinnedSoftBody::Piece {
  std::unique_ptr<btSoftBody> body;
  std::vector<std::int32_t> node_vertex;  // node index → mesh vertex
  std::vector<double> rest;               // link index → our rest length (Bullet resets its own)
  std::vector<std::int32_t> face_id;      // Bullet face slot → mesh face
  bool reapply = true;                    // we edited the body: Bullet resets rest lengths
};

SkinnedSoftBody::SkinnedSoftBody(btSoftBodyWorldInfo& info, std::function<void(btSoftBody*)> add,
                                 std::function<void(btSoftBody*)> remove,
                                 const mesh::SkinnedMesh& mesh, const skin::Skeleton& skeleton,
                                 const Material& material)
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
  adjacency_.build(mesh_);
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

SkinnedSoftBody::~SkinnedSoftBody() {
  for (auto& piece : pieces_)
    if (piece) remove_(piece->body.get());
}

bool SkinnedSoftBody::is_kinematic_by_weight(std::int32_t v) const {
  return mesh_.weights(0, v) >= material_.kinematic_weight;
}

SkinnedSoftBody::Piece& SkinnedSoftBody::new_piece() {
  auto piece = std::make_unique<Piece>();
  // This constructor (unlike the world-info-only one) creates the default material.
  piece->body = std::make_unique<btSoftBody>(info_, 0, nullptr, nullptr);
  btSoftBody& body = *piece->body;
  body.m_materials[0]->m_kLST = btScalar(material_.link_stiffness);
  body.m_cfg.kDP = btScalar(material_.damping);
  body.m_cfg.piterations = material_.position_iterations;
  body.getCollisionShape()->setMargin(btScalar(material_.margin));
  body.setActivationState(DISABLE_DEACTIVATION);
  add_(&body);
  pieces_.push_back(std::move(piece));
  ++stats_.new_pieces;
  return *pieces_.back();
}

void SkinnedSoftBody::build(const mesh::SkinnedMesh& m) {
  const auto n = static_cast<std::size_t>(m.vertex_count());
  faces_ = m.faces;
  face_piece_.assign(faces_.size(), -1);
  face_slot_.assign(faces_.size(), -1);
  vertex_faces_.assign(n, {});
  piece_of_.assign(n, -1);
  node_of_.assign(n, -1);
  for (std::size_t f = 0; f < faces_.size(); ++f) {
    for (const auto v : faces_[f])
      vertex_faces_[static_cast<std::size_t>(v)].push_back(std::int32_t(f));
    for (int k = 0; k < 3; ++k) {
      const auto [a, b] = edge_key(faces_[f][k], faces_[f][(k + 1) % 3]);
      const std::int32_t c = edge_faces_.find(a, b);
      edge_faces_.insert(a, b, c < 0 ? 1 : c + 1, true);
    }
  }
  const mesh::Pieces labels = mesh::label_pieces(m);
  std::vector<std::int32_t> piece_index(static_cast<std::size_t>(labels.count));
  for (std::int32_t p = 0; p < labels.count; ++p) {
    new_piece();
    piece_index[static_cast<std::size_t>(p)] = std::int32_t(pieces_.size()) - 1;
  }
  if (pieces_.empty()) new_piece();
  for (std::int32_t v = 0; v < m.vertex_count(); ++v) {
    const auto& vf = vertex_faces_[static_cast<std::size_t>(v)];
    const std::int32_t p = vf.empty() ? 0
                                      : piece_index[static_cast<std::size_t>(
                                            labels.face_piece[static_cast<std::size_t>(vf[0])])];
    add_node(p, v, m.current.col(v), Eigen::Vector3d::Zero());
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
  stats_ = {};
}

void SkinnedSoftBody::set_node_mass(std::int32_t v) {
  const auto i = static_cast<std::size_t>(v);
  btSoftBody::Node& node = body_of(v)->m_nodes[node_of_[i]];
  node.m_im = kinematic_[i] ? btScalar(0) : btScalar(1 / mass_[i]);
  // Link constants (c0) depend on inverse masses: Bullet recomputes them, and resets rest
  // lengths, at the next step.
  body_of(v)->m_bUpdateRtCst = true;
  pieces_[static_cast<std::size_t>(piece_of_[i])]->reapply = true;
}

void SkinnedSoftBody::add_node(std::int32_t p, std::int32_t v, const Eigen::Vector3d& x,
                               const Eigen::Vector3d& vel) {
  Piece& piece = *pieces_[static_cast<std::size_t>(p)];
  btSoftBody& body = *piece.body;
  body.appendNode(to_btv(x), 1);
  btSoftBody::Node& node = body.m_nodes[body.m_nodes.size() - 1];
  node.m_v = to_btv(vel);
  piece_of_[static_cast<std::size_t>(v)] = p;
  node_of_[static_cast<std::size_t>(v)] = body.m_nodes.size() - 1;
  piece.node_vertex.push_back(v);
  set_node_mass(v);
  body.m_bUpdateRtCst = true;
  piece.reapply = true;
}

void SkinnedSoftBody::add_face(std::int32_t p, std::int32_t f) {
  Piece& piece = *pieces_[static_cast<std::size_t>(p)];
  const auto& tri = faces_[static_cast<std::size_t>(f)];
  piece.body->appendFace(node_of_[static_cast<std::size_t>(tri[0])],
                         node_of_[static_cast<std::size_t>(tri[1])],
                         node_of_[static_cast<std::size_t>(tri[2])]);
  face_piece_[static_cast<std::size_t>(f)] = p;
  face_slot_[static_cast<std::size_t>(f)] = piece.body->m_faces.size() - 1;
  piece.face_id.push_back(f);
  piece.reapply = true;
}

void SkinnedSoftBody::remove_face_from_bullet(std::int32_t f) {
  const std::int32_t p = face_piece_[static_cast<std::size_t>(f)];
  if (p < 0) return;
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
  body.m_bUpdateRtCst = true;
  piece.reapply = true;
  ++stats_.removed_faces;
}

void SkinnedSoftBody::add_link(std::int32_t p, std::int32_t u, std::int32_t v, double rest) {
  Piece& piece = *pieces_[static_cast<std::size_t>(p)];
  btSoftBody& body = *piece.body;
  body.appendLink(node_of_[static_cast<std::size_t>(u)], node_of_[static_cast<std::size_t>(v)],
                  nullptr, false);
  btSoftBody::Link& link = body.m_links[body.m_links.size() - 1];
  link.m_rl = btScalar(rest);
  link.m_c1 = btScalar(rest * rest);
  piece.rest.push_back(rest);
  piece.reapply = true;
  const auto [a, b] = edge_key(u, v);
  edge_link_.insert(a, b, body.m_links.size() - 1, true);
  ++stats_.added_links;
}

void SkinnedSoftBody::remove_link(std::int32_t p, std::int32_t li) {
  Piece& piece = *pieces_[static_cast<std::size_t>(p)];
  btSoftBody& body = *piece.body;
  const int last = body.m_links.size() - 1;
  {
    const btSoftBody::Link& l = body.m_links[li];
    const auto [a, b] =
        edge_key(piece.node_vertex[static_cast<std::size_t>(l.m_n[0] - &body.m_nodes[0])],
                 piece.node_vertex[static_cast<std::size_t>(l.m_n[1] - &body.m_nodes[0])]);
    edge_link_.erase(a, b, li);
  }
  if (li != last) {
    body.m_links[li] = body.m_links[last];
    piece.rest[static_cast<std::size_t>(li)] = piece.rest[static_cast<std::size_t>(last)];
    const btSoftBody::Link& l = body.m_links[li];
    const auto [a, b] =
        edge_key(piece.node_vertex[static_cast<std::size_t>(l.m_n[0] - &body.m_nodes[0])],
                 piece.node_vertex[static_cast<std::size_t>(l.m_n[1] - &body.m_nodes[0])]);
    edge_link_.insert(a, b, li, true);
  }
  body.m_links.pop_back();
  piece.rest.pop_back();
  body.m_bUpdateRtCst = true;
  piece.reapply = true;
  ++stats_.removed_links;
}

void SkinnedSoftBody::remove_nodes(std::int32_t p, const std::vector<std::int32_t>& vertices) {
  // Compaction with one re-pointing pass (only on splits): links and faces touching these
  // nodes must already be gone.
  Piece& piece = *pieces_[static_cast<std::size_t>(p)];
  btSoftBody& body = *piece.body;
  const int count = body.m_nodes.size();
  std::vector<int> new_index(static_cast<std::size_t>(count), 0);
  for (const auto v : vertices)
    new_index[static_cast<std::size_t>(node_of_[static_cast<std::size_t>(v)])] = -1;
  int j = 0;
  for (int i = 0; i < count; ++i) {
    if (new_index[static_cast<std::size_t>(i)] < 0) {
      if (body.m_nodes[i].m_leaf) body.m_ndbvt.remove(body.m_nodes[i].m_leaf);
      continue;
    }
    if (j != i) {
      body.m_nodes[j] = body.m_nodes[i];
      piece.node_vertex[static_cast<std::size_t>(j)] =
          piece.node_vertex[static_cast<std::size_t>(i)];
    }
    if (body.m_nodes[j].m_leaf) body.m_nodes[j].m_leaf->data = &body.m_nodes[j];
    node_of_[static_cast<std::size_t>(piece.node_vertex[static_cast<std::size_t>(j)])] = j;
    new_index[static_cast<std::size_t>(i)] = j++;
  }
  btSoftBody::Node* base = count ? &body.m_nodes[0] : nullptr;
  auto repoint = [&](btSoftBody::Node*& n) {
    n = base + new_index[static_cast<std::size_t>(n - base)];
  };
  for (int i = 0; i < body.m_links.size(); ++i)
    repoint(body.m_links[i].m_n[0]), repoint(body.m_links[i].m_n[1]);
  for (int i = 0; i < body.m_faces.size(); ++i)
    for (auto& n : body.m_faces[i].m_n) repoint(n);
  while (body.m_nodes.size() > j) body.m_nodes.pop_back();  // resize() would build a Node
  piece.node_vertex.resize(static_cast<std::size_t>(j));
  body.m_bUpdateRtCst = true;
  piece.reapply = true;
}

void SkinnedSoftBody::mirror(const mesh::TopologyChange& change) {
  const std::int32_t v0 = change.base_vertex_count;
  if (v0 != std::int32_t(piece_of_.size()) || change.base_face_count != std::int32_t(faces_.size()))
    throw std::logic_error("SkinnedSoftBody: change does not match the mirrored mesh");
  const auto nnew = static_cast<std::int32_t>(change.new_vertices.size());
  const auto total = static_cast<std::size_t>(v0 + nnew);
  if (mesh_.vertex_count() < v0 + nnew)
    throw std::logic_error("SkinnedSoftBody: mesh lacks the change's new vertices");

  // 1. New vertices: x and v interpolated from the parents; mass taken from the parents in
  // proportion to the same coefficients, so Σm and Σm·v are unchanged exactly.
  std::vector<Eigen::Vector3d> nx(static_cast<std::size_t>(nnew)),
      nv(static_cast<std::size_t>(nnew));
  piece_of_.resize(total, -1);
  node_of_.resize(total, -1);
  mass_.resize(total, 0);
  pinned_.resize(total, 0);
  kinematic_.resize(total, 0);
  vertex_faces_.resize(total);
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

  // 2. Removed faces leave Bullet; edges no face uses any more lose their link.
  std::vector<std::int32_t> seeds;  // old vertices around the change (their pieces may split)
  std::vector<std::pair<std::int32_t, std::int32_t>> dropped;
  for (const auto f : change.removed_faces) {
    const auto tri = faces_[static_cast<std::size_t>(f)];
    remove_face_from_bullet(f);
    for (int k = 0; k < 3; ++k) {
      erase_value(vertex_faces_[static_cast<std::size_t>(tri[k])], f);
      seeds.push_back(tri[k]);
      const auto [a, b] = edge_key(tri[k], tri[(k + 1) % 3]);
      const std::int32_t c = edge_faces_.find(a, b) - 1;
      if (c > 0) {
        edge_faces_.insert(a, b, c, true);
      } else {
        edge_faces_.erase(a, b, c + 1);
        dropped.emplace_back(a, b);
      }
    }
  }
  for (const auto& [a, b] : dropped) {
    const std::int32_t li = edge_link_.find(a, b);
    if (li >= 0) remove_link(piece_of_[static_cast<std::size_t>(a)], li);
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
  for (const auto f : pending) {
    const auto& tri = faces_[static_cast<std::size_t>(f)];
    for (int k = 0; k < 3; ++k) {
      vertex_faces_[static_cast<std::size_t>(tri[k])].push_back(f);
      if (tri[k] < v0) seeds.push_back(tri[k]);
      const auto [a, b] = edge_key(tri[k], tri[(k + 1) % 3]);
      const std::int32_t c = edge_faces_.find(a, b);
      edge_faces_.insert(a, b, c < 0 ? 1 : c + 1, true);
    }
  }
  stats_.added_faces += std::int32_t(pending.size());
  stats_.new_nodes += nnew;

  // 4. Connected components around the change (a BFS over the affected pieces).
  std::vector<std::int32_t> affected;
  for (const auto v : seeds) affected.push_back(piece_of_[static_cast<std::size_t>(v)]);
  for (const auto& nvx : change.new_vertices)
    for (const auto p : nvx.parents)
      if (p >= 0 && p < v0) affected.push_back(piece_of_[static_cast<std::size_t>(p)]);
  std::sort(affected.begin(), affected.end());
  affected.erase(std::unique(affected.begin(), affected.end()), affected.end());
  std::vector<std::int32_t> label(total, -1);
  std::vector<std::vector<std::int32_t>> components;
  std::vector<std::int32_t> queue;
  auto explore = [&](std::int32_t start) {
    if (label[static_cast<std::size_t>(start)] >= 0 ||
        vertex_faces_[static_cast<std::size_t>(start)].empty())
      return;
    const std::int32_t c = std::int32_t(components.size());
    components.emplace_back();
    queue.assign(1, start);
    label[static_cast<std::size_t>(start)] = c;
    while (!queue.empty()) {
      const std::int32_t u = queue.back();
      queue.pop_back();
      components.back().push_back(u);
      for (const auto f : vertex_faces_[static_cast<std::size_t>(u)])
        for (const auto w : faces_[static_cast<std::size_t>(f)])
          if (label[static_cast<std::size_t>(w)] < 0) {
            label[static_cast<std::size_t>(w)] = c;
            queue.push_back(w);
          }
    }
  };
  for (const auto p : affected)
    for (const auto v : pieces_[static_cast<std::size_t>(p)]->node_vertex) explore(v);
  for (std::int32_t i = 0; i < nnew; ++i) explore(v0 + i);

  // Each old piece keeps the component holding most of its nodes; a component wanted by two
  // pieces (a merge) goes to the one with more nodes there; the rest become new pieces.
  std::vector<std::int32_t> owner(components.size(), -1), owner_count(components.size(), 0);
  {
    std::vector<std::pair<std::int32_t, std::int32_t>> best;  // per piece: (component, count)
    std::vector<std::int32_t> pieces_seen;
    for (std::size_t c = 0; c < components.size(); ++c) {
      std::vector<std::pair<std::int32_t, std::int32_t>> counts;
      for (const auto v : components[c]) {
        const std::int32_t p = piece_of_[static_cast<std::size_t>(v)];
        if (p < 0) continue;
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

  // 5. Moves (splits and merges): the moving nodes' faces and links leave their old body, the
  // nodes follow with x, v and mass exactly, and the faces and links are rebuilt in the new one.
  std::vector<std::tuple<std::int32_t, std::int32_t, double>> relink;
  for (std::size_t c = 0; c < components.size(); ++c) {
    std::vector<std::int32_t> moving;
    for (const auto v : components[c]) {
      const std::int32_t p = piece_of_[static_cast<std::size_t>(v)];
      if (p >= 0 && p != owner[c]) moving.push_back(v);
    }
    if (moving.empty()) continue;
    if (owner[c] < 0) {
      new_piece();
      owner[c] = std::int32_t(pieces_.size()) - 1;
    }
    std::vector<std::pair<std::int32_t, std::vector<std::int32_t>>> by_source;
    std::vector<std::pair<btVector3, btVector3>> state;
    for (const auto v : moving) {
      for (const auto f : vertex_faces_[static_cast<std::size_t>(v)]) {
        if (face_piece_[static_cast<std::size_t>(f)] < 0) continue;
        const auto tri = faces_[static_cast<std::size_t>(f)];
        remove_face_from_bullet(f);
        --stats_.removed_faces;  // re-added below: counted as moved, not removed
        pending.push_back(f);
        for (int k = 0; k < 3; ++k) {
          const auto [a, b] = edge_key(tri[k], tri[(k + 1) % 3]);
          const std::int32_t li = edge_link_.find(a, b);
          if (li < 0) continue;
          const std::int32_t lp = piece_of_[static_cast<std::size_t>(a)];
          relink.emplace_back(
              a, b, pieces_[static_cast<std::size_t>(lp)]->rest[static_cast<std::size_t>(li)]);
          remove_link(lp, li);
          --stats_.removed_links;
        }
      }
      const std::int32_t p = piece_of_[static_cast<std::size_t>(v)];
      auto it =
          std::find_if(by_source.begin(), by_source.end(), [&](auto& e) { return e.first == p; });
      if (it == by_source.end())
        by_source.emplace_back(p, std::vector<std::int32_t>{v});
      else
        it->second.push_back(v);
      const btSoftBody::Node& node = body_of(v)->m_nodes[node_of_[static_cast<std::size_t>(v)]];
      state.emplace_back(node.m_x, node.m_v);
    }
    for (const auto& [p, list] : by_source) remove_nodes(p, list);
    for (std::size_t i = 0; i < moving.size(); ++i) {
      add_node(owner[c], moving[i], to_eigen(state[i].first), to_eigen(state[i].second));
      // Bit-exact copy (the double round trip is exact, but say so in code).
      btSoftBody::Node& node =
          body_of(moving[i])->m_nodes[node_of_[static_cast<std::size_t>(moving[i])]];
      node.m_x = node.m_q = state[i].first;
      node.m_v = state[i].second;
    }
    stats_.moved_nodes += std::int32_t(moving.size());
  }

  // 6. New nodes join their component's piece (a new vertex without faces joins its parent's).
  for (std::int32_t i = 0; i < nnew; ++i) {
    const std::int32_t id = v0 + i;
    const std::int32_t c = label[static_cast<std::size_t>(id)];
    std::int32_t p = -1;
    if (c >= 0) {
      if (owner[static_cast<std::size_t>(c)] < 0) {
        new_piece();
        owner[static_cast<std::size_t>(c)] = std::int32_t(pieces_.size()) - 1;
      }
      p = owner[static_cast<std::size_t>(c)];
    } else {
      for (const auto parent : change.new_vertices[static_cast<std::size_t>(i)].parents)
        if (parent >= 0 && piece_of_[static_cast<std::size_t>(parent)] >= 0) {
          p = piece_of_[static_cast<std::size_t>(parent)];
          break;
        }
      if (p < 0) {
        new_piece();
        p = std::int32_t(pieces_.size()) - 1;
      }
    }
    add_node(p, id, nx[static_cast<std::size_t>(i)], nv[static_cast<std::size_t>(i)]);
  }
  for (const auto v : touched) set_node_mass(v);

  // 7. Faces and links into Bullet; a moved link keeps its rest length, a new one gets
  // (1 − s) × its current length.
  std::sort(pending.begin(), pending.end());
  pending.erase(std::unique(pending.begin(), pending.end()), pending.end());
  std::sort(relink.begin(), relink.end());
  for (const auto f : pending) {
    if (face_piece_[static_cast<std::size_t>(f)] >= 0) continue;
    const auto tri = faces_[static_cast<std::size_t>(f)];
    const std::int32_t p = piece_of_[static_cast<std::size_t>(tri[0])];
    add_face(p, f);
    for (int k = 0; k < 3; ++k) {
      const auto [a, b] = edge_key(tri[k], tri[(k + 1) % 3]);
      if (edge_link_.find(a, b) >= 0) continue;
      auto it = std::lower_bound(relink.begin(), relink.end(), std::tuple{a, b, -1.0});
      if (it != relink.end() && std::get<0>(*it) == a && std::get<1>(*it) == b) {
        add_link(p, a, b, std::get<2>(*it));
        --stats_.added_links;
      } else {
        add_link(p, a, b, (1 - material_.pretension) * (position(a) - position(b)).norm());
      }
    }
  }

  // Pieces left without nodes leave the world.
  for (auto& piece : pieces_)
    if (piece && piece->body->m_nodes.size() == 0) {
      remove_(piece->body.get());
      piece.reset();
    }
}

void SkinnedSoftBody::apply(const mesh::TopologyChange& change) {
  stats_ = {};
  mesh::apply(mesh_, change, &adjacency_);
  mirror(change);
}

void SkinnedSoftBody::sync_mesh() {
  for (std::int32_t v = 0; v < mesh_.vertex_count(); ++v) mesh_.current.col(v) = position(v);
}

mesh::CutResult SkinnedSoftBody::cut(const cga::Plane<double>& plane,
                                     const mesh::CutOptions& options) {
  sync_mesh();
  mesh::CutResult result = mesh::compute_cut(mesh_, plane, options);
  stats_ = {};
  if (result.status == mesh::CutStatus::Cut) apply(result.change);
  return result;
}

mesh::DrillResult SkinnedSoftBody::drill(const mesh::DrillTool& tool,
                                         const mesh::DrillOptions& options) {
  sync_mesh();
  mesh::DrillResult result = mesh::drill(mesh_, adjacency_, tool, options);
  stats_ = {};
  for (const auto& change : result.changes) mirror(change);
  return result;
}

void SkinnedSoftBody::begin_tear(const mesh::TearOptions& options) {
  tear_ = std::make_unique<mesh::Tear>(mesh_, adjacency_, options);
}

mesh::TearStep SkinnedSoftBody::tear_advance(const mesh::ScalpelSample& sample) {
  if (!tear_) begin_tear();
  sync_mesh();
  mesh::TearStep step = tear_->advance(sample);
  stats_ = {};
  for (const auto& change : step.changes) mirror(change);
  return step;
}

// --- Pose and skinning ---

void SkinnedSoftBody::set_pose(const skin::Pose& pose) {
  if (pose.local.size() != global_.size())
    throw std::invalid_argument("set_pose: wrong joint count");
  source_ = [pose](double, skin::Pose& out) { out = pose; };
}

void SkinnedSoftBody::play(const skin::Animation& animation, skin::Blend blend, bool loop) {
  source_ = [this, animation, blend, loop](double time, skin::Pose& out) {
    const double d = animation.duration();
    const double t = loop && d > 0 ? std::fmod(time, d) : time;
    animation.sample(skeleton_, t, blend, out);
  };
}

void SkinnedSoftBody::set_keyframes(skin::PoseTrack track, skin::Blend blend) {
  source_ = [track = std::move(track), blend](double time, skin::Pose& out) {
    track.sample(time, blend, out);
  };
}

void SkinnedSoftBody::set_pose_source(std::function<void(double, skin::Pose&)> source) {
  source_ = std::move(source);
}

void SkinnedSoftBody::set_pinned(std::span<const std::int32_t> vertices) {
  std::fill(pinned_.begin(), pinned_.end(), 0);
  for (const auto v : vertices) pinned_.at(static_cast<std::size_t>(v)) = 1;
  for (std::int32_t v = 0; v < vertex_count(); ++v) {
    const auto i = static_cast<std::size_t>(v);
    const bool k = pinned_[i] || is_kinematic_by_weight(v);
    if (k == bool(kinematic_[i])) continue;
    kinematic_[i] = k;
    set_node_mass(v);
    body_of(v)->m_bUpdateRtCst = true;  // link constants depend on inverse masses
    pieces_[static_cast<std::size_t>(piece_of_[i])]->reapply = true;
  }
}

void SkinnedSoftBody::pose_at(double time, skin::Pose& pose) {
  if (source_) source_(time, pose);
}

void SkinnedSoftBody::rebuild_skin_inputs() {
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

void SkinnedSoftBody::skin_targets(double time) {
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

void SkinnedSoftBody::update(double dt, double time) {
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

// --- Queries ---

std::int32_t SkinnedSoftBody::piece_count() const {
  return std::int32_t(std::count_if(pieces_.begin(), pieces_.end(),
                                    [](auto& p) { return p && p->body->m_faces.size() > 0; }));
}

std::vector<btSoftBody*> SkinnedSoftBody::pieces() const {
  std::vector<btSoftBody*> out;
  for (const auto& p : pieces_)
    if (p) out.push_back(p->body.get());
  return out;
}

btSoftBody* SkinnedSoftBody::body_of(std::int32_t v) const {
  return pieces_[static_cast<std::size_t>(piece_of_[static_cast<std::size_t>(v)])]->body.get();
}

std::int32_t SkinnedSoftBody::vertex_of(const btSoftBody* body, int node) const {
  for (const auto& p : pieces_)
    if (p && p->body.get() == body)
      return node >= 0 && std::size_t(node) < p->node_vertex.size()
                 ? p->node_vertex[std::size_t(node)]
                 : -1;
  return -1;
}

Eigen::Vector3d SkinnedSoftBody::position(std::int32_t v) const {
  return to_eigen(body_of(v)->m_nodes[node_of_[static_cast<std::size_t>(v)]].m_x);
}

Eigen::Vector3d SkinnedSoftBody::velocity(std::int32_t v) const {
  return to_eigen(body_of(v)->m_nodes[node_of_[static_cast<std::size_t>(v)]].m_v);
}

Eigen::Vector3d SkinnedSoftBody::target(std::int32_t v) const {
  const auto i = static_cast<std::size_t>(v);
  return {target_.x.at(i), target_.y.at(i), target_.z.at(i)};
}

double SkinnedSoftBody::total_mass() const {
  double m = 0;
  for (const double x : mass_) m += x;
  return m;
}

Eigen::Vector3d SkinnedSoftBody::momentum() const {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (std::int32_t v = 0; v < vertex_count(); ++v)
    p += mass_[static_cast<std::size_t>(v)] * velocity(v);
  return p;
}

double SkinnedSoftBody::momentum_scale() const {
  double s = 0;
  for (std::int32_t v = 0; v < vertex_count(); ++v)
    s += mass_[static_cast<std::size_t>(v)] * velocity(v).norm();
  return s;
}

double SkinnedSoftBody::rest_length(std::int32_t u, std::int32_t v) const {
  const auto [a, b] = edge_key(u, v);
  const std::int32_t li = edge_link_.find(a, b);
  if (li < 0) return -1;
  return pieces_[static_cast<std::size_t>(piece_of_[static_cast<std::size_t>(a)])]
      ->rest[static_cast<std::size_t>(li)];
}

std::int32_t SkinnedSoftBody::link_count() const {
  std::int32_t n = 0;
  for (const auto& p : pieces_)
    if (p) n += p->body->m_links.size();
  return n;
}

}  // namespace conform::bullet
