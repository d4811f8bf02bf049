#include "conform/mesh/face_index.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "conform/mesh/adjacency.hpp"
#include "face_index_box.hpp"

namespace conform::mesh {

namespace {

// Room for `more` elements beyond the size, growing geometrically (×1.5): a reserve() of just
// size + more on every change would reallocate and copy the whole array each time (O(F) per
// change, and fresh pages to fault in).
template <class T>
void reserve_more(std::vector<T>& v, std::size_t more) {
  const std::size_t need = v.size() + more;
  if (need > v.capacity()) v.reserve(std::max(need, v.capacity() + v.capacity() / 2));
}

}  // namespace

using boxes::area;
using boxes::contains;
using boxes::empty;
using boxes::grow;
using boxes::kInf;
using boxes::make_box;

FaceIndex::Box FaceIndex::face_box(const SkinnedMesh& mesh, std::int32_t f) const {
  const Face& t = mesh.faces[static_cast<std::size_t>(f)];
  double lo[3], hi[3];
  for (int k = 0; k < 3; ++k) lo[k] = hi[k] = mesh.current(k, t[0]);
  for (int c = 1; c < 3; ++c)
    for (int k = 0; k < 3; ++k) {
      const double x = mesh.current(k, t[c]);
      lo[k] = std::min(lo[k], x);
      hi[k] = std::max(hi[k], x);
    }
  return make_box<Box>(lo, hi);
}

void FaceIndex::fit_leaf(const SkinnedMesh& mesh, std::int32_t n) {
  Node& node = nodes_[static_cast<std::size_t>(n)];
  double lo[3] = {std::numeric_limits<double>::infinity(), 0, 0}, hi[3] = {-lo[0], 0, 0};
  if (node.count > 0) {
    const Face& t0 =
        mesh.faces[static_cast<std::size_t>(items_[static_cast<std::size_t>(node.first)])];
    for (int k = 0; k < 3; ++k) lo[k] = hi[k] = mesh.current(k, t0[0]);
  }
  for (std::int32_t i = 0; i < node.count; ++i) {
    const Face& t =
        mesh.faces[static_cast<std::size_t>(items_[static_cast<std::size_t>(node.first + i)])];
    for (auto v : t)
      for (int k = 0; k < 3; ++k) {
        const double x = mesh.current(k, v);
        lo[k] = std::min(lo[k], x);
        hi[k] = std::max(hi[k], x);
      }
  }
  node.box = make_box<Box>(lo, hi);
}

std::int32_t FaceIndex::new_leaf_block() {
  const auto first = static_cast<std::int32_t>(items_.size());
  items_.resize(items_.size() + kLeafCapacity, -1);
  return first;
}

void FaceIndex::build(const SkinnedMesh& mesh) {
  const std::int32_t nf = mesh.face_count();
  nodes_.clear();
  items_.clear();
  leaf_of_.assign(static_cast<std::size_t>(nf), -1);
  fitted_ = true;
  if (nf == 0) return;
  std::vector<std::int32_t> faces(static_cast<std::size_t>(nf));
  std::iota(faces.begin(), faces.end(), 0);
  nodes_.push_back({});
  build_subtree(mesh, faces, 0);
  reserve(nf / 8 + 1024);
  refit(mesh);
}

void FaceIndex::build_subtree(const SkinnedMesh& mesh, const std::vector<std::int32_t>& faces,
                              std::int32_t root) {
  // Faces in Morton order of their centroids (21 bits per axis over the centroids' box), then
  // a balanced tree over that order by halving: spatially coherent leaves at the cost of a sort.
  // New nodes are appended (after `root`, which exists); boxes are left to the caller.
  const auto nf = static_cast<std::int32_t>(faces.size());
  std::vector<Eigen::Vector3d> centroid(faces.size());
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const Face& t = mesh.faces[static_cast<std::size_t>(faces[i])];
    const Eigen::Vector3d c =
        (mesh.current.col(t[0]) + mesh.current.col(t[1]) + mesh.current.col(t[2])) / 3;
    centroid[i] = c;
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  const double extent = (hi - lo).maxCoeff();
  const double scale = extent > 0 ? (double(1 << 21) - 1) / extent : 0;
  auto spread = [](std::uint64_t x) {  // 21 bits to every third of 63
    x &= 0x1fffff;
    x = (x | x << 32) & 0x1f00000000ffffull;
    x = (x | x << 16) & 0x1f0000ff0000ffull;
    x = (x | x << 8) & 0x100f00f00f00f00full;
    x = (x | x << 4) & 0x10c30c30c30c30c3ull;
    x = (x | x << 2) & 0x1249249249249249ull;
    return x;
  };
  std::vector<std::pair<std::uint64_t, std::int32_t>> keyed(faces.size());
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const Eigen::Vector3d q = (centroid[i] - lo) * scale;
    std::uint64_t code = 0;
    for (int k = 0; k < 3; ++k) {
      const double x = std::isfinite(q[k]) ? std::clamp(q[k], 0.0, double(1 << 21) - 1) : 0;
      code |= spread(static_cast<std::uint64_t>(x)) << k;
    }
    keyed[i] = {code, faces[i]};
  }
  std::sort(keyed.begin(), keyed.end());
  const std::size_t leaves = faces.size() / kLeafBuild + 1;
  reserve_more(nodes_, 2 * leaves + 16);
  reserve_more(items_, kLeafCapacity * leaves + 64);
  struct Task {
    std::int32_t node, begin, end;
  };
  std::vector<Task> stack{{root, 0, nf}};
  while (!stack.empty()) {
    const Task task = stack.back();
    stack.pop_back();
    const std::int32_t n = task.end - task.begin;
    if (n <= kLeafBuild) {
      const std::int32_t first = new_leaf_block();
      Node& leaf = nodes_[static_cast<std::size_t>(task.node)];
      leaf.child = -1;
      leaf.first = first;
      leaf.count = n;
      for (std::int32_t i = 0; i < n; ++i) {
        const std::int32_t f = keyed[static_cast<std::size_t>(task.begin + i)].second;
        items_[static_cast<std::size_t>(first + i)] = f;
        leaf_of_[static_cast<std::size_t>(f)] = task.node;
      }
      continue;
    }
    const std::int32_t mid = task.begin + n / 2;
    const auto child = static_cast<std::int32_t>(nodes_.size());
    Node& node = nodes_[static_cast<std::size_t>(task.node)];
    node.child = child;
    node.first = -1;
    node.count = 0;
    Node c;
    c.parent = task.node;
    nodes_.push_back(c);
    nodes_.push_back(c);
    stack.push_back({child + 1, mid, task.end});
    stack.push_back({child, task.begin, mid});
  }
}

