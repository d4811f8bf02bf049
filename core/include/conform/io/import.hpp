// Loading rigged models: any format assimp reads (.dae, .fbx, .gltf/.glb, .x, .smd,
// .md5mesh, ...) or the built-in procedural arm ("arm", "arm:N").
//
// Import conventions:
// - assimp post-processing: triangulate, join identical vertices, validate the data
//   structure (import_flags()); no weight limiting — every influence is kept.
// - Every node of the scene becomes a joint (depth-first, parents first), with its own
//   transform as a versor; every aiBone becomes a bone on the node of the same name with its
//   offset matrix as versor B_n. A mesh without bones becomes one rigid bone on its node
//   (identity offset). A bone without a node of its name gets a root joint of its own at its
//   bind pose (B_n⁻¹), with a warning.
// - Influences: all kept (SkinnedModel::influences), each vertex's weights renormalized to
//   sum 1 (a warning when they were off by more than 1e-4; an error beyond
//   ImportOptions::weight_tolerance).
// - Transforms are decomposed as T R S; a non-uniform scale is not a versor, so its mean is
//   used and a warning is recorded once per node, offset or channel.
// - Animations: position, rotation and scaling keys per node channel, times in ticks;
//   ticks per second 25 when the file says 0.
// - Welding (ImportOptions::weld, on by default): each mesh's vertices at one position become
//   one vertex; UVs and normals are kept per face corner (SkinnedMesh::corner_uvs/normals).
// - Errors (missing file, unsupported format, unreadable or truncated file, no meshes, NaN
//   transforms or keys, weights not summing to 1, bone or vertex ids out of range) throw
//   ImportError whose message starts with the file name.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>

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
  /// Largest |Σ w − 1| of a skinned vertex before import fails; sums off by more than 1e-4
  /// but within this are renormalized with a warning.
  double weight_tolerance = 0.1;
  /// Read the file once in a forked child process first (POSIX), so that a file on which
  /// assimp itself crashes (assimp 5.2 segfaults or aborts on out-of-range bone or vertex
  /// indices in .x and .dae files) gives an ImportError instead of killing the caller. Costs
  /// a second read. Off by default: forking a multithreaded host is only safe when no other
  /// thread holds a lock the child needs; the `conform` command turns it on.
  bool crash_guard = false;
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
