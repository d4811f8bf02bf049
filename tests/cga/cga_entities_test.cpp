// Graded entities and predicates: spheres, planes, circles, lines, point pairs.
#include <gtest/gtest.h>

#include "cga_random.hpp"
#include "conform/cga.hpp"

namespace cga = conform::cga;
using MV = cga::Multivector<double>;
using V3 = cga::Vec3<double>;

namespace {
cga::testing::Random random(99);
double uniform(double a = -1, double b = 1) {
  return random.uniform(a, b);
}
V3 random_vec(double scale = 1) {
  return random.vec(scale);
}
V3 random_unit() {
  return random.unit();
}
}  // namespace

TEST(Sphere, ThroughFourPointsRecoversCentreAndRadius) {
  for (int n = 0; n < 1000; ++n) {
    const V3 c = random_vec(5);
    const double r = uniform(0.1, 3);
    const auto s = cga::Sphere<double>::through(c + r * random_unit(), c + r * random_unit(),
                                                c + r * random_unit(), c + r * random_unit());
    ASSERT_TRUE(s.has_value());
    EXPECT_LT((s->center() - c).norm(), 1e-7 * (1 + c.norm()));
    EXPECT_NEAR(s->radius(), r, 1e-7 * (1 + c.norm()));
    const V3 inside = c + 0.5 * r * random_unit(), outside = c + 1.5 * r * random_unit();
    EXPECT_TRUE(s->contains(inside));
    EXPECT_FALSE(s->contains(outside));
    // Every point of the sphere is on it: X·S = 0.
    EXPECT_NEAR(dot(cga::Point<double>::up(c + r * random_unit()), *s), 0.0,
                1e-7 * (1 + c.squaredNorm()));
  }
  // Coplanar points give no sphere.
  EXPECT_FALSE(
      cga::Sphere<double>::through(V3(0, 0, 0), V3(1, 0, 0), V3(0, 1, 0), V3(1, 1, 0)).has_value());
}

TEST(Plane, ThroughThreePointsAndSignedDistance) {
  for (int n = 0; n < 1000; ++n) {
    const V3 a = random_vec(5), b = random_vec(5), c = random_vec(5);
    const auto p = cga::Plane<double>::through(a, b, c);
    ASSERT_TRUE(p.has_value());
    const V3 normal = (b - a).cross(c - a).normalized();
    EXPECT_LT((p->normal() - normal).norm(), 1e-9);
    for (const V3* x : {&a, &b, &c}) EXPECT_NEAR(p->signed_distance(*x), 0.0, 1e-10);
    const V3 q = random_vec(5);
    EXPECT_NEAR(p->signed_distance(q), normal.dot(q - a), 1e-10);
    // X·Π equals the signed distance for a normalized point.
    EXPECT_NEAR(dot(cga::Point<double>::up(q), *p), p->signed_distance(q), 1e-10);
    EXPECT_EQ(p->side(a + normal), 1);
    EXPECT_EQ(p->side(a - normal), -1);
    EXPECT_EQ(p->side(a + 1e-12 * normal, 1e-9), 0);
  }
  EXPECT_FALSE(cga::Plane<double>::through(V3(0, 0, 0), V3(1, 1, 1), V3(2, 2, 2)).has_value());
}

TEST(Plane, SegmentIntersection) {
  const auto p = cga::Plane<double>::from_normal_distance(V3(0, 0, 1), 1.0);
  auto t = p.segment_intersection(V3(0, 0, 0), V3(0, 0, 4));
  ASSERT_TRUE(t.has_value());
  EXPECT_DOUBLE_EQ(*t, 0.25);
  EXPECT_FALSE(p.segment_intersection(V3(0, 0, 2), V3(1, 0, 3)).has_value());
  EXPECT_FALSE(p.segment_intersection(V3(0, 0, 1), V3(1, 0, 1)).has_value());  // in the plane
  auto touch = p.segment_intersection(V3(0, 0, 1), V3(0, 0, 3));
  ASSERT_TRUE(touch.has_value());
  EXPECT_DOUBLE_EQ(*touch, 0.0);
}