void FaceIndex::reserve(std::int32_t more) {
  // Each leaf split (about one per four inserted faces) adds two nodes and one leaf block.
  const auto m = static_cast<std::size_t>(std::max(more, 0));
  reserve_more(nodes_, m / 2 + 16);
  reserve_more(items_, kLeafCapacity * (m / 4 + 16));
  reserve_more(leaf_of_, m);
}

void FaceIndex::refit(const SkinnedMesh& mesh) {
  // Children come after their parents, so one backward pass fits every node.
  for (std::size_t i = nodes_.size(); i-- > 0;) {
    Node& n = nodes_[i];
    if (n.child < 0) {
      fit_leaf(mesh, static_cast<std::int32_t>(i));
    } else {
      n.box = nodes_[static_cast<std::size_t>(n.child)].box;
      grow(n.box, nodes_[static_cast<std::size_t>(n.child + 1)].box);
    }
  }
  fitted_ = true;
}

void FaceIndex::grow_up(std::int32_t n, const Box& box) {
  // Boxes nest, so the first ancestor that already holds `box` ends the climb.
  for (; n >= 0; n = nodes_[static_cast<std::size_t>(n)].parent) {
    Box& b = nodes_[static_cast<std::size_t>(n)].box;
    if (contains(b, box)) break;
    grow(b, box);
  }
}

