// RigidScalpel (rigid_scalpel.hpp): a kinematic btRigidBody's blade torn along a sheet of
// 3 cm faces. Checked against the same path given to the tear as one dense stroke (a sample
// every centimetre, a third of an edge): the same length within one local edge, the same
// tip, and a path on the blade's line.
#include <BulletCollision/CollisionShapes/btBoxShape.h>
#include <BulletDynamics/Dynamics/btRigidBody.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "conform/bullet/convert.hpp"
#include "conform/bullet/plugin.hpp"
#include "conform/bullet/rigid_scalpel.hpp"
#include "conform/skin/procedural_arm.hpp"
#include "plugin_world.hpp"

using namespace conform;
using conform::test::SoftWorld;

namespace {

constexpr double kSize = 0.3;     // the sheet, m
constexpr int kCells = 10;        // 3 cm faces
constexpr double kLineY = 0.013;  // the blade's line, off the grid lines
constexpr double kStartX = -0.12, kEndX = 0.12;
constexpr double kHalfBlade = 0.02;

// A pinned sheet in its own world, with a kinematic blade body that collides with nothing.
struct Bench {
  SoftWorld w;
  bullet::Plugin plugin{w.world};
  bullet::SkinnedSoftBody* body = nullptr;
  btBoxShape shape{btVector3(0.001f, 0.001f, btScalar(kHalfBlade))};
  std::unique_ptr<btRigidBody> blade;
  bool arm = false;
  explicit Bench(bool on_arm = false) : arm(on_arm) {
    const skin::Arm coarse = skin::make_arm({.segments = 12, .rings = 20});
    body = on_arm ? &plugin.add_skinned_body(coarse.mesh, coarse.skeleton,
                                             {.model = bullet::MaterialModel::bullet_links})
                  : &plugin.add_skinned_body(
                        conform::test::one_bone_sheet(kCells, kCells, kSize, kSize),
                        conform::test::one_bone_skeleton(),
                        {.model = bullet::MaterialModel::bullet_links});
    std::vector<std::int32_t> all(std::size_t(body->vertex_count()));
    for (std::size_t v = 0; v < all.size(); ++v) all[v] = std::int32_t(v);
    body->set_pinned(all);  // the sheet stays flat: the test is about sampling
    blade =
        std::make_unique<btRigidBody>(btRigidBody::btRigidBodyConstructionInfo(0, nullptr, &shape));
    blade->setCollisionFlags(blade->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
    blade->setActivationState(DISABLE_DEACTIVATION);
    w.world.addRigidBody(blade.get(), 0, 0);
    place(kStartX);
  }
  ~Bench() { w.world.removeRigidBody(blade.get()); }
  // On the sheet the blade (along z) moves along x; on the arm it is turned along y and
  // moves along the arm's axis (z) over its top, from z = 0.1 to 0.34 (the elbow's bulge).
  void place(double x) {
    if (arm)
      blade->setWorldTransform(
          btTransform(btQuaternion(btVector3(1, 0, 0), btScalar(-M_PI / 2)),
                      btVector3(btScalar(kLineY), btScalar(0.05), btScalar(x + 0.22))));
    else
      blade->setWorldTransform(
          btTransform(btQuaternion::getIdentity(), btVector3(btScalar(x), btScalar(kLineY), 0)));
  }
  // Moves the blade from kStartX to kEndX in frames of `step` metres, stepping the world,
  // and hands every frame's pose to `sample`.
  template <class Sample>
  void sweep(double step, Sample sample) {
    const int frames = int(std::lround((kEndX - kStartX) / step));
    for (int i = 0; i <= frames; ++i) {
      place(kStartX + (kEndX - kStartX) * i / frames);
      w.step();
      sample(plugin.time());
    }
  }
  Eigen::Vector3d tip() const { return body->position(body->tear()->right_border().back()); }
  // The largest distance of a tear vertex from the blade's line (y = kLineY, z = 0).
  double off_line() const {
    double worst = 0;
    for (auto v : body->tear()->right_border()) {
      const Eigen::Vector3d x = body->position(v);
      worst = std::max(worst, std::hypot(x.y() - kLineY, x.z()));
    }
    return worst;
  }
};

mesh::ScalpelSample blade_sample(double t, double x) {
  return {t, {x, kLineY, kHalfBlade}, {x, kLineY, -kHalfBlade}};
}

// The reference: the path as one dense stroke given to the tear directly.
struct Reference {
  Bench bench;
  Reference() {
    const int samples = int(std::lround((kEndX - kStartX) / 0.01));
    for (int i = 0; i <= samples; ++i)
      bench.body->tear_advance(blade_sample(i, kStartX + (kEndX - kStartX) * i / samples));
  }
};

const btVector3 kA(0, 0, btScalar(kHalfBlade)), kB(0, 0, btScalar(-kHalfBlade));

}  // namespace

TEST(RigidScalpel, SlowBladeTearsAsOneDenseStroke) {
  const Reference ref;
  const double ref_length = ref.bench.body->tear()->length();
  ASSERT_GT(ref_length, 0.9 * (kEndX - kStartX));  // the stroke tore the whole path
  // The premise, measured: one sample per frame of 2.5 mm extends the tear in few samples.
  Bench naive;
  int naive_samples = 0, naive_extended = 0;
  naive.sweep(0.0025, [&](double t) {
    const btVector3 x = naive.blade->getWorldTransform().getOrigin();
    naive_extended += naive.body->tear_advance(blade_sample(t, double(x.x()))).extended;
    ++naive_samples;
  });
  RecordProperty("per_frame_samples", naive_samples);
  RecordProperty("per_frame_extended", naive_extended);
  RecordProperty("per_frame_path_points", naive.body->tear()->path_length());
  RecordProperty("stroke_path_points", ref.bench.body->tear()->path_length());
  // The scalpel on the same motion.
  Bench b;
  bullet::RigidScalpel scalpel(*b.body, *b.blade, kA, kB);
  b.sweep(0.0025, [&](double t) { scalpel.update(t); });
  const auto& totals = scalpel.totals();
  RecordProperty("scalpel_samples", totals.samples);
  RecordProperty("scalpel_extended", totals.extended);
  RecordProperty("scalpel_held", totals.held);
  const double h = scalpel.edge_length();
  ASSERT_GT(h, 0);
  RecordProperty("scalpel_path_points", b.body->tear()->path_length());
  // Tolerance: the scalpel submits once the blade is min_advance·h = h/2 from the tip, so its
  // tip lags the blade by less than that at the end (the stroke's by less than its 1 cm
  // spacing); each tip is placed where the blade crosses, then moved toward its face's
  // incenter by at most a fraction of the face: within one local edge h of each other.
  EXPECT_NEAR(b.body->tear()->length(), ref_length, h);
  EXPECT_LT((b.tip() - ref.bench.tip()).norm(), h);
  // Crossings are on the blade's plane up to the tear's snapping (5 % of an edge) and tips
  // inside their face: every path point within a third of an edge of the line, as the stroke.
  EXPECT_LT(b.off_line(), std::max(ref.bench.off_line(), 0.34 * h) + 1e-9);
  EXPECT_GE(totals.extended, 0.8 * totals.samples);  // few wasted samples
  EXPECT_GT(totals.held, totals.samples);            // most frames were accumulated
  EXPECT_LE(b.body->tear()->path_length(), 1.25 * ref.bench.body->tear()->path_length());
}

TEST(RigidScalpel, FastBladeIsSubSampledFaceByFace) {
  const Reference ref;
  Bench b;
  bullet::RigidScalpel scalpel(*b.body, *b.blade, kA, kB);
  int updates = 0;
  b.sweep(0.06, [&](double t) {  // two edges per frame
    const auto u = scalpel.update(t);
    if (updates++ > 0) {
      EXPECT_GE(u.samples + u.held, 2) << "a frame was not sub-sampled";
    }
  });
  const double h = scalpel.edge_length();
  EXPECT_NEAR(b.body->tear()->length(), ref.bench.body->tear()->length(), h);
  EXPECT_LT((b.tip() - ref.bench.tip()).norm(), h);
  EXPECT_LT(b.off_line(), std::max(ref.bench.off_line(), 0.34 * h) + 1e-9);
}

TEST(RigidScalpel, BadOptionsThrowNamingTheValue) {
  Bench b;
  auto message = [&](const bullet::RigidScalpel::Options& o, btVector3 a, btVector3 bb) {
    try {
      bullet::RigidScalpel s(*b.body, *b.blade, a, bb, o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no throw");
  };
  EXPECT_EQ(message({.min_advance = 0}, kA, kB),
            "RigidScalpel: min_advance = 0 must be finite and > 0");
  EXPECT_EQ(message({.min_advance = 0.5, .max_advance = 0.25}, kA, kB),
            "RigidScalpel: max_advance = 0.25 must be finite and ≥ min_advance (0.5)");
  EXPECT_NE(message({}, kA, kA).find("must be finite and distinct"), std::string::npos);
  EXPECT_EQ(message({}, kA, kB), "no throw");
}

TEST(RigidScalpel, SlowBladeOverACurvedArm) {
  // The coarse arm (12 segments, 20 rings: 2.6 × 3.5 cm faces), the blade moving along its top
  // over the biceps to the elbow, 2.5 mm per frame; the stroke: a sample every centimetre.
  Bench ref(true);
  for (int i = 0; i <= 24; ++i) {
    const double z = 0.1 + 0.01 * i;
    ref.body->tear_advance({double(i), {kLineY, 0.07, z}, {kLineY, 0.03, z}});
  }
  ASSERT_GT(ref.body->tear()->length(), 0.9 * (kEndX - kStartX));
  Bench naive(true);
  int naive_samples = 0, naive_extended = 0;
  naive.sweep(0.0025, [&](double t) {
    const btTransform& pose = naive.blade->getWorldTransform();
    naive_extended +=
        naive.body->tear_advance({t, bullet::from_bt(pose * kA), bullet::from_bt(pose * kB)})
            .extended;
    ++naive_samples;
  });
  RecordProperty("per_frame_samples", naive_samples);
  RecordProperty("per_frame_extended", naive_extended);
  RecordProperty("per_frame_path_points", naive.body->tear()->path_length());
  Bench b(true);
  bullet::RigidScalpel scalpel(*b.body, *b.blade, kA, kB);
  b.sweep(0.0025, [&](double t) { scalpel.update(t); });
  const double h = scalpel.edge_length();
  RecordProperty("scalpel_samples", scalpel.totals().samples);
  RecordProperty("scalpel_extended", scalpel.totals().extended);
  RecordProperty("scalpel_path_points", b.body->tear()->path_length());
  RecordProperty("stroke_path_points", ref.body->tear()->path_length());
  EXPECT_NEAR(b.body->tear()->length(), ref.body->tear()->length(), h);
  EXPECT_LT((b.tip() - ref.tip()).norm(), h);
  EXPECT_GE(scalpel.totals().extended, 0.8 * scalpel.totals().samples);
  // About as many path points as the stroke (one per half edge or so), not one per frame.
  EXPECT_LE(b.body->tear()->path_length(), 1.25 * ref.body->tear()->path_length());
}
