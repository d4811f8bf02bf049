// Arm IK (conform/ik/arm_ik.hpp): forward kinematics is the judge. The closed form (scalar and
// batch, float and double), the readable algebra version, the explicit elbow branch, tracking
// smoothness, the edge cases and the joint limits; ArmIk and the (cos φ, sin φ) swivel;
// the previous Q12·Q3 kernel as a cross-check. Fixed seeds throughout.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include "conform/cga/rounds_flats.hpp"
#include "conform/ik/arm_ik.hpp"
#include "conform/ik/kernel.hpp"
#include "conform/ik/kernel_q12.hpp"

namespace ik = conform::ik;
namespace cga = conform::cga;
using Vec3d = Eigen::Vector3d;
using Quatd = Eigen::Quaterniond;

namespace {

constexpr double kPi = std::numbers::pi;

template <class T>
struct Targets {
  std::vector<T> x, y, z, phi;
};

// Uniform in the volume of the reachable shell, uniform directions and swivels.
template <class T>
Targets<T> random_targets(std::size_t n, double d1, double d2, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> g;
  const double rmin = std::abs(d1 - d2), rmax = d1 + d2;
  Targets<T> t;
  for (auto* v : {&t.x, &t.y, &t.z, &t.phi}) v->resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    Vec3d dir(g(rng), g(rng), g(rng));
    dir.normalize();
    const double r3 = rmin * rmin * rmin + u(rng) * (rmax * rmax * rmax - rmin * rmin * rmin);
    const Vec3d p = dir * std::cbrt(r3);
    t.x[i] = T(p.x()), t.y[i] = T(p.y()), t.z[i] = T(p.z());
    t.phi[i] = T((2 * u(rng) - 1) * kPi);
  }
  return t;
}

template <class T>
struct BatchResult {
  std::vector<T> qw, qx, qy, qz, ew, ex, px, py, pz;
  std::vector<std::uint8_t> st;
};

template <class T>
BatchResult<T> run_batch(const ik::Arm<T>& arm, const Targets<T>& t, int threads) {
  const std::size_t n = t.x.size();
  BatchResult<T> r;
  for (auto* v : {&r.qw, &r.qx, &r.qy, &r.qz, &r.ew, &r.ex, &r.px, &r.py, &r.pz}) v->resize(n);
  r.st.resize(n);
  ik::BatchSolveJob<T> job;
  job.arm = arm;
  job.x = t.x, job.y = t.y, job.z = t.z, job.swivel = t.phi;
  job.qs_w = r.qw, job.qs_x = r.qx, job.qs_y = r.qy, job.qs_z = r.qz;
  job.qe_w = r.ew, job.qe_x = r.ex;
  job.elbow_x = r.px, job.elbow_y = r.py, job.elbow_z = r.pz;
  job.status = r.st;
  job.threads = threads;
  EXPECT_TRUE(job.Run());
  return r;
}

// The swivel plane's unit normal n(φ) = R(P̂, φ)(P̂ × ẑ)/|P̂ × ẑ| (the documented convention),
// computed independently of the solvers with Eigen.
Vec3d swivel_normal(const Vec3d& p, double phi) {
  const Vec3d dir = p.normalized();
  Vec3d ref(0, 0, 1);
  if (dir.head<2>().squaredNorm() <= std::pow(64 * 2.2204460492503131e-16, 2)) ref = Vec3d(1, 0, 0);
  const Vec3d n0 = dir.cross(ref).normalized();
  return Eigen::AngleAxisd(phi, dir) * n0;
}

double rotation_angle(const Quatd& a, const Quatd& b) {
  const double d = std::min(1.0, std::abs(a.normalized().dot(b.normalized())));
  return 2 * std::acos(d);
}

// The same, accurate for small angles too (acos near 1 is not): θ = 4 asin(|a ∓ b|/2).
double rotation_distance(const Quatd& a, const Quatd& b) {
  const Eigen::Vector4d x = a.normalized().coeffs(), y = b.normalized().coeffs();
  const double d = std::min((x - y).norm(), (x + y).norm());
  return 4 * std::asin(std::min(1.0, d / 2));
}

bool finite(const ik::Solution<double>& s) {
  return s.qs.coeffs().allFinite() && s.qe.coeffs().allFinite() && s.elbow.allFinite();
}

}  // namespace

TEST(IkStatus, NamesAndFlags) {
  EXPECT_EQ(ik::to_string(ik::Status::kOk), "ok");
  const auto s = ik::Status::kClampedOuter | ik::Status::kTargetOnZAxis;
  EXPECT_EQ(ik::to_string(s), "clamped_outer|target_on_z_axis");
  EXPECT_TRUE(ik::has(s, ik::Status::kClampedOuter));
  EXPECT_FALSE(ik::has(s, ik::Status::kClampedInner));
  EXPECT_TRUE(ik::moved_target(s));
  EXPECT_FALSE(ik::moved_target(ik::Status::kTargetOnZAxis | ik::Status::kElbowOnZAxis));
}

// The first test of a job checks its validation.
TEST(IkBatch, ValidateRejectsBadJobs) {
  const auto t = random_targets<double>(16, 0.3, 0.25, 1);
  std::vector<double> out(16), shorter(15);
  std::vector<std::uint8_t> st(16);
  ik::BatchSolveJob<double> job;
  job.x = t.x, job.y = t.y, job.z = t.z, job.swivel = t.phi;
  job.qs_w = out, job.qs_x = out, job.qs_y = out, job.qs_z = out;
  job.qe_w = out, job.qe_x = out, job.elbow_x = out, job.elbow_y = out, job.elbow_z = out;
  job.status = st;
  EXPECT_TRUE(job.Validate());
  auto bad = job;
  bad.elbow_z = shorter;
  EXPECT_FALSE(bad.Validate());
  EXPECT_FALSE(bad.Run());
  bad = job;
  bad.arm.upper = 0;
  EXPECT_FALSE(bad.Validate());
  bad = job;
  bad.arm.fore = std::nan("");
  EXPECT_FALSE(bad.Validate());
  bad = job;
  bad.arm.limits.cone_half_angle = 1.0;  // the batch does not do shoulder cones
  EXPECT_FALSE(bad.Validate());
  bad = job;
  bad.arm.limits.elbow_min = 2.0, bad.arm.limits.elbow_max = 1.0;
  EXPECT_FALSE(bad.Validate());
  bad = job;
  bad.threads = -1;
  EXPECT_FALSE(bad.Validate());
}

