// The closed-form IK kernel shared by the scalar solvers and the SIMD batch: no library
// calls, and in the vector path branch-free (every choice is a select), so that
// `#pragma omp simd` loops vectorize it. Internal (not installed): use conform/ik/arm_ik.hpp.
// The per-arm constants it reads, detail::KernelConstants, are in arm_ik.hpp (ArmIk keeps
// them by value).
//
// It is eqs 10–18 of the first paper re-derived from the geometry, with Qs taken from the
// upper arm's frame instead of the paper's product Q12·Q3. With P̂ = Pw/L, L = |Pw| (clamped
// to the shell, the clamp done on L² = |Pw|² so that no root is waited for):
//   eq 11  n(φ) = cos φ n̂0 + sin φ P̂×n̂0,  n̂0 = (P̂×r)/|P̂×r|,  r = ẑ (x̂ on the z axis)
//   eq 12  Pp's coefficients collapse to tmp1 = |n|²·f1 f2 f3 f4/4 (§4.2's PP± products), with
//          the triangle factors f1 f4 = (d1+d2)² − L², f2 f3 = L² − (d1−d2)²: no |Pw| needed
//   eq 14  cos(θ4/2) = √(f2 f3 / (4 d1 d2)),  sin(θ4/2) = √(f1 f4 / (4 d1 d2))   (no 1 − c)
//   eq 13  elbow = d1 ê,  ê = cos α P̂ + sin α û,  û = n̂×P̂, α the angle at the shoulder:
//          cos α = (L² + d1² − d2²)/(2 L d1),  sin α = 2 d2 cos(θ4/2) sin(θ4/2)/L
//   eqs 15–18  Qs maps the rest frame (x̂, ŷ, ẑ) onto the upper arm's (−n̂, ŷ', ê),
//          ŷ' = cos α û − sin α P̂ (the hinge is Qs·x̂ = −n̂, as with Q12·Q3); its quaternion
//          by Shepperd's method with the pivot chosen as in Day (2015): the pivot's 4q² ≥ 1,
//          so one root and no cancellation. Sign: qs.w ≥ 0.
// Cost per solve: 5 square roots (4 independent ones on the inputs, 1 for Qs) and 3 divisions
// in the scalar path, about 110 multiplications and additions, and a polynomial sincos of φ
// unless (cos φ, sin φ) is given (the paper's pipeline takes cos(φ/2), sin(φ/2) as inputs;
// its Table 4, optimized: 8 roots, 10 divisions). The longest chain has two root steps (|Pw|,
// then Qs), each with its division alongside on the scalar common path (1/√x = √x·(1/x));
// the Q12·Q3 form (kernel_q12.hpp) had four root+division steps one after the other.
// In the vector path there is no division and no std::sqrt: GCC keeps sqrt's errno path (a
// call per element) unless the whole build uses -fno-math-errno, which would block
// vectorization; every root and reciprocal there is rsqrt() below (bit-trick seed + Newton,
// to the last ulp or two), which vectorizes.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <type_traits>

#include "conform/ik/arm_ik.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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

/// sin and cos of the reduced argument r, |r| ≤ π/4, and the quadrant q: x = q π/2 + r.
template <class T>
struct ReducedSinCos {
  T s, c;
  int q;
};

// For |x| ≤ kMaxSwivel: x = k π/2 + r with a three-part π/2 (Cody–Waite), Cephes minimax
// polynomials on |r| ≤ π/4 (evaluated by Estrin's scheme: a shorter chain than Horner's).
[[gnu::always_inline]] inline ReducedSinCos<double> sincos_reduced(double x) {
  constexpr double kShifter = 6755399441055744.0;  // 1.5·2^52: adding it rounds to integer
  const double k = (x * 0.63661977236758134308 + kShifter) - kShifter;
  const double r = ((x - k * 1.57079632673412561417e+00)  // π/2 in 33 + 33 + 53 bits (fdlibm)
                    - k * 6.07710050630396597660e-11) -
                   k * 2.02226624879595063154e-21;
  const double z = r * r, z2 = z * z, z4 = z2 * z2;
  const double sp = (-1.66666666666666307295e-1 + 8.33333333332211858878e-3 * z) +
                    z2 * (-1.98412698295895385996e-4 + 2.75573136213857245213e-6 * z) +
                    z4 * (-2.50507477628578072866e-8 + 1.58962301576546568060e-10 * z);
  const double cp = (4.16666666666665929218e-2 - 1.38888888888730564116e-3 * z) +
                    z2 * (2.48015872888517045348e-5 - 2.75573141792967388112e-7 * z) +
                    z4 * (2.08757008419747316778e-9 - 1.13585365213876817300e-11 * z);
  return {r + (r * z) * sp, (1.0 - 0.5 * z) + z2 * cp, static_cast<int>(k)};
}