std::int32_t FaceIndex::cheapest_child(std::int32_t n, const Box& box) const {
  // The child whose box grows least (surface area) to hold `box`, ties to the smaller box.
  const std::int32_t first = nodes_[static_cast<std::size_t>(n)].child;
  double best_cost = 0, best_area = 0;
  std::int32_t best = -1;
  for (std::int32_t c = first; c < first + 2; ++c) {
    Box u = nodes_[static_cast<std::size_t>(c)].box;
    const double before = area(u);
    grow(u, box);
    const double after = area(u), cost = after - before;
    if (best < 0 || cost < best_cost || (cost == best_cost && after < best_area))
      best = c, best_cost = cost, best_area = after;
  }
  return best;
}

void FaceIndex::insert(const SkinnedMesh& mesh, std::int32_t f, const Box& fb, std::int32_t near) {
  if (nodes_.empty()) {
    Node root;
    root.box = fb;
    root.first = new_leaf_block();
    nodes_.push_back(root);
    near = 0;
  }
  // From the hint up to the first box that already holds the face (its ancestors do too),
  // then down where the boxes grow least.
  std::int32_t n = near < 0 ? 0 : near;
  while (n > 0 && !contains(nodes_[static_cast<std::size_t>(n)].box, fb))
    n = nodes_[static_cast<std::size_t>(n)].parent;
  for (;;) {
    Node& node = nodes_[static_cast<std::size_t>(n)];
    grow(node.box, fb);
    if (node.child < 0) break;
    n = cheapest_child(n, fb);
  }
  Node& leaf = nodes_[static_cast<std::size_t>(n)];
  if (leaf.count < kLeafCapacity) {
    items_[static_cast<std::size_t>(leaf.first + leaf.count++)] = f;
    leaf_of_[static_cast<std::size_t>(f)] = n;
    return;
  }
  split_leaf(mesh, n, f);
}

void FaceIndex::split_leaf(const SkinnedMesh& mesh, std::int32_t n, std::int32_t extra) {
  std::array<std::int32_t, kLeafCapacity + 1> faces{};
  std::array<std::array<double, 3>, kLeafCapacity + 1> centroid{};
  const Node old = nodes_[static_cast<std::size_t>(n)];
  for (int i = 0; i < kLeafCapacity; ++i)
    faces[static_cast<std::size_t>(i)] = items_[static_cast<std::size_t>(old.first + i)];
  faces[kLeafCapacity] = extra;
  double lo[3] = {std::numeric_limits<double>::infinity(), 0, 0}, hi[3] = {-lo[0], 0, 0};
  for (int k = 1; k < 3; ++k) lo[k] = lo[0], hi[k] = hi[0];
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const Face& t = mesh.faces[static_cast<std::size_t>(faces[i])];
    for (int k = 0; k < 3; ++k) {
      const double c = (mesh.current(k, t[0]) + mesh.current(k, t[1]) + mesh.current(k, t[2])) / 3;
      centroid[i][static_cast<std::size_t>(k)] = c;
      lo[k] = std::min(lo[k], c);
      hi[k] = std::max(hi[k], c);
    }
  }
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (hi[k] - lo[k] > hi[axis] - lo[axis]) axis = k;
  std::array<int, kLeafCapacity + 1> idx{};
  std::iota(idx.begin(), idx.end(), 0);
  std::sort(idx.begin(), idx.end(), [&](int a, int b) {
    return centroid[static_cast<std::size_t>(a)][static_cast<std::size_t>(axis)] <
           centroid[static_cast<std::size_t>(b)][static_cast<std::size_t>(axis)];
  });
  const auto child = static_cast<std::int32_t>(nodes_.size());
  Node c0, c1;
  c0.parent = c1.parent = n;
  c0.first = old.first;
  c1.first = new_leaf_block();
  constexpr int half = (kLeafCapacity + 1) / 2;
  for (int i = 0; i < kLeafCapacity + 1; ++i) {
    const std::int32_t f = faces[static_cast<std::size_t>(idx[static_cast<std::size_t>(i)])];
    Node& c = i < half ? c0 : c1;
    items_[static_cast<std::size_t>(c.first + c.count++)] = f;
    leaf_of_[static_cast<std::size_t>(f)] = i < half ? child : child + 1;
  }
  for (int i = half; i < kLeafCapacity; ++i) items_[static_cast<std::size_t>(c0.first + i)] = -1;
  nodes_.push_back(c0);
  nodes_.push_back(c1);
  Node& node = nodes_[static_cast<std::size_t>(n)];
  node.child = child;
  node.first = -1;
  node.count = 0;
  fit_leaf(mesh, child);
  fit_leaf(mesh, child + 1);
  // The children's pads may reach a hair beyond the grown box: keep the ancestors enclosing.
  grow_up(n, nodes_[static_cast<std::size_t>(child)].box);
  grow_up(n, nodes_[static_cast<std::size_t>(child + 1)].box);
}

