// Welding a mesh that arrives split at its UV and normal seams: vertices at one position become
// one vertex, so that simulation and topology see one surface, while each face keeps its own
// corner UVs and normals (SkinnedMesh::corner_uvs / corner_normals), so that the seams survive.
//
// The rule.
// - Two vertices are at one position when their rest positions are within
//   `tolerance` × the diagonal of the rest positions' bounding box (default 1e-7: it welds the
//   bit-equal seam copies and no distinct nearby vertices), and they are in the same group (the
//   io layer welds each mesh of a file on its own: a mesh's vertices share one space, and
//   MeshInfo's vertex ranges stay contiguous).
// - Bone weights. Coincident vertices whose (up to 4) influences agree (the largest difference
//   of one bone's weight is at most `weight_tolerance`, default 1e-3) weld as they are: the
//   kept vertex's influences. Where they differ (a file whose seam copies were weighted
//   apart), `differing_weights` decides:
//   - `mean` (default): they weld all the same, and the welded vertex takes the mean of its
//     copies' influences (per bone; the 4 largest kept, scaled to the copies' mean sum), so
//     the seam stays closed as the model deforms, where the file's own copies would part.
//     Each copy then skins to the mean of where the file puts the copies (to first order).
//   - `keep_apart`: they stay apart, each skinning exactly as in the file (the seam opens as
//     they deform).
// - Greedy and deterministic: vertices are visited in index order and each joins the first
//   (lowest-index) kept vertex it matches, else is kept itself. Kept vertices keep their
//   relative order; a kept vertex keeps its own rest and current position, influences and UV;
//   its per-vertex normal becomes the renormalized sum of its cluster's normals.
// - Faces whose corners weld together (collapsed to a line or point) are dropped.
// Measurements on the test models: docs/notes/mesh_edits.md.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "conform/mesh/skinned_mesh.hpp"

namespace conform::mesh {

/// What welding does with coincident vertices whose bone weights differ (see above).
enum class DifferingWeights { mean, keep_apart };

struct WeldOptions {
  /// Relative to the rest positions' bounding-box diagonal.
  double tolerance = 1e-7;
  /// Largest difference of one bone's weight between two vertices that weld as they are.
  double weight_tolerance = 1e-3;
  DifferingWeights differing_weights = DifferingWeights::mean;
};

struct WeldResult {
  std::vector<std::int32_t> vertex_map;  // old vertex → new vertex
  std::vector<std::int32_t> face_map;    // old face → new face, −1 when it collapsed
  std::vector<std::int32_t> kept;        // new vertex → the old vertex it keeps
  std::int32_t merged = 0;               // vertices welded into another one
  std::int32_t kept_apart = 0;           // vertices left apart at a welded position (weights)
  std::vector<std::int32_t> averaged;    // new vertices given their copies' mean weights
  double largest_weight_difference = 0;  // between copies welded with their mean weights
  std::int32_t collapsed_faces = 0;
};

/// Welds `mesh` in place (see above). `group` is empty (one group) or gives each vertex's group.
/// First fills the corner arrays from the per-vertex UVs and normals when they are empty.
/// Throws std::invalid_argument on a negative tolerance or a group array of the wrong size.
WeldResult weld(SkinnedMesh& mesh, const WeldOptions& options = {},
                std::span<const std::int32_t> group = {});

}  // namespace conform::mesh
