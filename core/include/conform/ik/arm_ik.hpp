// Closed-form inverse kinematics of a two-segment arm (first paper, cga-ik-fpga, eqs 10–18).
//
// Frame: the shoulder is at the origin, the rest arm points along +z, the elbow flexes about
// the arm's local x axis. Inputs: wrist target Pw, swivel angle φ, lengths d1 (upper arm) and
// d2 (forearm). Outputs: shoulder and elbow quaternions Qs, Qe (Hamilton, unit, v' = q v q*),
// the elbow point and a status. Forward kinematics is the contract:
//   elbow = Qs·(0,0,d1),   wrist = Qs·((0,0,d1) + Qe·(0,0,d2)) = Pw (after clamping).
//
// Conventions (explicit, shared by every solver here):
// - Swivel plane: through the shoulder–wrist line L_sw, normal n(φ) = R(P̂, φ)·(P̂ × ẑ), i.e. the
//   plane containing L_sw and the z axis, turned right-handedly by φ about P̂ (paper eq 11).
//   When the target is on the z axis (within 64 ε) the reference ẑ is replaced by x̂.
// - Elbow branch: of the two points of Pp = Ze ∧ π_swivel, the elbow is the one on the side
//   of û = n̂ × P̂ (paper eq 13 with +tmpsqrt): elbow = a P̂ + h û. At φ = 0 the elbow is
//   displaced from L_sw towards +z; φ turns it right-handedly about the shoulder→wrist axis.
// - Elbow: Qe = cos(θ4/2) + sin(θ4/2) i, θ4 ∈ [0, π] the flexion (0 = straight); the forearm
//   swings towards local −y. The hinge axis in the world is Qs·x̂ = −n̂.
//
// - Qs is returned with qs.w ≥ 0 (q and −q are the same rotation).
//
// Three solvers give the same answer: solve_readable (the algebra, arm_ik_readable.cpp),
// solve / ArmIk (the closed form, scalar) and BatchSolveJob (the closed form over
// structure-of-arrays data, SIMD and OpenMP threads). See arm_ik_readable.cpp for every sign
// changed vs the paper. ArmIk computes the arm's constants once; solve(arm, …) keeps them
// per thread for the last arm it saw.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <span>
#include <string>

#include "conform/cga/motor.hpp"
#include "conform/cga/point.hpp"

namespace conform::ik {

namespace detail {

/// Per-arm constants, computed once per ArmIk or batch (the free solve() keeps the last ones).
template <class T>
struct KernelConstants {
  T d1;
  T reach_max, reach_min;    // clamp range of |Pw| (elbow limits included)
  T reach_max2, reach_min2;  // the same for |Pw|²
  T geo_max, geo_min;        // d1 + d2, |d1 − d2| (what is reachable at all)
  T sum2, diff2;             // (d1 + d2)², (d1 − d2)²
  T dd;                      // (d1 − d2)(d1 + d2), accurate when d1 ≈ d2
  T k2;                      // 1 / (4 d1 d2)
  T half_inv_d1;             // 1 / (2 d1)
  T two_d2;                  // 2 d2
  T tiny, tiny2;             // |Pw| below this is "at the shoulder"; its square
  T inv_reach_max, inv_reach_min;
  bool limit_max, limit_min;  // the elbow range narrows reach_max / reach_min
  T axis_tol2;                // (64 ε)²: squared sine of the angle to the z axis

