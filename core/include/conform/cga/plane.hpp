// Planes Π = n + d e∞ in inner (dual) form: X·Π = x·n − d is the signed distance for |n| = 1.
#pragma once

#include "conform/cga/point.hpp"

namespace conform::cga {

template <class T = double>
struct Plane : Vector<T> {
  Plane() = default;
  explicit Plane(const Vector<T>& v) : Vector<T>(v) {}

  /// Unit normal n and distance d from the origin along n.
  static Plane from_normal_distance(const Vec3<T>& normal, T distance) {
    const Vec3<T> n = normal.normalized();
    Plane p;
    p.e1 = n.x(), p.e2 = n.y(), p.e3 = n.z(), p.einf = distance;
    return p;
  }
  static Plane from_normal_point(const Vec3<T>& normal, const Vec3<T>& point) {
    const Vec3<T> n = normal.normalized();
    return from_normal_distance(n, n.dot(point));
  }
  /// Plane through three points: Π = (X1∧X2∧X3∧e∞)*, normalized; its normal is
  /// (b − a) × (c − a) / |…|. Empty when the points are collinear.
  static std::optional<Plane> through(const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c) {
    const Multivector<T> outer =
        Point<T>::up(a).mv() ^ Point<T>::up(b).mv() ^ Point<T>::up(c).mv() ^ einf<T>();
    Vector<T> v = Vector<T>::from(outer.dual());
    const T len = v.euclidean().norm();
    const T size = std::max({(b - a).norm(), (c - a).norm(), T(1e-300)});
    if (!(len > T(1e-12) * size * size) || !std::isfinite(len)) return std::nullopt;
    // Orient so that the normal follows the right-hand rule a→b→c.
    const T orient = v.euclidean().dot((b - a).cross(c - a)) < 0 ? T(-1) : T(1);
    Plane p;
    p.e1 = orient * v.e1 / len, p.e2 = orient * v.e2 / len, p.e3 = orient * v.e3 / len;
    p.einf = orient * v.einf / len;
    return p;
  }

  Vec3<T> normal() const { return this->euclidean(); }
  T distance() const { return this->einf; }
  /// X·Π for the normalized point x: x·n − d (signed distance when |n| = 1).
  T signed_distance(const Vec3<T>& x) const {
    return this->e1 * x.x() + this->e2 * x.y() + this->e3 * x.z() - this->einf;
  }
  /// +1, −1, or 0 within `tolerance` of the plane.
  int side(const Vec3<T>& x, T tolerance = T(0)) const {
    const T s = signed_distance(x);
    return s > tolerance ? 1 : (s < -tolerance ? -1 : 0);
  }
  /// Parameter t ∈ [0, 1] where the segment a→b crosses the plane; empty when it does not
  /// (both ends strictly on one side, or the segment lies in the plane).
  std::optional<T> segment_intersection(const Vec3<T>& a, const Vec3<T>& b) const {
    const T da = signed_distance(a), db = signed_distance(b);
    if ((da > 0 && db > 0) || (da < 0 && db < 0) || da == db) return std::nullopt;
    return da / (da - db);
  }
};

}  // namespace conform::cga