void FaceIndex::erase(std::int32_t f) {
  const std::int32_t n = leaf_of_[static_cast<std::size_t>(f)];
  leaf_of_[static_cast<std::size_t>(f)] = -1;
  if (n < 0) return;  // deferred (or absent): nothing in the tree
  Node& leaf = nodes_[static_cast<std::size_t>(n)];
  for (std::int32_t i = 0; i < leaf.count; ++i)
    if (items_[static_cast<std::size_t>(leaf.first + i)] == f) {
      items_[static_cast<std::size_t>(leaf.first + i)] =
          items_[static_cast<std::size_t>(leaf.first + leaf.count - 1)];
      items_[static_cast<std::size_t>(leaf.first + --leaf.count)] = -1;
      break;
    }
  leaf_of_[static_cast<std::size_t>(f)] = -1;
}

void FaceIndex::rename(std::int32_t from, std::int32_t to) {
  const std::int32_t n = leaf_of_[static_cast<std::size_t>(from)];
  if (n == kPending) {
    pending_hint_.insert(0, to, hint_of(from), true);
    pending_.push_back(to);
    leaf_of_[static_cast<std::size_t>(to)] = kPending;
    leaf_of_[static_cast<std::size_t>(from)] = -1;
    return;
  }
  const Node& leaf = nodes_[static_cast<std::size_t>(n)];
  for (std::int32_t i = 0; i < leaf.count; ++i)
    if (items_[static_cast<std::size_t>(leaf.first + i)] == from)
      items_[static_cast<std::size_t>(leaf.first + i)] = to;
  leaf_of_[static_cast<std::size_t>(to)] = n;
  leaf_of_[static_cast<std::size_t>(from)] = -1;
}

void FaceIndex::update(const SkinnedMesh& mesh, const TopologyChange& change) {
  const auto& removed = change.removed_faces;
  const auto& added = change.added_faces;
  const auto final_count = static_cast<std::int64_t>(change.base_face_count) +
                           static_cast<std::int64_t>(added.size()) -
                           static_cast<std::int64_t>(removed.size());
  if (change.base_face_count != face_count() || final_count != mesh.face_count())
    throw std::invalid_argument(
        "FaceIndex::update: the change was not computed for the indexed mesh (apply it first)");
  // Faces are tracked by slot. The removed faces leave first; then the slot bookkeeping of
  // apply() is replayed (visit_face_slots), and only then do the added faces enter, at their
  // final slots, so that their positions are read from the changed mesh.
  const std::size_t nr = removed.size(), na = added.size();
  std::vector<std::int32_t> old_leaf(nr);
  for (std::size_t j = 0; j < nr; ++j) {
    old_leaf[j] = hint_of(removed[j]);
    erase(removed[j]);
  }
  struct Slots {
    FaceIndex& index;
    std::vector<std::int32_t> slot_of;
    void fill(std::int32_t slot, std::size_t k) { slot_of[k] = slot; }
    void append(std::int32_t slot, std::size_t k) {
      slot_of[k] = slot;
      index.leaf_of_.push_back(-1);
    }
    // The moved face is a base face (visit_face_slots): it keeps its leaf under its new slot.
    void move(std::int32_t last, std::int32_t slot) { index.rename(last, slot); }
    void pop(std::int32_t) { index.leaf_of_.pop_back(); }
  } slots{*this, std::vector<std::int32_t>(na)};
  visit_face_slots(change, slots);
  const std::vector<std::int32_t>& slot_of = slots.slot_of;
  // The operations list added faces in the order of the faces they replace, so the k-th added
  // face most likely lies where removed face k·R/A lay: it enters the tree from that face's
  // leaf (and stays there when the leaf's box holds it).
  if (batch_) {
    for (std::size_t k = 0; k < na; ++k) add(mesh, slot_of[k], nr == 0 ? 0 : old_leaf[k * nr / na]);
    return;
  }
  std::vector<std::int32_t> hint(na);
  for (std::size_t k = 0; k < na; ++k) hint[k] = nr == 0 ? -1 : old_leaf[k * nr / na];
  insert_many(mesh, slot_of, hint);
}

