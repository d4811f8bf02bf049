// A rigged model: the skinned mesh, the skeleton, the animations and every imported influence.
//
// Meshes of a file are merged into one SkinnedMesh, in the scene's mesh order (mesh 0's
// vertices first, then mesh 1's, ...; within a mesh, assimp's vertex order after
// triangulation and joining identical vertices). A mesh that several nodes place is merged
// once per node (its instances, in node order). `meshes` records each instance's vertex and
// face range. Positions in `rest` are in each mesh's own space, which is the space its bones'
// offsets (B_n) start from, with the part of the mesh's bind transform that no versor
// represents (a non-uniform stretch, a mirror) baked in (see import.hpp; nothing is baked for
// a mesh whose bind transform is a similarity). Skinning maps them to world space, the space
// assimp's node hierarchy places the meshes in. `current` holds the skinned rest pose (every
// node at its own transform) in that world space.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "conform/mesh/skinned_mesh.hpp"
#include "conform/skin/animation.hpp"
#include "conform/skin/skeleton.hpp"
#include "conform/skin/skinning.hpp"

namespace conform::io {

struct MeshInfo {
  std::string name;
  std::int32_t first_vertex = 0, vertex_count = 0;
  std::int32_t first_face = 0, face_count = 0;
  std::int32_t joint = 0;   // the node the mesh hangs from
  std::int32_t bones = 0;   // bones of the mesh in the file (0: one rigid bone on `joint`)
  std::int32_t source = 0;  // the file's mesh index (shared by the instances of one mesh)
};

struct SkinnedModel {
  std::string source;               // the file, or "arm:N"
  mesh::SkinnedMesh mesh;           // the 4 largest influences per vertex, renormalized
  skin::InfluenceLists influences;  // every imported influence, weights renormalized per vertex
  skin::Skeleton skeleton;
  std::vector<skin::Animation> animations;
  std::vector<MeshInfo> meshes;
  std::vector<std::string> warnings;  // e.g. weights normalized, transforms approximated
  /// Centimetres per file unit as the file states it (FBX's UnitScaleFactor metadata), so that
  /// a user need not know the file's units; 0 when the file states none.
  double unit_scale_cm = 0;

  /// Index of the animation named `name_or_index`, or with that index; −1 if none.
  int find_animation(const std::string& name_or_index) const;
};

}  // namespace conform::io
