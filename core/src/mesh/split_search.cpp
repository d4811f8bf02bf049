#include "conform/mesh/split_search.hpp"

#include <algorithm>

namespace conform::mesh {

void SplitSearch::reserve(std::int32_t vertex_count) {
  label_.reserve(static_cast<std::size_t>(vertex_count));
  seed_slot_.reserve(static_cast<std::size_t>(vertex_count));
}

void SplitSearch::begin(std::int32_t vertex_count) {
  label_.resize(static_cast<std::size_t>(vertex_count), -1);
  seed_slot_.resize(static_cast<std::size_t>(vertex_count), -1);
}

std::int32_t SplitSearch::cluster_root(std::int32_t i) {
  while (cluster_[static_cast<std::size_t>(i)] != i)
    i = cluster_[static_cast<std::size_t>(i)] =
        cluster_[static_cast<std::size_t>(cluster_[static_cast<std::size_t>(i)])];
  return i;
}

void SplitSearch::seed_removed_face(const Face& face) {
  std::int32_t first = -1;
  for (const auto v : face) {
    seed(v);
    cluster_.resize(seeds_.size(), -1);
    const std::int32_t slot = seed_slot_[static_cast<std::size_t>(v)];
    if (cluster_[static_cast<std::size_t>(slot)] < 0)
      cluster_[static_cast<std::size_t>(slot)] = slot;
    if (first < 0)
      first = cluster_root(slot);
    else
      cluster_[static_cast<std::size_t>(cluster_root(slot))] = first;
  }
}

std::int32_t SplitSearch::root_of(std::int32_t s) {
  while (searches_[static_cast<std::size_t>(s)].root != s) {
    auto& r = searches_[static_cast<std::size_t>(s)].root;
    r = searches_[static_cast<std::size_t>(r)].root;
    s = r;
  }
  return s;
}

std::int32_t SplitSearch::group_of(std::int32_t vertex) const {
  const std::int32_t label = label_[static_cast<std::size_t>(vertex)];
  if (label < 0) return kUnreached;
  std::int32_t r = label;
  while (searches_[static_cast<std::size_t>(r)].root != r)
    r = searches_[static_cast<std::size_t>(r)].root;
  return r == open_root_ ? kOpen : group_of_root_[static_cast<std::size_t>(r)];
}

void SplitSearch::run(const Mesh& mesh) {
  for (const auto v : seeds_) seed_slot_[static_cast<std::size_t>(v)] = -1;
  start_searches(mesh);
  while (!active_.empty()) {
    if (merged_ && one_body_ && !to_the_end_ && growing_ > 1 && growing_ <= clusters_ &&
        body_unbroken()) {
      take_body_as_open_group();
      break;
    }
    merged_ = false;
    if (growing_ == 1 && !to_the_end_) {
      if (open_group_found(mesh)) break;
      to_the_end_ = true;
    }
    advance_searches(mesh);
  }
  collect_groups();
}

void SplitSearch::start_searches(const Mesh& mesh) {
  for (const auto v : seeds_) {
    const auto i = static_cast<std::size_t>(v);
    if (mesh.vertex_faces[i].empty() || label_[i] >= 0) continue;
    label_[i] = std::int32_t(searches_.size());
    searches_.push_back({{v}, 0, std::int32_t(searches_.size())});
  }
  active_.clear();
  for (std::size_t s = 0; s < searches_.size(); ++s) active_.push_back(std::int32_t(s));
  pending_in_.assign(searches_.size(), 1);
  growing_ = std::int32_t(searches_.size());
  open_root_ = open_body_ = -1;
  to_the_end_ = merged_ = false;
  // Is every old seed in one body (the proof's premise)?
  has_old_.assign(searches_.size(), 0);
  only_body_ = -1;
  one_body_ = true;
  for (std::size_t s = 0; s < searches_.size(); ++s) {
    const std::int32_t v = searches_[s].queue[0];
    if (v >= mesh.first_new_vertex) continue;
    has_old_[s] = 1;
    const std::int32_t p = mesh.body_of[static_cast<std::size_t>(v)];
    if (p < 0 || (only_body_ >= 0 && p != only_body_)) one_body_ = false;
    only_body_ = p;
  }
  one_body_ = one_body_ && only_body_ >= 0;
  boundary_.clear();
  for (std::size_t i = 0; i < cluster_.size(); ++i)
    if (!mesh.vertex_faces[static_cast<std::size_t>(seeds_[i])].empty())
      boundary_.push_back(std::int32_t(i));
  cluster_group_.assign(cluster_.size(), -1);
  // The proof needs each cluster in one group, so it is only tried with no more groups growing
  // than there are clusters (a cut's single ring never: the search must end the other way).
  clusters_ = 0;
  for (const auto i : boundary_) {
    auto& g = cluster_group_[static_cast<std::size_t>(cluster_root(i))];
    if (g < 0) g = 0, ++clusters_;
  }
  for (const auto i : boundary_) cluster_group_[static_cast<std::size_t>(cluster_root(i))] = -1;
}

bool SplitSearch::body_unbroken() {
  bool proven = true;
  for (const auto i : boundary_) {
    auto& g = cluster_group_[static_cast<std::size_t>(cluster_root(i))];
    const std::int32_t r =
        root_of(label_[static_cast<std::size_t>(seeds_[static_cast<std::size_t>(i)])]);
    if (g < 0) g = r;
    if (g != r) {
      proven = false;
      break;
    }
  }
  for (const auto i : boundary_) cluster_group_[static_cast<std::size_t>(cluster_root(i))] = -1;
  for (std::size_t k = 0; k < active_.size() && proven; ++k)
    proven = has_old_[static_cast<std::size_t>(root_of(active_[k]))];
  return proven;
}

void SplitSearch::take_body_as_open_group() {
  // One group for the body: every group holding an old vertex.
  open_body_ = only_body_;
  for (std::size_t s = 0; s < searches_.size(); ++s) {
    const std::int32_t r = root_of(std::int32_t(s));
    if (!has_old_[static_cast<std::size_t>(r)]) continue;
    if (open_root_ < 0) open_root_ = r;
    searches_[static_cast<std::size_t>(r)].root = open_root_;
  }
}

bool SplitSearch::open_group_found(const Mesh& mesh) {
  // Which bodies does the growing group touch so far? One: it is the rest of that body.
  const std::int32_t root = root_of(active_[0]);
  std::int32_t body = -1;
  bool several = false;
  for (std::size_t s = 0; s < searches_.size() && !several; ++s) {
    if (root_of(std::int32_t(s)) != root) continue;
    for (const auto v : searches_[s].queue) {
      const std::int32_t p = mesh.body_of[static_cast<std::size_t>(v)];
      if (p < 0) continue;
      if (body >= 0 && p != body) several = true;
      body = p;
    }
  }
  if (body < 0 || several) return false;
  open_root_ = root;
  open_body_ = body;
  return true;
}

void SplitSearch::advance_searches(const Mesh& mesh) {
  // Each active search expands one vertex.
  std::size_t kept = 0;
  for (const auto s : active_) {
    auto& search = searches_[static_cast<std::size_t>(s)];
    const std::int32_t u = search.queue[search.head++];
    std::int32_t rs = root_of(s);
    // Only the vertex after u in each of its faces: a face's vertices form a cycle under
    // "next", so its others are reached (and any other group labelling one of them is met)
    // from there, a third of the look-ups of all three.
    for (const auto f : mesh.vertex_faces[static_cast<std::size_t>(u)]) {
      const auto& tri = mesh.faces[static_cast<std::size_t>(f)];
      const std::int32_t w = tri[0] == u ? tri[1] : tri[1] == u ? tri[2] : tri[0];
      std::int32_t& label = label_[static_cast<std::size_t>(w)];
      if (label < 0) {
        label = s;
        searches_[static_cast<std::size_t>(s)].queue.push_back(w);
        if (w < mesh.first_new_vertex) has_old_[static_cast<std::size_t>(rs)] = 1;
        continue;
      }
      if (label == s) continue;
      const std::int32_t rw = root_of(label);
      if (rw == rs) continue;
      const std::int32_t r = std::min(rw, rs), o = std::max(rw, rs);
      merged_ = true;
      has_old_[static_cast<std::size_t>(r)] |= has_old_[static_cast<std::size_t>(o)];
      auto& pr = pending_in_[static_cast<std::size_t>(r)];
      auto& po = pending_in_[static_cast<std::size_t>(o)];
      if (pr > 0 && po > 0) --growing_;
      pr += po;
      po = 0;
      searches_[static_cast<std::size_t>(o)].root = r;
      rs = r;
    }
    if (searches_[static_cast<std::size_t>(s)].head <
        searches_[static_cast<std::size_t>(s)].queue.size())
      active_[kept++] = s;
    else if (--pending_in_[static_cast<std::size_t>(rs)] == 0)
      --growing_;
  }
  active_.resize(kept);
}

void SplitSearch::collect_groups() {
  // Complete groups, as lists of vertices.
  group_of_root_.assign(searches_.size(), -1);
  pieces_.clear();
  searched_ = 0;
  for (std::size_t s = 0; s < searches_.size(); ++s) {
    searched_ += std::int32_t(searches_[s].queue.size());
    const std::int32_t r = root_of(std::int32_t(s));
    if (r == open_root_) continue;
    auto& g = group_of_root_[static_cast<std::size_t>(r)];
    if (g < 0) {
      g = std::int32_t(pieces_.size());
      pieces_.emplace_back();
    }
    auto& list = pieces_[static_cast<std::size_t>(g)];
    list.insert(list.end(), searches_[s].queue.begin(), searches_[s].queue.end());
  }
}

void SplitSearch::clear() {
  for (const auto& s : searches_)
    for (const auto v : s.queue) label_[static_cast<std::size_t>(v)] = -1;
  for (const auto v : seeds_) seed_slot_[static_cast<std::size_t>(v)] = -1;
  searches_.clear();
  seeds_.clear();
  cluster_.clear();
  pieces_.clear();
}

}  // namespace conform::mesh
