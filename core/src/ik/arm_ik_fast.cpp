// The closed-form solvers: one target (solve) and structure-of-arrays batches (BatchSolveJob).
// The arithmetic is detail::solve_kernel (kernel.hpp, formulas beside it); this file only
// feeds it, vectorizes the batch loop and splits it across OpenMP threads.

#include <omp.h>

#include <algorithm>
#include <cstddef>
#include <limits>
#include <string>
#include <utility>

#include "conform/ik/arm_ik.hpp"
#include "conform/ik/kernel.hpp"
#include "conform/ik/limits.hpp"

// One clone per instruction set, picked at load time (the default build targets baseline
// x86-64: SSE2, 4 floats wide, two-operand instructions). The batch gets AVX-512 (16 floats)
// and AVX2 clones; the scalar common path an AVX2 one (three-operand instructions: none of the
// register copies that two-operand SSE needs).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(CONFORM_NO_CLONES)
#define CONFORM_IK_CLONES \
  __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#define CONFORM_IK_SCALAR_CLONES __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define CONFORM_IK_CLONES
#define CONFORM_IK_SCALAR_CLONES
#endif

namespace conform::ik {

std::string to_string(Status s) {
  if (s == Status::kOk) return "ok";
  static constexpr std::pair<Status, const char*> kNames[] = {
      {Status::kClampedOuter, "clamped_outer"},
      {Status::kClampedInner, "clamped_inner"},
      {Status::kTargetAtShoulder, "target_at_shoulder"},
      {Status::kTargetOnZAxis, "target_on_z_axis"},
      {Status::kElbowOnZAxis, "elbow_on_z_axis"},
      {Status::kElbowLimit, "elbow_limit"},
      {Status::kShoulderLimit, "shoulder_limit"},
      {Status::kInvalidInput, "invalid_input"}};
  std::string out;
  for (const auto& [flag, name] : kNames) {
    if (!has(s, flag)) continue;
    if (!out.empty()) out += '|';
    out += name;
  }
  return out;
}

template <class T>
bool Arm<T>::valid() const {
  const auto finite_pos = [](T v) { return std::isfinite(v) && v > T(0); };
  const JointLimits<T>& l = limits;
  return finite_pos(upper) && finite_pos(fore) && std::isfinite(l.elbow_min) &&
         std::isfinite(l.elbow_max) && l.elbow_min >= T(0) && l.elbow_min <= l.elbow_max &&
         l.elbow_max <= std::numbers::pi_v<T> && l.cone_half_angle > T(0) &&
         l.cone_axis.allFinite() && (!l.has_cone() || l.cone_axis.norm() > T(0));
}
template struct Arm<float>;
template struct Arm<double>;

namespace {

template <class T>
detail::KernelConstants<T> constants(const Arm<T>& arm) {
  return detail::KernelConstants<T>::make(arm.upper, arm.fore, arm.limits.elbow_min,
                                          arm.limits.elbow_max);
}

template <class T>
Solution<T> to_solution(const detail::KernelResult<T>& r) {
  Solution<T> s;
  s.qs = Quat<T>(r.qs_w, r.qs_x, r.qs_y, r.qs_z);
  s.qe = Quat<T>(r.qe_w, r.qe_x, T(0), T(0));
  s.elbow = Vec3<T>(r.ex, r.ey, r.ez);
  s.status = static_cast<Status>(r.status);
  return s;
}

template <class T>
Solution<T> invalid_arm() {
  Solution<T> s;
  s.status = Status::kInvalidInput;
  return s;
}

// The scalar solves: the common case (valid input, target neither at the shoulder nor on the
// z axis) without the rare cases' selects; the rest out of line with every case handled.
template <class T>
[[gnu::always_inline]] inline bool common_case(const detail::KernelConstants<T>& c, T px, T py,
                                               T pz) {
  const T rho2 = px * px + py * py;
  const T r2 = rho2 + pz * pz;
  // False for NaN in every comparison; the bound also excludes ±inf.
  return (r2 > c.tiny2) & (r2 < detail::kCommonMax<T>)&(rho2 > c.axis_tol2 * r2);
}

template <class T>
[[gnu::noinline]] detail::KernelResult<T> rare_angle(const detail::KernelConstants<T>& c,
                                                     const Vec3<T>& p, T phi) {
  return detail::solve_kernel<T, detail::Path::kScalar>(c, p.x(), p.y(), p.z(), phi);
}

template <class T>
[[gnu::noinline]] detail::KernelResult<T> rare_dir(const detail::KernelConstants<T>& c,
                                                   const Vec3<T>& p, SwivelCosSin<T> sw) {
  return detail::solve_kernel_dir<T, detail::Path::kScalar>(c, p.x(), p.y(), p.z(), sw.c, sw.s);
}

// The common case, writing the solution in place.
template <class T>
[[gnu::always_inline]] inline void common_angle_body(const detail::KernelConstants<T>& c, T px,
                                                     T py, T pz, T phi, Solution<T>& s) {
  const detail::SinCos<T> sc = detail::sincos_scalar(phi);
  s = to_solution(
      detail::solve_kernel_cs<T, detail::Path::kCommon>(c, px, py, pz, sc.c, sc.s, true));
}
template <class T>
[[gnu::always_inline]] inline void common_dir_body(const detail::KernelConstants<T>& c, T px, T py,
                                                   T pz, T cphi, T sphi, Solution<T>& s) {
  s = to_solution(
      detail::solve_kernel_cs<T, detail::Path::kCommon>(c, px, py, pz, cphi, sphi, true));
}
[[gnu::noinline]] CONFORM_IK_SCALAR_CLONES void common_angle(
    const detail::KernelConstants<float>& c, float px, float py, float pz, float phi,
    Solution<float>& s) {
  common_angle_body(c, px, py, pz, phi, s);
}
[[gnu::noinline]] CONFORM_IK_SCALAR_CLONES void common_angle(
    const detail::KernelConstants<double>& c, double px, double py, double pz, double phi,
    Solution<double>& s) {
  common_angle_body(c, px, py, pz, phi, s);
}
[[gnu::noinline]] CONFORM_IK_SCALAR_CLONES void common_dir(const detail::KernelConstants<float>& c,
                                                           float px, float py, float pz, float cphi,
                                                           float sphi, Solution<float>& s) {
  common_dir_body(c, px, py, pz, cphi, sphi, s);
}
[[gnu::noinline]] CONFORM_IK_SCALAR_CLONES void common_dir(const detail::KernelConstants<double>& c,
                                                           double px, double py, double pz,
                                                           double cphi, double sphi,
                                                           Solution<double>& s) {
  common_dir_body(c, px, py, pz, cphi, sphi, s);
}

template <class T>
[[gnu::always_inline]] inline bool angle_is_common(const detail::KernelConstants<T>& c,
                                                   const Vec3<T>& p, T phi) {
  return common_case(c, p.x(), p.y(), p.z()) & (phi <= T(kMaxSwivel)) & (phi >= T(-kMaxSwivel));
}
template <class T>
[[gnu::always_inline]] inline bool dir_is_common(const detail::KernelConstants<T>& c,
                                                 const Vec3<T>& p, SwivelCosSin<T> sw) {
  // The pair is used as given when it is unit to a few ulps, else normalized (out of line).
  const T q = sw.c * sw.c + sw.s * sw.s;
  const bool unit = std::abs(q - T(1)) <= T(8) * std::numeric_limits<T>::epsilon();
  return common_case(c, p.x(), p.y(), p.z()) & unit;
}

// As KernelResult (for the shoulder cone's probes).
template <class T>
[[gnu::always_inline]] inline detail::KernelResult<T> kernel_angle(
    const detail::KernelConstants<T>& c, const Vec3<T>& p, T phi) {
  if (angle_is_common(c, p, phi)) [[likely]] {
    const detail::SinCos<T> sc = detail::sincos_scalar(phi);
    return detail::solve_kernel_cs<T, detail::Path::kCommon>(c, p.x(), p.y(), p.z(), sc.c, sc.s,
                                                             true);
  }
  return rare_angle(c, p, phi);
}

template <class T>
[[gnu::always_inline]] inline detail::KernelResult<T> kernel_dir(
    const detail::KernelConstants<T>& c, const Vec3<T>& p, SwivelCosSin<T> sw) {
  if (dir_is_common(c, p, sw)) [[likely]] {
    return detail::solve_kernel_cs<T, detail::Path::kCommon>(c, p.x(), p.y(), p.z(), sw.c, sw.s,
                                                             true);
  }
  return rare_dir(c, p, sw);
}

// With a shoulder cone: the swivel is moved (or the arm turned) by limits.hpp.
template <class T, class Run>
Solution<T> solve_cone(const Arm<T>& arm, T swivel, Run&& run) {
  Status extra = Status::kOk;
  bool rotate_after = false;
  const detail::KernelResult<T> probe = run(swivel);
  if (probe.status & detail::kBitInvalid) return to_solution(probe);
  const T phi = detail::cone_swivel(
      arm, swivel,
      [&](T p) {
        const auto r = run(p);
        return Vec3<T>(r.ex, r.ey, r.ez);
      },
      extra, rotate_after);
  Solution<T> s = to_solution(run(phi));
  s.status |= extra;
  if (rotate_after) detail::cone_rotate(arm, s);
  return s;
}

template <class T>
[[gnu::always_inline]] inline Solution<T> solve_angle(const Arm<T>& arm,
                                                      const detail::KernelConstants<T>& c,
                                                      const Vec3<T>& target, T swivel) {
  if (!arm.limits.has_cone()) [[likely]] {
    Solution<T> s;
    if (angle_is_common(c, target, swivel)) [[likely]] {
      common_angle(c, target.x(), target.y(), target.z(), swivel, s);
      return s;
    }
    s = to_solution(rare_angle(c, target, swivel));
    return s;
  }
  return solve_cone(arm, swivel, [&](T phi) { return kernel_angle(c, target, phi); });
}

template <class T>
[[gnu::always_inline]] inline Solution<T> solve_dir(const Arm<T>& arm,
                                                    const detail::KernelConstants<T>& c,
                                                    const Vec3<T>& target, SwivelCosSin<T> swivel) {
  if (!arm.limits.has_cone()) [[likely]] {
    Solution<T> s;
    if (dir_is_common(c, target, swivel)) [[likely]] {
      common_dir(c, target.x(), target.y(), target.z(), swivel.c, swivel.s, s);
      return s;
    }
    s = to_solution(rare_dir(c, target, swivel));
    return s;
  }
  // The cone works on angles. An invalid pair stays invalid (the kernel reports it).
  const detail::KernelResult<T> probe = kernel_dir(c, target, swivel);
  if (probe.status & detail::kBitInvalid) return to_solution(probe);
  return solve_cone(arm, std::atan2(swivel.s, swivel.c),
                    [&](T phi) { return kernel_angle(c, target, phi); });
}

}  // namespace

namespace {

// The free solve()'s arm constants: kept per thread for the last arm seen (compared field by
// field, so any change of the arm recomputes them), as callers mostly solve for one arm.
template <class T>
struct ArmCache {
  Arm<T> arm{T(-1), T(-1), {}};  // invalid: never equal to a valid arm
  detail::KernelConstants<T> constants{};
  bool valid = false;
};

template <class T>
bool same_arm(const Arm<T>& a, const Arm<T>& b) {
  const JointLimits<T>&la = a.limits, &lb = b.limits;
  return (a.upper == b.upper) & (a.fore == b.fore) & (la.elbow_min == lb.elbow_min) &
         (la.elbow_max == lb.elbow_max) & (la.cone_half_angle == lb.cone_half_angle) &
         (la.cone_axis.x() == lb.cone_axis.x()) & (la.cone_axis.y() == lb.cone_axis.y()) &
         (la.cone_axis.z() == lb.cone_axis.z());
}

template <class T>
const ArmCache<T>& arm_cache(const Arm<T>& arm) {
  thread_local ArmCache<T> cache;
  if (!same_arm(arm, cache.arm)) [[unlikely]] {
    cache.arm = arm;
    cache.valid = arm.valid();
    if (cache.valid) cache.constants = constants(arm);
  }
  return cache;
}

}  // namespace

template <class T>
Solution<T> solve(const Arm<T>& arm, const Vec3<T>& target, T swivel) {
  const ArmCache<T>& cache = arm_cache(arm);
  if (!cache.valid) [[unlikely]]
    return invalid_arm<T>();
  return solve_angle(arm, cache.constants, target, swivel);
}

template <class T>
Solution<T> solve(const Arm<T>& arm, const Vec3<T>& target, SwivelCosSin<T> swivel) {
  const ArmCache<T>& cache = arm_cache(arm);
  if (!cache.valid) [[unlikely]]
    return invalid_arm<T>();
  return solve_dir(arm, cache.constants, target, swivel);
}

template Solution<float> solve(const Arm<float>&, const Vec3<float>&, float);
template Solution<double> solve(const Arm<double>&, const Vec3<double>&, double);
template Solution<float> solve(const Arm<float>&, const Vec3<float>&, SwivelCosSin<float>);
template Solution<double> solve(const Arm<double>&, const Vec3<double>&, SwivelCosSin<double>);

template <class T>
ArmIk<T>::ArmIk(const Arm<T>& arm) : arm_(arm), valid_(arm.valid()) {
  if (valid_) constants_ = constants(arm);
}

template <class T>
Solution<T> ArmIk<T>::solve(const Vec3<T>& target, T swivel) const {
  if (!valid_) [[unlikely]]
    return invalid_arm<T>();
  return solve_angle(arm_, constants_, target, swivel);
}

template <class T>
Solution<T> ArmIk<T>::solve(const Vec3<T>& target, SwivelCosSin<T> swivel) const {
  if (!valid_) [[unlikely]]
    return invalid_arm<T>();
  return solve_dir(arm_, constants_, target, swivel);
}

template class ArmIk<float>;
template class ArmIk<double>;

// ----- batch -----

namespace {

template <class T>
struct BatchPointers {
  const T *x, *y, *z, *phi;
  T *qw, *qx, *qy, *qz, *ew, *ex, *px, *py, *pz;
  std::uint8_t* st;
};

template <class T>
[[gnu::always_inline]] inline void run_range_body(const detail::KernelConstants<T>& constants,
                                                  const BatchPointers<T>& p, std::ptrdiff_t begin,
                                                  std::ptrdiff_t end) {
  const T* __restrict x = p.x;
  const T* __restrict y = p.y;
  const T* __restrict z = p.z;
  const T* __restrict phi = p.phi;
  T* __restrict qw = p.qw;
  T* __restrict qx = p.qx;
  T* __restrict qy = p.qy;
  T* __restrict qz = p.qz;
  T* __restrict ew = p.ew;
  T* __restrict ex = p.ex;
  T* __restrict px = p.px;
  T* __restrict py = p.py;
  T* __restrict pz = p.pz;
  std::uint8_t* __restrict st = p.st;
  const detail::KernelConstants<T> c = constants;  // a local copy: its loads cannot alias
#pragma omp simd
  for (std::ptrdiff_t i = begin; i < end; ++i) {
    const detail::KernelResult<T> r = detail::solve_kernel(c, x[i], y[i], z[i], phi[i]);
    qw[i] = r.qs_w, qx[i] = r.qs_x, qy[i] = r.qs_y, qz[i] = r.qs_z;
    ew[i] = r.qe_w, ex[i] = r.qe_x;
    px[i] = r.ex, py[i] = r.ey, pz[i] = r.ez;
    st[i] = r.status;
  }
}

CONFORM_IK_CLONES void run_range(const detail::KernelConstants<float>& c,
                                 const BatchPointers<float>& p, std::ptrdiff_t begin,
                                 std::ptrdiff_t end) {
  run_range_body(c, p, begin, end);
}
CONFORM_IK_CLONES void run_range(const detail::KernelConstants<double>& c,
                                 const BatchPointers<double>& p, std::ptrdiff_t begin,
                                 std::ptrdiff_t end) {
  run_range_body(c, p, begin, end);
}

}  // namespace

template <class T>
std::string BatchSolveJob<T>::validate() const {
  if (!arm.valid())
    return "arm: lengths " + std::to_string(arm.upper) + ", " + std::to_string(arm.fore) +
           " or elbow range is invalid";
  if (arm.limits.has_cone())
    return "arm.limits.cone_half_angle: " + std::to_string(arm.limits.cone_half_angle) +
           " (the batch does not honour a shoulder cone; use ArmIk)";
  const std::size_t n = x.size();
  const std::pair<const char*, std::size_t> sizes[] = {{"y", y.size()},
                                                       {"z", z.size()},
                                                       {"swivel", swivel.size()},
                                                       {"qs_w", qs_w.size()},
                                                       {"qs_x", qs_x.size()},
                                                       {"qs_y", qs_y.size()},
                                                       {"qs_z", qs_z.size()},
                                                       {"qe_w", qe_w.size()},
                                                       {"qe_x", qe_x.size()},
                                                       {"elbow_x", elbow_x.size()},
                                                       {"elbow_y", elbow_y.size()},
                                                       {"elbow_z", elbow_z.size()},
                                                       {"status", status.size()}};
  for (const auto& [name, size] : sizes)
    if (size != n)
      return std::string(name) + ": size " + std::to_string(size) + ", x has " + std::to_string(n);
  if (threads < 0) return "threads: " + std::to_string(threads) + " (must be >= 0)";
  return {};
}

template <class T>
bool BatchSolveJob<T>::run() const {
  if (!validate().empty()) return false;
  const auto c = constants(arm);
  const BatchPointers<T> p{x.data(),       y.data(),     z.data(),       swivel.data(),
                           qs_w.data(),    qs_x.data(),  qs_y.data(),    qs_z.data(),
                           qe_w.data(),    qe_x.data(),  elbow_x.data(), elbow_y.data(),
                           elbow_z.data(), status.data()};
  const auto n = static_cast<std::ptrdiff_t>(x.size());
  const int wanted = threads > 0 ? threads : omp_get_max_threads();
  // Below a few thousand solves a thread costs more to wake than it saves.
  constexpr std::ptrdiff_t kMinPerThread = 2048;
  const int team = static_cast<int>(std::clamp<std::ptrdiff_t>(n / kMinPerThread, 1, wanted));
  if (team <= 1) {
    run_range(c, p, 0, n);
    return true;
  }
  // Blocks handed out dynamically: on a shared machine a thread that loses its core for a
  // while does not hold the whole batch back (its blocks go to the other thread).
  constexpr std::ptrdiff_t kBlock = 4096;  // a multiple of 64: no shared cache lines
  const std::ptrdiff_t blocks = (n + kBlock - 1) / kBlock;
#pragma omp parallel for num_threads(team) schedule(dynamic, 1)
  for (std::ptrdiff_t b = 0; b < blocks; ++b)
    run_range(c, p, b * kBlock, std::min(n, (b + 1) * kBlock));
  return true;
}

template struct BatchSolveJob<float>;
template struct BatchSolveJob<double>;

}  // namespace conform::ik
