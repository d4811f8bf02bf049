// run.glb: the whole run in one glTF 2.0 binary that viewers open (Blender, f3d). The topology
// changes over time, so every kept frame is its own mesh under its own node, and one animation
// shows the frames in turn by scaling their nodes between 0 and 1 (a common glTF pattern:
// glTF has no visibility channel). Each run's frames (physics, geometric, ...) form a row of
// their own, side by side along x. Meshes carry normals, UVs (TEXCOORD_0) and vertex colours
// (COLOR_0) from the colour scale of the pictures; vertex i is vertex i of frames/NAME_STEP.ply.
// Written by tinygltf (Debian's libtinygltf-dev), not assimp's glb2 exporter: that one always
// joins identical vertices, which zipped up a tear's coincident lips (2 of 2694 vertices gone).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "render/frame_snapshot.hpp"

namespace conform::scenes {

class GltfSequence {
 public:
  /// Adds a frame; one of the same name and step is replaced (the scene's picture of that
  /// frame knows its wound, the plain frame does not).
  void add(FrameSnapshot frame);
  std::size_t size() const { return frames_.size(); }

  /// Writes the file atomically (a temporary beside it, then renamed), coloured by `scalar`
  /// ("stretch" or "gap"; `range` as in render.range). Throws std::runtime_error when assimp
  /// cannot write it.
  void write(const std::filesystem::path& path, const std::string& scalar, double range) const;

 private:
  std::vector<FrameSnapshot> frames_;
};

}  // namespace conform::scenes