TEST(IkKernel, SinCosAndRsqrtAreAccurate) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> wide(-1e4, 1e4), narrow(-4, 4);
  double worst_d = 0, worst_f = 0, worst_rs_d = 0, worst_rs_f = 0;
  int table_mismatch = 0;
  for (int i = 0; i < 200000; ++i) {
    const double x = (i % 2) ? wide(rng) : narrow(rng);
    const auto d = ik::detail::sincos(x);
    // The scalar path's quadrant table gives the very same numbers as the selects.
    const auto ds = ik::detail::sincos_scalar(x);
    if (ds.s != d.s || ds.c != d.c) ++table_mismatch;
    worst_d = std::max({worst_d, std::abs(d.s - std::sin(x)), std::abs(d.c - std::cos(x))});
    const float xf = static_cast<float>(x);
    const auto f = ik::detail::sincos(xf);
    const auto fs = ik::detail::sincos_scalar(xf);
    if (fs.s != f.s || fs.c != f.c) ++table_mismatch;
    // Reference in double at the float argument: only the float arithmetic is measured.
    worst_f = std::max(
        {worst_f, std::abs(f.s - std::sin(double(xf))), std::abs(f.c - std::cos(double(xf)))});
    const double r = std::exp(narrow(rng) * 5);  // 2e-9 … 5e8
    worst_rs_d = std::max(worst_rs_d, std::abs(ik::detail::rsqrt(r) * std::sqrt(r) - 1));
    const float rf = static_cast<float>(r);
    worst_rs_f =
        std::max(worst_rs_f, std::abs(double(ik::detail::rsqrt(rf)) * std::sqrt(double(rf)) - 1));
  }
  EXPECT_LT(worst_d, 4e-16);
  EXPECT_LT(worst_f, 4e-7);
  EXPECT_LT(worst_rs_d, 5e-16);
  EXPECT_LT(worst_rs_f, 3e-7);
  EXPECT_EQ(table_mismatch, 0);
  EXPECT_EQ(ik::detail::sqrt(0.0), 0.0);
  EXPECT_EQ(ik::detail::sqrt(0.0f), 0.0f);
}

namespace {

// Targets for the cross-checks below: random ones inside and outside the shell, and the edge
// cases (shoulder, z axis, near the axis, full extension and fold) with assorted swivels.
Targets<double> mixed_targets(std::size_t n, double d1, double d2, unsigned seed) {
  Targets<double> t = random_targets<double>(n, d1, d2, seed);
  std::mt19937_64 rng(seed + 1);
  std::uniform_real_distribution<double> u(0, 1);
  for (std::size_t i = 0; i < n; i += 3) {  // every third one anywhere in [0, 1.4 (d1 + d2)]
    const double len = std::sqrt(t.x[i] * t.x[i] + t.y[i] * t.y[i] + t.z[i] * t.z[i]);
    const double f = 1.4 * (d1 + d2) * u(rng) / len;
    t.x[i] *= f, t.y[i] *= f, t.z[i] *= f;
  }
  const double s = d1 + d2;
  const std::vector<Vec3d> edges = {
      Vec3d(0, 0, 0),           Vec3d(0, 0, 0.7 * s),     Vec3d(0, 0, -0.7 * s),
      Vec3d(0, 0, 2 * s),       Vec3d(1e-13, 0, 0.5 * s), Vec3d(0, 1e-9, -0.5 * s),
      Vec3d(0.3, 0.4, 0) * s,   Vec3d(0.6, 0, 0.8) * s,   Vec3d(0.01, 0.02, 0.0) * s,
      Vec3d(-0.2, 0.1, 0.9) * s};
  for (const Vec3d& e : edges)
    for (double phi : {0.0, 1.0, -2.5, kPi, -kPi / 2}) {
      t.x.push_back(e.x()), t.y.push_back(e.y()), t.z.push_back(e.z()), t.phi.push_back(phi);
    }
  return t;
}

}  // namespace