[[gnu::always_inline]] inline ReducedSinCos<float> sincos_reduced(float x) {
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
  return {sr, cr, static_cast<int>(k)};
}

/// sin and cos for |x| ≤ kMaxSwivel, the quadrant by selects (vectorizes).
template <class T>
[[gnu::always_inline]] inline SinCos<T> sincos(T x) {
  const ReducedSinCos<T> r = sincos_reduced(x);
  const int q = r.q;
  const T s = sel((q & 1) != 0, r.c, r.s);
  const T c = sel((q & 1) != 0, r.s, r.c);
  return {sel((q & 2) != 0, -s, s), sel(((q + 1) & 2) != 0, -c, c)};
}

/// The same for one solve: (c, s) turned by q quarter turns with factors 0, ±1 from a table
/// (exact: one of each pair of products is 0), loaded while the polynomials are evaluated.
template <class T>
[[gnu::always_inline]] inline SinCos<T> sincos_scalar(T x) {
  static constexpr T kCos[4] = {1, 0, -1, 0};
  static constexpr T kSin[4] = {0, 1, 0, -1};
  const ReducedSinCos<T> r = sincos_reduced(x);
  const T a = kCos[r.q & 3], b = kSin[r.q & 3];
  return {r.s * a + r.c * b, r.c * a - r.s * b};
}

// Select-based min/max (fmin/fmax do not vectorize without -ffast-math).
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

/// √x and 1/√x.
template <class T>
struct Root {
  T root, inv;
};

/// Selects and roots of the vector path: bool conditions, sel(), rsqrt() and sqrt() above.
template <class T>
struct VectorOps {
  using Mask = bool;
  [[gnu::always_inline]] static Mask less(T a, T b) { return a < b; }
  [[gnu::always_inline]] static T pick(Mask m, T a, T b) { return sel(m, a, b); }
  [[gnu::always_inline]] static T sqrt(T x) { return detail::sqrt(x); }
  [[gnu::always_inline]] static T rsqrt(T x) { return detail::rsqrt(x); }
  [[gnu::always_inline]] static Root<T> root(T x) {
    const T inv = detail::rsqrt(x);
    return {x * inv, inv};
  }
  [[gnu::always_inline]] static Root<T> root_parallel(T x) { return root(x); }
};

/// Selects and roots for one solve. With SSE2 the comparison masks stay in the vector
/// registers (sel() goes through the integer registers when it is not vectorized, and a plain
/// ?: becomes a branch, mispredicted with random targets) and the roots skip std::sqrt's errno
/// check (its arguments here are never negative). root_parallel(x) = {√x, √x · (1/x)}: the root
/// and the division run side by side (half the latency of 1/√x; for 1/x a normal number).
template <class T>
struct ScalarOps {
  using Mask = bool;
  [[gnu::always_inline]] static Mask less(T a, T b) { return a < b; }
  [[gnu::always_inline]] static T pick(Mask m, T a, T b) { return sel(m, a, b); }
  static T sqrt(T x) { return std::sqrt(x); }
  static T rsqrt(T x) { return T(1) / std::sqrt(x); }
  static Root<T> root(T x) {
    const T r = std::sqrt(x);
    return {r, T(1) / r};
  }
  static Root<T> root_parallel(T x) {
    const T r = std::sqrt(x);
    return {r, r * (T(1) / x)};
  }
};
#if defined(__SSE2__)
// A scalar as the low lane of a vector register, the other lanes left as they are (unused):
// _mm_set_sd would clear them with one more instruction per use. GCC takes the empty asm
// with a tied operand as a free re-interpretation of the register.
[[gnu::always_inline]] inline __m128d low_lane(double x) {
#if defined(__GNUC__) && !defined(__clang__)
  __m128d v;
  __asm__("" : "=x"(v) : "0"(x));
  return v;
#else
  return _mm_set_sd(x);
#endif
}
[[gnu::always_inline]] inline __m128 low_lane(float x) {
#if defined(__GNUC__) && !defined(__clang__)
  __m128 v;
  __asm__("" : "=x"(v) : "0"(x));
  return v;
#else
  return _mm_set_ss(x);
#endif
}

