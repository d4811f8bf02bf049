// The topology mirror: a change already applied to the mesh, applied to Bullet in the phases of
// ApplyStats::Seconds (vertices, faces, pieces, split, insert), each over one MirrorContext.
#include "topology_mirror.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "conform/membrane/crack_extension.hpp"
#include "edge_key.hpp"
#include "phase_clock.hpp"
#include "skinned_soft_body_impl.hpp"

namespace conform::bullet {

namespace {

void erase_value(std::vector<std::int32_t>& list, std::int32_t value) {
  const auto it = std::find(list.begin(), list.end(), value);
  if (it != list.end()) {
    *it = list.back();
    list.pop_back();
  }
}

}  // namespace

void SkinnedSoftBody::Impl::mirror(const mesh::TopologyChange& change) {
  ++topology_version_;
  membrane_.invalidate();  // rebuilt from the rest state at the next substep
  if (bind_.cols() > 0) membrane::extend_columns(bind_, change);  // as mesh::apply's rest
  const double start = thread_seconds();
  const std::int32_t v0 = change.base_vertex_count;
  if (v0 != std::int32_t(piece_of_.size()) || change.base_face_count != std::int32_t(faces_.size()))
    throw std::logic_error("SkinnedSoftBody: change does not match the mirrored mesh");
  if (mesh_.vertex_count() < v0 + std::int32_t(change.new_vertices.size()))
    throw std::logic_error("SkinnedSoftBody: mesh lacks the change's new vertices");
  MirrorContext c(change, v0, material_.bending_stiffness > 0, stats_.seconds, start);
  kept_.clear();
  bend_dirty_.clear();
  make_new_vertices(c);
  c.seconds.vertices += seconds_since(c.clock);
  remove_faces(c);
  assign_face_slots(c);
  c.seconds.faces += seconds_since(c.clock);
  find_pieces(c);
  c.seconds.pieces += seconds_since(c.clock);
  move_pieces(c);
  c.seconds.split += seconds_since(c.clock);
  place_changed_nodes(c);
  insert_faces_and_links(c);
  if (c.bending) refresh_changed_bending();
  refresh_changed_areas(c);
  drop_empty_pieces();
  refresh_released();
  kept_.clear();
  bend_dirty_.clear();
  split_.clear();
  c.seconds.insert += seconds_since(c.clock);
}

void SkinnedSoftBody::Impl::make_new_vertices(MirrorContext& c) {
  // 1. New vertices: x and v interpolated from the parents; mass taken from the parents in
  // proportion to the same coefficients, so Σm and Σm·v are unchanged exactly.
  piece_of_.resize(c.total, -1);
  node_of_.resize(c.total, -1);
  detached_.grow(c.total);
  mass_.resize(c.total, 0);
  pinned_.resize(c.total, 0);
  kinematic_.resize(c.total, 0);
  vertex_faces_.resize(c.total);
  for (std::size_t v = std::size_t(c.v0); v < c.total; ++v)
    vertex_faces_[v].reserve(8);  // one allocation
  auto pos = [&](std::int32_t p) {
    return p < c.v0 ? position(p) : c.x[static_cast<std::size_t>(p - c.v0)];
  };
  auto vel = [&](std::int32_t p) {
    return p < c.v0 ? velocity(p) : c.v[static_cast<std::size_t>(p - c.v0)];
  };
  for (std::int32_t i = 0; i < c.added; ++i) {
    const auto& nvx = c.change.new_vertices[static_cast<std::size_t>(i)];
    const std::int32_t id = c.v0 + i;
    Eigen::Vector3d x = nvx.displacement, v = Eigen::Vector3d::Zero();
    double share = std::numeric_limits<double>::infinity();
    bool pinned = false;
    for (int j = 0; j < 3; ++j) {
      const std::int32_t p = nvx.parents[static_cast<std::size_t>(j)];
      const double w = nvx.coefficients[static_cast<std::size_t>(j)];
      if (p < 0) continue;
      x += w * pos(p);
      v += w * vel(p);
      if (w > 0) share = std::min(share, mass_[static_cast<std::size_t>(p)] / w);
      pinned = pinned || (pinned_[static_cast<std::size_t>(p)] && w > 0);
    }
    const double mu = std::isfinite(share) ? 0.5 * share : 0.0;
    for (int j = 0; j < 3; ++j) {
      const std::int32_t p = nvx.parents[static_cast<std::size_t>(j)];
      const double w = nvx.coefficients[static_cast<std::size_t>(j)];
      if (p < 0 || !(w > 0)) continue;
      mass_[static_cast<std::size_t>(p)] -= w * mu;
      if (p < c.v0) c.touched.push_back(p);
    }
    mass_[static_cast<std::size_t>(id)] = mu;
    c.x[static_cast<std::size_t>(i)] = x;
    c.v[static_cast<std::size_t>(i)] = v;
    // A new vertex between pinned vertices (e.g. on a pinned border) stays pinned.
    pinned_[static_cast<std::size_t>(id)] = pinned;
    kinematic_[static_cast<std::size_t>(id)] = pinned || is_kinematic_by_weight(id);
  }
}

void SkinnedSoftBody::Impl::remove_faces(MirrorContext& c) {
  // 2. Removed faces leave Bullet and seed the split search; edges no face uses any more lose
  // their link (kept aside: an edge that comes back in the same change keeps its rest length).
  seed_mark_.resize(c.total, 0);
  split_.begin(std::int32_t(c.total));
  std::vector<std::pair<std::int32_t, std::int32_t>> dropped;
  for (const auto f : c.change.removed_faces) {
    const auto tri = faces_[static_cast<std::size_t>(f)];
    remove_face_from_bullet(f);
    split_.seed_removed_face(tri);
    for (int k = 0; k < 3; ++k) {
      erase_value(vertex_faces_[static_cast<std::size_t>(tri[k])], f);
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
    kept_.keep(a, b, a, b, pieces_[static_cast<std::size_t>(p)]->rest[std::size_t(li)], false);
    remove_link(p, li);
  }
}

void SkinnedSoftBody::Impl::assign_face_slots(MirrorContext& c) {
  // 3. The face slots by the mesh's rule (mesh::visit_face_slots, as mesh::apply does them):
  // added faces overwrite removed slots, then are appended; leftover removed slots are filled
  // by swap-with-last, which also moves the face's Bullet slot and its vertices' face lists.
  struct Slots {
    Impl& impl;
    MirrorContext& c;
    void fill(std::int32_t slot, std::size_t k) {
      impl.faces_[static_cast<std::size_t>(slot)] = c.change.added_faces[k];
      c.pending.push_back(slot);
    }
    void append(std::int32_t slot, std::size_t k) {
      impl.faces_.push_back(c.change.added_faces[k]);
      impl.face_piece_.push_back(-1);
      impl.face_slot_.push_back(-1);
      c.pending.push_back(slot);
    }
    void move(std::int32_t last, std::int32_t slot) { impl.move_face_slot(last, slot); }
    void pop(std::int32_t) {
      impl.faces_.pop_back();
      impl.face_piece_.pop_back();
      impl.face_slot_.pop_back();
    }
  };
  mesh::visit_face_slots(c.change, Slots{*this, c});
  // The added faces' vertices and the new vertices seed the split search too.
  c.new_edges.assign(c.pending.size(), 0);
  for (std::size_t i = 0; i < c.pending.size(); ++i) {
    const auto& tri = faces_[static_cast<std::size_t>(c.pending[i])];
    for (int k = 0; k < 3; ++k) {
      vertex_faces_[static_cast<std::size_t>(tri[k])].push_back(c.pending[i]);
      split_.seed(tri[k]);
      const auto [a, b] = edge_key(tri[k], tri[(k + 1) % 3]);
      if (++edge_faces_.at(a, b, 0) == 1) c.new_edges[i] |= std::uint8_t(1u << k);
    }
  }
  stats_.added_faces += std::int32_t(c.pending.size());
  stats_.new_nodes += c.added;
  for (std::int32_t i = 0; i < c.added; ++i) split_.seed(c.v0 + i);
}

void SkinnedSoftBody::Impl::move_face_slot(std::int32_t last, std::int32_t slot) {
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

void SkinnedSoftBody::Impl::find_pieces(MirrorContext& c) {
  // 4. Connected pieces around the change (mesh::SplitSearch). The open group keeps its body.
  // Each other body goes to the complete group holding most of its nodes; a group wanted by
  // two bodies (a merge) goes to the one with more nodes there; the remaining groups become
  // new bodies.
  split_.run({faces_, vertex_faces_, piece_of_, c.v0});
  stats_.searched_vertices += split_.searched_vertices();
  c.open_body = split_.open_body();
  const auto& groups = split_.pieces();
  c.owner.assign(groups.size(), -1);
  std::vector<std::int32_t> owner_count(groups.size(), 0);
  std::vector<std::pair<std::int32_t, std::int32_t>> best;  // per body: (group, count)
  std::vector<std::int32_t> bodies_seen;
  std::vector<std::pair<std::int32_t, std::int32_t>> counts;  // per body in a group
  for (std::size_t g = 0; g < groups.size(); ++g) {
    counts.clear();
    for (const auto v : groups[g]) {
      const std::int32_t p = piece_of_[static_cast<std::size_t>(v)];
      if (p < 0 || p == c.open_body) continue;
      auto it = std::find_if(counts.begin(), counts.end(), [&](auto& e) { return e.first == p; });
      if (it == counts.end())
        counts.emplace_back(p, 1);
      else
        ++it->second;
    }
    for (const auto& [p, n] : counts) {
      auto it = std::find(bodies_seen.begin(), bodies_seen.end(), p);
      if (it == bodies_seen.end()) {
        bodies_seen.push_back(p);
        best.emplace_back(std::int32_t(g), n);
      } else {
        auto& b = best[static_cast<std::size_t>(it - bodies_seen.begin())];
        if (n > b.second) b = {std::int32_t(g), n};
      }
    }
  }
  for (std::size_t i = 0; i < bodies_seen.size(); ++i) {
    const auto [g, n] = best[i];
    if (n > owner_count[static_cast<std::size_t>(g)]) {
      c.owner[static_cast<std::size_t>(g)] = bodies_seen[i];
      owner_count[static_cast<std::size_t>(g)] = n;
    }
  }
}

void SkinnedSoftBody::Impl::move_pieces(MirrorContext& c) {
  // 5. Moves (splits and merges): a group without a body is copied whole into a new one;
  // into an existing body, the moving nodes' faces and links leave their old body and the
  // nodes follow with x, v and mass exactly (the faces and links are rebuilt in phase 7).
  const auto& groups = split_.pieces();
  std::vector<std::int32_t> moving;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    moving.clear();
    for (const auto v : groups[g]) {
      const std::int32_t p = piece_of_[static_cast<std::size_t>(v)];
      if (p >= 0 && p != c.owner[g]) moving.push_back(v);
    }
    if (moving.empty()) continue;
    if (c.owner[g] < 0)
      c.owner[g] = move_to_new_piece(moving, std::int32_t(groups[g].size() - moving.size()),
                                     std::int32_t(c.pending.size()));
    else
      move_into_body(c, moving, c.owner[g]);
  }
}

void SkinnedSoftBody::Impl::move_into_body(MirrorContext& c, std::span<const std::int32_t> moving,
                                           std::int32_t into) {
  std::vector<btSoftBody::Node> state;
  for (const auto v : moving) {
    for (const auto f : vertex_faces_[static_cast<std::size_t>(v)]) {
      if (face_piece_[static_cast<std::size_t>(f)] < 0) continue;
      const auto tri = faces_[static_cast<std::size_t>(f)];
      remove_face_from_bullet(f);
      --stats_.removed_faces;  // re-added below: counted as moved, not removed
      c.moved_faces.push_back(f);
      for (int k = 0; k < 3; ++k) {
        const auto [a, b] = edge_key(tri[k], tri[(k + 1) % 3]);
        const std::int32_t li = edge_link_.find(a, b);
        if (li < 0) continue;  // moved already (from the face across)
        const std::int32_t lp = piece_of_[static_cast<std::size_t>(a)];
        c.moved_links.emplace_back(
            a, b, pieces_[static_cast<std::size_t>(lp)]->rest[static_cast<std::size_t>(li)]);
        remove_link(lp, li);
        --stats_.removed_links;
      }
    }
    state.push_back(body_of(v)->m_nodes[node_of_[static_cast<std::size_t>(v)]]);
  }
  remove_nodes_highest_first(moving);
  for (std::size_t i = 0; i < moving.size(); ++i) {
    add_node(into, moving[i], from_bt(state[i].m_x), from_bt(state[i].m_v));
    // Bit-exact copy (the double round trip is exact, but say so in code).
    btSoftBody::Node& node =
        body_of(moving[i])->m_nodes[node_of_[static_cast<std::size_t>(moving[i])]];
    node.m_x = state[i].m_x;
    node.m_q = state[i].m_q;
    node.m_v = state[i].m_v;
  }
  stats_.moved_nodes += std::int32_t(moving.size());
}

void SkinnedSoftBody::Impl::place_changed_nodes(MirrorContext& c) {
  // 6. Old vertices left without faces leave Bullet; new nodes join their group's body (a new
  // vertex without faces is detached at once); parents that gave mass get their new one.
  for (const auto v : split_.seeds())
    if (v < c.v0 && piece_of_[static_cast<std::size_t>(v)] >= 0 &&
        vertex_faces_[static_cast<std::size_t>(v)].empty())
      detach(v);
  for (std::int32_t i = 0; i < c.added; ++i) {
    const std::int32_t id = c.v0 + i;
    const std::int32_t group = split_.group_of(id);
    if (group == mesh::SplitSearch::kUnreached) {
      detached_.add(id, c.x[static_cast<std::size_t>(i)], c.v[static_cast<std::size_t>(i)]);
      ++stats_.detached_nodes;
      continue;
    }
    std::int32_t p = c.open_body;
    if (group != mesh::SplitSearch::kOpen) {
      auto& o = c.owner[static_cast<std::size_t>(group)];
      if (o < 0) {
        new_piece(c.open_body);
        o = std::int32_t(pieces_.size()) - 1;
      }
      p = o;
    }
    std::int32_t near = -1;  // a parent in the same body, whose tree leaf it joins
    for (const auto q : c.change.new_vertices[static_cast<std::size_t>(i)].parents)
      if (q >= 0 && piece_of_[static_cast<std::size_t>(q)] == p) {
        near = q;
        break;
      }
    add_node(p, id, c.x[static_cast<std::size_t>(i)], c.v[static_cast<std::size_t>(i)], near);
  }
  for (const auto v : c.touched) {  // once each (seed_mark_ is clear here)
    auto& mark = seed_mark_[static_cast<std::size_t>(v)];
    if (!mark) mark = 1, set_node_mass(v);
  }
  for (const auto v : c.touched) seed_mark_[static_cast<std::size_t>(v)] = 0;
}

void SkinnedSoftBody::Impl::insert_faces_and_links(MirrorContext& c) {
  // 7. Faces and links into Bullet; a moved link keeps its rest length, a new one gets
  // (1 − s) × its current length (or the rest length it had, if it left in this change).
  for (const auto f : c.moved_faces)
    add_face(piece_of_[static_cast<std::size_t>(faces_[static_cast<std::size_t>(f)][0])], f);
  for (const auto& [a, b, rest] : c.moved_links) {
    add_link(piece_of_[static_cast<std::size_t>(a)], a, b, rest);
    --stats_.added_links;
  }
  if (c.bending)
    for (const auto f : c.moved_faces) {
      const auto& tri = faces_[static_cast<std::size_t>(f)];
      for (int k = 0; k < 3; ++k) bend_dirty_.push_back(edge_key(tri[k], tri[(k + 1) % 3]));
    }
  for (std::size_t i = 0; i < c.pending.size(); ++i) {
    const std::int32_t f = c.pending[i];
    if (face_piece_[static_cast<std::size_t>(f)] >= 0) continue;
    const auto tri = faces_[static_cast<std::size_t>(f)];
    const std::int32_t p = piece_of_[static_cast<std::size_t>(tri[0])];
    add_face(p, f);
    for (int k = 0; k < 3; ++k) {
      const auto [a, b] = edge_key(tri[k], tri[(k + 1) % 3]);
      if (c.bending) bend_dirty_.emplace_back(a, b);
      if (!(c.new_edges[i] >> k & 1u)) continue;  // it has its link
      const double kept = kept_.find(a, b, a, b, false);
      if (kept >= 0) {
        add_link(p, a, b, kept);
        --stats_.added_links;
      } else {
        add_link(p, a, b, (1 - material_.pretension) * (position(a) - position(b)).norm());
      }
    }
  }
}

void SkinnedSoftBody::Impl::refresh_changed_bending() {
  // Bending links of the edges whose faces changed, each edge once.
  std::sort(bend_dirty_.begin(), bend_dirty_.end());
  bend_dirty_.erase(std::unique(bend_dirty_.begin(), bend_dirty_.end()), bend_dirty_.end());
  for (const auto& [a, b] : bend_dirty_) refresh_bending(a, b);
}

void SkinnedSoftBody::Impl::refresh_changed_areas(MirrorContext& c) {
  // Node areas around the change, each node once (area_mark_ is clear between changes).
  area_mark_.resize(c.total, 0);
  auto area = [&](std::int32_t v) {
    auto& mark = area_mark_[static_cast<std::size_t>(v)];
    if (!mark) mark = 1, update_node_area(v);
  };
  const auto& seeds = split_.seeds();
  for (const auto v : seeds) area(v);
  for (const auto f : c.pending)
    for (const auto v : faces_[static_cast<std::size_t>(f)]) area(v);
  for (const auto v : seeds) area_mark_[static_cast<std::size_t>(v)] = 0;
  for (const auto f : c.moved_faces)
    for (const auto v : faces_[static_cast<std::size_t>(f)]) area(v);
  for (const auto f : c.moved_faces)
    for (const auto v : faces_[static_cast<std::size_t>(f)])
      area_mark_[static_cast<std::size_t>(v)] = 0;
  for (const auto f : c.pending)
    for (const auto v : faces_[static_cast<std::size_t>(f)])
      area_mark_[static_cast<std::size_t>(v)] = 0;
}

}  // namespace conform::bullet
