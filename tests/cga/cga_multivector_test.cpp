// Property tests of the general multivector: identities over thousands of random inputs.
#include <gtest/gtest.h>

#include "cga_random.hpp"
#include "conform/cga.hpp"

namespace cga = conform::cga;
using MV = cga::Multivector<double>;
using V3 = cga::Vec3<double>;

namespace {

cga::testing::Random random(20261122);
V3 random_vec(double scale = 1) {
  return random.vec(scale);
}
MV random_mv() {
  return random.multivector();
}
MV random_vector() {
  return random.vector();
}

void expect_mv_near(const MV& a, const MV& b, double tol, const std::string& what) {
  for (int i = 0; i < cga::kBladeCount; ++i)
    ASSERT_NEAR(a[i], b[i], tol) << what << " blade " << cga::blade_name(i) << "\n a = " << a
                                 << "\n b = " << b;
}

}  // namespace

TEST(Multivector, BasisMetric) {
  EXPECT_EQ((cga::e1() * cga::e1()).to_string(), "1");
  EXPECT_EQ((cga::einf() * cga::einf()).max_abs(), 0.0);
  EXPECT_EQ((cga::e0() * cga::e0()).max_abs(), 0.0);
  EXPECT_DOUBLE_EQ(scalar_product(cga::einf(), cga::e0()), -1.0);
  // I² = −1 in G(4,1).
  EXPECT_DOUBLE_EQ((MV::pseudoscalar() * MV::pseudoscalar()).scalar(), -1.0);
}

TEST(Multivector, PointIdentities) {
  for (int n = 0; n < 2000; ++n) {
    const V3 x = random_vec(10), y = random_vec(10);
    const MV X = cga::Point<double>::up(x).mv(), Y = cga::Point<double>::up(y).mv();
    EXPECT_NEAR(scalar_product(X, X), 0.0, 1e-12 * (1 + x.squaredNorm()));
    EXPECT_NEAR(scalar_product(X, Y), -0.5 * (x - y).squaredNorm(),
                1e-11 * (1 + x.squaredNorm() + y.squaredNorm()));
    auto back = cga::down(X * 3.5);
    ASSERT_TRUE(back.has_value());
    EXPECT_LT((*back - x).norm(), 1e-12 * (1 + x.norm()));
  }
}

TEST(Multivector, DualTwiceIsNegation) {
  for (int n = 0; n < 1000; ++n) {
    const MV m = random_mv();
    expect_mv_near(m.dual().dual(), -m, 1e-13, "(m*)*");
    expect_mv_near(m.dual().undual(), m, 1e-13, "undual(dual)");
  }
}

TEST(Multivector, ProductsAreAssociativeAndDistributive) {
  for (int n = 0; n < 500; ++n) {
    const MV a = random_mv(), b = random_mv(), c = random_mv();
    expect_mv_near((a * b) * c, a * (b * c), 1e-11, "associativity");
    expect_mv_near((a ^ b) ^ c, a ^ (b ^ c), 1e-11, "outer associativity");
    expect_mv_near(a * (b + c), a * b + a * c, 1e-12, "distributivity");
    expect_mv_near((a * b).reverse(), b.reverse() * a.reverse(), 1e-11, "reverse of product");
  }
}

TEST(Multivector, VectorProductSplitsIntoInnerAndOuter) {
  for (int n = 0; n < 1000; ++n) {
    const MV a = random_vector(), b = random_vector();
    expect_mv_near(a * b, (a << b) + (a ^ b), 1e-13, "ab = a⌋b + a∧b");
    expect_mv_near(a << b, a >> b, 1e-13, "vector contractions agree");
  }
}

TEST(Multivector, VersorInverse) {
  for (int n = 0; n < 2000; ++n) {
    MV v(1.0);
    const int k = 1 + n % 4;
    for (int i = 0; i < k; ++i) {
      MV f = random_vector();
      if (std::abs(scalar_product(f, f)) < 0.05) f[cga::kE1] += 1.0;  // avoid near-null factors
      v = v * f;
    }
    auto inv = v.versor_inverse();
    ASSERT_TRUE(inv.has_value());
    expect_mv_near(v * *inv, MV(1.0), 1e-9, "V V⁻¹");
    auto general = v.inverse();
    ASSERT_TRUE(general.has_value());
    expect_mv_near(*general, *inv, 1e-8, "general inverse = versor inverse");
  }
}

