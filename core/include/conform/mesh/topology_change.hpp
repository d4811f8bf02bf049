// The result of a cut, tear or drill: plain data describing how the mesh changes, computed
// first and applied afterwards ("compute the change, then apply it"), to a SkinnedMesh here
// and to a live soft body by the Bullet plugin.
//
// Vertices. New vertex i gets index base_vertex_count + i. It is an affine combination of up
// to three parents (existing vertices or earlier new ones):
//   on an edge      parents (a, b, −1),  coefficients (1 − t, t, 0)
//   in a face       parents (a, b, c),   barycentric (p, q, r), p + q + r = 1
//   a duplicate     parents (a, −1, −1), coefficients (1, 0, 0)  — same place, new identity
// Its rest and current positions, UVs and normals (renormalized) are the same combination of
// the parents', and its weights follow §4.3 of the paper: blend the parents' weights with the
// coefficients, keep the 4 largest, renormalize (sorted decreasing, ties by bone index).
// `displacement` is added to the new vertex's current position only (the tear's optional
// geometric opening; zero otherwise).
//
// Faces. `removed_faces` (strictly increasing indices into the mesh's faces before the change)
// and `added_faces` are applied slot by slot, so the soft body can mirror it exactly:
//   1. the k-th added face overwrites the k-th removed slot, while both last;
//   2. further added faces are appended;
//   3. the remaining removed slots, from the highest down, are filled by moving the last face
//      into them and popping it (swap-with-last; a slot that is the last face is just popped).
// Faces not mentioned keep their index, except those moved in step 3.
//
// Face tags (skinned_mesh.hpp). `new_surface` lists the runs of added faces that are new
// surface, with their kind: a cut's cap, a drill's tube wall. Every other added face keeps the
// kind of the removed face it lies in (corner_attributes.hpp's origin; skin when none is
// found). Every added face gets op = the mesh's edit count after the change.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "conform/mesh/adjacency.hpp"
#include "conform/mesh/skinned_mesh.hpp"

namespace conform::mesh {

struct NewVertex {
  std::array<std::int32_t, 3> parents{-1, -1, -1};
  std::array<double, 3> coefficients{0, 0, 0};
  Eigen::Vector3d displacement = Eigen::Vector3d::Zero();

  static NewVertex on_edge(std::int32_t a, std::int32_t b, double t) {
    return {{a, b, -1}, {1 - t, t, 0}};
  }
  static NewVertex in_face(std::int32_t a, std::int32_t b, std::int32_t c, double p, double q,
                           double r) {
    return {{a, b, c}, {p, q, r}};
  }
  static NewVertex duplicate(std::int32_t a) { return {{a, -1, -1}, {1, 0, 0}}; }
  bool is_duplicate() const { return parents[1] < 0; }
};

/// Added faces [first, first + count) are new surface of this kind.
struct NewSurface {
  std::int32_t first = 0, count = 0;
  FaceKind kind = FaceKind::cap;
};

struct TopologyChange {
  std::int32_t base_vertex_count = 0;  // the mesh the change was computed for
  std::int32_t base_face_count = 0;
  std::vector<NewVertex> new_vertices;
  std::vector<std::int32_t> removed_faces;  // strictly increasing
  std::vector<Face> added_faces;
  std::vector<NewSurface> new_surface;  // increasing, disjoint runs of added faces
  EditKind edit = EditKind::other;      // what made the change: its added faces' tags say so

  bool empty() const {
    return new_vertices.empty() && removed_faces.empty() && added_faces.empty();
  }
  /// Empty when the change is well formed for a mesh of the base counts, else the first problem.
  std::string validate() const;
  /// Where face slot `f` of the base mesh ends up after apply(): its new index, or −1 when it
  /// was removed. O(removed) per call.
  std::int32_t face_after(std::int32_t f) const;
};

/// Applies `change` to `mesh` (positions, skinning data, UVs, normals, faces, face tags; +1 to
/// mesh.edits) and, when given, keeps `adjacency` up to date. Throws std::invalid_argument
/// (leaving both untouched) when the change does not validate, was computed for a mesh of
/// other counts, or the mesh's face_tags are neither empty nor one per face.
void apply(SkinnedMesh& mesh, const TopologyChange& change, Adjacency* adjacency = nullptr);

/// The face-slot rule (steps 1–3 above), written once for every copy of the faces that has to
/// follow a change: the mesh (apply), FaceIndex::update, face_after, added_face_indices, the
/// plugin's soft body. Calls, in order,
///   visitor.fill(slot, k)     step 1: added face k overwrites removed slot `slot`;
///   visitor.append(slot, k)   step 2: added face k is appended as face `slot`;
///   visitor.move(last, slot)  step 3: the last face moves into the removed slot (slot < last),
///   visitor.pop(last)         step 3: then the last slot is dropped (also when it was the
///                             removed slot itself).
/// `slot` and `last` are face indices of the copy at that moment, starting from
/// base_face_count faces. A slot filled in step 1 is below every slot of step 3, so the added
/// faces never move: added face k ends at the slot of its fill() or append().
template <class Visitor>
void visit_face_slots(const TopologyChange& change, Visitor&& visitor) {
  const auto& removed = change.removed_faces;
  const std::size_t added = change.added_faces.size();
  const std::size_t filled = removed.size() < added ? removed.size() : added;
  for (std::size_t k = 0; k < filled; ++k) visitor.fill(removed[k], k);
  std::int32_t count = change.base_face_count;
  for (std::size_t k = filled; k < added; ++k) visitor.append(count++, k);
  for (std::size_t k = removed.size(); k-- > filled;) {
    const std::int32_t slot = removed[k], last = --count;
    if (slot != last) visitor.move(last, slot);
    visitor.pop(last);
  }
}

/// §4.3: blends up to three vertices' (bones, weights) with `coefficients`, keeps the 4
/// largest, renormalizes; writes column `out` of mesh.bones / mesh.weights.
void blend_influences(SkinnedMesh& mesh, const std::array<std::int32_t, 3>& parents,
                      const std::array<double, 3>& coefficients, std::int32_t out);

}  // namespace conform::mesh
