// The scene's frame for a user's model: SI metres, Y up. A file is in its own units (a
// centimetre model spans 180 units) and may stand Z up (Source's .smd, Blender exports); the
// character scene brings it into the scene's frame once, at import, so that Bullet, gravity,
// the collision margin and every reported length are in metres and "up" is +y.
#pragma once

#include <string>

#include "conform/io/model.hpp"

namespace conform::scenes {

/// How a file's coordinates map to the scene's: `units_per_metre` file units make a metre,
/// and `up` ("y" or "z") is the file's up axis.
struct ModelFrame {
  double units_per_metre = 1;
  std::string up = "y";
};

/// Brings `model` into metres, Y up: its mesh-space rest positions are divided by the units
/// (each bone's offset takes the inverse dilation, so the skinning of the file is unchanged),
/// and a new root joint, named "(scene frame)", carries the file's world into the scene's
/// (1/units, and for Z up the rotation (x, y, z) → (x, z, −y)); every joint index (parents,
/// bones, animation channels, meshes) moves up by one. `current` (the skinned rest pose) and
/// the normals follow. One root transform, so the mesh, the skeleton and every animation are
/// moved alike. Throws std::invalid_argument for an up axis other than "y" or "z".
void to_scene_frame(io::SkinnedModel& model, const ModelFrame& frame);

/// A file's units per metre and where the figure comes from.
struct FileUnits {
  double units_per_metre = 1;
  std::string source;  // for summaries: "the file's UnitScaleFactor (1 cm)", "assumed: ..."
};

/// The unit `model`'s file states (FBX's UnitScaleFactor, in centimetres), else metres. Metres
/// is glTF's unit by its specification, Collada's after assimp applies its <unit>, and Bullet's
/// and SI's; the X, SMD and MD5 formats state none, and their test models (a 1.8 m human in
/// BCN_Epileptic.X, a 3.2 m animal in Testwuson.X) are drawn in metres. Throws
/// std::runtime_error, naming `file`, for a stated unit outside 1e-6 .. 1e6 units a metre.
FileUnits file_units(const io::SkinnedModel& model, const std::string& file);

}  // namespace conform::scenes