// ArmIk is solve(arm, …) with the constants kept: the same numbers, bit for bit, for every
// kind of arm and target. The (cos φ, sin φ) overload agrees with the angle (its pair comes
// from std::cos/std::sin, the angle's from the kernel's polynomial: rounding apart) and accepts
// any positive multiple of the pair.
TEST(IkSolver, MatchesFreeSolveAndCosSinOverload) {
  std::vector<ik::Arm<double>> arms(4);
  arms[1].limits.elbow_min = 0.3, arms[1].limits.elbow_max = 2.0;
  arms[2].upper = 0.2, arms[2].fore = 0.45;
  arms[3].limits.cone_axis = Vec3d(0, 0, 1), arms[3].limits.cone_half_angle = 1.2;
  for (std::size_t a = 0; a < arms.size(); ++a) {
    const ik::Arm<double>& arm = arms[a];
    const ik::ArmIk<double> solver(arm);
    ASSERT_TRUE(solver.valid());
    const double scale = arm.upper + arm.fore;
    const auto t = mixed_targets(3000, arm.upper, arm.fore, 600 + unsigned(a));
    double worst_q = 0, worst_elbow = 0;
    std::size_t status_differs = 0;
    for (std::size_t i = 0; i < t.x.size(); ++i) {
      const Vec3d p(t.x[i], t.y[i], t.z[i]);
      const auto free_sol = ik::solve(arm, p, t.phi[i]);
      const auto s = solver.solve(p, t.phi[i]);
      ASSERT_EQ(s.qs.coeffs(), free_sol.qs.coeffs()) << a << " " << i;
      ASSERT_EQ(s.qe.coeffs(), free_sol.qe.coeffs()) << a << " " << i;
      ASSERT_EQ(s.elbow, free_sol.elbow) << a << " " << i;
      ASSERT_EQ(s.status, free_sol.status) << a << " " << i;
      const double c = std::cos(t.phi[i]), sn = std::sin(t.phi[i]);
      for (const auto& cs : {solver.solve(p, ik::SwivelCosSin<double>{c, sn}),
                             ik::solve(arm, p, ik::SwivelCosSin<double>{2.5 * c, 2.5 * sn})}) {
        ASSERT_TRUE(finite(cs));
        worst_q =
            std::max({worst_q, rotation_distance(cs.qs, s.qs), rotation_distance(cs.qe, s.qe)});
        worst_elbow = std::max(worst_elbow, (cs.elbow - s.elbow).norm());
        // Flags decided at a threshold (elbow or target on the axis) may flip by rounding.
        if (cs.status != s.status) ++status_differs;
      }
    }
    EXPECT_LE(worst_q, 1e-12) << a;
    EXPECT_LE(worst_elbow, 1e-13 * scale) << a;
    EXPECT_LE(status_differs, 2u) << a;
  }
  // solve(arm, …) keeps the last arm's constants per thread: arms that alternate call by call,
  // or that differ in a single field, each get their own.
  std::vector<ik::Arm<double>> variants(5);
  variants[1].fore = 0.26;
  variants[2].limits.elbow_min = 0.4;
  variants[3].limits.elbow_max = 1.9;
  variants[4].limits.cone_half_angle = 0.9;
  variants.push_back(variants[4]);
  variants[5].limits.cone_axis = Vec3d(0, 1, 1);
  std::vector<ik::ArmIk<double>> solvers(variants.begin(), variants.end());
  const auto t = random_targets<double>(300, 0.3, 0.25, 91);
  for (std::size_t i = 0; i < t.x.size(); ++i) {
    const std::size_t k = (i * 7) % variants.size();
    const Vec3d p(t.x[i], t.y[i], t.z[i]);
    const auto a = ik::solve(variants[k], p, t.phi[i]);
    const auto b = solvers[k].solve(p, t.phi[i]);
    ASSERT_EQ(a.qs.coeffs(), b.qs.coeffs()) << k << " " << i;
    ASSERT_EQ(a.elbow, b.elbow) << k << " " << i;
    ASSERT_EQ(a.status, b.status) << k << " " << i;
  }

  // Invalid pairs and arms.
  const ik::ArmIk<double> solver;
  for (const auto& cs : {ik::SwivelCosSin<double>{0, 0}, ik::SwivelCosSin<double>{std::nan(""), 1},
                         ik::SwivelCosSin<double>{INFINITY, 0}}) {
    const auto s = solver.solve(Vec3d(0.1, 0.2, 0.3), cs);
    EXPECT_EQ(s.status, ik::Status::kInvalidInput);
    EXPECT_TRUE(finite(s));
    EXPECT_TRUE(s.qs.isApprox(Quatd::Identity()));
  }
  EXPECT_EQ(solver.solve(Vec3d(0.1, std::nan(""), 0.3), 0.2).status, ik::Status::kInvalidInput);
  EXPECT_EQ(solver.solve(Vec3d(0.1, 0.2, 0.3), 2e4).status, ik::Status::kInvalidInput);
  const ik::ArmIk<double> bad(ik::Arm<double>{0.3, -0.1, {}});
  EXPECT_FALSE(bad.valid());
  EXPECT_EQ(bad.solve(Vec3d(0.1, 0.2, 0.3), 0.2).status, ik::Status::kInvalidInput);
  EXPECT_EQ(bad.solve(Vec3d(0.1, 0.2, 0.3), ik::SwivelCosSin<double>{}).status,
            ik::Status::kInvalidInput);
  // The free solve after an invalid arm, and back.
  EXPECT_EQ(ik::solve(bad.arm(), Vec3d(0.1, 0.2, 0.3), 0.2).status, ik::Status::kInvalidInput);
  EXPECT_EQ(ik::solve(solver.arm(), Vec3d(0.1, 0.2, 0.3), 0.2).status, ik::Status::kOk);
}

