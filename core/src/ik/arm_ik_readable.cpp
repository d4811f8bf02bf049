// The arm IK written with the algebra, step by step as the first paper describes it (§3):
// spheres → circle Ze → swivel plane → point pair Pp → elbow Pe → lines L_se, L_ew → Qe;
// middle line Lm → Q12; planes πyz2, π_swivel → Q3; Qs = Q12 Q3. Every entity is a full
// Multivector and every step one product, so this is slow and meant to be read and to check
// the closed form (kernel.hpp), which must give the same answer.
//
// Signs and formulas changed with respect to the paper's text (as extracted from the PDF),
// each re-derived from the geometry and checked by forward kinematics (tests/ik/ik_*_test.cpp):
//  1. Eq 11 (swivel plane) is right as printed once "φ2" is read as cos²(φ/2):
//     n(φ) = cos φ (Pw × ẑ) + sin φ (Pw × (Pw × ẑ))/|Pw|, the plane through the z axis and
//     Pw turned right-handedly by φ about L_sw. It is 0 on the z axis: there we use x̂ for ẑ.
//  2. Eqs 12–13 are consistent as printed: with m = Pw × n they give
//     pe = (k Pw − √tmp1 · m/|n|)/|Pw|², k = (|Pw|² + d1² − d2²)/2, i.e. pe = a P̂ + h n̂×P̂.
//     The "+tmpsqrt" branch is the one we keep, for every φ (the explicit elbow branch).
//  3. Eq 14: the printed c4 = pe·(pe − pw)/(d1 d2) is −cos θ4 (L_ew oriented wrist→elbow),
//     and the printed Qe has "− √((1−c4)/2) i". Taken together with eq 17's signs they do not
//     reach the wrist. We use c4 = cos θ4 = angle between L_se and L_ew by eq 5, θ4 the flexion
//     (0 = straight), and Qe = √((1+c4)/2) + √((1−c4)/2) i — the text's Qe = cos(θ4/2) +
//     sin(θ4/2) i. (Sign of the i term flipped vs the extracted eq 14.)
//  4. Eq 15: Q12 = (pex(d1−pez), pey(d1−pez), pex²+pey²)/|Lm| = (d1 − pez)(Pe + d1ẑ)/|Lm|:
//     right, but 0/0 when the elbow is at +d1ẑ, and ill-conditioned near −d1ẑ. Here (as in the
//     paper) Lm = πe ∧ πm, with an explicit fallback on the z axis (k at +z, i at −z); the
//     previous closed form (kernel_q12.hpp) drops the factor (d1 − pez) and switches to the
//     bisector of Pe and −d1ẑ composed with i below the xy plane. The closed form (kernel.hpp)
//     has no Q12: it takes Qs from the upper arm's frame (−n̂, ŷ', ê) at once, which eqs 15–18
//     describe as a product (Qs·x̂ = −n̂ and Qs·ẑ = ê fix the rotation).
//  5. Eq 17: c3 = −(Q12 e1 Q̃12)·n̂ as printed, i.e. the hinge axis is Qs·x̂ = −n̂ (consistent
//     with 3). The printed sign test sign(πyz2·Pw) is right whenever the elbow is bent
//     (πyz2·Pw = d2 sin θ3 sin θ4) but is 0/0 at full extension; we take the sign of
//     s3 = −(Q12 e2 Q̃12)·n̂ = sin θ3 instead, defined everywhere.
//  6. Eq 16/9: √((1−c)/2) loses half the digits for small angles (float: 2e-4 rad); this file
//     keeps the paper's half-angle formulas; the closed form has no 1 − c: eq 14's half-angles
//     come from the triangle factors, Qs from Shepperd's method with the largest pivot.
//  7. Eq 18 is right as printed (Qs = Q12 Q3 with q12's scalar 0); kernel_q12.hpp adds the
//     scalar term for its lower-hemisphere Q12.
// Quaternions map to rotors by i = e3∧e2, j = e1∧e3, k = e2∧e1: q = w + xi + yj + zk is the
// rotor w − x e23 + y e13 − z e12, and X' = R X R̃ is v' = q v q*.
#include <cmath>

#include "conform/cga/multivector.hpp"
#include "conform/cga/plane.hpp"
#include "conform/cga/point.hpp"
#include "conform/cga/rounds_flats.hpp"
#include "conform/cga/sphere.hpp"
#include "conform/ik/arm_ik.hpp"
#include "conform/ik/kernel.hpp"
#include "conform/ik/limits.hpp"

