// The previous closed form (kept as the in-run baseline of benchmarks/ik_bench.cpp and as a
// cross-check in tests/ik/ik_arm_test.cpp): the same elbow as kernel.hpp, but Qs built as the
// paper builds it, Qs = Q12 Q3 (eqs 15–18), with two dependent half-angle roots, and the
// triangle factors f1…f4 from the root |Pw|. Internal; use conform/ik/arm_ik.hpp.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>

#include "conform/ik/kernel.hpp"

namespace conform::ik::detail::q12 {

using detail::kBitElbowAxis;
using detail::kBitElbowLimit;
using detail::kBitInner;
using detail::kBitInvalid;
using detail::kBitOuter;
using detail::kBitShoulder;
using detail::kBitTargetAxis;
using detail::KernelResult;
using detail::max0;
using detail::min0;
using detail::sel;
using detail::SinCos;
using detail::sincos;

/// Per-arm constants of this formulation.
template <class T>
struct KernelConstants {
  T d1, d2;
  T reach_max, reach_min;  // clamp range of |Pw| (elbow limits included)
  T geo_max, geo_min;      // d1 + d2, |d1 − d2| (what is reachable at all)
  T d1_minus_d2;
  T dd;        // (d1 − d2)(d1 + d2), accurate when d1 ≈ d2
  T k_half;    // 1 / (2 √(d1 d2))
  T two_d1d2;  // 2 d1 d2
  T inv_d1;
  T tiny, tiny2;  // |Pw| below this is "at the shoulder"; its square
  T inv_reach_max, inv_reach_min;
  bool limit_max, limit_min;  // the elbow range narrows reach_max / reach_min
  T axis_tol2;                // (64 ε)²: squared sine of the angle to the z axis

