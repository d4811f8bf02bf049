// The skinned triangle mesh shared by import, skinning, topology operations and the plugin.
//
// Shapes (libigl style, #V vertices, #F faces):
//   rest       3 × #V  bind-pose positions, in the model space the skeleton's bind versors use
//   current    3 × #V  current positions (posed by skinning, or simulated); what cut/tear/drill
//                      operate on
//   faces      #F      counter-clockwise (outward normal by the right-hand rule) triangles
//   bones      4 × #V  bone indices of the up to 4 largest influences, unused slots 0
//   weights    4 × #V  their weights, sorted decreasing, summing to 1, unused slots 0
//   uvs        2 × #V  or empty
//   normals    3 × #V  rest-space normals, or empty
//   corner_uvs      6 × #F  per face corner ("wedge") UVs (u0 v0 u1 v1 u2 v2), or empty
//   corner_normals  9 × #F  per face corner rest-space normals (corner 0's xyz first), or empty
//   face_tags  #F      per face: what surface it is and the change that made it, or empty
//                      (then every face is skin from the model; apply() fills them in)
//
// Per-vertex and per-corner attributes. A file split at its UV and normal seams is welded on
// import (weld.hpp): one vertex per position for simulation and topology, while the corner
// arrays keep each face's own UVs and normals, so that the seams survive into the written and
// rendered mesh (mesh_export.hpp splits vertices by corner again). The per-vertex uvs/normals
// then hold one representative value (see weld.hpp). Meshes built without seams (the
// procedural arm) have no corner arrays. The corner arrays follow the faces through every
// TopologyChange (corner_attributes.hpp).
//
// Face tags. Every face is skin (from the model), cap (the section a capped cut closes) or tube
// wall (a drill's tube), and records the change that made it: `edits` counts the
// TopologyChanges applied to the mesh, and a face added by change n (1, 2, …) has op n and that
// change's kind of edit (cut, tear, drill, other); faces from the model have op 0, edit model. An
// added face listed in the change's `new_surface` gets that kind; every other added face lies in a
// removed face (a split or relabelled face) and keeps that face's kind (cap pieces of a later tear
// stay cap). Tags follow their face through every slot operation (topology_change.hpp), as the
// corner attributes do.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "conform/mesh/column_array.hpp"

namespace conform::mesh {

inline constexpr int kMaxInfluences = 4;

using Face = std::array<std::int32_t, 3>;

/// What surface a face is (see "Face tags" above). Values are stable (written to PLY).
enum class FaceKind : std::uint8_t { skin = 0, cap = 1, tube = 2 };

/// What kind of edit a change is (TopologyChange::edit), so what made a face. Values are
/// stable (written to PLY). `other`: a change made by hand or by another operation (refine).
enum class EditKind : std::uint8_t { model = 0, cut = 1, tear = 2, drill = 3, other = 4 };

struct FaceTag {
  FaceKind kind = FaceKind::skin;
  std::uint32_t op = 0;             // the change that made the face (0: the model)
  EditKind edit = EditKind::model;  // that change's kind (model: the face is the model's)
  bool operator==(const FaceTag&) const = default;
};

struct SkinnedMesh {
  // Per-vertex fields keep spare capacity (column_array.hpp): appending vertices is amortized
  // O(added), not a copy of every column.
  ColumnArray<double, 3> rest;
  ColumnArray<double, 3> current;
  std::vector<Face> faces;
  ColumnArray<std::int32_t, kMaxInfluences> bones;
  ColumnArray<double, kMaxInfluences> weights;
  ColumnArray<double, 2> uvs;
  ColumnArray<double, 3> normals;
  ColumnArray<double, 6> corner_uvs;
  ColumnArray<double, 9> corner_normals;
  std::vector<FaceTag> face_tags;  // #F, or empty: all skin, op 0
  std::uint32_t edits = 0;         // TopologyChanges applied (the op of the last one)

  std::int32_t vertex_count() const { return static_cast<std::int32_t>(rest.cols()); }
  std::int32_t face_count() const { return static_cast<std::int32_t>(faces.size()); }
  bool has_uvs() const { return uvs.cols() == rest.cols() && uvs.cols() > 0; }
  bool has_normals() const { return normals.cols() == rest.cols() && normals.cols() > 0; }
  bool has_corner_uvs() const { return corner_uvs.cols() == face_count() && face_count() > 0; }
  bool has_corner_normals() const {
    return corner_normals.cols() == face_count() && face_count() > 0;
  }
  bool has_face_tags() const { return face_tags.size() == faces.size() && !faces.empty(); }
  /// Face f's tag (skin, op 0 when the mesh has none).
  FaceTag face_tag(std::int32_t f) const {
    return has_face_tags() ? face_tags[static_cast<std::size_t>(f)] : FaceTag{};
  }
};

}  // namespace conform::mesh