TEST(Multivector, GeneralInverseOfRandomElements) {
  int inverted = 0;
  for (int n = 0; n < 300; ++n) {
    const MV a = random_mv();
    auto inv = a.inverse();
    if (!inv) continue;
    ++inverted;
    expect_mv_near(a * *inv, MV(1.0), 1e-8, "a a⁻¹");
    expect_mv_near(*inv * a, MV(1.0), 1e-8, "a⁻¹ a");
  }
  EXPECT_GT(inverted, 250);
}

TEST(Multivector, NonInvertibleElementsReportFailure) {
  // Null vectors, 1 + e∞∧e0-type idempotent factors and zero have no inverse.
  EXPECT_FALSE(cga::einf().inverse().has_value());
  EXPECT_FALSE(cga::einf().versor_inverse().has_value());
  EXPECT_FALSE(cga::Point<double>::up(1, 2, 3).mv().inverse().has_value());
  MV idem(1.0);
  idem[cga::kEinf0] = 1.0;  // the d = 0 "dilator" of the paper: (1 + E)(1 − E) = 0
  EXPECT_FALSE(idem.inverse().has_value());
  EXPECT_FALSE(MV().inverse().has_value());
  EXPECT_FALSE(MV().versor_inverse().has_value());
  MV nan(1.0);
  nan[3] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(nan.inverse().has_value());
  EXPECT_FALSE(nan.versor_inverse().has_value());
}

TEST(Multivector, DownOfPointAtInfinityFails) {
  EXPECT_FALSE(cga::down(cga::einf()).has_value());
  EXPECT_FALSE(cga::down(cga::e1() * 2.0 + cga::einf()).has_value());
  MV nan = cga::Point<double>::up(1, 2, 3).mv();
  nan[cga::kE1] = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(cga::down(nan).has_value());
}

TEST(Multivector, ExpOfBivectorIsAVersor) {
  for (int n = 0; n < 300; ++n) {
    MV b = random_mv().grade(2) * 2.0;
    const MV e = cga::exp(b);
    const MV em = cga::exp(-b);
    expect_mv_near(e * em, MV(1.0), 1e-9, "exp(B) exp(−B)");
  }
}

TEST(Multivector, ParseAndPrintRoundTrip) {
  for (int n = 0; n < 300; ++n) {
    const MV m = random_mv();
    const MV back = cga::parse_multivector<double>(m.to_string());
    expect_mv_near(back, m, 0.0, "print/parse");
  }
  const MV p = cga::parse_multivector<double>("1.5 + 2*e1 - 0.5 einf^e0 + e21 + 3e-1*e3inf0");
  EXPECT_DOUBLE_EQ(p[cga::kScalar], 1.5);
  EXPECT_DOUBLE_EQ(p[cga::kE1], 2.0);
  EXPECT_DOUBLE_EQ(p[cga::kEinf0], -0.5);
  EXPECT_DOUBLE_EQ(p[cga::kE12], -1.0);  // e2∧e1 = −e12
  EXPECT_DOUBLE_EQ(p[cga::kE3inf0], 0.3);
  EXPECT_THROW(cga::parse_multivector<double>("2*e4"), std::invalid_argument);
  EXPECT_THROW(cga::parse_multivector<double>("e11"), std::invalid_argument);
  EXPECT_THROW(cga::parse_multivector<double>(""), std::invalid_argument);
  EXPECT_THROW(cga::parse_multivector<double>("1 + x"), std::invalid_argument);
}

TEST(Multivector, FloatAgreesWithDouble) {
  for (int n = 0; n < 200; ++n) {
    const MV a = random_mv(), b = random_mv();
    const auto af = a.cast<float>(), bf = b.cast<float>();
    const auto pf = (af * bf).cast<double>();
    expect_mv_near(pf, a * b, 1e-4, "float product");
  }
}
