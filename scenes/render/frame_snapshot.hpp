// One kept frame of a run as pictures and the glTF sequence need it: a copy of the current
// surface (the mesh goes on changing), its vertex normals and UVs, the event's border vertices
// and a scalar per vertex to colour it by.
//
// Scalars (per vertex):
//   stretch  mean strain of the vertex's edges, |current| / |rest| - 1 (the rest mesh is the
//            skin as it was pre-stressed, so a skin that relaxes beside a wound goes negative);
//   gap      on a lip (a border vertex) the distance to the nearest vertex of the other lip,
//            the local width of the wound; 0 elsewhere.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "conform/mesh/skinned_mesh.hpp"

namespace conform::scenes {

struct FrameSnapshot {
  std::string name;  // "physics", "geometric", ...
  int step = 0;
  double time = 0;                  // s
  Eigen::Matrix3Xd positions;       // 3 × #V, current
  Eigen::Matrix3Xd normals;         // 3 × #V, area-weighted from the current faces
  Eigen::Matrix2Xd uvs;             // 2 × #V (zero when the mesh has none)
  std::vector<mesh::Face> faces;    // #F
  std::vector<double> scalar;       // #V
  std::vector<std::int32_t> focus;  // the event's vertices (both lips), may be empty
  std::string caption;              // under the panel in the picture, e.g. its largest gap
  double wound = std::nan("");      // the largest gap across the lips, m; NaN without lips
};

/// The lips of a wound or cut, as vertex ids of the mesh.
struct Lips {
  std::vector<std::int32_t> left, right;
};

/// Copies `mesh` (current positions) and computes `scalar` ("stretch" or "gap") on it.
FrameSnapshot snapshot(const std::string& name, int step, double time,
                       const mesh::SkinnedMesh& mesh, const Lips& lips, const std::string& scalar);

/// Per-vertex mean edge strain |current| / |rest| - 1 (0 for a vertex on no face).
std::vector<double> edge_stretch(const mesh::SkinnedMesh& mesh);

/// Per-vertex gap width: for a lip vertex the distance to the nearest vertex of the other lip.
std::vector<double> gap_width(const Eigen::Matrix3Xd& positions, const Lips& lips);

/// The largest gap width over the lips' vertices (FrameSnapshot::wound); NaN without two lips.
double largest_gap(const Eigen::Matrix3Xd& positions, const Lips& lips);

}  // namespace conform::scenes
