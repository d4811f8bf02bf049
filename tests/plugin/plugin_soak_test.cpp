// A random-operation soak of a running simulation: on the procedural arm and on two
// real characters of Debian's assimp-testmodels, a seeded random sequence of cuts (capped or
// not, regional or not), tears (a few scalpel samples each), drills, releases of pieces,
// animation changes and steps, then the teardown in a random one of the two supported orders
// (plugin.hpp). After every edit: mass and momentum unchanged to 1e-9 (in the plugin's books
// and summed over Bullet's own nodes), Bullet's invariants (plugin_world.hpp), every vertex
// held by exactly one node of one body or detached, finite state, and the mesh's own
// invariants (in single-precision Bullet the momentum check allows the rounding of the new
// nodes' velocities to btScalar, velocity_rounding). An operation refused with an exception (a
// clear message) is allowed and counted; a crash or undefined behaviour is not (the sanitized stage
// runs this test too). CONFORM_SOAK_OPERATIONS sets the operation count of each run and
// CONFORM_SOAK_SEED adds to the seeds (for a longer or another soak by hand).
#include <BulletSoftBody/btSoftBody.h>
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "conform/bullet/plugin.hpp"
#include "conform/io/import.hpp"
#include "conform/mesh/analysis.hpp"
#include "conform/skin/procedural_arm.hpp"
#include "plugin_world.hpp"

using namespace conform;
using conform::test::SoftWorld;

