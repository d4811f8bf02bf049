// The full multivector of G(4,1): 32 coefficients in the blade order of blades.hpp.
//
// General and exact rather than fast: the graded types (point.hpp, motor.hpp, ...) and their
// derived kernels are the fast path, and every kernel is tested against this class.
#pragma once

#include <array>
#include <cmath>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>

#include "conform/cga/blades.hpp"
#include "conform/cga/detail/product_table.hpp"

namespace conform::cga {

template <class T = double>
class Multivector {
 public:
  using Scalar = T;
  std::array<T, kBladeCount> c{};

  constexpr Multivector() = default;
  constexpr explicit Multivector(T scalar) { c[0] = scalar; }
  static Multivector blade(int index, T coeff = T(1)) {
    Multivector m;
    m.c[static_cast<std::size_t>(index)] = coeff;
    return m;
  }
  /// The pseudoscalar I = e1∧e2∧e3∧e∞∧e0.
  static Multivector pseudoscalar() { return blade(kE123inf0); }

  T& operator[](int i) { return c[static_cast<std::size_t>(i)]; }
  const T& operator[](int i) const { return c[static_cast<std::size_t>(i)]; }

  template <class U>
  Multivector<U> cast() const {
    Multivector<U> r;
    for (int i = 0; i < kBladeCount; ++i) r[i] = static_cast<U>((*this)[i]);
    return r;
  }

  // ----- linear structure -----
  friend Multivector operator+(Multivector a, const Multivector& b) {
    for (int i = 0; i < kBladeCount; ++i) a[i] += b[i];
    return a;
  }
  friend Multivector operator-(Multivector a, const Multivector& b) {
    for (int i = 0; i < kBladeCount; ++i) a[i] -= b[i];
    return a;
  }
  friend Multivector operator-(Multivector a) {
    for (auto& x : a.c) x = -x;
    return a;
  }
  friend Multivector operator*(Multivector a, T s) {
    for (auto& x : a.c) x *= s;
    return a;
  }
  friend Multivector operator*(T s, Multivector a) { return a * s; }
  friend Multivector operator/(Multivector a, T s) { return a * (T(1) / s); }
  Multivector& operator+=(const Multivector& b) { return *this = *this + b; }
  Multivector& operator-=(const Multivector& b) { return *this = *this - b; }
  Multivector& operator*=(T s) { return *this = *this * s; }

  // ----- products -----
  /// Geometric product ab.
  friend Multivector operator*(const Multivector& a, const Multivector& b) {
    return apply(detail::product_tables().geometric, a, b);
  }
  Multivector& operator*=(const Multivector& b) { return *this = *this * b; }
  /// Outer product a∧b.
  friend Multivector operator^(const Multivector& a, const Multivector& b) {
    return apply(detail::product_tables().outer, a, b);
  }
  /// Left contraction a⌋b.
  friend Multivector operator<<(const Multivector& a, const Multivector& b) {
    return apply(detail::product_tables().left_contraction, a, b);
  }
  /// Right contraction a⌊b.
  friend Multivector operator>>(const Multivector& a, const Multivector& b) {
    return apply(detail::product_tables().right_contraction, a, b);
  }
  /// Scalar product ⟨ab⟩₀.
  friend T scalar_product(const Multivector& a, const Multivector& b) {
    return apply(detail::product_tables().scalar, a, b)[0];
  }
  /// Regressive product a∨b = (a* ∧ b*)^{-*}, i.e. undual(dual(a) ∧ dual(b)).
  friend Multivector operator&(const Multivector& a, const Multivector& b) {
    return (a.dual() ^ b.dual()).undual();
  }