// The three paths of the kernel: the scalar common-case one (rare cases' selects left out,
// 1/√x as √x·(1/x)) agrees with the scalar all-cases one to a few ulps, the vector one
// (Newton roots) to rounding; the previous formulation (Q12·Q3, kernel_q12.hpp) gives the same
// rotation and elbow. Qs has w ≥ 0.
template <class T>
void check_kernel_paths(double tol_q, double tol_len) {
  namespace d = ik::detail;
  for (const auto& [d1, d2] : {std::pair{0.3, 0.25}, std::pair{0.2, 0.45}, std::pair{0.4, 0.4}}) {
    for (const double flex_min : {0.0, 0.25}) {
      const auto c = d::KernelConstants<T>::make(d1, d2, flex_min, 2.6);
      const auto c12 = d::q12::KernelConstants<T>::make(d1, d2, flex_min, 2.6);
      const auto t = mixed_targets(4000, d1, d2, 77);
      double worst_q = 0, worst_len = 0, worst_vec = 0;
      std::size_t common = 0, status_differs = 0, negative_w = 0;
      for (std::size_t i = 0; i < t.x.size(); ++i) {
        const T x = T(t.x[i]), y = T(t.y[i]), z = T(t.z[i]), phi = T(t.phi[i]);
        const auto all = d::solve_kernel<T, d::Path::kScalar>(c, x, y, z, phi);
        const auto vec = d::solve_kernel<T, d::Path::kVector>(c, x, y, z, phi);
        const auto old = d::q12::solve_kernel<T, false>(c12, x, y, z, phi);
        if (all.qs_w < T(0)) ++negative_w;
        const T r2 = x * x + y * y + z * z;
        if (r2 > c.tiny2 && x * x + y * y > c.axis_tol2 * r2) {
          ++common;
          const auto sc = d::sincos_scalar(phi);
          const auto fast = d::solve_kernel_cs<T, d::Path::kCommon>(c, x, y, z, sc.c, sc.s, true);
          const double e = 8 * std::numeric_limits<T>::epsilon();
          for (const auto& [f, g] :
               {std::pair{fast.qs_w, all.qs_w}, std::pair{fast.qs_x, all.qs_x},
                std::pair{fast.qs_y, all.qs_y}, std::pair{fast.qs_z, all.qs_z},
                std::pair{fast.qe_w, all.qe_w}, std::pair{fast.qe_x, all.qe_x}})
            ASSERT_LE(std::abs(double(f) - double(g)), e) << i;
          for (const auto& [f, g] :
               {std::pair{fast.ex, all.ex}, std::pair{fast.ey, all.ey}, std::pair{fast.ez, all.ez}})
            ASSERT_LE(std::abs(double(f) - double(g)), e * (d1 + d2)) << i;
          ASSERT_EQ(fast.status, all.status) << i;
        }
        // Within rounding of the shell the flexion is √ε-sensitive to |Pw| (the formulations
        // round |Pw| differently): only the bitwise check above there.
        const double len = std::sqrt(double(x) * x + double(y) * y + double(z) * z);
        const double eps = std::numeric_limits<T>::epsilon();
        if (std::abs(len - (d1 + d2)) < 1e3 * eps * (d1 + d2) ||
            std::abs(len - std::abs(d1 - d2)) < 1e3 * eps * (d1 + d2))
          continue;
        const Quatd qa(all.qs_w, all.qs_x, all.qs_y, all.qs_z),
            qv(vec.qs_w, vec.qs_x, vec.qs_y, vec.qs_z), qo(old.qs_w, old.qs_x, old.qs_y, old.qs_z);
        worst_vec = std::max({worst_vec, (qa.coeffs() - qv.coeffs()).norm(),
                              std::abs(double(all.qe_x) - double(vec.qe_x))});
        worst_q = std::max({worst_q, rotation_distance(qa, qo),
                            std::abs(double(all.qe_w) - double(old.qe_w)),
                            std::abs(double(all.qe_x) - double(old.qe_x))});
        worst_len = std::max({worst_len, std::abs(double(all.ex) - double(old.ex)),
                              std::abs(double(all.ey) - double(old.ey)),
                              std::abs(double(all.ez) - double(old.ez))});
        // Threshold flags (elbow on the axis, clamps at the shell) may flip by rounding.
        if (all.status != old.status || all.status != vec.status) ++status_differs;
      }
      EXPECT_GT(common, t.x.size() / 2);
      EXPECT_EQ(negative_w, 0u);
      EXPECT_LE(worst_q, tol_q) << d1 << " " << d2 << " " << flex_min;
      EXPECT_LE(worst_vec, tol_q) << d1 << " " << d2 << " " << flex_min;
      EXPECT_LE(worst_len, tol_len * (d1 + d2)) << d1 << " " << d2 << " " << flex_min;
      EXPECT_LE(status_differs, 4u) << d1 << " " << d2 << " " << flex_min;
    }
  }
}

TEST(IkKernel, PathsAgreeAndMatchTheQ12Form) {
  check_kernel_paths<double>(1e-12, 1e-14);
  check_kernel_paths<float>(2e-5, 4e-6);
}

// The algebra helpers the readable solver relies on (not covered elsewhere).
TEST(IkAlgebra, CircleCentreAndPointPairDissect) {
  const Vec3d c1(0.1, -0.2, 0.3), c2(0.4, 0.1, -0.1);
  const double r1 = 0.5, r2 = 0.35;
  const auto s1 = cga::Sphere<double>::from_center_radius(c1, r1);
  const auto s2 = cga::Sphere<double>::from_center_radius(c2, r2);
  const auto z = cga::Circle<double>::meet(s1, s2);
  const Vec3d axis = (c2 - c1).normalized();
  const double dist = (c2 - c1).norm();
  const double a = (dist * dist + r1 * r1 - r2 * r2) / (2 * dist);
  EXPECT_LT((z.center() - (c1 + a * axis)).norm(), 1e-12);
  EXPECT_NEAR(z.radius_squared(), r1 * r1 - a * a, 1e-12);
  const auto plane = cga::Plane<double>::from_normal_point(axis.unitOrthogonal(), c1);
  const auto pair = cga::PointPair<double>::meet(z, plane).dissect();
  ASSERT_TRUE(pair.has_value());
  for (const Vec3d& p : {pair->first, pair->second}) {
    EXPECT_NEAR((p - c1).norm(), r1, 1e-12);
    EXPECT_NEAR((p - c2).norm(), r2, 1e-12);
    EXPECT_NEAR(plane.signed_distance(p), 0, 1e-12);
  }
  EXPECT_GT((pair->first - pair->second).norm(), 0.1);
}

// 1M random reachable targets through the batch (the fast path), double: the wrist lands on
// the target, the elbow is at distance d1 on the swivel plane and on the forward-kinematics
// elbow, and the scalar solver gives the same numbers.
TEST(IkFast, MillionRandomTargetsDouble) {
  const ik::Arm<double> arm;  // 0.30 / 0.25
  const double scale = arm.upper + arm.fore;
  const std::size_t n = 1'000'000;
  const auto t = random_targets<double>(n, arm.upper, arm.fore, 20261122);
  const auto r = run_batch(arm, t, 2);
  double worst_wrist = 0, worst_plane = 0, worst_elbow = 0, worst_unit = 0, worst_scalar = 0;
  std::size_t not_ok = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3d p(t.x[i], t.y[i], t.z[i]);
    const Quatd qs(r.qw[i], r.qx[i], r.qy[i], r.qz[i]), qe(r.ew[i], r.ex[i], 0, 0);
    const auto fk = ik::forward_kinematics(arm, qs, qe);
    const Vec3d elbow(r.px[i], r.py[i], r.pz[i]);
    worst_wrist = std::max(worst_wrist, (fk.wrist - p).norm());
    worst_elbow = std::max(worst_elbow, (fk.elbow - elbow).norm());
    worst_plane = std::max(worst_plane, std::abs(swivel_normal(p, t.phi[i]).dot(elbow)));
    worst_unit = std::max({worst_unit, std::abs(qs.norm() - 1), std::abs(qe.norm() - 1)});
    if (r.st[i] != 0) ++not_ok;
    if (i % 101 == 0) {  // the scalar entry point runs the same kernel
      const auto s = ik::solve(arm, p, t.phi[i]);
      worst_scalar = std::max({worst_scalar, (s.qs.coeffs() - qs.coeffs()).norm(),
                               (s.qe.coeffs() - qe.coeffs()).norm(), (s.elbow - elbow).norm()});
    }
  }
  RecordProperty("worst_wrist_error_over_reach", std::to_string(worst_wrist / scale));
  std::printf("double: worst wrist error %.3g (%.3g of d1+d2), elbow %.3g, plane %.3g\n",
              worst_wrist, worst_wrist / scale, worst_elbow, worst_plane);
  EXPECT_LE(worst_wrist, 1e-10 * scale);
  EXPECT_LE(worst_elbow, 1e-10 * scale);
  EXPECT_LE(worst_plane, 1e-12 * scale);
  EXPECT_LE(worst_unit, 1e-14);
  EXPECT_LE(worst_scalar, 1e-13);
  EXPECT_EQ(not_ok, 0u);
}

