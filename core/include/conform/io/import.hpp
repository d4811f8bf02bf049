// Loading rigged models: any format assimp reads (.dae, .fbx, .gltf/.glb, .x, .smd,
// .md5mesh, ...) or the built-in procedural arm ("arm", "arm:N").
//
// Import conventions:
// - assimp post-processing: triangulate, join identical vertices, validate the data
//   structure (import_flags()); no weight limiting — every influence is kept.
// - Every node of the scene becomes a joint (depth-first, parents first), with its own
//   transform as a versor; every aiBone becomes a bone on the node of the same name. A mesh
//   without bones becomes one rigid bone on its node. A bone without a node of its name gets a
//   root joint of its own at its bind pose (O⁻¹), with a warning. A mesh placed by several
//   nodes is imported once per node (MeshInfo::source names the file's mesh).
// - Exact bind transforms: at the rest pose the model reproduces the file's matrix skinning
//   x' = Σ w G_b O_b x (G_b the bone node's global matrix, O_b its offset). Each mesh's bind
//   transform K = Q N: Q, the nearest proper similarity, is carried by the versors; N, the
//   non-uniform stretch or mirror, is baked into the rest positions, x_rest = N x (normals by
//   N⁻ᵀ, faces rewound when N mirrors; nothing is baked when K is a similarity). Mirroring
//   nodes and bones below approximated nodes stay exact too. Not exact: a non-uniform scale
//   that an animation really moves (animated, or above an animated bone), or a key that
//   changes a node's parity. There the nearest similarity is used, and the importer warns with
//   the largest deviation from the file's matrix skinning (at the rest pose and every key
//   time) relative to the model's diagonal. Derivation: docs/notes/import_skinning_ik.md.
// - Influences: all kept (SkinnedModel::influences). Each vertex's weights are normalized to
//   sum 1; sums off by more than 1e-4 (exports that truncate influences) give one summary
//   warning, or with ImportOptions::strict_weights an error. A vertex whose bones give it no
//   weight is an error.
// - Animations: position, rotation and scaling keys per node channel, times in ticks;
//   ticks per second 25 when the file says 0.
// - Welding (ImportOptions::weld, on by default): each mesh's vertices at one position become
//   one vertex; UVs and normals are kept per face corner (SkinnedMesh::corner_uvs/normals).
// - Errors (missing file, unsupported format, unreadable or truncated file, no meshes, NaN
//   transforms or keys, strict weights not summing to 1, bone or vertex ids out of range)
//   throw ImportError whose message starts with the file name.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>

#include "conform/io/isolation_limits.hpp"
#include "conform/io/model.hpp"
#include "conform/mesh/weld.hpp"

namespace conform::io {

class ImportError : public std::runtime_error {
 public:
  ImportError(const std::string& file, const std::string& problem)
      : std::runtime_error(file + ": " + problem), file_(file), problem_(problem) {}
  const std::string& file() const { return file_; }
  const std::string& problem() const { return problem_; }

 private:
  std::string file_, problem_;
};

struct ImportOptions {
  /// Refuse a vertex whose bone weights do not sum to 1 (to 1e-4) instead of normalizing it
  /// with a summary warning (the command line's --strict-weights, scene files'
  /// model.strict_weights).
  bool strict_weights = false;
  /// Import in a forked child process (POSIX) with the caps of `isolation`, so that a file on
  /// which assimp crashes, hangs or allocates without bound (docs/notes/import_skinning_ik.md)
  /// gives an ImportError saying so instead of killing or corrupting the caller: the child does
  /// the whole import and sends the model back as bytes; assimp never runs in the caller. The
  /// child dies with the calling thread. Off by default for library users: forking a
  /// multithreaded host is only safe when no other thread holds a lock the child needs; every
  /// `conform` command turns it on.
  bool isolate = false;
  IsolationLimits isolation;
  /// Weld each mesh's vertices at one position, keeping UVs and normals per face corner
  /// (io/weld_model.hpp, mesh/weld.hpp: the tolerance is relative to the bounding-box diagonal;
  /// vertices whose weights differ stay apart).
  bool weld = true;
  mesh::WeldOptions weld_options;
};

/// The assimp post-processing flags used by import_model (aiPostProcessSteps bits).
unsigned import_flags();

/// Imports a model file with assimp. Throws ImportError.
SkinnedModel import_model(const std::filesystem::path& file, const ImportOptions& options = {});

/// The procedural arm at resolution N as a model (no animations).
SkinnedModel arm_model(int resolution = 1);

/// "arm" or "arm:N" → the procedural arm; anything else → import_model. Throws ImportError
/// (also for a malformed arm spec).
SkinnedModel load_model(const std::string& spec, const ImportOptions& options = {});

}  // namespace conform::io
