// Motors, dilators and versors: derived kernels against the general geometric product and
// against Eigen's matrices; exp/log, blends, conversions.
#include <gtest/gtest.h>

#include <numbers>
#include "cga_random.hpp"
#include "conform/cga.hpp"

namespace cga = conform::cga;
using MV = cga::Multivector<double>;
using V3 = cga::Vec3<double>;
using Q = cga::Quat<double>;
using Motor = cga::Motor<double>;

namespace {

cga::testing::Random random(7);
double uniform(double a = -1, double b = 1) {
  return random.uniform(a, b);
}
V3 random_vec(double scale = 1) {
  return random.vec(scale);
}
Q random_quat() {
  return random.quat();
}
Motor random_motor() {
  return random.motor();
}

void expect_vec_near(const V3& a, const V3& b, double tol, const std::string& what) {
  ASSERT_LE((a - b).norm(), tol) << what << ": " << a.transpose() << " vs " << b.transpose();
}
void expect_motor_near(const Motor& a, const Motor& b, double tol, const std::string& what) {
  const MV d = a.mv() - b.mv();
  ASSERT_LE(d.max_abs(), tol) << what << "\n a = " << a.mv() << "\n b = " << b.mv();
}

// V X V⁻¹ with the general product, down-projected.
V3 general_sandwich(const MV& v, const V3& x) {
  const MV r = v * cga::Point<double>::up(x).mv() * v.versor_inverse().value();
  return cga::down(r).value();
}

}  // namespace

TEST(Motor, ComponentsMatchTheGeneralProductOfTranslatorAndRotor) {
  for (int n = 0; n < 1000; ++n) {
    const Q q = random_quat();
    const V3 t = random_vec(3);
    MV rotor(q.w());
    rotor[cga::kE23] = -q.x(), rotor[cga::kE13] = q.y(), rotor[cga::kE12] = -q.z();
    MV translator(1.0);
    translator[cga::kE1inf] = -0.5 * t.x(), translator[cga::kE2inf] = -0.5 * t.y();
    translator[cga::kE3inf] = -0.5 * t.z();
    const MV expected = translator * rotor;
    const MV got = Motor::from_rotation_translation(q, t).mv();
    for (int i = 0; i < cga::kBladeCount; ++i) ASSERT_NEAR(got[i], expected[i], 1e-14);
  }
}

TEST(Motor, RotorRotatesRightHanded) {
  const Motor m = Motor::from_axis_angle(V3(0, 0, 1), std::numbers::pi / 2);
  expect_vec_near(m.apply(V3(1, 0, 0)), V3(0, 1, 0), 1e-15, "e1 → e2 about +z");
  expect_vec_near(general_sandwich(m.mv(), V3(1, 0, 0)), V3(0, 1, 0), 1e-15, "general");
}

TEST(Motor, KernelEqualsGeneralSandwichAndEigenMatrix) {
  for (int n = 0; n < 2000; ++n) {
    const Q q = random_quat();
    const V3 t = random_vec(5);
    const Motor m = Motor::from_rotation_translation(q, t);
    const Motor scaled = m * 3.0;  // non-unit motors act the same
    const V3 x = random_vec(10);
    Eigen::Isometry3d iso = Eigen::Translation3d(t) * q;
    const V3 expected = iso * x;
    expect_vec_near(m.apply(x), expected, 1e-12, "kernel vs Eigen isometry");
    expect_vec_near(scaled.apply(x), expected, 1e-12, "scaled motor kernel");
    expect_vec_near(general_sandwich(m.mv(), x), expected, 1e-11, "general product");
    const Eigen::Vector4d h = m.matrix() * x.homogeneous();
    expect_vec_near(h.head<3>(), expected, 1e-12, "4×4 matrix");
  }
}

TEST(Motor, CompositionEqualsGeneralProduct) {
  for (int n = 0; n < 2000; ++n) {
    const Motor a = random_motor() * uniform(0.5, 2), b = random_motor() * uniform(0.5, 2);
    const MV expected = a.mv() * b.mv();
    const Motor got = a * b;
    for (int i = 0; i < cga::kBladeCount; ++i) ASSERT_NEAR(got.mv()[i], expected[i], 1e-12);
    // b applies first.
    const V3 x = random_vec(3);
    expect_vec_near(got.apply(x), a.apply(b.apply(x)), 1e-11, "composition order");
  }
}

