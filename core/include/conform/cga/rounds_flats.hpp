// Circles, lines and point pairs in inner (dual) form, built as intersections of spheres and
// planes exactly as in the papers: circle Z = S1∧S2, line L = Π1∧Π2, point pair P = Z∧Π.
// They are stored as full multivectors of one grade: clear rather than fast, since they only
// appear once per IK solve or per operation, never per vertex.
#pragma once

#include <utility>

#include "conform/cga/plane.hpp"
#include "conform/cga/sphere.hpp"

namespace conform::cga {

/// Circle (grade 2): the points on both spheres / on the sphere and the plane.
template <class T = double>
struct Circle {
  Multivector<T> mv;
  static Circle meet(const Vector<T>& s1, const Vector<T>& s2) { return {s1.mv() ^ s2.mv()}; }
  /// Centre and squared radius, from the outer form C = Z*: centre = C e∞ C, r² = C²/(e∞⌋C)².
  Vec3<T> center() const {
    const Multivector<T> outer = mv.dual();
    const Multivector<T> c = outer * einf<T>() * outer;
    return Vec3<T>(c[kE1], c[kE2], c[kE3]) / c[kE0];
  }
  T radius_squared() const {
    const Multivector<T> outer = mv.dual();
    const Multivector<T> d = einf<T>() << outer;
    return -(outer * outer).scalar() / (d * d).scalar();
  }
};

/// Line (grade 2): the meet of two planes; direction and a point on it.
template <class T = double>
struct Line {
  Multivector<T> mv;
  static Line meet(const Plane<T>& a, const Plane<T>& b) { return {a.mv() ^ b.mv()}; }
  /// Through two points: the outer form X1∧X2∧e∞ dualized.
  static Line through(const Vec3<T>& a, const Vec3<T>& b) {
    return {(Point<T>::up(a).mv() ^ Point<T>::up(b).mv() ^ einf<T>()).dual()};
  }
  /// Unit direction (sign fixed by the outer form X1∧X2∧e∞: from X1 to X2).
  Vec3<T> direction() const {
    // For L = X1∧X2∧e∞ = (x2 − x1)∧e∞∧... the contraction (e∞∧e0)⌋L is −(x2 − x1) plus
    // nothing else, so the direction is its negated Euclidean part.
    const Multivector<T> outer = mv.undual();
    const Multivector<T> d = (e0<T>() ^ einf<T>()) << outer;
    Vec3<T> v(-d[kE1], -d[kE2], -d[kE3]);
    return v.normalized();
  }
};

/// Point pair (grade 3 in inner form): the two points of a circle cut by a plane.
template <class T = double>
struct PointPair {
  Multivector<T> mv;
  static PointPair meet(const Circle<T>& z, const Vector<T>& plane_or_sphere) {
    return {z.mv ^ plane_or_sphere.mv()};
  }
  /// The two points, or empty when the pair is imaginary (the circle misses the plane) or
  /// degenerate. With the outer form B = P*, the points are (B ∓ √(B²)) / (−e∞⌋B); the
  /// first returned point takes −√, the second +√ (a fixed, documented order).
  std::optional<std::pair<Vec3<T>, Vec3<T>>> dissect() const {
    const Multivector<T> b = mv.dual();
    const T b2 = (b * b).scalar();
    const Multivector<T> d = einf<T>() << b;
    if (!(b2 >= T(0)) || d.max_abs() == T(0)) return std::nullopt;
    const T root = std::sqrt(b2);
    const Multivector<T> minus = (b - Multivector<T>(root)) * d;
    const Multivector<T> plus = (b + Multivector<T>(root)) * d;
    auto p = down(minus);
    auto q = down(plus);
    if (!p || !q) return std::nullopt;
    return std::make_pair(*p, *q);
  }
};

}  // namespace conform::cga