void FaceIndex::insert_many(const SkinnedMesh& mesh, const std::vector<std::int32_t>& faces,
                            const std::vector<std::int32_t>& hint) {
  // Few faces: one by one from their hints. Many (a drill's tube walls and rings, a large
  // refinement): a face whose box lies within its hint's leaf or two levels above it is local
  // and enters one by one as well (a short climb and descent); the others (no hint, or faces
  // away from the leaf they replace, e.g. inside the limb) would each climb near the root and
  // descend its whole depth: they are built into one subtree instead (as build() does), hung
  // where its box grows the tree least.
  if (faces.size() <= kBulkMin || nodes_.empty()) {
    if (faces.size() > kBulkMin) return insert_subtree(mesh, faces);
    for (std::size_t k = 0; k < faces.size(); ++k)
      insert(mesh, faces[k], face_box(mesh, faces[k]), std::max(hint[k], 0));
    return;
  }
  std::vector<std::int32_t> rest;
  Box rest_box;
  for (int k = 0; k < 3; ++k) rest_box.lo[k] = kInf, rest_box.hi[k] = -kInf;
  for (std::size_t k = 0; k < faces.size(); ++k) {
    const Box fb = face_box(mesh, faces[k]);
    bool local = false;
    std::int32_t n = hint[k];
    for (int up = 0; up < 3 && n >= 0 && !local;
         ++up, n = nodes_[static_cast<std::size_t>(n)].parent)
      local = contains(nodes_[static_cast<std::size_t>(n)].box, fb);
    if (local)
      insert(mesh, faces[k], fb, hint[k]);
    else
      rest.push_back(faces[k]), grow(rest_box, fb);
  }
  if (rest.size() > kBulkMin) return insert_subtree(mesh, rest, &rest_box);
  for (auto f : rest) insert(mesh, f, face_box(mesh, f), 0);
}

void FaceIndex::insert_subtree(const SkinnedMesh& mesh, const std::vector<std::int32_t>& faces,
                               const Box* box) {
  const auto first_new = static_cast<std::int32_t>(nodes_.size());
  std::int32_t root = 0, slot = 0;  // the new subtree's root; the slot that takes it
  if (nodes_.empty()) {
    nodes_.push_back({});
  } else {
    // The batch's box, then down from the root where it grows the boxes least (as insert()),
    // to a leaf L. Only a leaf can take a sibling in place (an internal node's children must
    // stay after it): L's slot becomes the parent of L (moved to the end) and the new subtree.
    Box bb;
    if (box) {
      bb = *box;
    } else {
      for (int k = 0; k < 3; ++k) bb.lo[k] = kInf, bb.hi[k] = -kInf;
      for (auto f : faces) grow(bb, face_box(mesh, f));
    }
    std::int32_t n = 0;
    while (nodes_[static_cast<std::size_t>(n)].child >= 0) n = cheapest_child(n, bb);
    root = slot = n;
    if (nodes_[static_cast<std::size_t>(n)].count > 0) {
      Node moved = nodes_[static_cast<std::size_t>(n)];
      moved.parent = n;
      for (std::int32_t i = 0; i < moved.count; ++i)
        leaf_of_[static_cast<std::size_t>(items_[static_cast<std::size_t>(moved.first + i)])] =
            first_new;
      Node fresh;
      fresh.parent = n;
      nodes_.push_back(moved);
      nodes_.push_back(fresh);
      Node& at = nodes_[static_cast<std::size_t>(n)];
      at.child = first_new;
      at.first = -1;
      at.count = 0;
      root = first_new + 1;
    }
  }
  build_subtree(mesh, faces, root);
  // Fit the new nodes (children after parents), then the slot that took them, then upwards.
  for (auto i = static_cast<std::int32_t>(nodes_.size()); i-- > first_new;) fit_node(mesh, i);
  if (slot < first_new) fit_node(mesh, slot);
  const std::int32_t up = nodes_[static_cast<std::size_t>(slot)].parent;
  if (up >= 0) grow_up(up, nodes_[static_cast<std::size_t>(slot)].box);
}