namespace {

// What the soak runs on: a mesh, its skeleton and animations, and a material.
struct Subject {
  std::string name;
  mesh::SkinnedMesh mesh;
  skin::Skeleton skeleton;
  std::vector<skin::Animation> animations;
  bullet::Material material;
  double size = 0;  // bounding diagonal of the bind pose, in the model's units
};

Subject arm_subject() {
  const skin::Arm arm = skin::make_arm(1);
  Subject s{"arm", arm.mesh, arm.skeleton, {}, {}, mesh::bounding_diagonal(arm.mesh)};
  return s;  // the default material: the skin membrane
}

// A real rigged model (welded, as users get it) with the character scene's Bullet links scaled
// to the model's size; nothing when assimp-testmodels is not installed.
std::optional<Subject> model_subject(const std::string& file, double bending) {
  const std::filesystem::path path = std::filesystem::path(CONFORM_ASSIMP_MODELS) / file;
  if (!std::filesystem::exists(path)) return std::nullopt;
  io::SkinnedModel model = io::load_model(path.string());
  Subject s{file, std::move(model.mesh), std::move(model.skeleton), std::move(model.animations), {},
            0};
  s.size = mesh::bounding_diagonal(s.mesh);
  s.material = {.model = bullet::MaterialModel::bullet_links,
                .link_stiffness = 0.02,
                .damping = 0.01,
                .pretension = 0.02,
                .target_stiffness = 2000,
                .target_damping = 20,
                .bending_stiffness = bending,
                .margin = std::min(0.005 * s.size, 0.5)};  // the plugin's range is [0, 1]
  return s;
}

enum Op { kStep, kCut, kTear, kDrill, kRelease, kAnimation, kOps };
const char* const kOpNames[kOps] = {"step", "cut", "tear", "drill", "release", "animation"};

// Σm and Σm·v twice over: in the plugin's books, and over the nodes Bullet holds (each node's
// mass from the books, since a kinematic node's inverse mass is 0 in Bullet) plus the
// detached vertices; and Σ 1/m_im over Bullet's free nodes plus the kinematic ones' book mass.
struct Weighing {
  double mass = 0, bullet_mass = 0, bullet_inverse_mass = 0, scale = 0;
  Eigen::Vector3d momentum = Eigen::Vector3d::Zero(), bullet_momentum = Eigen::Vector3d::Zero();
};

Weighing weigh(const bullet::SkinnedSoftBody& body) {
  Weighing w;
  w.mass = body.total_mass();
  w.momentum = body.momentum();
  w.scale = body.momentum_scale();
  for (btSoftBody* sb : body.pieces())
    for (int i = 0; i < sb->m_nodes.size(); ++i) {
      const btSoftBody::Node& n = sb->m_nodes[i];
      const std::int32_t v = body.vertex_of(sb, i);
      if (v < 0) continue;  // reported by the invariants
      const double m = body.mass(v);
      w.bullet_mass += m;
      w.bullet_inverse_mass += n.m_im > 0 ? 1 / double(n.m_im) : m;
      w.bullet_momentum += m * Eigen::Vector3d(n.m_v.x(), n.m_v.y(), n.m_v.z());
    }
  for (std::int32_t v = 0; v < body.vertex_count(); ++v)
    if (body.detached(v)) {
      w.bullet_mass += body.mass(v), w.bullet_inverse_mass += body.mass(v);
      w.bullet_momentum += body.mass(v) * body.velocity(v);
    }
  return w;
}

// What single-precision Bullet's rounding of the new nodes' interpolated velocities can add to
// Σm·v: a few ulps of Σm|v| over the vertices an edit added (none with double precision, where
// the books' double arithmetic is all there is).
double velocity_rounding(const bullet::SkinnedSoftBody& body, std::int32_t old_vertices) {
  if (sizeof(btScalar) != 4) return 0;
  double s = 0;
  for (std::int32_t v = old_vertices; v < body.vertex_count(); ++v)
    s += body.mass(v) * body.velocity(v).norm();
  return 4 * 1.2e-7 * s;
}

// The first broken conservation between two weighings, or an empty string; `rounding` is the
// momentum error allowed on top of 1e-9 of Σm|v| (velocity_rounding).
std::string conservation_problem(const Weighing& a, const Weighing& b, double rounding = 0) {
  const double tol = 1e-9;
  // Bullet keeps inverse masses in btScalar: single precision rounds each one to 6e-8.
  const double inverse_tol = sizeof(btScalar) == 4 ? 1e-6 : 1e-9;
  const double p_scale = std::max(a.scale, 1e-300);
  auto off = [](double x, double y) { return std::abs(x - y) / std::max(std::abs(y), 1e-300); };
  auto text = [](const char* what, double relative) {
    char out[96];
    std::snprintf(out, sizeof out, "%s off by %.3g (relative)", what, relative);
    return std::string(out);
  };
  if (off(b.mass, a.mass) > tol) return text("books' mass", off(b.mass, a.mass));
  if (off(b.bullet_mass, a.mass) > tol)
    return text("Bullet nodes' mass", off(b.bullet_mass, a.mass));
  if (off(b.bullet_inverse_mass, a.mass) > inverse_tol)
    return text("Bullet's inverse masses", off(b.bullet_inverse_mass, a.mass));
  const double dp = (b.momentum - a.momentum).norm() / p_scale,
               dq = (b.bullet_momentum - a.momentum).norm() / p_scale;
  const double allowed = tol + rounding / p_scale;
  if (dp > allowed) return text("books' momentum", dp);
  if (dq > allowed) return text("Bullet nodes' momentum", dq);
  return {};
}

// Every vertex is on exactly one node of one of the body's pieces (which are all in the world
// and hold no node of another vertex) or detached; state finite; the mesh's columns agree and
// its faces, weights and bone ids are valid; no edge more overused or misoriented than in the
// input.
std::string holding_problem(const bullet::SkinnedSoftBody& body, btSoftRigidDynamicsWorld& world,
                            const mesh::MeshReport& input) {
  const auto& m = body.mesh();
  const std::int32_t n = body.vertex_count();
  if (m.current.cols() != n || m.bones.cols() != n || m.weights.cols() != n)
    return "mesh columns disagree with the vertex count";
  std::set<const btSoftBody*> in_world;
  for (int i = 0; i < world.getSoftBodyArray().size(); ++i)
    in_world.insert(world.getSoftBodyArray()[i]);
  std::set<const btSoftBody*> seen;
  std::int32_t nodes = 0;
  for (btSoftBody* sb : body.pieces()) {
    if (!seen.insert(sb).second) return "a piece listed twice";
    if (!in_world.count(sb)) return "a piece outside the world";
    for (int i = 0; i < sb->m_nodes.size(); ++i, ++nodes) {
      const std::int32_t v = body.vertex_of(sb, i);
      if (v < 0 || v >= n) return "a node of no vertex";
      if (body.body_of(v) != sb || body.node_of(v) != i) return "a node of another vertex";
      const auto& x = sb->m_nodes[i].m_x;
      if (!std::isfinite(double(x.x() + x.y() + x.z()))) return "a non-finite node";
    }
  }
  if (nodes + body.detached_count() != n) return "nodes + detached != vertices";
  for (std::int32_t v = 0; v < n; ++v) {
    if (!body.position(v).allFinite() || !body.velocity(v).allFinite())
      return "vertex " + std::to_string(v) + " not finite";
    for (int k = 0; k < 4; ++k)
      if (!(m.weights(k, v) >= 0) || m.bones(k, v) < 0 ||
          m.bones(k, v) >= body.skeleton().bone_count())
        return "vertex " + std::to_string(v) + " has a bad influence";
  }
  const mesh::MeshReport r = mesh::check_mesh(m);
  if (!r.indices_valid || !r.finite) return "mesh: " + r.summary();
  if (r.overused_edges > input.overused_edges || r.misoriented_edges > input.misoriented_edges)
    return "mesh has new overused or misoriented edges: " + r.summary();
  if (body.piece_count() != mesh::label_pieces(m).count) return "pieces != the mesh's pieces";
  return conform::test::bullet_internals_problem(body);
}

// One soak run: a subject simulated in its own world, a seeded sequence of random operations,
// the checks after each edit, and the counts.
class Soak {
 public:
  Soak(const Subject& subject, const skin::Animation* foreign, std::uint32_t seed)
      : subject_(subject), foreign_(foreign), rng_(seed) {
    world_ = std::make_unique<SoftWorld>(9.81 * subject.size / 0.9);  // g at the model's scale
    plugin_ = std::make_unique<bullet::Plugin>(world_->world);
    body_ = &plugin_->add_skinned_body(subject.mesh, subject.skeleton, subject.material);
    input_ = mesh::check_mesh(subject.mesh);
    if (std::getenv("CONFORM_SOAK_VERBOSE")) std::printf("input: %s\n", input_.summary().c_str());
    edge_ = mean_edge();
    start_animation();
    world_->step(3);  // moving: the momentum checks mean something
  }

