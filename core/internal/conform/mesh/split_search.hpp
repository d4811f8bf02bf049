// Incremental split search: the connected pieces (faces sharing a vertex) that a topology
// change leaves around the changed vertices, found without exploring the unchanged rest of a
// body. The caller (the Bullet plugin) keeps the faces, each vertex's face list and the body
// each vertex belonged to before the change; this is plain mesh work over those arrays.
//
// How: a piece can only split where faces changed, so one search starts at every changed
// vertex; searches that meet merge into a group, and they advance in turn, one vertex each,
// until at most one group is still growing. The exhausted groups are complete pieces; the
// growing one is the rest of its body, left unexplored (the open group), unless it reaches
// vertices of two bodies (a merge) or of none. A shorter proof ends changes inside one body
// (a drill through both walls of a limb): an old path can only have used removed faces within
// one cluster of them, so once each cluster's surviving vertices are in one group, every old
// vertex that keeps faces is still connected to all others.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "conform/mesh/skinned_mesh.hpp"

namespace conform::mesh {

class SplitSearch {
 public:
  /// group_of(): a vertex no search reached.
  static constexpr std::int32_t kUnreached = -1;
  /// group_of(): a vertex of the open group (the rest of open_body()).
  static constexpr std::int32_t kOpen = -2;

  /// The mesh after the change.
  struct Mesh {
    std::span<const Face> faces;
    std::span<const std::vector<std::int32_t>> vertex_faces;  // per vertex: its faces
    /// Per vertex: its body before the change, −1 for none (a new or detached vertex).
    std::span<const std::int32_t> body_of;
    std::int32_t first_new_vertex = 0;  // vertices from here on are the change's new ones
  };

  /// Room for the per-vertex labels of meshes up to `vertex_count` vertices.
  void reserve(std::int32_t vertex_count);
  /// Starts a change on a mesh of `vertex_count` vertices (after the change).
  void begin(std::int32_t vertex_count);
  /// A removed face, with its vertices as they were: they seed a search, and the face joins
  /// the cluster of removed faces it shares a vertex with. All removed faces come first.
  void seed_removed_face(const Face& face);
  /// A vertex of an added face, or a new vertex (each seeds once, in order of its first call).
  void seed(std::int32_t vertex) {
    auto& slot = seed_slot_[static_cast<std::size_t>(vertex)];
    if (slot < 0) slot = std::int32_t(seeds_.size()), seeds_.push_back(vertex);
  }
  /// The changed vertices, in seeding order (valid until clear()).
  const std::vector<std::int32_t>& seeds() const { return seeds_; }

  /// Runs the searches (seeds without faces start none).
  void run(const Mesh& mesh);
  /// The body the open group is the rest of; −1 when there is no open group.
  std::int32_t open_body() const { return open_body_; }
  /// The complete groups, each a whole connected piece (lists of vertices).
  const std::vector<std::vector<std::int32_t>>& pieces() const { return pieces_; }
  /// The index in pieces() of a vertex's group, kOpen or kUnreached.
  std::int32_t group_of(std::int32_t vertex) const;
  /// Vertices labelled by all searches of the last run().
  std::int32_t searched_vertices() const { return searched_; }
  /// Ends the change: clears the seeds and the labels (O(searched vertices)).
  void clear();

 private:
  struct Search {
    std::vector<std::int32_t> queue;  // the vertices it labelled, in order
    std::size_t head = 0;             // queue[head..] are still to expand
    std::int32_t root;
  };
  std::int32_t root_of(std::int32_t search);
  std::int32_t cluster_root(std::int32_t seed);
  void start_searches(const Mesh& mesh);
  bool body_unbroken();
  void take_body_as_open_group();
  bool open_group_found(const Mesh& mesh);
  void advance_searches(const Mesh& mesh);
  void collect_groups();

  // Per vertex (−1 between changes): its search, and its index among the seeds.
  std::vector<std::int32_t> label_, seed_slot_;
  std::vector<std::int32_t> seeds_;
  // Clusters of removed faces over the seeds they make (a union-find of seed indices).
  std::vector<std::int32_t> cluster_;
  std::vector<Search> searches_;
  std::vector<std::int32_t> active_;      // searches with vertices to expand
  std::vector<std::int32_t> pending_in_;  // per root: its searches with vertices to expand
  std::vector<std::uint8_t> has_old_;     // per root: holds a vertex older than the change
  std::vector<std::int32_t> boundary_;    // seeds of removed faces that keep faces
  std::vector<std::int32_t> cluster_group_;
  std::int32_t growing_ = 0, clusters_ = 0, only_body_ = -1;
  bool one_body_ = false, merged_ = false, to_the_end_ = false;
  std::int32_t open_root_ = -1, open_body_ = -1, searched_ = 0;
  std::vector<std::int32_t> group_of_root_;
  std::vector<std::vector<std::int32_t>> pieces_;
};

}  // namespace conform::mesh
