// The sheet of `membrane-edge`: a flat square tensor grid in z = 0, skinned to one bone, whose
// element size is `element_size` within a fine band around the line x = 0 (where the cut goes)
// and around y = 0 (the mid-edge row where the retraction is measured), growing geometrically
// toward the border. The line x = 0 and the row y = 0 are grid lines, so the cut runs along
// vertices and the lips' distances from the edge are the vertices' own |x|.
#pragma once

#include <vector>

#include "conform/mesh/skinned_mesh.hpp"

namespace conform::scenes {

struct EdgeSheetOptions {
  double width = 0.45;         // W, m: side of the square
  double element_size = 4e-3;  // h, m, in the fine bands
  double fine_across = 0.18;   // half-width of the fine band about x = 0, m
  double fine_along = 0.09;    // half-width of the fine band about y = 0, m
  double grading = 1.2;        // growth ratio of the element size outside the bands
};

struct EdgeSheet {
  mesh::SkinnedMesh mesh;             // the intact sheet, weight 1 on bone 0
  std::vector<double> xs, ys;         // the grid's coordinates, ascending, both through 0
  std::vector<std::int32_t> mid_row;  // the vertices at y = 0, by ascending x
};

/// Throws std::invalid_argument for a non-positive size or a grading outside [1, 2].
EdgeSheet make_edge_sheet(const EdgeSheetOptions& options);

}  // namespace conform::scenes