  // `count` random operations, each checked; stops at the first failed check.
  void run(int count) {
    for (int i = 0; i < count && !::testing::Test::HasFatalFailure(); ++i) {
      const double pick = unit(rng_);
      const Op op = pick < 0.25   ? kStep
                    : pick < 0.4  ? kCut
                    : pick < 0.6  ? kTear
                    : pick < 0.75 ? kDrill
                    : pick < 0.85 ? kRelease
                                  : kAnimation;
      label_ = subject_.name + " op " + std::to_string(i) + " (" + kOpNames[op] + ")";
      ++done_[op];
      switch (op) {
        case kStep:
          world_->step(1 + int(rng_() % 3));
          break;
        case kCut:
          edit(op, [&] { cut(); });
          break;
        case kTear:
          tear();
          break;
        case kDrill:
          edit(op, [&] { drill(); });
          break;
        case kRelease:
          edit(op, [&] { release(); });
          break;
        case kAnimation:
          edit(op, [&] { change_animation(); });
          break;
        default:
          break;
      }
      ASSERT_EQ(holding_problem(*body_, world_->world, input_), "") << label_;
      check_handles();
    }
  }

  // Bullet's standard teardown (remove and delete every soft body, then the plugin) or the
  // world before the plugin, at random.
  const char* teardown() {
    const bool standard = rng_() % 2 == 0;
    if (standard) {
      btSoftBodyArray& bodies = world_->world.getSoftBodyArray();
      for (int i = bodies.size() - 1; i >= 0; --i) {
        btSoftBody* sb = bodies[i];
        world_->world.removeSoftBody(sb);
        delete sb;
      }
      plugin_.reset();
      world_.reset();
    } else {
      world_.reset();
      plugin_.reset();
    }
    return standard ? "standard" : "world first";
  }

