// Per face corner attributes ("wedges": UVs and normals per corner, skinned_mesh.hpp) and how
// they follow a TopologyChange. Written once here; apply() (topology_change.hpp) uses it for
// every cut, tear and drill.
//
// The rule for an added face's corners. Every added face either lies in a face the change
// removes (a piece of a split face, a face relabelled to a duplicated vertex) or is new surface
// (a cap, a drill's tube wall):
//   - its origin is the removed face, among those incident to the added face's corners' base
//     vertices (following new vertices' parents back to the base mesh), closest to the added
//     face's centroid (rest positions) with a normal within 60° of the added face's; it must
//     lie within 5 % of the added face's longest edge;
//   - a corner at a vertex of the origin (or at a duplicate of one) copies that corner's
//     attributes exactly; any other corner interpolates the origin's corner attributes
//     barycentrically (coordinates clamped to the triangle), normals renormalized. So a corner
//     takes the attributes of the side of the seam its face lies on;
//   - new surface gets the face's rest normal, and UVs by planar projection: the rest position
//     on the axes (e_u, e_v) of the face's plane, e_u = unit(n × a) with a the coordinate axis
//     least aligned with the normal n, e_v = n × e_u, in model units. A planar cap thus gets
//     one continuous projection.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "conform/mesh/skinned_mesh.hpp"

namespace conform::mesh {

struct TopologyChange;

/// Fills mesh.corner_uvs / corner_normals from the per-vertex uvs / normals, where present.
void make_corner_attributes(SkinnedMesh& mesh);

/// The planar-projection UV of new surface (see above) at rest position `p` on a plane of unit
/// normal `n`.
Eigen::Vector2d planar_uv(const Eigen::Vector3d& p, const Eigen::Vector3d& n);

/// The corner attributes of `change.added_faces`, one column per added face (empty matrices
/// when the mesh has no corner UVs / normals), and each added face's origin (a base face
/// index, or −1 for new surface). `mesh` holds the change's new vertices (apply_vertices has
/// run) and still its base faces.
struct AddedCorners {
  Eigen::Matrix<double, 6, Eigen::Dynamic> uvs;
  Eigen::Matrix<double, 9, Eigen::Dynamic> normals;
  std::vector<std::int32_t> origin;
};
AddedCorners added_corner_attributes(const SkinnedMesh& mesh, const TopologyChange& change);

/// Only the origins of AddedCorners (computed whether or not the mesh has corner attributes):
/// per added face, the removed base face it lies in, or −1 for new surface.
std::vector<std::int32_t> added_face_origins(const SkinnedMesh& mesh, const TopologyChange& change);

}  // namespace conform::mesh
