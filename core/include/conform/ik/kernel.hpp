// The closed-form IK kernel shared by the scalar solver and the SIMD batch: branch-free
// (every choice is a select), no library calls, so that `#pragma omp simd` loops vectorize
// it. Internal: use conform/ik/arm_ik.hpp.
//
// It is eqs 10–18 of the first paper re-derived from the geometry. With P̂ = Pw/L, L = |Pw|,
// and the triangle factors f1 = d1+d2−L, f2 = L+d1−d2, f3 = L−d1+d2, f4 = L+d1+d2 (all ≥ 0
// once L is clamped to the shell):
//   eq 11  n(φ) = cos φ (P̂×r) + sin φ P̂×(P̂×r),  r = ẑ (x̂ on the z axis); |n| = |P̂×r|
//   eq 12  Pp's coefficients collapse to tmp1 = |n|²·f1 f2 f3 f4/4 (§4.2's PP± products)
//   eq 13  elbow = a P̂ + h û,  û = n̂×P̂,  a = (L² + (d1−d2)(d1+d2))/(2L),
//          h = √(f1f2f3f4)/(2L) = 2 d1 d2 cos(θ4/2) sin(θ4/2)/L
//   eq 14  cos(θ4/2) = √(f2 f3)/(2√(d1d2)),  sin(θ4/2) = √(f1 f4)/(2√(d1d2))   (no 1 − c)
//   eq 15  Q12 = half-turn about the bisector m = ê + σẑ, σ = sign(e_z); for σ < 0 the
//          bisector of ê and −ẑ composed with a half-turn about x: Q12 = (0, m̂)·i
//   eq 17  c3 = −(Q12 x̂)·n̂,  s3 = −(Q12 ŷ)·n̂,  Q3 = half-angle of (c3, s3)
//   eq 18  Qs = Q12 Q3
// Half-angles use t = √((1+|c|)/2), u = s/(2t): accurate for every angle, unlike √((1−c)/2).
//
// Cost per solve: 6 square roots and 4 divisions (scalar path; the paper's Table 4, optimized:
// 8 roots, 10 divisions), about 130 multiplications and additions, and a polynomial sincos of
// φ (the paper's pipeline takes cos(φ/2), sin(φ/2) as inputs). In the vector path there is no
// division and no std::sqrt: GCC keeps sqrt's errno path (a call per element) unless the whole
// build uses -fno-math-errno, which would block vectorization; every root and reciprocal there
// is rsqrt() below (bit-trick seed + Newton, to the last ulp or two), which vectorizes.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>