  static KernelConstants make(double d1, double d2, double flex_min, double flex_max) {
    KernelConstants c{};
    c.d1 = T(d1);
    const double sum = d1 + d2, diff = d1 - d2;
    c.geo_max = T(sum), c.geo_min = T(std::abs(diff));
    // |Pw|² as a function of the flexion θ: (d1+d2)² − 4 d1 d2 sin²(θ/2)
    // = (d1−d2)² + 4 d1 d2 cos²(θ/2), each written where it has no cancellation.
    c.limit_max = flex_min > 0;
    c.limit_min = flex_max < std::numbers::pi;
    double lmax2 = sum * sum, lmin2 = diff * diff;
    if (c.limit_max) {
      const double s = std::sin(flex_min / 2);
      lmax2 -= 4 * d1 * d2 * s * s;
    }
    if (c.limit_min) {
      const double co = std::cos(flex_max / 2);
      lmin2 += 4 * d1 * d2 * co * co;
    }
    const double tiny = 64 * std::numeric_limits<T>::epsilon() * sum;
    const double lmax = c.limit_max ? std::sqrt(lmax2) : sum;
    const double lmin = std::max(c.limit_min ? std::sqrt(lmin2) : std::abs(diff), tiny);
    c.reach_max = T(lmax), c.reach_min = T(lmin);
    c.reach_max2 = T(lmax2), c.reach_min2 = T(std::max(lmin2, tiny * tiny));
    c.sum2 = T(sum * sum), c.diff2 = T(diff * diff);
    c.dd = T(diff * sum);
    c.k2 = T(0.25 / (d1 * d2));
    c.half_inv_d1 = T(0.5 / d1);
    c.two_d2 = T(2 * d2);
    c.tiny = T(tiny);
    c.tiny2 = T(tiny * tiny);
    c.inv_reach_max = T(1) / c.reach_max;
    c.inv_reach_min = T(1) / c.reach_min;
    const double tol = 64 * std::numeric_limits<T>::epsilon();
    c.axis_tol2 = T(tol * tol);
    return c;
  }
};

}  // namespace detail

template <class T>
using Vec3 = cga::Vec3<T>;
template <class T>
using Quat = cga::Quat<T>;

/// Bit flags: kOk, or any combination of the others.
enum class Status : std::uint8_t {
  kOk = 0,
  kClampedOuter = 1 << 0,      // |Pw| > d1 + d2: moved onto the outer shell, same direction
  kClampedInner = 1 << 1,      // |Pw| < |d1 − d2|: moved onto the inner shell, same direction
  kTargetAtShoulder = 1 << 2,  // |Pw| ≈ 0: direction undefined, +z used
  kTargetOnZAxis = 1 << 3,     // swivel reference ẑ degenerate, x̂ used instead
  kElbowOnZAxis = 1 << 4,      // elbow on the z axis (eq 15 as printed is 0/0 there; ours is not)
  kElbowLimit = 1 << 5,        // the elbow range clamped the reach
  kShoulderLimit = 1 << 6,     // the shoulder cone moved the swivel angle or the arm
  kInvalidInput = 1 << 7,      // non-finite input, |φ| > kMaxSwivel or a bad arm: identity pose
};

constexpr Status operator|(Status a, Status b) {
  return static_cast<Status>(static_cast<std::uint8_t>(a) | static_cast<std::uint8_t>(b));
}
constexpr Status& operator|=(Status& a, Status b) {
  return a = a | b;
}
/// True when `s` has every bit of `flag`.
constexpr bool has(Status s, Status flag) {
  return (static_cast<std::uint8_t>(s) & static_cast<std::uint8_t>(flag)) ==
         static_cast<std::uint8_t>(flag);
}
/// True when the target was moved (reach clamps and joint limits): the wrist is not on Pw.
constexpr bool moved_target(Status s) {
  constexpr auto mask = static_cast<std::uint8_t>(Status::kClampedOuter | Status::kClampedInner |
                                                  Status::kElbowLimit | Status::kShoulderLimit |
                                                  Status::kInvalidInput);
  return (static_cast<std::uint8_t>(s) & mask) != 0;
}
/// "ok", or the set flags joined by '|', e.g. "clamped_outer|target_on_z_axis".
std::string to_string(Status s);

/// Swivel angles beyond ±kMaxSwivel rad are rejected (kInvalidInput): the vectorized sine
/// reduces its argument accurately only up to there.
inline constexpr double kMaxSwivel = 1e4;

/// Optional joint limits; the defaults limit nothing.
template <class T = double>
struct JointLimits {
  T elbow_min = 0;  // flexion range [rad], 0 = straight arm
  T elbow_max = std::numbers::pi_v<T>;
  Vec3<T> cone_axis = Vec3<T>(0, 0, 1);       // shoulder cone: upper arm within cone_half_angle
  T cone_half_angle = std::numbers::pi_v<T>;  // of cone_axis; π = no limit
  bool has_elbow_limit() const { return elbow_min > T(0) || elbow_max < std::numbers::pi_v<T>; }
  bool has_cone() const { return cone_half_angle < std::numbers::pi_v<T>; }
};

/// The arm. Defaults: upper arm 0.30 m, forearm 0.25 m (the procedural arm's proportions).
template <class T = double>
struct Arm {
  T upper = T(0.30);  // d1
  T fore = T(0.25);   // d2
  JointLimits<T> limits{};
  bool valid() const;
};

template <class T = double>
struct Solution {
  Quat<T> qs = Quat<T>::Identity();  // shoulder
  Quat<T> qe = Quat<T>::Identity();  // elbow: w + x i only
  Vec3<T> elbow = Vec3<T>::Zero();
  Status status = Status::kOk;
};

template <class T = double>
struct ForwardResult {
  Vec3<T> elbow, wrist;
};

/// elbow = Qs·(0,0,d1), wrist = Qs·((0,0,d1) + Qe·(0,0,d2)); the quaternions need not be unit
/// (the rotation of q is that of q/|q|).
template <class T>
ForwardResult<T> forward_kinematics(const Arm<T>& arm, const Quat<T>& qs, const Quat<T>& qe) {
  const Vec3<T> fore = qe.normalized() * Vec3<T>(0, 0, arm.fore);
  const Quat<T> s = qs.normalized();
  return {s * Vec3<T>(0, 0, arm.upper), s * (Vec3<T>(0, 0, arm.upper) + fore)};
}

/// The swivel angle φ given as (c, s) = (cos φ, sin φ): for callers that have the pair (a
/// swivel that repeats, or one given as a direction), it saves the solver's sine and cosine.
/// Any positive multiple of the pair is accepted (it is normalized); (0, 0) or a non-finite
/// pair is invalid input.
template <class T = double>
struct SwivelCosSin {
  T c = T(1), s = T(0);
  static SwivelCosSin from_angle(T phi) { return {std::cos(phi), std::sin(phi)}; }
};

/// Fast closed form (eqs 10–18 re-derived for accuracy), one target. Honours all limits.
/// The arm's constants are kept per thread for the last arm seen (recomputed when any field
/// of the arm differs); ArmIk keeps them explicitly.
template <class T>
Solution<T> solve(const Arm<T>& arm, const Vec3<T>& target, T swivel);
template <class T>
Solution<T> solve(const Arm<T>& arm, const Vec3<T>& target, SwivelCosSin<T> swivel);

/// The fast closed form for one arm: the arm's constants (lengths, squares, reciprocals and
/// the elbow range's reach) are computed once, here. Same results as solve(arm, …).
template <class T = double>
class ArmIk {
 public:
  explicit ArmIk(const Arm<T>& arm = Arm<T>{});
  const Arm<T>& arm() const { return arm_; }
  /// False for an invalid arm (then every solve returns kInvalidInput).
  bool valid() const { return valid_; }
  Solution<T> solve(const Vec3<T>& target, T swivel) const;
  Solution<T> solve(const Vec3<T>& target, SwivelCosSin<T> swivel) const;

