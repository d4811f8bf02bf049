// The face index's boxes (face_index.hpp): float boxes padded to hold their doubles, and the
// segment's slab test against them. Internal to core.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace conform::mesh::boxes {

constexpr float kInf = std::numeric_limits<float>::infinity();

// A box from double bounds, padded by 1e−6 of its largest extent plus its largest coordinate:
// more than a float's rounding (2^−24 relative), so the float box still holds the doubles, and
// enough that rounding in the slab test never rejects a point of a face.
template <class Box>
Box make_box(const double lo[3], const double hi[3]) {
  Box b;
  if (!(lo[0] <= hi[0])) {  // empty (or NaN)
    for (int k = 0; k < 3; ++k) b.lo[k] = kInf, b.hi[k] = -kInf;
    return b;
  }
  double ext = 0, mag = 0;
  for (int k = 0; k < 3; ++k) {
    ext = std::max(ext, hi[k] - lo[k]);
    mag = std::max({mag, std::abs(lo[k]), std::abs(hi[k])});
  }
  const double pad = 1e-6 * (ext + mag);
  for (int k = 0; k < 3; ++k) {
    b.lo[k] = static_cast<float>(lo[k] - pad);
    b.hi[k] = static_cast<float>(hi[k] + pad);
  }
  return b;
}

template <class Box>
void grow(Box& b, const Box& o) {
  for (int k = 0; k < 3; ++k) {
    b.lo[k] = std::min(b.lo[k], o.lo[k]);
    b.hi[k] = std::max(b.hi[k], o.hi[k]);
  }
}

template <class Box>
bool empty(const Box& b) {
  return !(b.lo[0] <= b.hi[0]);
}

template <class Box>
double area(const Box& b) {
  if (empty(b)) return 0;
  const double x = double(b.hi[0]) - b.lo[0], y = double(b.hi[1]) - b.lo[1],
               z = double(b.hi[2]) - b.lo[2];
  return 2 * (x * y + y * z + z * x);
}

template <class Box>
bool contains(const Box& outer, const Box& inner) {
  if (empty(inner)) return true;
  for (int k = 0; k < 3; ++k)
    if (inner.lo[k] < outer.lo[k] || inner.hi[k] > outer.hi[k]) return false;
  return true;
}

// The segment p + t d, t in [0, tmax], against a box; on a hit, the parameter where it enters.
struct Ray {
  Eigen::Vector3d p, d, inv;
  Ray(const Eigen::Vector3d& a, const Eigen::Vector3d& b) : p(a), d(b - a) {
    for (int k = 0; k < 3; ++k) inv[k] = d[k] != 0 ? 1 / d[k] : 0;
  }
  template <class Box>
  bool hits(const Box& b, double tmax, double& enter) const {
    if (empty(b)) return false;
    double t0 = 0, t1 = tmax;
    for (int k = 0; k < 3; ++k) {
      const double lo = b.lo[k], hi = b.hi[k];
      if (d[k] == 0) {
        if (p[k] < lo || p[k] > hi) return false;
        continue;
      }
      double ta = (lo - p[k]) * inv[k], tb = (hi - p[k]) * inv[k];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
      if (t0 > t1) return false;
    }
    enter = t0;
    return true;
  }
};

}  // namespace conform::mesh::boxes
