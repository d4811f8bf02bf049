// Spheres S = C − ½r²e∞ in inner (dual) form; a point X lies on S when X·S = 0.
#pragma once

#include "conform/cga/point.hpp"

namespace conform::cga {

template <class T = double>
struct Sphere : Vector<T> {
  Sphere() = default;
  explicit Sphere(const Vector<T>& v) : Vector<T>(v) {}

  static Sphere from_center_radius(const Vec3<T>& center, T radius) {
    Sphere s(Point<T>::up(center));
    s.einf -= T(0.5) * radius * radius;
    return s;
  }
  /// The sphere through four points: S = (X1∧X2∧X3∧X4)*, scaled to weight 1. Empty when the
  /// points are coplanar (the result is a plane) or coincide.
  static std::optional<Sphere> through(const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c,
                                       const Vec3<T>& d) {
    const Multivector<T> outer =
        Point<T>::up(a).mv() ^ Point<T>::up(b).mv() ^ Point<T>::up(c).mv() ^ Point<T>::up(d).mv();
    const Vector<T> v = Vector<T>::from(outer.dual());
    const T size = outer.max_abs();
    if (!(std::abs(v.e0) > T(1e-10) * size)) return std::nullopt;
    Vector<T> n{v.e1 / v.e0, v.e2 / v.e0, v.e3 / v.e0, v.einf / v.e0, T(1)};
    return Sphere(n);
  }

  /// Centre (the sphere must have non-zero weight).
  Vec3<T> center() const { return this->euclidean() / this->e0; }
  /// Signed squared radius r² = S²/w² (negative for an imaginary sphere).
  T radius_squared() const { return dot(*this, *this) / (this->e0 * this->e0); }
  T radius() const { return std::sqrt(std::max(T(0), radius_squared())); }
  /// X·S / w_S for a normalized point: ½(r² − |x − c|²); positive inside.
  T inside_measure(const Vec3<T>& x) const { return dot(Point<T>::up(x), *this) / this->e0; }
  bool contains(const Vec3<T>& x) const { return inside_measure(x) > T(0); }
};

}  // namespace conform::cga
