// Measurements and checks of a triangle mesh (on its current positions): areas, volumes, the
// invariants the topology operations must keep, and the split into connected pieces.
#pragma once

#include <algorithm>
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

/// Triangle quality without trigonometry: the squared sine of the smallest angle of (a, b, c)
/// (the angle opposite the shortest side, which is acute), 0 for a degenerate triangle. It
/// orders triangles as their smallest angles do.
inline double smallest_angle_sin2(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                  const Eigen::Vector3d& c) {
  const double ab = (b - a).squaredNorm(), bc = (c - b).squaredNorm(), ca = (a - c).squaredNorm();
  const double cross2 = (b - a).cross(c - a).squaredNorm();  // (2 × area)²
  // sin² of the angle between the two longer sides: cross² / (their squared lengths' product).
  const double longer = std::max({ab * bc, bc * ca, ca * ab});
  return longer > 0 ? cross2 / longer : 0.0;
}

/// The smallest angle of (a, b, c) in radians (0 for a degenerate triangle).
double smallest_angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c);

/// The sliver guarantee of the topology operations (cut, tear, drill): every face an operation
/// adds inside an original face has smallest angle ≥ min(floor, half the smallest angle of that
/// original face). This returns that bound as a squared sine (compare with
/// smallest_angle_sin2), for the original face (a, b, c) and `floor` in radians.
double sliver_bound_sin2(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         const Eigen::Vector3d& c, double floor);

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
/// O(V + F); its working arrays are kept per thread between calls.
Pieces label_pieces(const SkinnedMesh& mesh);

}  // namespace conform::mesh