  void report() const {
    std::printf("soak %s: %d vertices, %d faces, %d pieces at the end;", subject_.name.c_str(),
                body_->vertex_count(), body_->mesh().face_count(), body_->piece_count());
    for (int op = 0; op < kOps; ++op) {
      std::printf(" %s %d (refused %d", kOpNames[op], done_[op], refused_[op]);
      if (op == kTear)
        std::printf("; %d samples, %d did not extend)", tear_samples_, noop_[op]);
      else if (op == kCut || op == kDrill)
        std::printf(", missed %d)", noop_[op]);
      else
        std::printf(")");
    }
    std::printf("\n");
    for (const auto& [message, n] : refusals_)
      std::printf("  refused %dx: %s\n", n, message.c_str());
  }

  int done(Op op) const { return done_[op]; }
  int refused(Op op) const { return refused_[op]; }
  int noop(Op op) const { return noop_[op]; }
  int tear_samples() const { return tear_samples_; }

 private:
  static double unit(std::mt19937& rng) { return std::uniform_real_distribution<>(0, 1)(rng); }

  double mean_edge() const {
    const auto& m = body_->mesh();
    double sum = 0;
    for (const auto& f : m.faces)
      for (int k = 0; k < 3; ++k)
        sum +=
            (m.current.col(f[std::size_t(k)]) - m.current.col(f[std::size_t((k + 1) % 3)])).norm();
    return sum / (3.0 * double(std::max<std::size_t>(m.faces.size(), 1)));
  }

  Eigen::Vector3d random_unit() {
    std::normal_distribution<double> n(0, 1);
    const Eigen::Vector3d d(n(rng_), n(rng_), n(rng_));
    return d.norm() > 1e-6 ? Eigen::Vector3d(d.normalized()) : Eigen::Vector3d::UnitX();
  }

  // A random face's centroid at its simulated place, and the face's normal.
  Eigen::Vector3d surface_point(Eigen::Vector3d& normal) {
    const auto& faces = body_->mesh().faces;
    if (faces.empty()) return normal = random_unit(), Eigen::Vector3d::Zero();
    const auto& f = faces[std::size_t(rng_() % std::uint32_t(faces.size()))];
    const Eigen::Vector3d a = body_->position(f[0]), b = body_->position(f[1]),
                          c = body_->position(f[2]);
    const Eigen::Vector3d n = (b - a).cross(c - a);
    normal = n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : random_unit();
    return (a + b + c) / 3;
  }

  // Runs one edit between steps: a refusal (an exception with a message) is counted; either
  // way Σm and Σm·v must be what they were.
  template <class Edit>
  void edit(Op op, Edit&& run_edit, bool topological = true) {
    const Weighing before = weigh(*body_);
    const std::uint64_t version = body_->topology_version();
    const std::int32_t vertices = body_->vertex_count();
    try {
      run_edit();
    } catch (const std::exception& e) {
      ++refused_[op];
      ++refusals_[std::string(kOpNames[op]) + ": " + e.what()];
    }
    if (topological && op != kAnimation && op != kRelease && body_->topology_version() == version)
      ++noop_[op];
    ASSERT_EQ(conservation_problem(before, weigh(*body_), velocity_rounding(*body_, vertices)), "")
        << label_;
  }