template <>
struct ScalarOps<double> {
  struct Mask {
    __m128d m;
  };
  [[gnu::always_inline]] static Mask less(double a, double b) {
    return {_mm_cmplt_sd(low_lane(a), low_lane(b))};
  }
  [[gnu::always_inline]] static double pick(Mask m, double a, double b) {
    return _mm_cvtsd_f64(_mm_or_pd(_mm_and_pd(m.m, low_lane(a)), _mm_andnot_pd(m.m, low_lane(b))));
  }
  [[gnu::always_inline]] static double sqrt(double x) {
    const __m128d v = low_lane(x);
    return _mm_cvtsd_f64(_mm_sqrt_sd(v, v));
  }
  [[gnu::always_inline]] static double rsqrt(double x) { return 1.0 / sqrt(x); }
  [[gnu::always_inline]] static Root<double> root(double x) {
    const double r = sqrt(x);
    return {r, 1.0 / r};
  }
  [[gnu::always_inline]] static Root<double> root_parallel(double x) {
    const double r = sqrt(x);
    return {r, r * (1.0 / x)};
  }
};
template <>
struct ScalarOps<float> {
  struct Mask {
    __m128 m;
  };
  [[gnu::always_inline]] static Mask less(float a, float b) {
    return {_mm_cmplt_ss(low_lane(a), low_lane(b))};
  }
  [[gnu::always_inline]] static float pick(Mask m, float a, float b) {
    return _mm_cvtss_f32(_mm_or_ps(_mm_and_ps(m.m, low_lane(a)), _mm_andnot_ps(m.m, low_lane(b))));
  }
  [[gnu::always_inline]] static float sqrt(float x) {
    return _mm_cvtss_f32(_mm_sqrt_ss(low_lane(x)));
  }
  [[gnu::always_inline]] static float rsqrt(float x) { return 1.0f / sqrt(x); }
  [[gnu::always_inline]] static Root<float> root(float x) {
    const float r = sqrt(x);
    return {r, 1.0f / r};
  }
  [[gnu::always_inline]] static Root<float> root_parallel(float x) {
    const float r = sqrt(x);
    return {r, r * (1.0f / x)};
  }
};
#endif

/// The common path's bound on |Pw|²: 1/|Pw|² stays a normal number.
template <class T>
inline constexpr T kCommonMax = std::is_same_v<T, float> ? T(1e36) : T(1e300);

/// The paths of solve_kernel_cs.
enum class Path {
  kVector,  // SIMD lanes: every case by selects, roots by rsqrt()
  kScalar,  // one solve: every case by selects, roots by std::sqrt and division
  kCommon,  // one solve, the caller has checked: valid input, not at the shoulder, not on the
            // z axis, |Pw|² < kCommonMax (the rare cases' selects are left out; 1/√x is
            // computed as √x · (1/x), whose two operations do not wait for each other)
};

