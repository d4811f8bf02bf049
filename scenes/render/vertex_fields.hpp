// One kept frame of a body as the ParaView series writes it (vtk_series.hpp): the mesh's
// vertices (all of them, numbered as the mesh and its PLY frames number them), its triangles with
// their tags, and per vertex the fields a researcher analyses. A field that the
// scene does not define is left empty and its reason is in `omitted`.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "conform/mesh/skinned_mesh.hpp"

namespace conform::scenes {

struct VertexFields {
  Eigen::Matrix3Xd positions;         // 3 x #V, the simulated positions, m
  std::vector<mesh::Face> faces;      // into positions
  std::vector<mesh::FaceTag> tags;    // per face
  Eigen::Matrix3Xd displacement;      // 3 x #V, from the bind pose's position, m
  Eigen::Matrix3Xd velocity;          // 3 x #V, m/s
  std::vector<double> stretch;        // #V, mean edge strain (frame_snapshot.hpp)
  std::vector<double> gap;            // #V, width across the lips, m; empty: no lips
  Eigen::Matrix2Xd principal_stress;  // 2 x #V, sigma_1 >= sigma_2, Pa; 0 columns: no membrane
  std::vector<std::int32_t> piece;    // #V, the piece's index among the body's live pieces
  std::vector<std::string> omitted;   // "gap: why", for each field left out
};

}  // namespace conform::scenes