namespace conform::ik::detail {

/// c ? a : b as a bit mask. GCC (with the default -ftrapping-math) sinks arithmetic into the
/// arms of a plain ?: and then refuses to if-convert it; both arms here are always computed.
[[gnu::always_inline]] inline float sel(bool c, float a, float b) {
  const std::uint32_t m = c ? ~0U : 0U;
  return std::bit_cast<float>((std::bit_cast<std::uint32_t>(a) & m) |
                              (std::bit_cast<std::uint32_t>(b) & ~m));
}
[[gnu::always_inline]] inline double sel(bool c, double a, double b) {
  const std::uint64_t m = c ? ~0ULL : 0ULL;
  return std::bit_cast<double>((std::bit_cast<std::uint64_t>(a) & m) |
                               (std::bit_cast<std::uint64_t>(b) & ~m));
}

/// 1/√x for x > 0 (finite): y ← y (3/2 − x y²/2) from the classic seed; the relative error
/// 3.4e-2 → 1.7e-3 → 4.5e-6 → 3e-11 → 1e-21, so 3 steps for float, 4 for double.
[[gnu::always_inline]] inline double rsqrt(double x) {
  double y = std::bit_cast<double>(0x5fe6eb50c7b537a9ULL - (std::bit_cast<std::uint64_t>(x) >> 1));
  const double hx = 0.5 * x;
  y = y * (1.5 - hx * y * y);
  y = y * (1.5 - hx * y * y);
  y = y * (1.5 - hx * y * y);
  y = y * (1.5 - hx * y * y);
  return y;
}
[[gnu::always_inline]] inline float rsqrt(float x) {
  float y = std::bit_cast<float>(0x5f375a86U - (std::bit_cast<std::uint32_t>(x) >> 1));
  const float hx = 0.5f * x;
  y = y * (1.5f - hx * y * y);
  y = y * (1.5f - hx * y * y);
  y = y * (1.5f - hx * y * y);
  return y;
}
/// √x = x/√x for x ≥ 0 (0 stays 0: the seed of 0 is finite).
template <class T>
[[gnu::always_inline]] inline T sqrt(T x) {
  return x * rsqrt(x);
}

template <class T>
struct SinCos {
  T s, c;
};

// sin and cos for |x| ≤ kMaxSwivel: x = k π/2 + r with a three-part π/2 (Cody–Waite),
// Cephes minimax polynomials on |r| ≤ π/4, quadrant by selects.
[[gnu::always_inline]] inline SinCos<double> sincos(double x) {
  constexpr double kShifter = 6755399441055744.0;  // 1.5·2^52: adding it rounds to integer
  const double k = (x * 0.63661977236758134308 + kShifter) - kShifter;
  double r = x - k * 1.57079632673412561417e+00;  // π/2 in 33 + 33 + 53 bits (fdlibm)
  r = r - k * 6.07710050630396597660e-11;
  r = r - k * 2.02226624879595063154e-21;
  const double z = r * r;
  const double sp = ((((1.58962301576546568060e-10 * z - 2.50507477628578072866e-8) * z +
                       2.75573136213857245213e-6) *
                          z -
                      1.98412698295895385996e-4) *
                         z +
                     8.33333333332211858878e-3) *
                        z -
                    1.66666666666666307295e-1;
  const double cp = ((((-1.13585365213876817300e-11 * z + 2.08757008419747316778e-9) * z -
                       2.75573141792967388112e-7) *
                          z +
                      2.48015872888517045348e-5) *
                         z -
                     1.38888888888730564116e-3) *
                        z +
                    4.16666666666665929218e-2;
  const double sr = r + r * z * sp;
  const double cr = 1.0 - 0.5 * z + z * z * cp;
  const int q = static_cast<int>(k);
  const double s = sel((q & 1) != 0, cr, sr);
  const double c = sel((q & 1) != 0, sr, cr);
  return {sel((q & 2) != 0, -s, s), sel(((q + 1) & 2) != 0, -c, c)};
}

[[gnu::always_inline]] inline SinCos<float> sincos(float x) {
  constexpr float kShifter = 12582912.0f;  // 1.5·2^23
  const float k = (x * 0.636619772f + kShifter) - kShifter;
  float r = x - k * 1.5703125f;  // Cephes' π/2 split
  r = r - k * 4.837512969970703125e-4f;
  r = r - k * 7.54978995489188216e-8f;
  const float z = r * r;
  const float sr = ((-1.9515295891e-4f * z + 8.3321608736e-3f) * z - 1.6666654611e-1f) * z * r + r;
  const float cr =
      ((2.443315711809948e-5f * z - 1.388731625493765e-3f) * z + 4.166664568298827e-2f) * z * z -
      0.5f * z + 1.0f;
  const int q = static_cast<int>(k);
  const float s = sel((q & 1) != 0, cr, sr);
  const float c = sel((q & 1) != 0, sr, cr);
  return {sel((q & 2) != 0, -s, s), sel(((q + 1) & 2) != 0, -c, c)};
}

/// Per-arm constants, computed once per solve or per batch.
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

// Select-based min/max/abs (fmin/fmax do not vectorize without -ffast-math).
template <class T>
[[gnu::always_inline]] inline T max0(T x, T lo) {
  return sel(x < lo, lo, x);
}
template <class T>
[[gnu::always_inline]] inline T min0(T x, T hi) {
  return sel(x > hi, hi, x);
}

template <class T>
struct KernelResult {
  T qs_w, qs_x, qs_y, qs_z;
  T qe_w, qe_x;
  T ex, ey, ez;         // elbow point
  std::uint8_t status;  // Status bits
};

// Status bits, as in arm_ik.hpp (kept numeric here so the kernel stays header-light).
inline constexpr std::uint8_t kBitOuter = 1, kBitInner = 2, kBitShoulder = 4, kBitTargetAxis = 8,
                              kBitElbowAxis = 16, kBitElbowLimit = 32, kBitInvalid = 128;

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

}  // namespace conform::ik::detail