/// One solve from the target and the swivel as (cos φ, sin φ), a unit pair. `swivel_ok`
/// false or a non-finite target gives the identity pose with kBitInvalid.
template <class T, Path kPath = Path::kVector>
[[gnu::always_inline]] inline KernelResult<T> solve_kernel_cs(const KernelConstants<T>& c, T px,
                                                              T py, T pz, T cphi, T sphi,
                                                              bool swivel_ok) {
  constexpr bool kVector = kPath == Path::kVector;
  constexpr bool kRare = kPath != Path::kCommon;  // handle the rare cases here
  using Ops = std::conditional_t<kVector, VectorOps<T>, ScalarOps<T>>;
  // Clamps: selects for the vectorizer, min/max instructions for one solve.
  const auto at_least = [](T x, T lo) {
    if constexpr (kVector) {
      return max0(x, lo);
    } else {
      return x < lo ? lo : x;
    }
  };
  const auto at_most = [](T x, T hi) {
    if constexpr (kVector) {
      return min0(x, hi);
    } else {
      return x > hi ? hi : x;
    }
  };

  const T r2_in = px * px + py * py + pz * pz;
  bool valid = true, at_shoulder = false, on_axis = false;
  T r2 = r2_in;
  if constexpr (kRare) {
    // Invalid input (NaN, ±inf, |P|² overflow, bad swivel): solve a harmless target, report
    // it. Bitwise & and | on the conditions (not && ||): no branches for the vectorizer.
    valid = (r2_in - r2_in == T(0)) & swivel_ok;
    px = sel(valid, px, T(0));
    py = sel(valid, py, T(0));
    pz = sel(valid, pz, T(1));
    cphi = sel(valid, cphi, T(1));
    sphi = sel(valid, sphi, T(0));
    r2 = sel(valid, r2_in, T(1));
    at_shoulder = r2 <= c.tiny2;
    px = sel(at_shoulder, T(0), px);  // the direction of a target at the shoulder is +z
    py = sel(at_shoulder, T(0), py);
    pz = sel(at_shoulder, T(1), pz);
  }
  const T r2d = kRare ? sel(at_shoulder, T(1), r2) : r2;  // |P|² of the direction used
  const T r2s = kRare ? sel(at_shoulder, T(0), r2) : r2;  // |Pw|²

  // The roots that depend on the inputs only run side by side: 1/|P|, 1/|n0| and the
  // half-angles of the flexion (eq 14) from the clamped |Pw|².
  const auto root = [](T x) {
    if constexpr (kPath == Path::kCommon) {
      return Ops::root_parallel(x);
    } else {
      return Ops::root(x);
    }
  };
  const Root<T> len = root(r2d);
  const T inv_r = len.inv;
  // diff2 ≤ reach_min2 ≤ l2 ≤ reach_max2 ≤ sum2 (also after rounding): both factors ≥ 0.
  const T l2 = at_most(at_least(r2s, c.reach_min2), c.reach_max2);
  const T ce = Ops::sqrt((l2 - c.diff2) * c.k2);  // cos(θ4/2)
  const T se = Ops::sqrt((c.sum2 - l2) * c.k2);   // sin(θ4/2)
  // Swivel reference (eq 11): n0 = P × r, r = ẑ (x̂ when P is on the z axis); n̂0 and
  // ĝ = P̂ × n̂0 = (P × n0)/(|P||n0|) span the plane normal to P.
  const T rho2 = px * px + py * py;
  if constexpr (kRare) on_axis = rho2 <= c.axis_tol2 * r2d;
  const T n0x = kRare ? sel(on_axis, T(0), py) : py;
  const T n0y = kRare ? sel(on_axis, pz, -px) : -px;
  const T n0z = kRare ? sel(on_axis, -py, T(0)) : T(0);
  const T inv_n0 = root(kRare ? sel(on_axis, py * py + pz * pz, rho2) : rho2).inv;

  // The clamped distance (eq 10): the clamp decides 1/L.
  const T l0 = kRare ? sel(at_shoulder, T(0), len.root) : len.root;
  const T inv_l = Ops::pick(Ops::less(c.reach_max2, r2s), c.inv_reach_max,
                            Ops::pick(Ops::less(r2s, c.reach_min2), c.inv_reach_min, inv_r));

  const T ux = px * inv_r, uy = py * inv_r, uz = pz * inv_r;        // P̂
  const T ax = n0x * inv_n0, ay = n0y * inv_n0, az = n0z * inv_n0;  // n̂0
  const T inv_rn = inv_r * inv_n0;
  const T gx = (py * n0z - pz * n0y) * inv_rn, gy = (pz * n0x - px * n0z) * inv_rn,
          gz = (px * n0y - py * n0x) * inv_rn;  // P̂ × n̂0
  const T nx = cphi * ax + sphi * gx, ny = cphi * ay + sphi * gy, nz = cphi * az + sphi * gz;
  const T wx = sphi * ax - cphi * gx, wy = sphi * ay - cphi * gy,
          wz = sphi * az - cphi * gz;  // û = n̂ × P̂

  // The angle α at the shoulder between L_sw and L_se (eqs 12–13: a = d1 cos α, h = d1 sin α).
  const T ca = (l2 + c.dd) * inv_l * c.half_inv_d1;
  const T sa = c.two_d2 * ce * se * inv_l;
  const T ex = ca * ux + sa * wx, ey = ca * uy + sa * wy, ez = ca * uz + sa * wz;  // ê
  const T yx = ca * wx - sa * ux, yy = ca * wy - sa * uy, yz = ca * wz - sa * uz;  // ŷ'

  // Qs: the rotation with columns (−n̂, ŷ', ê), Shepperd's method. The four candidates
  // 4q² = 1 ± r00 ± r11 ± r22 and the pivot of Day (2015), whose 4q² ≥ 1.
  const T r00 = -nx, r11 = yy, r22 = ez;
  const T a0 = T(1) + r00, b0 = T(1) - r00, p0 = r11 + r22, m0 = r11 - r22;
  const auto low = Ops::less(r22, T(0));
  const auto c01 = Ops::less(r11, r00);   // (low) x, else y
  const auto c0m = Ops::less(r00, -r11);  // (!low) z, else w
  const T tw = a0 + p0, tx = a0 - p0, ty = b0 + m0, tz = b0 - m0;
  const auto pick = [](auto m, T a, T b) { return Ops::pick(m, a, b); };
  const T t = pick(low, pick(c01, tx, ty), pick(c0m, tz, tw));
  // Off-diagonal sums and differences (R_ij = column j, row i).
  const T dwx = yz - ey;   // R21 − R12
  const T dwy = ex + nz;   // R02 − R20
  const T dwz = -ny - yx;  // R10 − R01
  const T sxy = yx - ny;   // R01 + R10
  const T sxz = ex - nz;   // R02 + R20
  const T syz = ey + yz;   // R12 + R21
  const T vw = pick(low, pick(c01, dwx, dwy), pick(c0m, dwz, t));
  const T vx = pick(low, pick(c01, t, sxy), pick(c0m, sxz, dwx));
  const T vy = pick(low, pick(c01, sxy, t), pick(c0m, syz, dwy));
  const T vz = pick(low, pick(c01, sxz, syz), pick(c0m, t, dwz));
  // q = v / (2√t); the sign makes w ≥ 0.
  const T half_rt = T(0.5) * root(t).inv;
  const T k = pick(Ops::less(vw, T(0)), -half_rt, half_rt);

  KernelResult<T> r;
  const T d1 = c.d1;
  if constexpr (kRare) {
    r.qs_w = sel(valid, vw * k, T(1));
    r.qs_x = sel(valid, vx * k, T(0));
    r.qs_y = sel(valid, vy * k, T(0));
    r.qs_z = sel(valid, vz * k, T(0));
    // Qe = cos(θ4/2) + sin(θ4/2) i: "+" where the extracted eq 14 prints "−" (readable note 3).
    r.qe_w = sel(valid, ce, T(1));
    r.qe_x = sel(valid, se, T(0));
    r.ex = sel(valid, d1 * ex, T(0));
    r.ey = sel(valid, d1 * ey, T(0));
    r.ez = sel(valid, d1 * ez, d1);
  } else {
    r.qs_w = vw * k, r.qs_x = vx * k, r.qs_y = vy * k, r.qs_z = vz * k;
    r.qe_w = ce, r.qe_x = se;
    r.ex = d1 * ex, r.ey = d1 * ey, r.ez = d1 * ez;
  }

  // Status bits by arithmetic on the conditions (selects here are not if-converted).
  const T e_off_axis = ex * ex + ey * ey;
  const bool elbow_limit = ((l0 > c.reach_max) & c.limit_max) | ((l0 < c.reach_min) & c.limit_min);
  const int st = int(l0 > c.geo_max) * kBitOuter + int(l0 < c.geo_min) * kBitInner +
                 int(at_shoulder) * kBitShoulder + int(on_axis) * kBitTargetAxis +
                 int(e_off_axis <= c.axis_tol2) * kBitElbowAxis + int(elbow_limit) * kBitElbowLimit;
  r.status = static_cast<std::uint8_t>(int(valid) * st + int(!valid) * kBitInvalid);
  return r;
}