// The same in float; forward kinematics is evaluated in double from the float outputs, so that
// only the solver's rounding is measured.
TEST(IkFast, MillionRandomTargetsFloat) {
  const ik::Arm<float> arm;
  const double scale = double(arm.upper) + double(arm.fore);
  const ik::Arm<double> armd{double(arm.upper), double(arm.fore), {}};
  const std::size_t n = 1'000'000;
  const auto t = random_targets<float>(n, arm.upper, arm.fore, 777);
  const auto r = run_batch(arm, t, 2);
  double worst_wrist = 0, worst_plane = 0;
  std::size_t above_1e6 = 0, moved = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3d p(t.x[i], t.y[i], t.z[i]);
    const Quatd qs(r.qw[i], r.qx[i], r.qy[i], r.qz[i]), qe(r.ew[i], r.ex[i], 0, 0);
    // A float target can round to just outside the shell: then the judge is the clamped one.
    const double len = p.norm();
    const Vec3d goal = p * (std::clamp(len, std::abs(armd.upper - armd.fore), scale) / len);
    if (ik::moved_target(static_cast<ik::Status>(r.st[i]))) ++moved;
    const double err = (ik::forward_kinematics(armd, qs, qe).wrist - goal).norm();
    worst_wrist = std::max(worst_wrist, err);
    if (err > 1e-6 * scale) ++above_1e6;
    const Vec3d elbow(r.px[i], r.py[i], r.pz[i]);
    worst_plane = std::max(worst_plane, std::abs(swivel_normal(p, t.phi[i]).dot(elbow)));
  }
  std::printf(
      "float: worst wrist error %.3g (%.3g of d1+d2), %zu above 1e-6, plane %.3g, "
      "%zu moved by rounding\n",
      worst_wrist, worst_wrist / scale, above_1e6, worst_plane, moved);
  EXPECT_LE(worst_wrist, 1e-5 * scale);
  EXPECT_LE(worst_plane, 1e-6 * scale);
  EXPECT_LE(moved, 100u);
}

// The batch gives the same answers on 1 and 2 threads, in double and float, and with
// arbitrary lengths (d1 < d2, d1 = d2).
TEST(IkFast, BatchThreadsAndArmShapes) {
  for (const auto& [d1, d2] : {std::pair{0.3, 0.25}, std::pair{0.2, 0.45}, std::pair{0.4, 0.4}}) {
    const ik::Arm<double> arm{d1, d2, {}};
    const auto t = random_targets<double>(50000, d1, d2, 99);
    const auto a = run_batch(arm, t, 1), b = run_batch(arm, t, 2);
    EXPECT_EQ(a.qw, b.qw);
    EXPECT_EQ(a.pz, b.pz);
    double worst = 0;
    for (std::size_t i = 0; i < t.x.size(); ++i) {
      const Vec3d p(t.x[i], t.y[i], t.z[i]);
      const auto fk = ik::forward_kinematics(arm, Quatd(a.qw[i], a.qx[i], a.qy[i], a.qz[i]),
                                             Quatd(a.ew[i], a.ex[i], 0, 0));
      worst = std::max(worst, (fk.wrist - p).norm());
    }
    EXPECT_LE(worst, 1e-10 * (d1 + d2)) << d1 << " " << d2;
  }
}

// The readable version (the algebra) reaches the targets too and agrees with the closed form.
TEST(IkReadable, AgreesWithFastAndReachesTargets) {
  const ik::Arm<double> arm;
  const double scale = arm.upper + arm.fore;
  const auto t = random_targets<double>(20000, arm.upper, arm.fore, 4242);
  double worst_wrist = 0, worst_qs = 0, worst_qe = 0, worst_elbow = 0, worst_plane = 0;
  for (std::size_t i = 0; i < t.x.size(); ++i) {
    const Vec3d p(t.x[i], t.y[i], t.z[i]);
    const auto slow = ik::solve_readable(arm, p, t.phi[i]);
    const auto fast = ik::solve(arm, p, t.phi[i]);
    ASSERT_TRUE(finite(slow)) << i;
    EXPECT_EQ(slow.status, fast.status) << i;
    worst_wrist =
        std::max(worst_wrist, (ik::forward_kinematics(arm, slow.qs, slow.qe).wrist - p).norm());
    worst_qs = std::max(worst_qs, rotation_angle(slow.qs, fast.qs));
    worst_qe = std::max(worst_qe, (slow.qe.coeffs() - fast.qe.coeffs()).norm());
    worst_elbow = std::max(worst_elbow, (slow.elbow - fast.elbow).norm());
    worst_plane = std::max(worst_plane, std::abs(swivel_normal(p, t.phi[i]).dot(slow.elbow)));
  }
  std::printf(
      "readable: worst wrist %.3g, |Qs - Qs_fast| %.3g rad, Qe %.3g, elbow %.3g, plane %.3g\n",
      worst_wrist, worst_qs, worst_qe, worst_elbow, worst_plane);
  // The paper's half-angle formulas (eqs 8, 9, 16) lose about half the digits near a zero
  // angle (error ≈ √(kε) for a cosine k ulps off): looser than the closed form, still far
  // below anything visible.
  EXPECT_LE(worst_wrist, 1e-10 * scale);
  EXPECT_LE(worst_qs, 3e-7);
  EXPECT_LE(worst_qe, 3e-7);
  EXPECT_LE(worst_elbow, 1e-10 * scale);
  EXPECT_LE(worst_plane, 1e-12 * scale);
}

