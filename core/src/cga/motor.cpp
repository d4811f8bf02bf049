#include "conform/cga/motor.hpp"

#include <cmath>

namespace conform::cga {
namespace {

// The motor algebra is the dual quaternions: real part q = (s, −e23, e13, −e12) and dual part
// d = ½ t q = (−e123∞, −e1∞, −e2∞, −e3∞). The map is linear and agrees with the geometric
// product on every T R, whose span is the whole motor space, so it is an algebra isomorphism.
template <class T>
DualQuaternion<T> to_dq(const Motor<T>& m) {
  return {Quat<T>(m.s, -m.e23, m.e13, -m.e12), Quat<T>(-m.e123inf, -m.e1inf, -m.e2inf, -m.e3inf)};
}

template <class T>
Motor<T> from_dq(const Quat<T>& r, const Quat<T>& d) {
  Motor<T> m;
  m.s = r.w(), m.e23 = -r.x(), m.e13 = r.y(), m.e12 = -r.z();
  m.e123inf = -d.w(), m.e1inf = -d.x(), m.e2inf = -d.y(), m.e3inf = -d.z();
  return m;
}

template <class T>
Quat<T> operator+(const Quat<T>& a, const Quat<T>& b) {
  return Quat<T>(a.coeffs() + b.coeffs());
}

template <class T>
T sinc(T x) {  // sin(x)/x without the 0/0
  return std::abs(x) < T(1e-4) ? T(1) - x * x / T(6) : std::sin(x) / x;
}

}  // namespace

template <class T>
Motor<T> Motor<T>::from_rotation_translation(const Quat<T>& q, const Vec3<T>& t) {
  // T R = R − ½ (t R) e∞, see the header for the expansion.
  const Vec3<T> v(q.x(), q.y(), q.z());
  const Vec3<T> dual = T(-0.5) * (q.w() * t - v.cross(t));
  Motor m;
  m.s = q.w(), m.e12 = -q.z(), m.e13 = q.y(), m.e23 = -q.x();
  m.e1inf = dual.x(), m.e2inf = dual.y(), m.e3inf = dual.z();
  m.e123inf = T(0.5) * v.dot(t);
  return m;
}

template <class T>
std::optional<Motor<T>> Motor<T>::from_matrix(const Eigen::Matrix<T, 4, 4>& m) {
  const Eigen::Matrix<T, 3, 3> r = m.template topLeftCorner<3, 3>();
  const T tol = T(1e-6);
  if (!m.allFinite() ||
      (r * r.transpose() - Eigen::Matrix<T, 3, 3>::Identity()).cwiseAbs().maxCoeff() > tol ||
      std::abs(r.determinant() - T(1)) > tol || std::abs(m(3, 0)) > tol ||
      std::abs(m(3, 1)) > tol || std::abs(m(3, 2)) > tol || std::abs(m(3, 3) - T(1)) > tol)
    return std::nullopt;
  return from_rotation_translation(Quat<T>(r).normalized(), m.template topRightCorner<3, 1>());
}

template <class T>
Vec3<T> Motor<T>::translation() const {
  // (0, t) = 2 d q̄ / |q|² with q = (w, v), d = (d0, dv) = (−e123∞, −e1∞, −e2∞, −e3∞):
  //   t = 2 (w dv − d0 v + v × dv) / |q|².
  const T w = s, vx = -e23, vy = e13, vz = -e12;
  const T d0 = -e123inf, dx = -e1inf, dy = -e2inf, dz = -e3inf;
  const T k = T(2) / (w * w + vx * vx + vy * vy + vz * vz);
  return Vec3<T>(k * (w * dx - d0 * vx + vy * dz - vz * dy),
                 k * (w * dy - d0 * vy + vz * dx - vx * dz),
                 k * (w * dz - d0 * vz + vx * dy - vy * dx));
}

template <class T>
Eigen::Matrix<T, 4, 4> Motor<T>::matrix() const {
  const RigidKernel<T> k = kernel();
  Eigen::Matrix<T, 4, 4> m = Eigen::Matrix<T, 4, 4>::Identity();
  m.template topLeftCorner<3, 3>() = k.a;
  m.template topRightCorner<3, 1>() = k.b;
  return m;
}

template <class T>
DualQuaternion<T> Motor<T>::dual_quaternion() const {
  return to_dq(*this);
}

template <class T>
Multivector<T> Motor<T>::mv() const {
  Multivector<T> m;
  m[kScalar] = s, m[kE12] = e12, m[kE13] = e13, m[kE23] = e23;
  m[kE1inf] = e1inf, m[kE2inf] = e2inf, m[kE3inf] = e3inf, m[kE123inf] = e123inf;
  return m;
}

template <class T>
Motor<T> Motor<T>::compose(const Motor& a, const Motor& b) {
  // (ra + ε da)(rb + ε db) = ra rb + ε (ra db + da rb), with the Hamilton product
  // (w1, v1)(w2, v2) = (w1 w2 − v1·v2, w1 v2 + w2 v1 + v1 × v2), written out on components.
  const T aw = a.s, ax = -a.e23, ay = a.e13, az = -a.e12;
  const T bw = b.s, bx = -b.e23, by = b.e13, bz = -b.e12;
  const T pw = -a.e123inf, px = -a.e1inf, py = -a.e2inf, pz = -a.e3inf;  // da
  const T qw = -b.e123inf, qx = -b.e1inf, qy = -b.e2inf, qz = -b.e3inf;  // db
  Motor m;
  m.s = aw * bw - ax * bx - ay * by - az * bz;
  m.e23 = -(aw * bx + bw * ax + ay * bz - az * by);
  m.e13 = aw * by + bw * ay + az * bx - ax * bz;
  m.e12 = -(aw * bz + bw * az + ax * by - ay * bx);
  const T dw = (aw * qw - ax * qx - ay * qy - az * qz) + (pw * bw - px * bx - py * by - pz * bz);
  const T dx = (aw * qx + qw * ax + ay * qz - az * qy) + (pw * bx + bw * px + py * bz - pz * by);
  const T dy = (aw * qy + qw * ay + az * qx - ax * qz) + (pw * by + bw * py + pz * bx - px * bz);
  const T dz = (aw * qz + qw * az + ax * qy - ay * qx) + (pw * bz + bw * pz + px * by - py * bx);
  m.e123inf = -dw, m.e1inf = -dx, m.e2inf = -dy, m.e3inf = -dz;
  return m;
}

template <class T>
std::optional<Motor<T>> Motor<T>::inverse() const {
  // (r + ε d)⁻¹ = r⁻¹ − ε r⁻¹ d r⁻¹.
  const DualQuaternion<T> x = to_dq(*this);
  const T n = x.real.squaredNorm();
  if (!(n > std::numeric_limits<T>::min()) || !std::isfinite(n)) return std::nullopt;
  const Quat<T> ri(x.real.conjugate().coeffs() / n);
  const Quat<T> di = ri * x.dual * ri;
  return from_dq<T>(ri, Quat<T>(-di.coeffs()));
}

template <class T>
Motor<T> Motor<T>::normalized() const {
  const Quat<T> q = rotation();
  return from_rotation_translation(Quat<T>(q.coeffs() / q.norm()), translation());
}

template <class T>
RigidKernel<T> Motor<T>::kernel() const {
  // M X M⁻¹ for X = up(x) is up(A x + b) with A the rotation matrix of q/|q| and b = t:
  //   A x = ((w² − |v|²) x + 2 (v·x) v + 2 w (v × x)) / |q|².
  const T w = s, x = -e23, y = e13, z = -e12;
  const T n = T(1) / (w * w + x * x + y * y + z * z);
  RigidKernel<T> k;
  k.a << (w * w + x * x - y * y - z * z) * n, T(2) * (x * y - w * z) * n,
      T(2) * (x * z + w * y) * n,  //
      T(2) * (x * y + w * z) * n, (w * w - x * x + y * y - z * z) * n,
      T(2) * (y * z - w * x) * n,  //
      T(2) * (x * z - w * y) * n, T(2) * (y * z + w * x) * n, (w * w - x * x - y * y + z * z) * n;
  k.b = translation();
  return k;
}

template <class T>
Multivector<T> MotorBivector<T>::mv() const {
  Multivector<T> m;
  m[kE12] = e12, m[kE13] = e13, m[kE23] = e23;
  m[kE1inf] = e1inf, m[kE2inf] = e2inf, m[kE3inf] = e3inf;
  return m;
}

// Screw form. For M = T_t R with R = cos(φ/2) − sin(φ/2) u I₃ (u I₃ = u1 e23 − u2 e13 + u3 e12),
// split t = t∥ + t⊥ along u. R about the axis through c = ½(t⊥ + cot(φ/2) u × t⊥) followed by
// t∥ is M, and T_c B T_c⁻¹ = B + (B·c) e∞ gives
//   log M = −½ [ φ u I₃ + (t∥ − (φ/2) u × t⊥ + (φ/2) cot(φ/2) t⊥) e∞ ].
// The inverse map (exp) solves the 2-D relation v⊥ = k t⊥ − (φ/2) u × t⊥, k = (φ/2)cot(φ/2):
//   t⊥ = cos(φ/2) sinc(φ/2) v⊥ + sin(φ/2) sinc(φ/2) u × v⊥.
template <class T>
MotorBivector<T> log(const Motor<T>& motor) {
  Motor<T> m = motor;
  if (m.s < 0) m = -m;  // same motion, shortest path
  const Quat<T> q = m.rotation();
  const T qn = q.norm();
  const Vec3<T> v = Vec3<T>(q.x(), q.y(), q.z()) / qn;
  const T w = q.w() / qn;
  const Vec3<T> t = m.translation();
  const T sin_half = v.norm();
  const T half = std::atan2(sin_half, w);  // φ/2 ∈ [0, π/2]
  MotorBivector<T> b;
  Vec3<T> ve;
  if (sin_half < T(1e-12) * std::max(T(1), std::abs(w))) {
    ve = t;  // pure translation (or identity)
  } else {
    const Vec3<T> u = v / sin_half;
    const Vec3<T> t_par = u * u.dot(t);
    const Vec3<T> t_perp = t - t_par;
    const T k = half * w / sin_half;  // (φ/2) cot(φ/2)
    ve = t_par - half * u.cross(t_perp) + k * t_perp;
    // rotation generator −(φ/2) u I₃
    b.e23 = -half * u.x(), b.e13 = half * u.y(), b.e12 = -half * u.z();
  }
  b.e1inf = T(-0.5) * ve.x(), b.e2inf = T(-0.5) * ve.y(), b.e3inf = T(-0.5) * ve.z();
  return b;
}

template <class T>
Motor<T> exp(const MotorBivector<T>& b) {
  // −(φ/2) u = (e23, −e13, e12) of B.
  const Vec3<T> rot(-b.e23, b.e13, -b.e12);  // (φ/2) u
  const T half = rot.norm();
  const Vec3<T> ve = T(-2) * Vec3<T>(b.e1inf, b.e2inf, b.e3inf);
  Vec3<T> t;
  Quat<T> q = Quat<T>::Identity();
  if (half < std::numeric_limits<T>::min()) {
    t = ve;
  } else {
    const Vec3<T> u = rot / half;
    const Vec3<T> v_par = u * u.dot(ve);
    const Vec3<T> v_perp = ve - v_par;
    const T sc = sinc(half);
    t = v_par + std::cos(half) * sc * v_perp + std::sin(half) * sc * u.cross(v_perp);
    const T sh = std::sin(half);
    q = Quat<T>(std::cos(half), sh * u.x(), sh * u.y(), sh * u.z());
  }
  return Motor<T>::from_rotation_translation(q, t);
}

template <class T>
Motor<T> blend_linear(const Motor<T>& m1, const Motor<T>& m2, T alpha) {
  const Motor<T> b2 = m1.dot_rotation(m2) < 0 ? -m2 : m2;
  const Motor<T> mix = m1 * (T(1) - alpha) + b2 * alpha;
  return mix.normalized();
}

template <class T>
Motor<T> blend_log(const Motor<T>& m1, const Motor<T>& m2, T alpha) {
  const auto inv = m1.inverse();
  if (!inv) return blend_linear(m1, m2, alpha);
  MotorBivector<T> d = log(*inv * m2);
  d.e12 *= alpha, d.e13 *= alpha, d.e23 *= alpha;
  d.e1inf *= alpha, d.e2inf *= alpha, d.e3inf *= alpha;
  return m1 * exp(d);
}

template class Motor<float>;
template class Motor<double>;
template struct MotorBivector<float>;
template struct MotorBivector<double>;
template MotorBivector<float> log(const Motor<float>&);
template MotorBivector<double> log(const Motor<double>&);
template Motor<float> exp(const MotorBivector<float>&);
template Motor<double> exp(const MotorBivector<double>&);
template Motor<float> blend_linear(const Motor<float>&, const Motor<float>&, float);
template Motor<double> blend_linear(const Motor<double>&, const Motor<double>&, double);
template Motor<float> blend_log(const Motor<float>&, const Motor<float>&, float);
template Motor<double> blend_log(const Motor<double>&, const Motor<double>&, double);

}  // namespace conform::cga
