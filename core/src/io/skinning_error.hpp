// How far the imported model's CGA skinning is from matrix skinning computed from the file's
// own matrices: the measure the importer reports when it had to approximate a transform (a
// non-uniform scale that a bone animates, a mirror that changes with the animation).
#pragma once

#include <assimp/scene.h>

#include <cstdint>
#include <string>
#include <vector>

#include "conform/io/model.hpp"

namespace conform::io::detail {

/// One placed mesh of the file: which aiMesh, the node that places it (used when it has no
/// bones), the first vertex in the merged mesh, and the baked transform K (rest = K · file).
struct MeshInstance {
  unsigned mesh = 0;
  const aiNode* node = nullptr;
  std::int32_t first_vertex = 0;
  Eigen::Matrix4d bake = Eigen::Matrix4d::Identity();
};

struct SkinningError {
  double worst = 0;     // largest vertex distance, in model units
  double diagonal = 0;  // of the matrix-skinned bind pose
  std::string where;    // "the rest pose" or "animation 'A' at t = 0.4 s"
};

/// Matrix skinning x' = Σ w G_b O_b x (a mesh without bones: x' = G_node x; a bone without a
/// node: x' = x), weights normalized, node transforms from the animation's keys with their
/// full (non-uniform) scale, against the model's CGA skinning with linear key blending, at the
/// rest pose and at every key time of every animation.
SkinningError skinning_error(const aiScene& scene, const SkinnedModel& model,
                             const std::vector<MeshInstance>& instances);

}  // namespace conform::io::detail
