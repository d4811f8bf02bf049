// Export of a SkinnedMesh's positions as PLY (binary little-endian or ASCII) or OBJ.
//
// Seams. A mesh with corner attributes (a welded import, skinned_mesh.hpp) is written with
// one vertex per distinct (vertex, corner UV, corner normal), numbered in order of first use
// by the faces' corners: the seams as the file had them. Per-vertex UVs are then not used, and
// the corner normals are written too. A mesh without corner attributes is written as before:
// one vertex per vertex, its UVs, no normals.
//
// Face tags (skinned_mesh.hpp). A PLY of a mesh with face tags gives each face three more
// properties after its vertex_indices: `uchar surface` (0 skin, 1 cap, 2 tube wall), `uint op`
// (the change that made the face, 0: the model) and `uchar edit` (that change's kind: 0 model,
// 1 cut, 2 tear, 3 drill, 4 other). OBJ has no face properties: none.
//
// Files are written atomically: the data go to a temporary file in the same directory, which
// is renamed over the target only once it is complete, so a reader never sees half a mesh.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string_view>

#include "conform/mesh/skinned_mesh.hpp"

namespace conform::io {

enum class MeshFormat { PlyBinary, PlyAscii, Obj };

struct MeshExportOptions {
  MeshFormat format = MeshFormat::PlyBinary;
  /// Write the rest (bind-pose) positions instead of the current ones.
  bool rest_positions = false;
  /// Write UVs when the mesh has them (PLY: s, t properties; OBJ: vt lines).
  bool uvs = true;
  /// Write normals when the mesh has corner normals (PLY: nx, ny, nz; OBJ: vn lines).
  bool normals = true;
  /// Write the face tags when the mesh has them (PLY only: surface, op, edit).
  bool face_tags = true;
};

/// "ply" (binary), "ply-ascii" or "obj"; throws std::invalid_argument otherwise.
MeshFormat parse_mesh_format(std::string_view name);
/// ".ply" or ".obj".
const char* mesh_format_extension(MeshFormat format);

/// Writes `mesh` to `path`. When `faces` is not empty only those faces (indices into
/// mesh.faces) are written, with the vertices they use renumbered in increasing order; this is
/// how one piece of a cut mesh is exported. Throws std::runtime_error on I/O failure or a
/// NaN or infinite position, UV or normal among the written vertices (the target is then left
/// untouched) and std::out_of_range on an invalid face or vertex index.
void write_mesh(const std::filesystem::path& path, const mesh::SkinnedMesh& mesh,
                const MeshExportOptions& options = {}, std::span<const std::int32_t> faces = {});

/// The size in bytes of the file that write_mesh would write now (encoded in memory, not
/// written): for a cap on a command's output checked before anything is written. Throws as
/// write_mesh does for a non-finite vertex or a bad index.
std::size_t mesh_file_size(const mesh::SkinnedMesh& mesh, const MeshExportOptions& options = {},
                           std::span<const std::int32_t> faces = {});

}  // namespace conform::io