  // ----- involutions and grades -----
  /// Reverse ã: grade k gets (−1)^{k(k−1)/2}.
  Multivector reverse() const { return with_grade_signs({1, 1, -1, -1, 1, 1}); }
  /// Grade involution â: grade k gets (−1)^k.
  Multivector grade_involution() const { return with_grade_signs({1, -1, 1, -1, 1, -1}); }
  /// Clifford conjugate ā = reverse of the grade involution.
  Multivector conjugate() const { return with_grade_signs({1, -1, -1, 1, 1, -1}); }
  /// ⟨a⟩_k.
  Multivector grade(int k) const {
    Multivector r;
    for (int i = 0; i < kBladeCount; ++i)
      if (kBladeGrade[static_cast<std::size_t>(i)] == k) r[i] = (*this)[i];
    return r;
  }
  T scalar() const { return c[0]; }

  /// Dual m* = −m I (so (m*)* = −m).
  Multivector dual() const { return -(*this * pseudoscalar()); }
  /// Inverse of dual: undual(dual(m)) = m, undual(m) = m I.
  Multivector undual() const { return *this * pseudoscalar(); }

  // ----- norms and inverses -----
  /// ⟨m m̃⟩₀, may be negative or zero in this non-Euclidean algebra.
  T norm_squared() const { return scalar_product(*this, reverse()); }
  T norm() const { return std::sqrt(std::abs(norm_squared())); }
  /// Largest absolute coefficient.
  T max_abs() const {
    T m = 0;
    for (T x : c) m = std::max(m, std::abs(x));
    return m;
  }
  bool is_finite() const {
    for (T x : c)
      if (!std::isfinite(x)) return false;
    return true;
  }

  /// Cheap versor inverse Ṽ / (V Ṽ); empty when V Ṽ is not a non-zero scalar.
  std::optional<Multivector> versor_inverse() const;
  /// General inverse (solves a x = 1 as a 32×32 linear system); empty when not invertible.
  std::optional<Multivector> inverse() const;

  /// Printing and parsing by blade names, e.g. "1.5 + 2*e1 - 0.5*einf^e0".
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const Multivector& m) {
    return os << m.to_string();
  }

 private:
  static Multivector apply(const detail::ProductTable& table, const Multivector& a,
                           const Multivector& b) {
    Multivector r;
    const detail::ProductTerm* terms = table.terms.data();
    for (int lhs = 0; lhs < kBladeCount; ++lhs) {
      const T x = a.c[static_cast<std::size_t>(lhs)];
      if (x == T(0)) continue;
      const auto end = table.lhs_begin[static_cast<std::size_t>(lhs) + 1];
      for (auto k = table.lhs_begin[static_cast<std::size_t>(lhs)]; k < end; ++k) {
        const detail::ProductTerm& t = terms[k];
        r.c[t.out] += static_cast<T>(t.coeff) * x * b.c[t.rhs];
      }
    }
    return r;
  }
  Multivector with_grade_signs(std::array<int, 6> sign) const {
    Multivector r = *this;
    for (int i = 0; i < kBladeCount; ++i)
      if (sign[static_cast<std::size_t>(kBladeGrade[static_cast<std::size_t>(i)])] < 0)
        r[i] = -r[i];
    return r;
  }
};

/// Parses a sum of terms "coef*blade" with blade names written as a product of basis vectors
/// (e1, e2, e3, einf, e0; e.g. "e12", "e1^einf", "e21" = −e12); throws std::invalid_argument
/// naming the offending term.
template <class T = double>
Multivector<T> parse_multivector(std::string_view text);

/// exp(B) by scaling and squaring of the Taylor series (any multivector; used for bivectors).
template <class T>
Multivector<T> exp(const Multivector<T>& b);

/// Basis vectors as multivectors.
template <class T = double>
inline Multivector<T> e1() {
  return Multivector<T>::blade(kE1);
}
template <class T = double>
inline Multivector<T> e2() {
  return Multivector<T>::blade(kE2);
}
template <class T = double>
inline Multivector<T> e3() {
  return Multivector<T>::blade(kE3);
}
template <class T = double>
inline Multivector<T> einf() {
  return Multivector<T>::blade(kEinf);
}
template <class T = double>
inline Multivector<T> e0() {
  return Multivector<T>::blade(kE0);
}

extern template class Multivector<float>;
extern template class Multivector<double>;

}  // namespace conform::cga