  static KernelConstants make(double d1, double d2, double flex_min, double flex_max) {
    KernelConstants c{};
    c.d1 = T(d1), c.d2 = T(d2);
    c.geo_max = T(d1 + d2), c.geo_min = T(std::abs(d1 - d2));
    // |Pw| as a function of the flexion: L(θ)² = d1² + d2² + 2 d1 d2 cos θ.
    const auto reach = [&](double flex) {
      return std::sqrt(std::max(0.0, d1 * d1 + d2 * d2 + 2 * d1 * d2 * std::cos(flex)));
    };
    const double lmax = flex_min > 0 ? reach(flex_min) : d1 + d2;
    const double lmin = flex_max < std::numbers::pi ? reach(flex_max) : std::abs(d1 - d2);
    const double tiny = 64 * std::numeric_limits<T>::epsilon() * (d1 + d2);
    c.reach_max = flex_min > 0 ? T(lmax) : c.geo_max;
    c.reach_min = T(std::max(lmin, tiny));
    c.d1_minus_d2 = T(d1 - d2);
    c.dd = T((d1 - d2) * (d1 + d2));
    c.k_half = T(0.5 / std::sqrt(d1 * d2));
    c.two_d1d2 = T(2 * d1 * d2);
    c.inv_d1 = T(1 / d1);
    c.tiny = T(tiny);
    c.tiny2 = T(tiny * tiny);
    c.inv_reach_max = T(1) / c.reach_max;
    c.inv_reach_min = T(1) / c.reach_min;
    c.limit_max = flex_min > 0;
    c.limit_min = flex_max < std::numbers::pi;
    const double tol = 64 * std::numeric_limits<T>::epsilon();
    c.axis_tol2 = T(tol * tol);
    return c;
  }
};

/// kVector: roots by rsqrt() (vectorizes); otherwise by std::sqrt and division, whose latency
/// is shorter for one solve at a time (the results agree to an ulp or two).
template <class T, bool kVector = true>
[[gnu::always_inline]] inline KernelResult<T> solve_kernel(const KernelConstants<T>& c, T px, T py,
                                                           T pz, T phi) {
  const auto rsqrt = [](T x) {
    if constexpr (kVector) {
      return detail::rsqrt(x);
    } else {
      return T(1) / std::sqrt(x);
    }
  };
  const auto sqrt = [](T x) {
    if constexpr (kVector) {
      return detail::sqrt(x);
    } else {
      return std::sqrt(x);
    }
  };
  // Invalid input (NaN, ±inf, |P|² overflow, huge φ): solve a harmless target, report it.
  const T r2_in = px * px + py * py + pz * pz;
  // Bitwise & and | on the conditions (not && ||): no branches for the vectorizer.
  const bool valid = (r2_in - r2_in == T(0)) & (phi <= T(1e4)) & (phi >= T(-1e4));
  px = sel(valid, px, T(0));
  py = sel(valid, py, T(0));
  pz = sel(valid, pz, T(1));
  phi = sel(valid, phi, T(0));
  const T r2 = sel(valid, r2_in, T(1));

  // Direction and clamped distance (eq 10). The roots below depend on the inputs only, so
  // they run side by side (short latency for one solve).
  const bool at_shoulder = r2 <= c.tiny2;
  px = sel(at_shoulder, T(0), px);  // the direction of a target at the shoulder is +z
  py = sel(at_shoulder, T(0), py);
  pz = sel(at_shoulder, T(1), pz);
  const T r2d = sel(at_shoulder, T(1), r2);
  const T inv_r = rsqrt(r2d);
  const T l0 = sel(at_shoulder, T(0), r2d * inv_r);
  const T ux = px * inv_r, uy = py * inv_r, uz = pz * inv_r;  // P̂
  const T l = min0(max0(l0, c.reach_min), c.reach_max);
  const T inv_l =
      sel(l0 > c.reach_max, c.inv_reach_max, sel(l0 < c.reach_min, c.inv_reach_min, inv_r));

  // Swivel reference (eq 11): n0 = Pw × r, r = ẑ (x̂ when Pw is on the z axis); n̂0 and
  // ĝ = P̂ × n̂0 = (Pw × n0)/(|Pw||n0|) span the plane normal to Pw.
  const T rho2 = px * px + py * py;
  const bool on_axis = rho2 <= c.axis_tol2 * r2d;
  const T n0x = sel(on_axis, T(0), py);
  const T n0y = sel(on_axis, pz, -px);
  const T n0z = sel(on_axis, -py, T(0));
  const T inv_n0 = rsqrt(sel(on_axis, py * py + pz * pz, rho2));
  const T ax = n0x * inv_n0, ay = n0y * inv_n0, az = n0z * inv_n0;  // n̂0
  const T inv_rn = inv_r * inv_n0;
  const T gx = (py * n0z - pz * n0y) * inv_rn, gy = (pz * n0x - px * n0z) * inv_rn,
          gz = (px * n0y - py * n0x) * inv_rn;  // P̂ × n̂0
  const SinCos<T> sc = sincos(phi);
  const T nx = sc.c * ax + sc.s * gx, ny = sc.c * ay + sc.s * gy, nz = sc.c * az + sc.s * gz;
  const T wx = sc.s * ax - sc.c * gx, wy = sc.s * ay - sc.c * gy, wz = sc.s * az - sc.c * gz;  // û

  // Elbow flexion (eq 14) from the triangle factors.
  const T f1 = max0(c.geo_max - l, T(0));
  const T f2 = max0(l + c.d1_minus_d2, T(0));
  const T f3 = max0(l - c.d1_minus_d2, T(0));
  const T f4 = c.geo_max + l;
  const T ce = sqrt(f2 * f3) * c.k_half;  // cos(θ4/2)
  const T se = sqrt(f1 * f4) * c.k_half;  // sin(θ4/2)

  // Elbow point (eqs 12–13): a = d1 cos α, h = d1 sin α.
  const T a = (l * l + c.dd) * (T(0.5) * inv_l);
  const T h = c.two_d1d2 * ce * se * inv_l;
  const T pex = a * ux + h * wx, pey = a * uy + h * wy, pez = a * uz + h * wz;

  // Q12 (eq 15): half-turn about the bisector of ê and σẑ. Eq 15 is (d1 − pez)(Pe + d1ẑ)
  // normalized; its factor (d1 − pez) is dropped (0/0 with the elbow at +d1ẑ), and below the
  // xy plane the −ẑ bisector avoids the 0/0 at −d1ẑ.
  const T ex = pex * c.inv_d1, ey = pey * c.inv_d1, ez = pez * c.inv_d1;
  const bool upper = ez >= T(0);
  const T mz = sel(upper, ez + T(1), ez - T(1));
  const T m2 = ex * ex + ey * ey + mz * mz;
  const T inv_m = rsqrt(m2);
  const T q12w = sel(upper, T(0), -ex * inv_m);
  const T q12x = sel(upper, ex * inv_m, T(0));
  const T q12y = sel(upper, ey * inv_m, mz * inv_m);
  const T q12z = sel(upper, mz * inv_m, -ey * inv_m);

  // Q3 (eqs 16–17): rotation about local z taking x̂ to Q12⁻¹(−n̂); with the reflection
  // w = 2(m̂·n̂)m̂ − n̂: c3 = −w_x, s3 = −σ w_y.
  const T t = T(2) * (ex * nx + ey * ny + mz * nz) * (inv_m * inv_m);
  const T c3 = nx - t * ex;
  const T s3 = sel(upper, ny - t * ey, t * ey - ny);
  const T hh = T(0.5) * (T(1) + std::fabs(c3));
  const T inv_h3 = rsqrt(hh);
  const T h3 = hh * inv_h3;
  const T v3 = s3 * T(0.5) * inv_h3;
  const T q3w = sel(c3 >= T(0), h3, std::fabs(v3));
  // The sign of sin(θ3/2) is that of s3, not eq 17's sign(πyz2·Pw), which is 0/0 when the
  // arm is straight.
  const T q3z = sel(c3 >= T(0), v3, sel(s3 >= T(0), h3, -h3));

  // Qs = Q12 Q3 (eq 18; q12w = 0 on the upper hemisphere, as in the paper).
  KernelResult<T> r;
  r.qs_w = sel(valid, q12w * q3w - q12z * q3z, T(1));
  r.qs_x = sel(valid, q12x * q3w + q12y * q3z, T(0));
  r.qs_y = sel(valid, q12y * q3w - q12x * q3z, T(0));
  r.qs_z = sel(valid, q12z * q3w + q12w * q3z, T(0));
  // Qe = cos(θ4/2) + sin(θ4/2) i: "+" where the extracted eq 14 prints "−" (readable note 3).
  r.qe_w = sel(valid, ce, T(1));
  r.qe_x = sel(valid, se, T(0));
  r.ex = sel(valid, pex, T(0));
  r.ey = sel(valid, pey, T(0));
  r.ez = sel(valid, pez, c.d1);

  // Status bits by arithmetic on the conditions (selects here are not if-converted).
  const T e_off_axis = ex * ex + ey * ey;
  const bool elbow_limit = ((l0 > c.reach_max) & c.limit_max) | ((l0 < c.reach_min) & c.limit_min);
  const int st = int(l0 > c.geo_max) * kBitOuter + int(l0 < c.geo_min) * kBitInner +
                 int(at_shoulder) * kBitShoulder + int(on_axis) * kBitTargetAxis +
                 int(e_off_axis <= c.axis_tol2) * kBitElbowAxis + int(elbow_limit) * kBitElbowLimit;
  r.status = static_cast<std::uint8_t>(int(valid) * st + int(!valid) * kBitInvalid);
  return r;
}

}  // namespace conform::ik::detail::q12