// In float the paper's half-angle formulas √((1 ± c)/2) (eqs 8, 9, 16), which the readable
// version keeps, lose half the digits near a zero angle (√ε ≈ 2.4e-4): the readable float solver
// is good to about 1e-4 of the reach, the closed form (scalar entry point) to 1e-6.
TEST(IkReadable, FloatPrecisionOfBothVersions) {
  const ik::Arm<float> arm;
  const ik::Arm<double> armd{double(arm.upper), double(arm.fore), {}};
  const double scale = armd.upper + armd.fore;
  const auto t = random_targets<float>(3000, arm.upper, arm.fore, 31);
  double worst_readable = 0, worst_fast = 0;
  for (std::size_t i = 0; i < t.x.size(); ++i) {
    const Eigen::Vector3f p(t.x[i], t.y[i], t.z[i]);
    const Vec3d goal = p.cast<double>();
    const auto r = ik::solve_readable(arm, p, t.phi[i]);
    const auto f = ik::solve(arm, p, t.phi[i]);
    worst_readable = std::max(
        worst_readable,
        (ik::forward_kinematics(armd, r.qs.cast<double>(), r.qe.cast<double>()).wrist - goal)
            .norm());
    worst_fast = std::max(
        worst_fast,
        (ik::forward_kinematics(armd, f.qs.cast<double>(), f.qe.cast<double>()).wrist - goal)
            .norm());
  }
  std::printf("float: readable worst wrist %.3g of reach, closed form %.3g\n",
              worst_readable / scale, worst_fast / scale);
  EXPECT_LE(worst_readable, 1e-3 * scale);
  EXPECT_LE(worst_fast, 2e-6 * scale);
}

// The elbow branch is explicit: the elbow is on the side n̂ × P̂ of the shoulder–wrist line,
// and at φ = 0 it is displaced towards +z. Both solvers.
TEST(IkBranch, ElbowSideIsConsistent) {
  const ik::Arm<double> arm;
  const auto t = random_targets<double>(2000, arm.upper, arm.fore, 5);
  for (std::size_t i = 0; i < t.x.size(); ++i) {
    const Vec3d p(t.x[i], t.y[i], t.z[i]);
    const Vec3d u = swivel_normal(p, t.phi[i]).cross(p.normalized());
    const Vec3d centre = p.normalized() * p.normalized().dot(ik::solve(arm, p, t.phi[i]).elbow);
    for (const auto& s : {ik::solve(arm, p, t.phi[i]), ik::solve_readable(arm, p, t.phi[i])}) {
      EXPECT_GE((s.elbow - centre).dot(u), 0) << i;
    }
    const auto zero = ik::solve(arm, p, 0.0);
    const Vec3d off = zero.elbow - p.normalized() * p.normalized().dot(zero.elbow);
    EXPECT_GE(off.z(), -1e-12) << i;
  }
}

// A figure-eight traced by the wrist with a smoothly varying swivel: consecutive solves never
// make a joint jump larger than a small bound (no branch or sign flips of the rotation).
TEST(IkTracking, FigureEightIsSmooth) {
  const ik::Arm<double> arm;
  const int n = 10000;
  const Vec3d centre(0.15, 0.25, 0.2);
  double worst_qs = 0, worst_qe = 0, worst_elbow = 0, worst_wrist = 0;
  ik::Solution<double> prev;
  for (int i = 0; i <= n; ++i) {
    const double s = 2 * kPi * i / n;
    const Vec3d p = centre + Vec3d(0.15 * std::sin(s), 0.1 * std::sin(2 * s), 0.05 * std::cos(s));
    const double phi = 0.4 + 0.5 * std::sin(s);
    const auto sol = ik::solve(arm, p, phi);
    ASSERT_EQ(sol.status, ik::Status::kOk) << i;
    worst_wrist =
        std::max(worst_wrist, (ik::forward_kinematics(arm, sol.qs, sol.qe).wrist - p).norm());
    if (i > 0) {
      worst_qs = std::max(worst_qs, rotation_angle(sol.qs, prev.qs));
      worst_qe = std::max(worst_qe, rotation_angle(sol.qe, prev.qe));
      worst_elbow = std::max(worst_elbow, (sol.elbow - prev.elbow).norm());
    }
    prev = sol;
  }
  // The path moves ≤ 0.35 m·2π/n ≈ 2.2e-4 m per step; the joints turn at a few rad per unit
  // path length here, so 5e-3 rad per step is a generous bound that a branch flip (≈ 1 rad)
  // or a 2π jump would break by orders of magnitude.
  std::printf("tracking: worst step Qs %.3g rad, Qe %.3g rad, elbow %.3g m\n", worst_qs, worst_qe,
              worst_elbow);
  EXPECT_LE(worst_qs, 5e-3);
  EXPECT_LE(worst_qe, 5e-3);
  EXPECT_LE(worst_elbow, 1e-3);
  EXPECT_LE(worst_wrist, 1e-10);
}