  void cut() {
    Eigen::Vector3d n;
    const Eigen::Vector3d p = surface_point(n);
    mesh::CutOptions options{.cap = rng_() % 2 == 0};
    const auto region = rng_() % 3;
    if (region == 1)
      options.region = mesh::CutRegion::sphere(
          p, (0.05 + 0.25 * unit(rng_)) * subject_.size,
          rng_() % 2 ? mesh::CutRegion::Keep::touching : mesh::CutRegion::Keep::inside);
    else if (region == 2)
      options.region = mesh::CutRegion::seed(p);
    const auto plane = cga::Plane<double>::from_normal_point(random_unit(), p);
    const mesh::CutResult r = body_->cut(plane, options);
    if (std::getenv("CONFORM_SOAK_VERBOSE"))
      std::printf("%s: cap %d region %d at (%g %g %g): loops %d capped %d nested %d, %s\n",
                  label_.c_str(), int(options.cap), int(region), p.x(), p.y(), p.z(), r.loops,
                  r.capped_loops, r.nested_loops, r.message.c_str());
  }

  // A tear of 2 to 6 scalpel samples: the blade crosses the surface along its normal at a
  // random face and moves along a tangent, half a mean edge per sample; each sample an edit.
  void tear() {
    Eigen::Vector3d normal;
    Eigen::Vector3d at = surface_point(normal);
    const Eigen::Vector3d heading = normal.cross(random_unit()).normalized();
    const double depth = 3 * edge_;
    const int samples = 2 + int(rng_() % 5);
    edit(
        kTear, [&] { body_->begin_tear(); }, false);
    for (int k = 0; k < samples && !::testing::Test::HasFatalFailure(); ++k, ++tear_samples_) {
      edit(kTear, [&] {
        body_->tear_advance({tear_time_, at + depth * normal, at - depth * normal});
      });
      tear_time_ += 1.0 / 60;
      at += 0.5 * edge_ * heading;
      ASSERT_EQ(holding_problem(*body_, world_->world, input_), "") << label_ << " sample " << k;
    }
  }

  // Along the surface normal, as a drill is held; sometimes through a closed surface (a tube).
  void drill() {
    Eigen::Vector3d n;
    const Eigen::Vector3d p = surface_point(n);
    const double reach = rng_() % 4 == 0 ? subject_.size : 2 * edge_;
    body_->drill({p + reach * n, p - reach * n, (0.3 + 0.9 * unit(rng_)) * edge_},
                 {.min_rim_points = 6, .max_refinements = 2, .tube = rng_() % 4 == 0});
  }

  // A random live piece (sometimes a stale id, which must be refused), random release options.
  void release() {
    const std::vector<bullet::PieceId> ids = body_->piece_ids();
    bullet::PieceId id = ids.empty() ? bullet::PieceId{} : ids[rng_() % ids.size()];
    if (!seen_ids_.empty() && rng_() % 5 == 0) id = seen_ids_[rng_() % seen_ids_.size()];
    bullet::ReleaseOptions options{.link_stiffness = 0.2 + 0.8 * unit(rng_)};
    if (rng_() % 3 == 0) options.volume_modulus = 200 * unit(rng_);
    body_->release_piece(id, options);
  }

  // The model's first animation, looped, or (the arm) keyframes bending shoulder and elbow.
  void start_animation() {
    if (!subject_.animations.empty()) return body_->play(subject_.animations.front());
    skin::PoseTrack track;
    track.set_key(0, skin::Pose::rest(subject_.skeleton));
    track.set_key(1, conform::test::bent_arm_pose(subject_.skeleton, 0.6, 1.3));
    body_->set_keyframes(std::move(track));
  }

  // Another animation of the model (or its own again), a pose sampled from it, new keyframes
  // (the arm), the body's clock, or another skeleton's animation (refused when it does not fit).
  void change_animation() {
    const auto kind = rng_() % 5;
    if (kind == 4 && foreign_) {  // refused when its channels name joints this one lacks
      body_->play(*foreign_);
      return;
    }
    if (kind == 3) {
      body_->set_clock({.start = unit(rng_), .speed = 2 * unit(rng_) - 0.5, .paused = false});
      return;
    }
    if (subject_.animations.empty()) {
      skin::PoseTrack track;
      track.set_key(plugin_->time(), body_->pose());
      track.set_key(
          plugin_->time() + 0.2 + unit(rng_),
          conform::test::bent_arm_pose(subject_.skeleton, 2 * unit(rng_) - 1, 2.4 * unit(rng_)));
      body_->set_keyframes(std::move(track), rng_() % 2 ? skin::Blend::log : skin::Blend::linear);
      return;
    }
    const auto& animation = subject_.animations[rng_() % subject_.animations.size()];
    if (kind == 2) {
      skin::Pose pose;
      animation.sample(subject_.skeleton, unit(rng_) * animation.duration(), skin::Blend::log,
                       pose);
      body_->set_pose(pose);
    } else {
      body_->play(animation, kind ? skin::Blend::log : skin::Blend::linear, rng_() % 2 == 0);
    }
  }

