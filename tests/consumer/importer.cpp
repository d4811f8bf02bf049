// A stand-alone tool that uses an installed conform::io: it loads a model (a file through
// assimp, or "arm" for the procedural arm) and prints what it holds.
#include <cstdio>
#include <exception>

#include "conform/io/import.hpp"

int main(int argc, char** argv) {
  const char* spec = argc > 1 ? argv[1] : "arm";
  try {
    const conform::io::SkinnedModel model = conform::io::load_model(spec);
    std::printf("importer: %s: %d vertices, %d faces, %d bones, %zu animations\n", spec,
                model.mesh.vertex_count(), model.mesh.face_count(), model.skeleton.bone_count(),
                model.animations.size());
    return model.mesh.vertex_count() > 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "importer: %s\n", e.what());
    return 1;
  }
}