 private:
  Arm<T> arm_;
  detail::KernelConstants<T> constants_{};
  bool valid_ = false;
};

extern template class ArmIk<float>;
extern template class ArmIk<double>;

/// The geometric version written with the algebra: spheres, circle Ze = S1∧S2, swivel plane,
/// point pair Pp = Ze∧π, lines L_se, L_ew, angles by eq 5, quaternions by eqs 8, 9, 14–18.
/// Slow (full 32-blade products) and, near the singular half-angles of eqs 8/9, less accurate.
template <class T>
Solution<T> solve_readable(const Arm<T>& arm, const Vec3<T>& target, T swivel);

/// Many targets for one arm, structure of arrays (ozz-style job: owns no buffers).
/// Every span must have the size of `x`. Qe is returned as qe_w + qe_x i (its y, z are 0).
/// The elbow range limit is honoured; the shoulder cone is not (validate() rejects it).
template <class T>
struct BatchSolveJob {
  Arm<T> arm;
  std::span<const T> x, y, z, swivel;
  std::span<T> qs_w, qs_x, qs_y, qs_z;
  std::span<T> qe_w, qe_x;
  std::span<T> elbow_x, elbow_y, elbow_z;
  std::span<std::uint8_t> status;  // Status bits
  int threads = 0;                 // OpenMP threads; 0 = OpenMP's default, 1 = this thread only

  /// Empty when the job can run; else the first bad input, named with its value.
  std::string validate() const;
  /// Runs the job; false (and nothing written) when validate() is not empty.
  bool run() const;
  /// The first spelling of the same pair (ozz's), kept for existing callers.
  bool Validate() const { return validate().empty(); }
  bool Run() const { return run(); }
};

extern template struct BatchSolveJob<float>;
extern template struct BatchSolveJob<double>;

}  // namespace conform::ik