  // Handles: every id seen so far is either live (with its body) or stale (null body).
  void check_handles() {
    for (const bullet::PieceId id : body_->piece_ids()) {
      ASSERT_NE(body_->piece_body(id), nullptr) << label_;
      if (seen_ids_.size() < 256) seen_ids_.push_back(id);
    }
    for (const bullet::PieceId id : seen_ids_)
      ASSERT_EQ(body_->piece_valid(id), body_->piece_body(id) != nullptr) << label_;
  }

  const Subject& subject_;
  const skin::Animation* foreign_;
  std::mt19937 rng_;
  std::unique_ptr<SoftWorld> world_;
  std::unique_ptr<bullet::Plugin> plugin_;
  bullet::SkinnedSoftBody* body_ = nullptr;
  mesh::MeshReport input_;
  double edge_ = 0, tear_time_ = 0;
  std::string label_;
  std::array<int, kOps> done_{}, refused_{}, noop_{};
  int tear_samples_ = 0;
  std::map<std::string, int> refusals_;
  std::vector<bullet::PieceId> seen_ids_;
};

std::uint32_t seed_offset() {
  const char* n = std::getenv("CONFORM_SOAK_SEED");
  return n ? std::uint32_t(std::strtoul(n, nullptr, 10)) : 0;
}

int operations() {
  const char* n = std::getenv("CONFORM_SOAK_OPERATIONS");
  return n ? std::max(1, std::atoi(n)) : 60;
}

// The soak of one subject with one seed: every operation kind ran, none crashed, and the
// teardown is clean (under ASan: no use after free, no leak).
void soak(const Subject& subject, const skin::Animation* foreign, std::uint32_t seed) {
  Soak s(subject, foreign, seed + seed_offset());
  s.run(operations());
  s.report();
  if (::testing::Test::HasFatalFailure()) return;
  for (int op = 0; op < kOps; ++op) EXPECT_GT(s.done(Op(op)), 0) << kOpNames[op];
  EXPECT_GT(s.tear_samples(), 0);
  std::printf("  teardown: %s\n", s.teardown());
}

const Subject& arm() {
  static const Subject s = arm_subject();
  return s;
}
const std::optional<Subject>& huesitos() {
  static const std::optional<Subject> s = model_subject("FBX/huesitos.fbx", 0.3);
  return s;
}
const std::optional<Subject>& wuson() {
  static const std::optional<Subject> s = model_subject("X/Testwuson.X", 0.0);
  return s;
}
const skin::Animation* first_animation(const std::optional<Subject>& s) {
  return s && !s->animations.empty() ? &s->animations.front() : nullptr;
}

}  // namespace

TEST(PluginSoak, ArmUnderRandomOperations) {
  soak(arm(), first_animation(huesitos()), 16001);
}

TEST(PluginSoak, HuesitosUnderRandomOperations) {
  if (!huesitos()) GTEST_SKIP() << "assimp-testmodels not installed";
  soak(*huesitos(), first_animation(wuson()), 16002);
}

TEST(PluginSoak, WusonUnderRandomOperations) {
  if (!wuson()) GTEST_SKIP() << "assimp-testmodels not installed";
  ASSERT_GE(wuson()->animations.size(), 2u);  // "another animation" is a real one here
  soak(*wuson(), first_animation(huesitos()), 16003);
}
