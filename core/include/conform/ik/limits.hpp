// Joint limits shared by the scalar solvers (internal; use conform/ik/arm_ik.hpp).
//
// The elbow range is a reach clamp: |Pw| = L(θ4), L(θ)² = d1² + d2² + 2 d1 d2 cos θ, so a
// flexion range [θmin, θmax] is the shell L(θmax) ≤ |Pw| ≤ L(θmin) (done in the kernel).
//
// The shoulder cone (upper arm within γ of an axis â) is met first by moving the swivel: on
// the elbow circle, ê(φ)·â = C + A cos φ + B sin φ exactly (the elbow turns about L_sw), so the
// feasible swivels are cos(φ − φa) ≥ τ, φa = atan2(B, A), τ = (cos γ − C)/√(A² + B²); the
// nearest feasible φ is taken. When no swivel is feasible the best one is used and the whole
// arm is then turned about the shoulder onto the cone (the wrist leaves the target).
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

#include "conform/ik/arm_ik.hpp"

namespace conform::ik::detail {

/// `elbow_at(φ)` returns the solver's elbow point for swivel φ (same target). Returns the
/// swivel to solve with; sets kShoulderLimit in `status` when it differs from `swivel`, and
/// `rotate_after` when even the best swivel leaves the elbow outside the cone.
template <class T, class ElbowAt>
T cone_swivel(const Arm<T>& arm, T swivel, ElbowAt&& elbow_at, Status& status, bool& rotate_after) {
  rotate_after = false;
  if (!arm.limits.has_cone()) return swivel;
  const Vec3<T> axis = arm.limits.cone_axis.normalized();
  const T cos_gamma = std::cos(arm.limits.cone_half_angle);
  const T pi = std::numbers::pi_v<T>;
  const T e0 = elbow_at(T(0)).dot(axis) / arm.upper;
  const T e90 = elbow_at(pi / 2).dot(axis) / arm.upper;
  const T e180 = elbow_at(pi).dot(axis) / arm.upper;
  const T c = (e0 + e180) / 2, a = (e0 - e180) / 2, b = e90 - c;
  const T r = std::hypot(a, b);
  const T slack = T(1e-9);
  if (!(r > slack)) {  // the elbow does not move with φ (straight arm, or cone axis on L_sw)
    if (c < cos_gamma - slack) status |= Status::kShoulderLimit, rotate_after = true;
    return swivel;
  }
  const T phi_a = std::atan2(b, a);
  const T tau = (cos_gamma - c) / r;
  if (tau <= T(-1) || std::cos(swivel - phi_a) >= tau - slack) return swivel;
  status |= Status::kShoulderLimit;
  if (tau > T(1)) {
    rotate_after = true;
    return phi_a;
  }
  const T half = std::acos(tau);
  // The two boundary swivels; take the one nearest to the request (angles wrap).
  const auto dist = [&](T p) { return std::abs(std::remainder(p - swivel, 2 * pi)); };
  const T lo = phi_a - half, hi = phi_a + half;
  T best = dist(lo) <= dist(hi) ? lo : hi;
  best = swivel + std::remainder(best - swivel, 2 * pi);  // keep the caller's winding
  return best;
}

/// Turns the solved arm about the shoulder so that the upper arm lies on the cone.
template <class T>
void cone_rotate(const Arm<T>& arm, Solution<T>& s) {
  const Vec3<T> axis = arm.limits.cone_axis.normalized();
  const Vec3<T> e = s.elbow.normalized();
  const T angle = std::acos(std::clamp(e.dot(axis), T(-1), T(1)));
  const T excess = angle - arm.limits.cone_half_angle;
  if (!(excess > T(0))) return;
  Vec3<T> k = e.cross(axis);
  if (!(k.norm() > T(1e-12))) k = e.unitOrthogonal();
  const Quat<T> turn(Eigen::AngleAxis<T>(excess, k.normalized()));
  s.qs = (turn * s.qs).normalized();
  s.elbow = turn * s.elbow;
}

}  // namespace conform::ik::detail
