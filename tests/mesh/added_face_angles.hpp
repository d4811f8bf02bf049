// The sliver check shared by the cut and tear tests: the smallest angle of the faces an
// operation added, against the guarantee min(floor, half the smallest angle of the input face
// each lies in).
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

#include "conform/mesh/analysis.hpp"
#include "conform/mesh/skinned_mesh.hpp"

namespace conform::test {

// The faces of `out` that are not faces of `in` (those an operation added), except `skip`,
// each against the face of `in` it lies in (found geometrically: the input face containing
// its centroid, on the current positions, which the operation did not move). Returns the
// smallest angle (radians) of the added faces and the worst ratio of that angle to the
// guarantee min(floor, half the smallest angle of the original face) (≥ 1: the guarantee holds).
struct AngleReport {
  double smallest = std::acos(-1.0);  // smallest angle of an added face
  double worst_ratio = 1e300;         // min over added faces of angle / guaranteed bound
  int faces = 0;
};
inline AngleReport added_face_angles(const mesh::SkinnedMesh& in, const mesh::SkinnedMesh& out,
                                     double floor, const std::vector<mesh::Face>& skip = {}) {
  auto key = [](mesh::Face f) {
    std::rotate(f.begin(), std::min_element(f.begin(), f.end()), f.end());
    return f;
  };
  std::set<mesh::Face> old, skipped;
  for (const mesh::Face& f : in.faces) old.insert(key(f));
  for (const mesh::Face& f : skip) skipped.insert(key(f));
  struct Orig {
    Eigen::Vector3d a, b, c, centre;
    double radius, angle;
  };
  std::vector<Orig> orig;
  for (const mesh::Face& f : in.faces) {
    Orig o{in.current.col(f[0]), in.current.col(f[1]), in.current.col(f[2]), {}, 0, 0};
    o.centre = (o.a + o.b + o.c) / 3;
    o.radius =
        std::max({(o.a - o.centre).norm(), (o.b - o.centre).norm(), (o.c - o.centre).norm()});
    o.angle = mesh::smallest_angle(o.a, o.b, o.c);
    orig.push_back(o);
  }
  AngleReport r;
  for (const mesh::Face& f : out.faces) {
    if (old.count(key(f)) || skipped.count(key(f))) continue;
    const Eigen::Vector3d a = out.current.col(f[0]), b = out.current.col(f[1]),
                          c = out.current.col(f[2]), p = (a + b + c) / 3;
    // The containing input face: smallest distance from p (barycentric clamp).
    double best = 1e300, bound_angle = 0;
    for (const Orig& o : orig) {
      if ((p - o.centre).norm() > o.radius * (1 + 1e-9) + 1e-12) continue;
      const Eigen::Vector3d n = (o.b - o.a).cross(o.c - o.a);
      const double area2 = n.squaredNorm();
      if (!(area2 > 0)) continue;
      const double l0 = (o.c - o.b).cross(p - o.b).dot(n) / area2,
                   l1 = (o.a - o.c).cross(p - o.c).dot(n) / area2, l2 = 1 - l0 - l1;
      const double off = std::abs((p - o.a).dot(n)) / std::sqrt(area2) +
                         std::max(0.0, -std::min({l0, l1, l2})) * o.radius;
      if (off < best) best = off, bound_angle = o.angle;
    }
    ++r.faces;
    const double angle = mesh::smallest_angle(a, b, c);
    r.smallest = std::min(r.smallest, angle);
    r.worst_ratio = std::min(r.worst_ratio, angle / std::min(floor, bound_angle / 2));
  }
  return r;
}

}  // namespace conform::test