namespace conform::ik {

namespace {

using cga::Multivector;

template <class T>
Multivector<T> rotor(const Quat<T>& q) {
  Multivector<T> r(q.w());
  r[cga::kE23] = -q.x();
  r[cga::kE13] = q.y();
  r[cga::kE12] = -q.z();
  return r;
}

template <class T>
Quat<T> quaternion(const Multivector<T>& r) {
  return Quat<T>(r[cga::kScalar], -r[cga::kE23], r[cga::kE13], -r[cga::kE12]);
}

/// cos of the angle between two lines or planes by eq 5: o1·o2 / (|o1||o2|), |o| = √|⟨o õ⟩|.
template <class T>
T cos_angle(const Multivector<T>& o1, const Multivector<T>& o2) {
  const T n1 = std::sqrt(std::abs(scalar_product(o1, o1.reverse())));
  const T n2 = std::sqrt(std::abs(scalar_product(o2, o2.reverse())));
  const T c = scalar_product(o1, o2.reverse()) / (n1 * n2);
  return std::clamp(c, T(-1), T(1));
}

/// The target after the reach rules (the same as the closed form's): clamped Pw and flags.
template <class T>
struct Prepared {
  Vec3<T> pw;
  bool on_axis = false;
  bool valid = true;
  Status status = Status::kOk;
};

template <class T>
Prepared<T> prepare(const Arm<T>& arm, const Vec3<T>& target, T swivel) {
  const auto c = detail::KernelConstants<T>::make(arm.upper, arm.fore, arm.limits.elbow_min,
                                                  arm.limits.elbow_max);
  Prepared<T> p;
  if (!target.allFinite() || !std::isfinite(target.squaredNorm()) || !std::isfinite(swivel) ||
      std::abs(swivel) > T(kMaxSwivel)) {
    p.valid = false;
    p.status = Status::kInvalidInput;
    return p;
  }
  const T l0 = target.norm();
  const bool at_shoulder = !(l0 > c.tiny);
  const Vec3<T> dir = at_shoulder ? Vec3<T>(0, 0, 1) : Vec3<T>(target / l0);
  const T l = std::clamp(l0, c.reach_min, c.reach_max);
  p.pw = dir * l;
  p.on_axis = dir.x() * dir.x() + dir.y() * dir.y() <= c.axis_tol2;
  if (l0 > c.geo_max) p.status |= Status::kClampedOuter;
  if (l0 < c.geo_min) p.status |= Status::kClampedInner;
  if (at_shoulder) p.status |= Status::kTargetAtShoulder;
  if (p.on_axis) p.status |= Status::kTargetOnZAxis;
  if ((l0 > c.reach_max && c.limit_max) || (l0 < c.reach_min && c.limit_min))
    p.status |= Status::kElbowLimit;
  return p;
}

template <class T>
Solution<T> solve_prepared(const Arm<T>& arm, const Prepared<T>& p, T phi) {
  using MV = Multivector<T>;
  using cga::Point;
  const T d1 = arm.upper, d2 = arm.fore;
  const MV e0 = cga::e0<T>(), einf = cga::einf<T>();
  const MV pw = Point<T>::up(p.pw).mv();

  // The elbow lies on both spheres: S1 about the wrist (radius d2), S2 about the shoulder
  // (radius d1); their meet is the circle Ze = S1 ∧ S2.
  const auto s1 = cga::Sphere<T>::from_center_radius(p.pw, d2);             // Pw − ½d2²e∞
  const auto s2 = cga::Sphere<T>::from_center_radius(Vec3<T>::Zero(), d1);  // e0 − ½d1²e∞
  const auto ze = cga::Circle<T>::meet(s1, s2);

  // Swivel plane: the plane through shoulder, wrist and the reference point (ẑ, or x̂ when
  // Pw is on the z axis), π0* = e0 ∧ Pw ∧ R ∧ e∞, turned by φ about L_sw = (e0 ∧ Pw ∧ e∞)*
  // with the rotor cos(φ/2) + sin(φ/2) L̂ (eq 4).
  const Vec3<T> ref = p.on_axis ? Vec3<T>(1, 0, 0) : Vec3<T>(0, 0, 1);
  const MV pi0_outer = e0 ^ pw ^ Point<T>::up(ref).mv() ^ einf;
  MV pi0 = pi0_outer.dual();
  // Orient π0 so that its normal is Pw × ref (the dual's sign is a convention).
  if (pi0[cga::kE1] * (p.pw.y() * ref.z() - p.pw.z() * ref.y()) +
          pi0[cga::kE2] * (p.pw.z() * ref.x() - p.pw.x() * ref.z()) +
          pi0[cga::kE3] * (p.pw.x() * ref.y() - p.pw.y() * ref.x()) <
      T(0))
    pi0 = -pi0;
  pi0 = pi0 / std::sqrt(scalar_product(pi0, pi0));
  MV l_sw = (e0 ^ pw ^ einf).dual();
  l_sw = l_sw / std::sqrt(std::abs(scalar_product(l_sw, l_sw.reverse())));
  // L̂ as a rotor generator: it must turn right-handedly about P̂ (i.e. be the quaternion P̂);
  // the dual's sign decides that, so fix it against the Euclidean direction.
  const Quat<T> axis_q = quaternion(MV(T(0)) + l_sw);
  if (axis_q.vec().dot(p.pw) < T(0)) l_sw = -l_sw;
  const auto turn = [&](T angle) { return MV(std::cos(angle / 2)) + l_sw * std::sin(angle / 2); };
  const MV r_swivel = turn(phi);
  const MV pi_swivel = r_swivel * pi0 * r_swivel.reverse();

  // The elbow candidates: the point pair Pp = Ze ∧ π_swivel.
  const auto pp = cga::PointPair<T>{ze.mv ^ pi_swivel};
  const auto pair = pp.dissect();
  Vec3<T> elbow;
  // Explicit branch: the point on the positive side of π_side, the swivel plane turned by
  // −90° about L_sw (normal n̂ × P̂). At full extension the pair degenerates to one point.
  const MV r_side = turn(-std::numbers::pi_v<T> / 2);
  const MV pi_side = r_side * pi_swivel * r_side.reverse();
  if (pair) {
    const cga::Vector<T> x1 = Point<T>::up(pair->first);
    const T side1 = dot(x1, cga::Vector<T>::from(pi_side));
    elbow = side1 >= T(0) ? pair->first : pair->second;
  } else {
    // Tangent (or rounding-imaginary) pair: its single point is the circle's centre.
    elbow = ze.center();
  }
  const MV pe = Point<T>::up(elbow).mv();

  // Qe from the angle between the lines L_se (shoulder→elbow) and L_ew (elbow→wrist), eq 5,
  // and the half-angle formulas eqs 8–9.
  const MV l_se = (e0 ^ pe ^ einf).dual();
  const MV l_ew = (pe ^ pw ^ einf).dual();
  const T c4 = cos_angle(l_se, l_ew);
  const Quat<T> qe(std::sqrt((1 + c4) / 2), std::sqrt((1 - c4) / 2), 0, 0);

  // Q12: a half-turn about the middle line Lm of ẑ d1 and Pe: the meet of the middle plane
  // πm = Pze − Pe and the plane πe* = e0 ∧ Pze ∧ Pe ∧ e∞ (eq 15).
  const MV pze = Point<T>::up(Vec3<T>(0, 0, d1)).mv();
  Quat<T> q12;
  const T elbow_off_axis = std::hypot(elbow.x(), elbow.y());
  Status flags = p.status;
  if (elbow_off_axis <= T(64) * std::numeric_limits<T>::epsilon() * d1) {
    flags |= Status::kElbowOnZAxis;
    q12 = elbow.z() >= 0 ? Quat<T>(0, 0, 0, 1) : Quat<T>(0, 1, 0, 0);
  } else {
    const MV pi_m = pze - pe;
    const MV pi_e = (e0 ^ pze ^ pe ^ einf).dual();
    const MV l_m = pi_e ^ pi_m;
    q12 = quaternion(l_m);  // a bivector through the origin: its scalar part is 0
    q12.w() = 0;
    q12.normalize();
  }
  const MV r12 = rotor(q12);

  // Q3 about the local z axis: the angle between πyz2 = Q12 e1 Q̃12 and the hinge plane
  // −π_swivel (eq 17; sign from πxz2 = Q12 e2 Q̃12, see note 5), half-angles by eq 16.
  const MV pi_yz2 = r12 * cga::e1<T>() * r12.reverse();
  const MV pi_xz2 = r12 * cga::e2<T>() * r12.reverse();
  const MV hinge = -pi_swivel;
  const T c3 = cos_angle(pi_yz2, hinge);
  const T sign = scalar_product(pi_xz2, hinge) >= T(0) ? T(1) : T(-1);
  const Quat<T> q3(std::sqrt((1 + c3) / 2), 0, 0, sign * std::sqrt((1 - c3) / 2));

  // Qs = Q12 Q3 (eq 18) as the geometric product of the two rotors.
  Solution<T> s;
  s.qs = quaternion(r12 * rotor(q3));
  s.qe = qe;
  s.elbow = elbow;
  s.status = flags;
  return s;
}

}  // namespace

template <class T>
Solution<T> solve_readable(const Arm<T>& arm, const Vec3<T>& target, T swivel) {
  // As the closed form: identity pose, elbow at rest (at the origin for an invalid arm).
  Solution<T> invalid;
  invalid.status = Status::kInvalidInput;
  if (!arm.valid()) return invalid;
  invalid.elbow = Vec3<T>(0, 0, arm.upper);
  const Prepared<T> p = prepare(arm, target, swivel);
  if (!p.valid) return invalid;
  Status extra = Status::kOk;
  bool rotate_after = false;
  const T phi = detail::cone_swivel(
      arm, swivel, [&](T ph) { return solve_prepared(arm, p, ph).elbow; }, extra, rotate_after);
  Solution<T> s = solve_prepared(arm, p, phi);
  s.status |= extra;
  if (rotate_after) detail::cone_rotate(arm, s);
  return s;
}

template Solution<float> solve_readable(const Arm<float>&, const Vec3<float>&, float);
template Solution<double> solve_readable(const Arm<double>&, const Vec3<double>&, double);

}  // namespace conform::ik
