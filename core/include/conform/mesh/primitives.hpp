// Small generated test meshes with skinning data: a closed icosphere, a flat sheet and a
// closed capped cylinder. Each vertex is influenced by up to 3 bones with smooth weights that
// vary along z (bone 0 below, bone 1 in the middle, bone 2 above), and carries UVs and
// rest-space normals, so that topology operations can be checked on every attribute.
#pragma once

#include <cstdint>
#include <vector>

#include "conform/mesh/skinned_mesh.hpp"

namespace conform::mesh {

/// Icosahedron subdivided `subdivisions` times (20·4^s faces), projected on the sphere of
/// `radius` about the origin. Closed, manifold, outward-oriented.
SkinnedMesh make_icosphere(int subdivisions, double radius = 1.0);

/// An nx × ny grid of quads (2·nx·ny faces) spanning [−w/2, w/2] × [−h/2, h/2] in the plane
/// z = 0, normals +z. Open (it has a boundary).
SkinnedMesh make_sheet(int nx, int ny, double width = 1.0, double height = 1.0);

/// A planar grid at the given coordinates: vertex (i, j) at us[i] u_axis + vs[j] v_axis (index
/// j * us.size() + i), weighted fully to bone 0, UV (us[i], vs[j]) / uv_size + 1/2, normal
/// u_axis x v_axis; each quad split into two faces along alternating diagonals, counter-
/// clockwise about that normal. For graded sheets (the membrane checks' meshes).
SkinnedMesh make_grid_sheet(const std::vector<double>& us, const std::vector<double>& vs,
                            const Eigen::Vector3d& u_axis, const Eigen::Vector3d& v_axis,
                            double uv_size);

/// A cylinder of `radius` about the z axis from z = 0 to z = `length`, with `segments` around
/// and `rings` along, closed by two fan caps. Closed, manifold, outward-oriented.
SkinnedMesh make_cylinder(int segments, int rings, double radius, double length);

/// Assigns the smooth three-bone weights described above from the rest positions' z,
/// with the bone boundaries at z0 and z1 (z0 < z1) and blend half-width `blend`.
void assign_height_weights(SkinnedMesh& mesh, double z0, double z1, double blend);

}  // namespace conform::mesh
