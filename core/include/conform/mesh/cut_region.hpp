// Where a planar cut acts (CutOptions::region).
//
// A plane meets a mesh in one or more sections: the connected sets of faces it crosses or
// touches (two faces are in one section when they share a vertex). On a closed surface each
// section is a closed loop around something (the tail, the torso, a leg); an unbounded plane
// cuts them all. A region keeps whole sections and leaves the others untouched, so a kept
// section separates and caps exactly as the unbounded cut would, and nothing outside the kept
// sections changes (no new vertex, no re-indexed face).
//
// A section's points are its crossing points (where the plane crosses an edge: the cut's new
// vertices) and its vertices taken as on the plane (duplicated by the cut). The sections kept:
//   sphere / box, Keep::inside    those whose points all lie in the region: no new vertex
//                                 outside it;
//   sphere / box, Keep::touching  those with at least one point in the region (a region
//                                 smaller than the loop it picks);
//   seed                          the one section with the point nearest to `center` (the part
//                                 of the section connected to a seed point).
// Regions are in the space of the positions cut (mesh.current; in the plugin, world space).
#pragma once

#include <string>

#include <Eigen/Core>

namespace conform::mesh {

struct CutRegion {
  enum class Shape { everywhere, sphere, box, seed };
  enum class Keep { inside, touching };

  Shape shape = Shape::everywhere;
  Keep keep = Keep::inside;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();        // sphere and box centre; the seed
  double radius = 0;                                       // sphere, > 0
  Eigen::Vector3d half_extents = Eigen::Vector3d::Zero();  // box, along its axes, each > 0
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();      // box: columns are orthonormal axes

  static CutRegion sphere(const Eigen::Vector3d& center, double radius, Keep keep = Keep::inside);
  static CutRegion box(const Eigen::Vector3d& center, const Eigen::Vector3d& half_extents,
                       const Eigen::Matrix3d& axes = Eigen::Matrix3d::Identity(),
                       Keep keep = Keep::inside);
  static CutRegion seed(const Eigen::Vector3d& point);

  /// Empty when usable, else the field, its value and what it must be.
  std::string validate() const;
  /// Whether x lies in the sphere or box (closed); always true for everywhere and seed.
  bool contains(const Eigen::Vector3d& x) const;
};

}  // namespace conform::mesh
