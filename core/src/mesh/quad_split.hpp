// The quad-diagonal rule of the cut, the tear and the drill: a quad (a, b, c, d) left by a
// split face is cut along the diagonal (a, c) or (b, d) that gives its two triangles the larger
// smallest angle, (a, c) on a tie. Each operation measures the smallest angle its own way
// (the cut and the tear by its sin², the drill by its tangent), so the measure is a parameter.
#pragma once

#include <Eigen/Core>
#include <algorithm>

namespace conform::mesh {

struct QuadSplit {
  bool first_diagonal;  // (a, c); else (b, d)
  double quality;       // the smallest angle's measure of the chosen split
};

/// `measure(x, y, z)`: a measure of the smallest angle of triangle (x, y, z), increasing with it.
template <class Measure>
QuadSplit best_quad_split(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                          const Eigen::Vector3d& c, const Eigen::Vector3d& d, Measure measure) {
  const double q1 = std::min(measure(a, b, c), measure(a, c, d));
  const double q2 = std::min(measure(a, b, d), measure(b, c, d));
  return q1 >= q2 ? QuadSplit{true, q1} : QuadSplit{false, q2};
}

}  // namespace conform::mesh