TEST(Motor, InverseEqualsGeneralInverse) {
  for (int n = 0; n < 500; ++n) {
    const Motor m = random_motor() * uniform(0.5, 2);
    const MV general = m.mv().versor_inverse().value();
    const Motor inv = m.inverse().value();
    for (int i = 0; i < cga::kBladeCount; ++i) ASSERT_NEAR(inv.mv()[i], general[i], 1e-12);
    expect_motor_near(m * inv, Motor::identity(), 1e-12, "M M⁻¹");
  }
  Motor zero = Motor::identity() * 0.0;
  EXPECT_FALSE(zero.inverse().has_value());
}

TEST(Motor, ConversionsRoundTrip) {
  for (int n = 0; n < 1000; ++n) {
    const Q q = random_quat();
    const V3 t = random_vec(5);
    const Motor m = Motor::from_rotation_translation(q, t);
    expect_vec_near(m.translation(), t, 1e-13, "translation");
    EXPECT_NEAR(std::abs(m.rotation().dot(q)), 1.0, 1e-13);
    const auto from_matrix = Motor::from_matrix(m.matrix());
    ASSERT_TRUE(from_matrix.has_value());
    const V3 x = random_vec(2);
    expect_vec_near(from_matrix->apply(x), m.apply(x), 1e-12, "4×4 round trip");
    const Motor from_dq = Motor::from_dual_quaternion(m.dual_quaternion());
    expect_motor_near(from_dq, m, 1e-13, "dual quaternion round trip");
    // Dual quaternion convention: dual = ½ t q.
    const Q half_tq = Q(0, 0.5 * t.x(), 0.5 * t.y(), 0.5 * t.z()) * q;
    EXPECT_LT((m.dual_quaternion().dual.coeffs() - half_tq.coeffs()).norm(), 1e-13);
  }
  Eigen::Matrix4d bad = Eigen::Matrix4d::Identity();
  bad(0, 0) = 2;  // a scale is not a rigid motion
  EXPECT_FALSE(Motor::from_matrix(bad).has_value());
  bad = Eigen::Matrix4d::Identity();
  bad(0, 0) = -1;  // a reflection is not a rotation
  EXPECT_FALSE(Motor::from_matrix(bad).has_value());
}

TEST(Motor, ExpLogRoundTrip) {
  for (int n = 0; n < 2000; ++n) {
    Motor m = random_motor();
    if (m.s < 0) m = -m;  // log returns the shortest-path generator
    const Motor back = cga::exp(cga::log(m));
    expect_motor_near(back, m, 1e-11, "exp(log M)");
  }
}

TEST(Motor, ExpMatchesSeriesOfTheGeneralAlgebra) {
  for (int n = 0; n < 300; ++n) {
    cga::MotorBivector<double> b{uniform(),      uniform(),      uniform(),
                                 uniform(-3, 3), uniform(-3, 3), uniform(-3, 3)};
    const MV series = cga::exp(b.mv());
    const MV closed = cga::exp(b).mv();
    for (int i = 0; i < cga::kBladeCount; ++i) ASSERT_NEAR(closed[i], series[i], 1e-11);
  }
}

TEST(Motor, ExpLogEdgeCasesAreExact) {
  // Identity.
  const auto li = cga::log(Motor::identity());
  EXPECT_EQ(li.mv().max_abs(), 0.0);
  expect_motor_near(cga::exp(li), Motor::identity(), 0.0, "identity");
  // Pure translation: log = −½ t e∞.
  const V3 t(1, -2, 3);
  const auto lt = cga::log(Motor::from_translation(t));
  EXPECT_DOUBLE_EQ(lt.e1inf, -0.5);
  EXPECT_DOUBLE_EQ(lt.e3inf, -1.5);
  EXPECT_EQ(lt.e12, 0.0);
  expect_motor_near(cga::exp(lt), Motor::from_translation(t), 1e-15, "translation");
  // Half turns about each axis, with and without translation.
  for (const V3& axis : {V3(1, 0, 0), V3(0, 1, 0), V3(0, 0, 1), V3(1, 1, 1).normalized()}) {
    const Motor half = Motor::from_rotation_translation(
        Q(Eigen::AngleAxisd(std::numbers::pi, axis)), V3(0.3, -0.2, 0.7));
    const auto l = cga::log(half);
    ASSERT_TRUE(l.mv().is_finite());
    const Motor back = cga::exp(l);
    const V3 x(0.1, 0.2, 0.3);
    expect_vec_near(back.apply(x), half.apply(x), 1e-12, "half turn");
  }
}

