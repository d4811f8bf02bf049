// Conformal points X = x + ½x²e∞ + e0 (grade 1), with up/down projection.
#pragma once

#include <Eigen/Core>
#include <optional>

#include "conform/cga/multivector.hpp"

namespace conform::cga {

template <class T>
using Vec3 = Eigen::Matrix<T, 3, 1>;

/// A grade-1 element stored by its five coefficients on e1, e2, e3, e∞, e0. Points, spheres
/// and planes (in their inner, "dual" form) are all of this shape.
template <class T = double>
struct Vector {
  T e1 = 0, e2 = 0, e3 = 0, einf = 0, e0 = 0;

  Vec3<T> euclidean() const { return {e1, e2, e3}; }
  Multivector<T> mv() const {
    Multivector<T> m;
    m[kE1] = e1, m[kE2] = e2, m[kE3] = e3, m[kEinf] = einf, m[kE0] = e0;
    return m;
  }
  static Vector from(const Multivector<T>& m) { return {m[kE1], m[kE2], m[kE3], m[kEinf], m[kE0]}; }
  /// Inner product a·b = a1b1 + a2b2 + a3b3 − a∞b0 − a0b∞.
  friend T dot(const Vector& a, const Vector& b) {
    return a.e1 * b.e1 + a.e2 * b.e2 + a.e3 * b.e3 - a.einf * b.e0 - a.e0 * b.einf;
  }
};

template <class T = double>
struct Point : Vector<T> {
  Point() = default;
  explicit Point(const Vector<T>& v) : Vector<T>(v) {}

  /// up(x) = x + ½x²e∞ + e0.
  static Point up(const Vec3<T>& x) {
    Point p;
    p.e1 = x.x(), p.e2 = x.y(), p.e3 = x.z(), p.einf = T(0.5) * x.squaredNorm(), p.e0 = T(1);
    return p;
  }
  static Point up(T x, T y, T z) { return up(Vec3<T>(x, y, z)); }

  /// down(X) = x / w with weight w = −X·e∞ (the e0 coefficient); empty for a point at
  /// infinity (weight zero relative to its size) or non-finite input.
  std::optional<Vec3<T>> down() const {
    const T w = this->e0;
    const T size = std::max({std::abs(this->e1), std::abs(this->e2), std::abs(this->e3),
                             std::sqrt(std::abs(this->einf))});
    if (!std::isfinite(w) || !std::isfinite(size) ||
        std::abs(w) <= T(64) * std::numeric_limits<T>::epsilon() * size || w == T(0))
      return std::nullopt;
    return Vec3<T>(this->e1 / w, this->e2 / w, this->e3 / w);
  }
  /// The same point scaled to weight 1 (empty at infinity).
  std::optional<Point> normalized() const {
    auto x = down();
    if (!x) return std::nullopt;
    return up(*x);
  }
};

/// down() of any multivector's grade-1 part.
template <class T>
std::optional<Vec3<T>> down(const Multivector<T>& m) {
  return Point<T>(Vector<T>::from(m)).down();
}

}  // namespace conform::cga
