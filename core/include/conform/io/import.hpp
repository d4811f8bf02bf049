// Loading rigged models: any format assimp reads (.dae, .fbx, .gltf/.glb, .x, .smd,
// .md5mesh, ...) or the built-in procedural arm ("arm", "arm:N"). Every node becomes a joint
// and every influence is kept, with each vertex's weights normalized; at the rest pose the
// model reproduces the file's matrix skinning exactly, except where an animation moves a
// non-uniform scale or changes a node's parity, and there the importer warns with the
// deviation. Welding (ImportOptions::weld, on by default) merges each mesh's vertices at one
// position. Errors throw ImportError, whose message starts with the file name. The conventions
// in full: docs/notes/import_skinning_ik.md, "Import conventions (io/import.hpp)".
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
