// A bounding volume hierarchy over the faces of a mesh, on its CURRENT positions, answering
// segment queries (the scalpel's blade, the drill's axis) in O(log F + hits) instead of a scan
// of every face. Queries are exact provided the boxes were fitted to the current positions:
// boxes are floats padded by more than their rounding, and the final test is the exact (double)
// segment–triangle test.
//
// Why a BVH: the meshes are far from uniform (rounded caps, refinement near a drill's rims) and
// move every step; a refit is one bottom-up pass that keeps the structure, and faces can be
// inserted and removed locally, where a grid would re-bin every face. Leaves hold up to 8 faces.
//
// Keeping the index in sync (the caller's duty, except where noted):
//   - build(mesh) once per mesh state (O(F log F));
//   - whenever the current positions move (skinning, simulation, Tear::open): refit(mesh)
//     (O(F), structure kept), or mark_moved() to have the next operation refit before it
//     queries (ensure_fitted); the plugin marks, so the refit is paid only when a tear starts
//     or a drill runs;
//   - after every TopologyChange applied to the mesh: update(mesh, change), with the mesh
//     already changed (O(changed faces · depth)). Tear and drill given an index do this
//     themselves; a cut (or any other change) applied by the caller must be followed by
//     update() as well. More than 16 faces added away from the ones they replace (a drill's
//     tube walls) are built into one subtree, so the tree stays shallow;
//   - boxes only grow under update(): after many changes, refit() tightens them and build()
//     restores a balanced tree.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "conform/mesh/adjacency.hpp"
#include "conform/mesh/skinned_mesh.hpp"
#include "conform/mesh/topology_change.hpp"

namespace conform::mesh {

struct SegmentHit {
  std::int32_t face = -1;
  double t = 0;                         // the point p + t (q − p), t in [0, 1]
  std::array<double, 3> bary{0, 0, 0};  // barycentric in the face, for its corners in order
};

/// Segment p→q against triangle (a, b, c) (Möller–Trumbore, closed bounds, so a segment through
/// an edge or a vertex meets every face sharing it). On a hit, writes the segment parameter and
/// the barycentric coordinates. A segment in the triangle's plane (|det| ≤ 1e−300) misses.
bool segment_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& a,
                      const Eigen::Vector3d& b, const Eigen::Vector3d& c, double& t,
                      std::array<double, 3>& bary);

/// Every face the segment meets, by one scan of all faces, sorted by (t, face). O(F). The
/// brute-force oracle of FaceIndex (tests, benchmarks), and how the tear and the drill search
/// when they are given no index.
std::vector<SegmentHit> scan_segment_hits(const SkinnedMesh& mesh, const Eigen::Vector3d& p,
                                          const Eigen::Vector3d& q);

class FaceIndex {
 public:
  FaceIndex() = default;
  explicit FaceIndex(const SkinnedMesh& mesh) { build(mesh); }

  /// Builds the tree (median splits of the face centroids along the longest axis) and fits it.
  void build(const SkinnedMesh& mesh);
  /// Refits every box to the current positions, bottom-up; the tree is kept. O(F).
  void refit(const SkinnedMesh& mesh);
  /// The positions moved: the next ensure_fitted() refits.
  void mark_moved() { fitted_ = false; }
  void ensure_fitted(const SkinnedMesh& mesh) {
    if (!fitted_) refit(mesh);
  }
  bool fitted() const { return fitted_; }
  /// Mirrors apply(mesh, change) (call it after the apply, with the changed mesh): faces in
  /// removed slots leave the tree, added faces enter it where their boxes grow it least, and
  /// faces moved by the swap-with-last step are renamed. Throws std::invalid_argument when the
  /// change was not computed for the mesh this index describes.
  void update(const SkinnedMesh& mesh, const TopologyChange& change);
  /// Between begin_batch() and end_batch(mesh), update() defers its insertions: an operation
  /// that applies several changes in a row (the two phases of a tear step) inserts only the faces
  /// that survive them all, as one update() would. No queries (and no validate) inside a batch.
  /// (The drill applies one change and needs no batch.)
  void begin_batch() { batch_ = true; }
  void end_batch(const SkinnedMesh& mesh);

