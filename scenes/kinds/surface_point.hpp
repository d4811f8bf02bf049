// The point of a triangle set nearest a query point, with the face's normal turned toward the
// query: how the character scene snaps a placement onto a model's skin.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <span>

#include "conform/mesh/skinned_mesh.hpp"

namespace conform::scenes {

struct SurfacePoint {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit, on the query's side of the face
  std::int32_t face = -1;                            // −1: no face given
  double distance = 0;                               // from the query
};

/// The point nearest `query` on the faces `faces` (indices into `all`) of the mesh at
/// `positions`. Degenerate faces (zero area) are skipped.
SurfacePoint nearest_surface_point(const Eigen::Matrix3Xd& positions,
                                   std::span<const mesh::Face> all,
                                   std::span<const std::int32_t> faces,
                                   const Eigen::Vector3d& query);

}  // namespace conform::scenes