/// The same from the swivel angle φ (|φ| ≤ kMaxSwivel, else kBitInvalid), by sincos() above.
template <class T, Path kPath = Path::kVector>
[[gnu::always_inline]] inline KernelResult<T> solve_kernel(const KernelConstants<T>& c, T px, T py,
                                                           T pz, T phi) {
  const bool ok = (phi <= T(1e4)) & (phi >= T(-1e4));  // false for NaN too
  const SinCos<T> sc = sincos(sel(ok, phi, T(0)));
  return solve_kernel_cs<T, kPath>(c, px, py, pz, sc.c, sc.s, ok);
}

/// The same from any positive multiple of (cos φ, sin φ); (0, 0) or non-finite: kBitInvalid.
template <class T, Path kPath = Path::kVector>
[[gnu::always_inline]] inline KernelResult<T> solve_kernel_dir(const KernelConstants<T>& c, T px,
                                                               T py, T pz, T cphi, T sphi) {
  const T q = cphi * cphi + sphi * sphi;
  const bool ok = (q - q == T(0)) & (q >= std::numeric_limits<T>::min());
  const T qq = sel(ok, q, T(1));
  using Ops = std::conditional_t<kPath == Path::kVector, VectorOps<T>, ScalarOps<T>>;
  const T inv = Ops::rsqrt(qq);
  return solve_kernel_cs<T, kPath>(c, px, py, pz, sel(ok, cphi * inv, T(1)),
                                   sel(ok, sphi * inv, T(0)), ok);
}

}  // namespace conform::ik::detail
