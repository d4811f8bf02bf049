// Dilators and versors (motor × dilator): the similarity transforms of the skinning path.
//
// D = 1 + c e∞∧e0 with c = (1 − d)/(1 + d) (second paper eq 12) scales about the origin by d:
// E = e∞∧e0 gives E e0 = e0 = −e0 E and E e∞ = −e∞ = −e∞ E, so D e0 D⁻¹ = e0/d and
// D e∞ D⁻¹ = d e∞, and D X D⁻¹ = x + ½x² d e∞ + e0/d, which is up(d x) at weight 1/d.
//
// A versor here is V = M D (dilate about the origin, then rigid motion), so
//   V X V⁻¹ ≅ up(d R x + t), and (M1 D1)(M2 D2) = (M1 · D1 M2 D1⁻¹)(D1 D2), where D1 M2 D1⁻¹ is
// M2 with its translation scaled by d1. Every composition of motors and dilators is of this
// form, so a Versor is closed under the geometric product.
#pragma once

#include "conform/cga/motor.hpp"

namespace conform::cga {

template <class T = double>
struct Dilator {
  T d = 1;  // scale factor, > 0

  /// 1 + (1 − d)/(1 + d) e∞∧e0.
  Multivector<T> mv() const {
    Multivector<T> m(T(1));
    m[kEinf0] = (T(1) - d) / (T(1) + d);
    return m;
  }
  /// D⁻¹ = (1+d)²/(4d) + (d² − 1)/(4d) e∞∧e0 (eq 13).
  Multivector<T> inverse_mv() const {
    Multivector<T> m((T(1) + d) * (T(1) + d) / (T(4) * d));
    m[kEinf0] = (d * d - T(1)) / (T(4) * d);
    return m;
  }
};

/// x' = A x + b with A = d R: one 3×4 matrix–vector product per point.
template <class T = double>
using SimilarityKernel = RigidKernel<T>;

template <class T = double>
struct Versor {
  Motor<T> motor;  // applied after the dilation
  T scale = 1;     // dilation about the origin, > 0

  static Versor identity() { return {}; }
  static Versor from_motor(const Motor<T>& m) { return {m, T(1)}; }
  static Versor from_dilator(const Dilator<T>& d) { return {Motor<T>(), d.d}; }
  /// The rigid motion (q, t) after a dilation by `scale` about the origin.
  static Versor from_trs(const Vec3<T>& t, const Quat<T>& q, T scale) {
    return {Motor<T>::from_rotation_translation(q, t), scale};
  }

  /// The 12-component multivector M D.
  Multivector<T> mv() const { return motor.mv() * Dilator<T>{scale}.mv(); }

  friend Versor operator*(const Versor& a, const Versor& b) {
    return {a.motor * conjugated_by_dilation(b.motor, a.scale), a.scale * b.scale};
  }
  /// Empty when the scale is not positive and finite or the motor is not invertible.
  std::optional<Versor> inverse() const {
    if (!(scale > T(0)) || !std::isfinite(scale)) return std::nullopt;
    auto mi = motor.inverse();
    if (!mi) return std::nullopt;
    // (M D)⁻¹ = D⁻¹ M⁻¹ = (D⁻¹ M⁻¹ D) D⁻¹.
    return Versor{conjugated_by_dilation(*mi, T(1) / scale), T(1) / scale};
  }

  /// D M D⁻¹ for a dilation by d: the motor's e∞ part −½ t R (e1∞, e2∞, e3∞, e123∞) is linear
  /// in t and the dilation scales t by d, so those four components are multiplied by d.
  static Motor<T> conjugated_by_dilation(Motor<T> m, T d) {
    m.e1inf *= d, m.e2inf *= d, m.e3inf *= d, m.e123inf *= d;
    return m;
  }

  SimilarityKernel<T> kernel() const {
    SimilarityKernel<T> k = motor.kernel();
    k.a *= scale;
    return k;
  }
  Vec3<T> apply(const Vec3<T>& x) const { return kernel().apply(x); }
  Eigen::Matrix<T, 4, 4> matrix() const {
    const auto k = kernel();
    Eigen::Matrix<T, 4, 4> m = Eigen::Matrix<T, 4, 4>::Identity();
    m.template topLeftCorner<3, 3>() = k.a;
    m.template topRightCorner<3, 1>() = k.b;
    return m;
  }
};

/// Blends: motors as in motor.hpp, scales geometrically (log-linear), which is what the log
/// blend of two dilators about the same centre gives.
template <class T>
Versor<T> blend_linear(const Versor<T>& a, const Versor<T>& b, T alpha) {
  return {blend_linear(a.motor, b.motor, alpha), (T(1) - alpha) * a.scale + alpha * b.scale};
}
template <class T>
Versor<T> blend_log(const Versor<T>& a, const Versor<T>& b, T alpha) {
  return {blend_log(a.motor, b.motor, alpha),
          std::exp((T(1) - alpha) * std::log(a.scale) + alpha * std::log(b.scale))};
}

}  // namespace conform::cga