TEST(Motor, BlendEndpointsAreExact) {
  for (int n = 0; n < 500; ++n) {
    const Motor a = random_motor(), b = random_motor();
    const V3 x = random_vec(2);
    expect_vec_near(cga::blend_linear(a, b, 0.0).apply(x), a.apply(x), 1e-12, "linear α=0");
    expect_vec_near(cga::blend_linear(a, b, 1.0).apply(x), b.apply(x), 1e-12, "linear α=1");
    expect_vec_near(cga::blend_log(a, b, 0.0).apply(x), a.apply(x), 1e-12, "log α=0");
    expect_vec_near(cga::blend_log(a, b, 1.0).apply(x), b.apply(x), 1e-11, "log α=1");
  }
}

TEST(Motor, LogBlendOfRotationsAboutOneAxisInterpolatesTheAngle) {
  for (int n = 0; n < 500; ++n) {
    const V3 axis = random_vec().normalized();
    const double a1 = uniform(-1.5, 1.5), a2 = uniform(-1.5, 1.5), alpha = uniform(0, 1);
    const Motor m1 = Motor::from_axis_angle(axis, a1), m2 = Motor::from_axis_angle(axis, a2);
    const Motor expected = Motor::from_axis_angle(axis, (1 - alpha) * a1 + alpha * a2);
    const V3 x = random_vec(2);
    expect_vec_near(cga::blend_log(m1, m2, alpha).apply(x), expected.apply(x), 1e-12, "log blend");
    // and equals Eigen's slerp
    const Q slerp = m1.rotation().slerp(alpha, m2.rotation());
    expect_vec_near(cga::blend_log(m1, m2, alpha).apply(x), slerp * x, 1e-12, "slerp");
  }
}

TEST(Motor, LogBlendIsSymmetric) {
  for (int n = 0; n < 300; ++n) {
    const Motor a = random_motor(), b = random_motor();
    const double alpha = uniform(0, 1);
    const V3 x = random_vec(2);
    expect_vec_near(cga::blend_log(a, b, alpha).apply(x), cga::blend_log(b, a, 1 - alpha).apply(x),
                    1e-10, "symmetry");
  }
}

TEST(Dilator, ScalesAboutTheOriginByD) {
  for (int n = 0; n < 1000; ++n) {
    const double d = std::exp(uniform(-2, 2));
    const cga::Dilator<double> dil{d};
    const MV D = dil.mv();
    const MV product = D * dil.inverse_mv();
    ASSERT_NEAR(product[0], 1.0, 1e-12);
    ASSERT_LT((product - MV(1.0)).max_abs(), 1e-12) << "eq 13 inverse";
    const V3 x = random_vec(4);
    expect_vec_near(general_sandwich(D, x), d * x, 1e-11 * (1 + d), "D X D⁻¹");
  }
}

TEST(Versor, KernelAndCompositionEqualTheGeneralProduct) {
  for (int n = 0; n < 1000; ++n) {
    const cga::Versor<double> a{random_motor(), std::exp(uniform(-1, 1))};
    const cga::Versor<double> b{random_motor(), std::exp(uniform(-1, 1))};
    const V3 x = random_vec(3);
    expect_vec_near(a.apply(x), general_sandwich(a.mv(), x), 1e-10, "versor kernel");
    const MV product = a.mv() * b.mv();
    const cga::Versor<double> ab = a * b;
    // Dilators of eq 12 are not unit: D_a D_b = (1 + c_a c_b) D_{ab}, the same versor up to
    // that scalar weight, c = (1 − d)/(1 + d).
    const double ca = (1 - a.scale) / (1 + a.scale), cb = (1 - b.scale) / (1 + b.scale);
    const MV weighted = ab.mv() * (1 + ca * cb);
    for (int i = 0; i < cga::kBladeCount; ++i) ASSERT_NEAR(weighted[i], product[i], 1e-10);
    expect_vec_near(ab.apply(x), a.apply(b.apply(x)), 1e-10, "composition");
    const auto inv = a.inverse();
    ASSERT_TRUE(inv.has_value());
    expect_vec_near(inv->apply(a.apply(x)), x, 1e-10, "inverse");
    // Against the similarity matrix t ∘ R ∘ d.
    const Eigen::Matrix4d mat = a.matrix();
    const Eigen::Vector4d h = mat * x.homogeneous();
    expect_vec_near(h.head<3>(), a.motor.apply(a.scale * x), 1e-10, "similarity matrix");
  }
  EXPECT_FALSE((cga::Versor<double>{Motor::identity(), 0.0}.inverse().has_value()));
  EXPECT_FALSE((cga::Versor<double>{Motor::identity(), -1.0}.inverse().has_value()));
}
