// One step of a tear's growth as a mesh::TopologyChange, computed on the rest mesh and applied
// by mesh::apply (like the slit of slit_sheet.hpp, so a live soft body can mirror it).
//
// From the tip vertex T along a direction d in the sheet: the ray from T crosses the face of T's
// fan that it enters and leaves it through the opposite edge (b, c) at Q. Q becomes the new tip:
//   - on the edge: a new vertex splitting (b, c) and both its faces, where it lies at least
//     snap_fraction of the edge from either end;
//   - else the nearer end (the crack runs along the edge T-b or T-c, no sliver is made).
// T, which had been the tip (shared by both lips), is then duplicated for the faces on one side
// of the path (T's fan falls into two parts between the old lips and the new edge T-Q), so the
// crack opens up to Q. The crack grows by one element of the fan per step: |Q - T|.
//
// mesh::Tear cannot do this step: its first sample starts a new tear at a new vertex inside the
// face the blade hits, never at an existing crack's tip, and a tear's start is never duplicated.
//
// The step stops (no change, reached_border) where Q would be on a fixed vertex or on the mesh's
// border (an edge with one face): a tear that reaches the border stops.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "conform/mesh/skinned_mesh.hpp"
#include "conform/mesh/topology_change.hpp"

namespace conform::membrane {

struct CrackExtension {
  mesh::TopologyChange change;  // empty when the crack did not grow
  std::int32_t new_tip = -1;    // the new tip's vertex index after the change
  std::int32_t duplicate = -1;  // the old tip's copy, which takes the faces left of the path
  bool reached_border = false;
  std::string message;  // why it did not grow (empty when it did)
};

/// The change that extends the crack whose tip is `tip` along `direction` (rest space, projected
/// onto the sheet), on `mesh`'s rest positions; `fixed` flags the pinned vertices (one per vertex).
CrackExtension crack_extension(const mesh::SkinnedMesh& mesh,
                               const std::vector<std::uint8_t>& fixed, std::int32_t tip,
                               const Eigen::Vector3d& direction, double snap_fraction = 0.15);

/// New vertices' columns appended to x (3 x base_vertex_count before, 3 x #V after), each the
/// change's affine combination of its parents' columns (mesh::apply's rule for positions).
void extend_columns(Eigen::Matrix3Xd& x, const mesh::TopologyChange& change);

}  // namespace conform::membrane
