// Motors M = T R (rotation, then translation): the 8-component even versors of rigid motion.
//
// Components, in blade order: s, e12, e13, e23, e1∞, e2∞, e3∞, e123∞. With the rotor
// R = w − x e23 + y e13 − z e12 (quaternion q = w + xi + yj + zk, i = e3∧e2, j = e1∧e3,
// k = e2∧e1) and the translator T = 1 − ½ t e∞, expanding T R = R − ½ (t R) e∞ gives
//   s = w, e12 = −z, e13 = y, e23 = −x,
//   (e1∞, e2∞, e3∞) = −½ (w t − v × t),   e123∞ = ½ v·t,     v = (x, y, z).
// Since (0, t) ⊗ q = (−v·t, w t − v × t), the translation comes back as
//   (0, t) = (−2 e123∞, −2 (e1∞, e2∞, e3∞)) ⊗ q̄ / |q|².
#pragma once

#include <Eigen/Geometry>
#include <optional>

#include "conform/cga/point.hpp"

namespace conform::cga {

template <class T>
using Quat = Eigen::Quaternion<T>;

/// The rigid part of a motor applied to points: x' = A x + b (a 3×4 matrix), precomputed once
/// per motor so that applying it to many points costs one 3×4 matrix–vector product.
template <class T = double>
struct RigidKernel {
  Eigen::Matrix<T, 3, 3> a;
  Vec3<T> b;
  Vec3<T> apply(const Vec3<T>& x) const { return a * x + b; }
};

template <class T = double>
struct DualQuaternion {
  Quat<T> real;  // rotation q
  Quat<T> dual;  // ½ t q
};

template <class T = double>
class Motor {
 public:
  T s = 1, e12 = 0, e13 = 0, e23 = 0, e1inf = 0, e2inf = 0, e3inf = 0, e123inf = 0;

  Motor() = default;
  static Motor identity() { return Motor(); }
  /// Rotation by q (need not be unit: the sandwich divides by |q|²) then translation by t.
  static Motor from_rotation_translation(const Quat<T>& q, const Vec3<T>& t);
  static Motor from_quaternion(const Quat<T>& q) {
    return from_rotation_translation(q, Vec3<T>::Zero());
  }
  static Motor from_translation(const Vec3<T>& t) {
    return from_rotation_translation(Quat<T>::Identity(), t);
  }
  /// Right-handed rotation by `angle` about `axis` (through the origin).
  static Motor from_axis_angle(const Vec3<T>& axis, T angle) {
    return from_quaternion(Quat<T>(Eigen::AngleAxis<T>(angle, axis.normalized())));
  }
  /// From a 4×4 rigid matrix [R t; 0 1]; empty when the 3×3 block is not a rotation
  /// (orthonormal with determinant +1, to 1e-6) or the last row is not (0 0 0 1).
  static std::optional<Motor> from_matrix(const Eigen::Matrix<T, 4, 4>& m);
  static Motor from_dual_quaternion(const DualQuaternion<T>& dq) {
    const Quat<T> t2 = Quat<T>(dq.dual.coeffs() * T(2)) * dq.real.conjugate();
    const T n = dq.real.squaredNorm();
    return from_rotation_translation(dq.real, Vec3<T>(t2.x(), t2.y(), t2.z()) / n);
  }
  static Motor from_multivector(const Multivector<T>& m) {
    Motor r;
    r.s = m[kScalar], r.e12 = m[kE12], r.e13 = m[kE13], r.e23 = m[kE23];
    r.e1inf = m[kE1inf], r.e2inf = m[kE2inf], r.e3inf = m[kE3inf], r.e123inf = m[kE123inf];
    return r;
  }

  Quat<T> rotation() const { return Quat<T>(s, -e23, e13, -e12); }
  /// Translation t (the rotation's |q|² divided out).
  Vec3<T> translation() const;
  Eigen::Matrix<T, 4, 4> matrix() const;
  DualQuaternion<T> dual_quaternion() const;
  Multivector<T> mv() const;

  /// Geometric product (composition: (a * b) applies b first, then a).
  friend Motor operator*(const Motor& a, const Motor& b) { return compose(a, b); }
  static Motor compose(const Motor& a, const Motor& b);
  /// Reverse M̃ (the inverse of a unit motor).
  Motor reverse() const { return {s, -e12, -e13, -e23, -e1inf, -e2inf, -e3inf, e123inf}; }
  /// M⁻¹ = M̃ / (M M̃); empty when the rotation part is zero.
  std::optional<Motor> inverse() const;
  /// The same motion with |q| = 1 and w ≥ 0 is not implied: only the scale is removed.
  Motor normalized() const;
  T rotation_norm_squared() const { return s * s + e12 * e12 + e13 * e13 + e23 * e23; }

  RigidKernel<T> kernel() const;
  /// M X M⁻¹ for a Euclidean point, via the kernel.
  Vec3<T> apply(const Vec3<T>& x) const { return kernel().apply(x); }

  friend Motor operator+(const Motor& a, const Motor& b) {
    return {a.s + b.s,         a.e12 + b.e12,     a.e13 + b.e13,     a.e23 + b.e23,
            a.e1inf + b.e1inf, a.e2inf + b.e2inf, a.e3inf + b.e3inf, a.e123inf + b.e123inf};
  }
  friend Motor operator*(const Motor& a, T k) {
    return {a.s * k,     a.e12 * k,   a.e13 * k,   a.e23 * k,
            a.e1inf * k, a.e2inf * k, a.e3inf * k, a.e123inf * k};
  }
  friend Motor operator-(const Motor& a) { return a * T(-1); }
  T dot_rotation(const Motor& b) const { return s * b.s + e12 * b.e12 + e13 * b.e13 + e23 * b.e23; }

 private:
  Motor(T s_, T a, T b, T c, T d, T e, T f, T g)
      : s(s_), e12(a), e13(b), e23(c), e1inf(d), e2inf(e), e3inf(f), e123inf(g) {}
};

/// The motor's generator: B = e12·b12 + e13·b13 + e23·b23 + e1∞·b1 + e2∞·b2 + e3∞·b3.
template <class T = double>
struct MotorBivector {
  T e12 = 0, e13 = 0, e23 = 0, e1inf = 0, e2inf = 0, e3inf = 0;
  Multivector<T> mv() const;
};

/// log M: the bivector B with exp(B) = ±M, chosen with rotation angle in [0, π] (the shortest
/// path; M and −M are the same motion). Exact for identity, pure translations and half turns.
template <class T>
MotorBivector<T> log(const Motor<T>& m);
/// exp B for a motor generator, closed form (screw motion).
template <class T>
Motor<T> exp(const MotorBivector<T>& b);

/// Normalized linear blend ((1−α) m1 + α m2, with m2's sign matched to m1), renormalized to a
/// unit motor (rotation normalized, translation recovered from the blended dual part).
template <class T>
Motor<T> blend_linear(const Motor<T>& m1, const Motor<T>& m2, T alpha);
/// Logarithmic blend m1 exp(α log(m1⁻¹ m2)) (second paper §2.5); exact screw interpolation.
template <class T>
Motor<T> blend_log(const Motor<T>& m1, const Motor<T>& m2, T alpha);

}  // namespace conform::cga
