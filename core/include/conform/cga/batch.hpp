// Applying one motor or versor to many points (structure of arrays).
//
// The per-motor coefficients (kernel(): x' = A x + b, A = d·R from the rotor, b = t) are
// computed once; each point then costs 9 multiplies and 9 adds, the same as a 3×4 matrix.
#pragma once

#include <cstddef>
#include <span>

#include "conform/cga/motor.hpp"

namespace conform::cga {

/// Points as three coordinate arrays of equal length.
template <class T>
struct PointsSoA {
  std::span<const T> x, y, z;
};
template <class T>
struct MutablePointsSoA {
  std::span<T> x, y, z;
};

/// out = A in + b for every point; `in` and `out` may be the same arrays. Single-threaded and
/// vectorized; callers parallelise across blocks if they want threads.
template <class T>
void apply_batch(const RigidKernel<T>& k, PointsSoA<T> in, MutablePointsSoA<T> out) {
  const std::size_t n = in.x.size();
  const T a00 = k.a(0, 0), a01 = k.a(0, 1), a02 = k.a(0, 2), b0 = k.b[0];
  const T a10 = k.a(1, 0), a11 = k.a(1, 1), a12 = k.a(1, 2), b1 = k.b[1];
  const T a20 = k.a(2, 0), a21 = k.a(2, 1), a22 = k.a(2, 2), b2 = k.b[2];
  const T* __restrict xi = in.x.data();
  const T* __restrict yi = in.y.data();
  const T* __restrict zi = in.z.data();
  T* xo = out.x.data();
  T* yo = out.y.data();
  T* zo = out.z.data();
#pragma omp simd
  for (std::size_t i = 0; i < n; ++i) {
    const T x = xi[i], y = yi[i], z = zi[i];
    xo[i] = a00 * x + a01 * y + a02 * z + b0;
    yo[i] = a10 * x + a11 * y + a12 * z + b1;
    zo[i] = a20 * x + a21 * y + a22 * z + b2;
  }
}

}  // namespace conform::cga