void FaceIndex::fit_node(const SkinnedMesh& mesh, std::int32_t i) {
  Node& n = nodes_[static_cast<std::size_t>(i)];
  if (n.child < 0) return fit_leaf(mesh, i);
  n.box = nodes_[static_cast<std::size_t>(n.child)].box;
  grow(n.box, nodes_[static_cast<std::size_t>(n.child + 1)].box);
}

std::int32_t FaceIndex::hint_of(std::int32_t f) const {
  const std::int32_t n = leaf_of_[static_cast<std::size_t>(f)];
  if (n != kPending) return std::max(n, 0);
  return std::max(pending_hint_.find(0, f), 0);
}

void FaceIndex::add(const SkinnedMesh& mesh, std::int32_t f, std::int32_t near) {
  if (!batch_) return insert(mesh, f, face_box(mesh, f), near);
  leaf_of_[static_cast<std::size_t>(f)] = kPending;
  pending_hint_.insert(0, f, near, true);
  pending_.push_back(f);
}

void FaceIndex::end_batch(const SkinnedMesh& mesh) {
  batch_ = false;
  std::vector<std::int32_t> faces, hint;
  for (auto f : pending_) {
    if (f >= face_count() || leaf_of_[static_cast<std::size_t>(f)] != kPending) continue;
    faces.push_back(f);
    hint.push_back(hint_of(f));
    leaf_of_[static_cast<std::size_t>(f)] = -1;
  }
  pending_.clear();
  pending_hint_.clear();
  insert_many(mesh, faces, hint);
}

int FaceIndex::depth() const {
  if (nodes_.empty()) return 0;
  std::vector<int> d(nodes_.size(), 1);
  int deepest = 1;
  for (std::size_t i = 1; i < nodes_.size(); ++i) {
    d[i] = d[static_cast<std::size_t>(nodes_[i].parent)] + 1;
    deepest = std::max(deepest, d[i]);
  }
  return deepest;
}

std::string FaceIndex::validate(const SkinnedMesh& mesh) const {
  if (face_count() != mesh.face_count()) return "face count differs from the mesh's";
  std::vector<int> seen(leaf_of_.size(), 0);
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    const Node& n = nodes_[i];
    if (i > 0 && (n.parent < 0 || static_cast<std::size_t>(n.parent) >= i))
      return "node " + std::to_string(i) + ": bad parent";
    if (n.child >= 0) {
      if (static_cast<std::size_t>(n.child) <= i ||
          static_cast<std::size_t>(n.child) + 1 >= nodes_.size())
        return "node " + std::to_string(i) + ": bad children";
      for (int c = 0; c < 2; ++c) {
        const Node& ch = nodes_[static_cast<std::size_t>(n.child + c)];
        if (ch.parent != static_cast<std::int32_t>(i))
          return "node " + std::to_string(i) + ": child's parent differs";
        if (fitted_ && !contains(n.box, ch.box))
          return "node " + std::to_string(i) + ": child box outside";
      }
      continue;
    }
    if (n.count < 0 || n.count > kLeafCapacity) return "leaf " + std::to_string(i) + ": bad count";
    for (std::int32_t k = 0; k < n.count; ++k) {
      const std::int32_t f = items_[static_cast<std::size_t>(n.first + k)];
      if (f < 0 || f >= face_count()) return "leaf " + std::to_string(i) + ": face out of range";
      if (seen[static_cast<std::size_t>(f)]++) return "face " + std::to_string(f) + " twice";
      if (leaf_of_[static_cast<std::size_t>(f)] != static_cast<std::int32_t>(i))
        return "face " + std::to_string(f) + ": leaf_of differs";
      if (fitted_ && !contains(n.box, face_box(mesh, f)))
        return "face " + std::to_string(f) + ": box outside its leaf";
    }
  }
  for (std::size_t f = 0; f < seen.size(); ++f)
    if (!seen[f]) return "face " + std::to_string(f) + " in no leaf";
  return {};
}

}  // namespace conform::mesh
