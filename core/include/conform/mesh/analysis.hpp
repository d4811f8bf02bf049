// Measurements and checks of a triangle mesh (on its current positions): areas, volumes, the
// invariants the topology operations must keep, and the split into connected pieces.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "conform/mesh/skinned_mesh.hpp"

namespace conform::mesh {

/// Sum of the faces' areas (all faces, or only `faces`).
double surface_area(const SkinnedMesh& mesh, std::span<const std::int32_t> faces = {});
/// Signed volume enclosed by the faces (divergence theorem; positive for a closed,
/// outward-oriented surface).
double signed_volume(const SkinnedMesh& mesh, std::span<const std::int32_t> faces = {});
/// Length of the diagonal of the current positions' bounding box (0 for an empty mesh).
double bounding_diagonal(const SkinnedMesh& mesh);

struct MeshReport {
  bool indices_valid = true;              // every face index in [0, #V), no repeated vertex
  bool finite = true;                     // every current position finite
  std::int32_t tiny_faces = 0;            // faces of area ≤ min_area
  std::int32_t boundary_edges = 0;        // undirected edges used by one face
  std::int32_t overused_edges = 0;        // undirected edges used by more than two faces
  std::int32_t misoriented_edges = 0;     // edges used twice in the same direction
  std::int32_t nonmanifold_vertices = 0;  // vertices whose faces form more than one fan
  bool closed() const { return boundary_edges == 0; }
  bool manifold() const { return overused_edges == 0 && nonmanifold_vertices == 0; }
  bool oriented() const { return misoriented_edges == 0; }
  std::string summary() const;
};

/// Checks indices, finiteness, tiny faces (area ≤ min_area), edge use and orientation and
/// vertex fans. O(F log F).
MeshReport check_mesh(const SkinnedMesh& mesh, double min_area = 0);

struct Pieces {
  std::vector<std::int32_t> face_piece;  // #F: the piece of each face
  std::int32_t count = 0;
  /// The faces of piece p, in increasing order.
  std::vector<std::int32_t> faces_of(std::int32_t p) const;
};

/// Connected components of faces sharing a vertex, numbered in order of their lowest face.
/// O(V + F).
Pieces label_pieces(const SkinnedMesh& mesh);

}  // namespace conform::mesh