TEST(Circle, MeetOfTwoSpheres) {
  for (int n = 0; n < 500; ++n) {
    // Two spheres whose intersection circle is known: centres on an axis.
    const V3 c1 = random_vec(3), axis = random_unit();
    const double r1 = uniform(1, 2), h = uniform(-0.8, 0.8) * r1;  // circle plane offset
    const double rc = std::sqrt(r1 * r1 - h * h);
    const double dist = uniform(0.3, 2);
    const V3 c2 = c1 + axis * dist;
    const double r2 = std::sqrt(rc * rc + (dist - h) * (dist - h));
    const auto z = cga::Circle<double>::meet(cga::Sphere<double>::from_center_radius(c1, r1),
                                             cga::Sphere<double>::from_center_radius(c2, r2));
    EXPECT_LT((z.center() - (c1 + axis * h)).norm(), 1e-9);
    EXPECT_NEAR(z.radius_squared(), rc * rc, 1e-9);
  }
}

TEST(PointPair, CircleCutByPlaneDissectsIntoItsTwoPoints) {
  for (int n = 0; n < 500; ++n) {
    const V3 c = random_vec(2);
    const double r = uniform(0.5, 2);
    const auto s1 = cga::Sphere<double>::from_center_radius(c, r);
    const auto s2 = cga::Plane<double>::from_normal_point(V3(0, 0, 1), c);  // equator
    const cga::Circle<double> z{s1.mv() ^ s2.mv()};
    const double offset = uniform(-0.9, 0.9) * r;
    const auto cut = cga::Plane<double>::from_normal_point(V3(1, 0, 0), c + V3(offset, 0, 0));
    const auto pp = cga::PointPair<double>::meet(z, cut);
    const auto pts = pp.dissect();
    ASSERT_TRUE(pts.has_value());
    const double y = std::sqrt(r * r - offset * offset);
    const V3 a = c + V3(offset, y, 0), b = c + V3(offset, -y, 0);
    const bool order1 = (pts->first - a).norm() < 1e-8 && (pts->second - b).norm() < 1e-8;
    const bool order2 = (pts->first - b).norm() < 1e-8 && (pts->second - a).norm() < 1e-8;
    EXPECT_TRUE(order1 || order2) << pts->first.transpose() << " / " << pts->second.transpose();
  }
  // A plane that misses the circle gives an imaginary pair: no points.
  const auto s = cga::Sphere<double>::from_center_radius(V3::Zero(), 1);
  const auto eq = cga::Plane<double>::from_normal_distance(V3(0, 0, 1), 0);
  const auto far = cga::Plane<double>::from_normal_distance(V3(1, 0, 0), 5);
  EXPECT_FALSE(cga::PointPair<double>::meet(cga::Circle<double>{s.mv() ^ eq.mv()}, far)
                   .dissect()
                   .has_value());
}

TEST(Line, MeetOfTwoPlanesAndThroughTwoPoints) {
  for (int n = 0; n < 500; ++n) {
    const V3 a = random_vec(3), b = random_vec(3);
    const cga::Line<double> l = cga::Line<double>::through(a, b);
    const V3 dir = (b - a).normalized();
    EXPECT_LT((l.direction() - dir).norm(), 1e-9)
        << l.direction().transpose() << " vs " << dir.transpose();
    // Points of the line satisfy X ∧ L_outer = 0, i.e. X⌋L_inner = 0.
    const V3 on = a + uniform(-2, 2) * (b - a);
    const MV x = cga::Point<double>::up(on).mv();
    EXPECT_LT((x << l.mv).max_abs(), 1e-9 * (1 + on.squaredNorm()));
    const V3 off = on + dir.unitOrthogonal();
    EXPECT_GT((cga::Point<double>::up(off).mv() << l.mv).max_abs(), 1e-3);
    // The meet of two planes containing the line contains the same points.
    const auto p1 = cga::Plane<double>::through(a, b, a + dir.unitOrthogonal()).value();
    const auto p2 = cga::Plane<double>::through(a, b, a + dir.cross(dir.unitOrthogonal())).value();
    const auto m = cga::Line<double>::meet(p1, p2);
    EXPECT_LT((x << m.mv).max_abs(), 1e-9 * (1 + on.squaredNorm()));
    EXPECT_LT(std::abs(std::abs(m.direction().dot(dir)) - 1), 1e-9);
  }
}