  /// Room for `more` faces beyond the current count without reallocating (a copy of an index
  /// has none; build() leaves some).
  void reserve(std::int32_t more);

  /// True when the index describes a mesh of this face count (a cheap sanity check).
  bool matches(const SkinnedMesh& mesh) const { return face_count() == mesh.face_count(); }
  std::int32_t face_count() const { return static_cast<std::int32_t>(leaf_of_.size()); }
  std::int32_t node_count() const { return static_cast<std::int32_t>(nodes_.size()); }
  /// Longest root-to-leaf path (1 for a lone leaf, 0 when empty). O(nodes).
  int depth() const;

  /// Every face the segment p→q meets, sorted by (t, face); `out` is overwritten.
  void segment_hits(const SkinnedMesh& mesh, const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                    std::vector<SegmentHit>& out) const;
  std::vector<SegmentHit> segment_hits(const SkinnedMesh& mesh, const Eigen::Vector3d& p,
                                       const Eigen::Vector3d& q) const {
    std::vector<SegmentHit> out;
    segment_hits(mesh, p, q, out);
    return out;
  }
  /// The hit nearest p (smallest t, then lowest face), or face −1.
  SegmentHit first_hit(const SkinnedMesh& mesh, const Eigen::Vector3d& p,
                       const Eigen::Vector3d& q) const;

  /// Checks the structure against the mesh: every face in exactly one leaf, parents and
  /// children consistent, every face's box inside its leaf's and every child's inside its
  /// parent's (on the current positions). Empty when sound, else the first problem. O(F).
  std::string validate(const SkinnedMesh& mesh) const;

 private:
  static constexpr int kLeafBuild = 4, kLeafCapacity = 8;
  static constexpr std::size_t kBulkMin = 16;  // more faces without a local hint: one subtree
  struct Box {
    float lo[3], hi[3];
  };
  struct Node {
    Box box;
    std::int32_t child = -1;   // internal: children at child and child + 1; leaf: −1
    std::int32_t parent = -1;  // −1 at the root
    std::int32_t first = 0;    // leaf: its block of kLeafCapacity slots in items_
    std::int32_t count = 0;    // leaf: faces in the block
  };
  Box face_box(const SkinnedMesh& mesh, std::int32_t f) const;
  void fit_leaf(const SkinnedMesh& mesh, std::int32_t n);
  std::int32_t new_leaf_block();
  void insert(const SkinnedMesh& mesh, std::int32_t f, const Box& box, std::int32_t near);
  void erase(std::int32_t f);
  void rename(std::int32_t from, std::int32_t to);
  void split_leaf(const SkinnedMesh& mesh, std::int32_t n, std::int32_t extra);
  void grow_up(std::int32_t n, const Box& box);
  std::int32_t cheapest_child(std::int32_t n, const Box& box) const;     // internal node n
  void add(const SkinnedMesh& mesh, std::int32_t f, std::int32_t near);  // insert, or defer
  void insert_many(const SkinnedMesh& mesh, const std::vector<std::int32_t>& faces,
                   const std::vector<std::int32_t>& hint);
  void insert_subtree(const SkinnedMesh& mesh, const std::vector<std::int32_t>& faces,
                      const Box* box = nullptr);  // box: the faces' boxes' union, if known
  void build_subtree(const SkinnedMesh& mesh, const std::vector<std::int32_t>& faces,
                     std::int32_t root);
  void fit_node(const SkinnedMesh& mesh, std::int32_t n);
  std::int32_t hint_of(std::int32_t f) const;

  static constexpr std::int32_t kPending = -2;  // leaf_of_ of a deferred face

  std::vector<Node> nodes_;            // children always after their parent
  std::vector<std::int32_t> items_;    // leaf blocks of face slots
  std::vector<std::int32_t> leaf_of_;  // face slot → its leaf (kPending: deferred)
  bool fitted_ = false;
  bool batch_ = false;
  std::vector<std::int32_t> pending_;  // deferred slots (may repeat, or be gone)
  EdgeMap pending_hint_;               // (0, slot) → where to start inserting it
};

}  // namespace conform::mesh