// Edge cases: never NaN, a status that says what happened, the wrist on the clamped target.
TEST(IkEdges, UnreachableShoulderAndAxes) {
  const ik::Arm<double> arm;  // 0.30 / 0.25: shell [0.05, 0.55]
  struct Case {
    Vec3d target;
    ik::Status expect;
    Vec3d reached;
  };
  const double s = std::sqrt(1.0 / 3);
  const std::vector<Case> cases = {
      {Vec3d(1, 1, 1), ik::Status::kClampedOuter, Vec3d(s, s, s) * 0.55},
      {Vec3d(0.55 * s, 0.55 * s, 0.55 * s), ik::Status::kOk, Vec3d(s, s, s) * 0.55},
      {Vec3d(0.01, 0, 0), ik::Status::kClampedInner, Vec3d(0.05, 0, 0)},
      // Clamped onto the inner shell: the elbow folds back onto the z axis.
      {Vec3d(0, 0, 0),
       ik::Status::kClampedInner | ik::Status::kTargetAtShoulder | ik::Status::kTargetOnZAxis |
           ik::Status::kElbowOnZAxis,
       Vec3d(0, 0, 0.05)},
      {Vec3d(0, 0, 0.4), ik::Status::kTargetOnZAxis, Vec3d(0, 0, 0.4)},
      {Vec3d(0, 0, -0.4), ik::Status::kTargetOnZAxis, Vec3d(0, 0, -0.4)},
      {Vec3d(0, 0, 0.55), ik::Status::kTargetOnZAxis | ik::Status::kElbowOnZAxis,
       Vec3d(0, 0, 0.55)},
      {Vec3d(0, 0, -0.55), ik::Status::kTargetOnZAxis | ik::Status::kElbowOnZAxis,
       Vec3d(0, 0, -0.55)},
      {Vec3d(0, 0, 3),
       ik::Status::kClampedOuter | ik::Status::kTargetOnZAxis | ik::Status::kElbowOnZAxis,
       Vec3d(0, 0, 0.55)},
      // Exactly on the inner shell (0.30 − 0.25 in binary, not the literal 0.05, which is a
      // hair off the shell: the fold is √ε-sensitive and the elbow would leave the axis).
      {Vec3d(0, 0, 0.30 - 0.25), ik::Status::kTargetOnZAxis | ik::Status::kElbowOnZAxis,
       Vec3d(0, 0, 0.30 - 0.25)},
      {Vec3d(1e-20, 0, 0.3), ik::Status::kTargetOnZAxis, Vec3d(1e-20, 0, 0.3)},
  };
  for (double phi : {0.0, 1.0, -2.5, kPi}) {
    for (const auto& c : cases) {
      // At full extension and full fold the angles are √ε-sensitive to |Pw|: the closed form
      // stays consistent (wrist within rounding), the readable version's half-angle formulas
      // (eqs 8/9) lose about half the digits there.
      // At the exact fold an ulp in |Pw| moves the elbow √ε·d off the axis, so whether the
      // elbow-on-axis flag (64 ε) is set there, and whether |Pw| rounds an ulp inside the
      // shell (clamped_inner), depends on rounding: those two bits are not compared.
      const bool fold = std::abs(c.target.norm() - (arm.upper - arm.fore)) < 1e-15;
      for (const auto& [sol, tolerance] :
           {std::pair{ik::solve(arm, c.target, phi), 1e-12},
            std::pair{ik::solve_readable(arm, c.target, phi), 1e-7}}) {
        ASSERT_TRUE(finite(sol)) << c.target.transpose() << " φ " << phi;
        const auto mask = static_cast<std::uint8_t>(
            fold ? ~std::uint8_t(ik::Status::kElbowOnZAxis | ik::Status::kClampedInner) : 0xFF);
        if (fold) {
          EXPECT_LT(sol.elbow.head<2>().norm(), 1e-6);
        }
        EXPECT_EQ(std::uint8_t(sol.status) & mask, std::uint8_t(c.expect) & mask)
            << c.target.transpose() << " φ " << phi << " " << ik::to_string(sol.status);
        const auto fk = ik::forward_kinematics(arm, sol.qs, sol.qe);
        EXPECT_LT((fk.wrist - c.reached).norm(), tolerance) << c.target.transpose() << " φ " << phi;
        EXPECT_LT((fk.elbow - sol.elbow).norm(), tolerance) << c.target.transpose() << " φ " << phi;
      }
    }
  }
  // Equal segments: the shoulder itself is reachable (fully folded elbow).
  const ik::Arm<double> equal{0.3, 0.3, {}};
  const auto folded = ik::solve(equal, Vec3d(0, 0, 0), 0.3);
  ASSERT_TRUE(finite(folded));
  EXPECT_TRUE(ik::has(folded.status, ik::Status::kTargetAtShoulder));
  EXPECT_FALSE(ik::has(folded.status, ik::Status::kClampedInner));
  EXPECT_LT(ik::forward_kinematics(equal, folded.qs, folded.qe).wrist.norm(), 1e-12);
}

// The elbow exactly on the z axis (+d1 ẑ and −d1 ẑ): the printed eq 15 is 0/0 at +z; ours is
// defined. The swivel that puts the elbow there is found from the elbow circle itself.
TEST(IkEdges, ElbowOnZAxis) {
  const ik::Arm<double> arm;
  for (double zsign : {1.0, -1.0}) {
    const double flex = 1.1;
    // Shoulder rotation identity (or a half-turn about x): elbow at ±d1 ẑ.
    const Quatd qs = zsign > 0 ? Quatd::Identity() : Quatd(0, 1, 0, 0);
    const Quatd qe(std::cos(flex / 2), std::sin(flex / 2), 0, 0);
    const Vec3d p = ik::forward_kinematics(arm, qs, qe).wrist;
    // elbow(φ) = C + A cos φ + B sin φ: pick φ maximizing ±z.
    const double e0 = ik::solve(arm, p, 0.0).elbow.z(), e90 = ik::solve(arm, p, kPi / 2).elbow.z(),
                 e180 = ik::solve(arm, p, kPi).elbow.z();
    const double a = (e0 - e180) / 2, b = e90 - (e0 + e180) / 2;
    const double phi = std::atan2(zsign * b, zsign * a);
    for (const auto& sol : {ik::solve(arm, p, phi), ik::solve_readable(arm, p, phi)}) {
      ASSERT_TRUE(finite(sol));
      EXPECT_LT((sol.elbow - Vec3d(0, 0, zsign * arm.upper)).norm(), 1e-12);
      const auto fk = ik::forward_kinematics(arm, sol.qs, sol.qe);
      EXPECT_LT((fk.wrist - p).norm(), 1e-10) << zsign;
      EXPECT_NEAR(2 * std::atan2(sol.qe.x(), sol.qe.w()), flex, 1e-9);
    }
  }
}

TEST(IkEdges, InvalidInputs) {
  const ik::Arm<double> arm;
  const double nan = std::nan(""), inf = INFINITY;
  for (const auto& [p, phi] :
       {std::pair{Vec3d(nan, 0, 0), 0.0}, std::pair{Vec3d(0.1, inf, 0), 0.0},
        std::pair{Vec3d(0.1, 0.1, 0.1), nan}, std::pair{Vec3d(0.1, 0.1, 0.1), 2e4}}) {
    for (const auto& s : {ik::solve(arm, p, phi), ik::solve_readable(arm, p, phi)}) {
      EXPECT_EQ(s.status, ik::Status::kInvalidInput);
      EXPECT_TRUE(finite(s));
      EXPECT_TRUE(s.qs.isApprox(Quatd::Identity()));
    }
  }
  for (const ik::Arm<double>& bad : {ik::Arm<double>{-1, 0.2, {}}, ik::Arm<double>{nan, 0.2, {}}}) {
    for (const auto& s :
         {ik::solve(bad, Vec3d(0.1, 0, 0), 0.0), ik::solve_readable(bad, Vec3d(0.1, 0, 0), 0.0)}) {
      EXPECT_EQ(s.status, ik::Status::kInvalidInput);
      EXPECT_TRUE(finite(s));
    }
  }
  // Full extension is not singular here (the paper's eq 17 is 0/0 there).
  const auto straight = ik::solve(arm, Vec3d(Vec3d(0.3, 0.4, 0.0).normalized() * 0.55), 0.7);
  EXPECT_EQ(straight.status, ik::Status::kOk);
  EXPECT_EQ(straight.qe.x(), 0.0);
}

TEST(IkLimits, ElbowRangeClampsTheReach) {
  ik::Arm<double> arm;
  arm.limits.elbow_min = 0.2;
  arm.limits.elbow_max = 1.5;
  const auto reach = [&](double flex) {
    return std::sqrt(arm.upper * arm.upper + arm.fore * arm.fore +
                     2 * arm.upper * arm.fore * std::cos(flex));
  };
  const Vec3d dir = Vec3d(0.2, -0.5, 0.3).normalized();
  struct Case {
    double distance, flex;
    ik::Status status;
  };
  for (const auto& c :
       {Case{0.1, 1.5, ik::Status::kElbowLimit}, Case{0.549, 0.2, ik::Status::kElbowLimit},
        Case{0.7, 0.2, ik::Status::kElbowLimit | ik::Status::kClampedOuter},
        Case{reach(1.0), 1.0, ik::Status::kOk}}) {
    const auto s = ik::solve(arm, Vec3d(dir * c.distance), 0.3);
    EXPECT_EQ(s.status, c.status) << c.distance;
    EXPECT_NEAR(2 * std::atan2(s.qe.x(), s.qe.w()), c.flex, 1e-9) << c.distance;
    const Vec3d wrist = ik::forward_kinematics(arm, s.qs, s.qe).wrist;
    EXPECT_LT((wrist - dir * reach(c.flex)).norm(), 1e-10) << c.distance;
    const auto r = ik::solve_readable(arm, Vec3d(dir * c.distance), 0.3);
    EXPECT_EQ(r.status, c.status);
    EXPECT_LT((r.elbow - s.elbow).norm(), 1e-10);
  }
  // The batch honours the elbow range too.
  Targets<double> t;
  t.x = {dir.x() * 0.1}, t.y = {dir.y() * 0.1}, t.z = {dir.z() * 0.1}, t.phi = {0.3};
  const auto b = run_batch(arm, t, 1);
  EXPECT_EQ(b.st[0], static_cast<std::uint8_t>(ik::Status::kElbowLimit));
  EXPECT_NEAR(2 * std::atan2(b.ex[0], b.ew[0]), 1.5, 1e-9);
}

TEST(IkLimits, ShoulderConeMovesTheSwivelOrTheArm) {
  ik::Arm<double> arm;
  arm.limits.cone_axis = Vec3d(0, 0, 1);
  arm.limits.cone_half_angle = 1.0;
  const auto upper_angle = [&](const ik::Solution<double>& s) {
    return std::acos(std::clamp(s.elbow.normalized().z(), -1.0, 1.0));
  };
  // Feasible: the wrist stays on the target, the swivel moves the elbow into the cone.
  const Vec3d p(0.35, 0.1, 0.2);
  const auto free_sol = ik::solve(ik::Arm<double>{}, p, 2.5);
  ASSERT_GT(upper_angle(free_sol), 1.0 + 1e-3);  // the requested swivel violates the cone
  for (const auto& s : {ik::solve(arm, p, 2.5), ik::solve_readable(arm, p, 2.5)}) {
    EXPECT_EQ(s.status, ik::Status::kShoulderLimit);
    EXPECT_LE(upper_angle(s), 1.0 + 1e-9);
    EXPECT_LT((ik::forward_kinematics(arm, s.qs, s.qe).wrist - p).norm(), 1e-10);
  }
  // Inside the cone already: nothing changes.
  const auto ok = ik::solve(arm, p, 0.0);
  EXPECT_EQ(ok.status, ik::Status::kOk);
  EXPECT_LT((ok.qs.coeffs() - ik::solve(ik::Arm<double>{}, p, 0.0).qs.coeffs()).norm(), 1e-15);
  // Infeasible (target behind the cone): the arm is turned onto the cone boundary.
  const Vec3d behind(0.0, 0.1, -0.4);
  const auto s = ik::solve(arm, behind, 0.0);
  EXPECT_EQ(s.status, ik::Status::kShoulderLimit);
  EXPECT_NEAR(upper_angle(s), 1.0, 1e-9);
  EXPECT_LT((ik::forward_kinematics(arm, s.qs, s.qe).elbow - s.elbow).norm(), 1e-12);
  EXPECT_TRUE(finite(s));
}
