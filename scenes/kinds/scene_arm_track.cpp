// `arm-track`: a btMultiBody arm (spherical shoulder, revolute elbow, the procedural arm's
// segment lengths) whose joint motors follow the closed-form CGA IK solution for a moving
// target — a figure-eight, then random waypoints — while the procedural arm's skin follows the
// physical bones through CGA skinning (eq 17).
//
// The arm runs twice in lockstep on the same targets: with gravity compensation (feed-forward
// joint torques cancelling gravity's moment at the current configuration) and without. The
// motors are torque-limited (maxImpulse = maxTorque · dt), so without compensation gravity
// shows up as tracking error wherever the servo saturates.
#include <BulletDynamics/ConstraintSolver/btConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <BulletDynamics/Featherstone/btMultiBodyJointMotor.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>
#include <BulletDynamics/Featherstone/btMultiBodySphericalJointMotor.h>
#include <btBulletCollisionCommon.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <random>

#include "conform/bullet/convert.hpp"
#include "conform/ik/arm_ik.hpp"
#include "conform/skin/procedural_arm.hpp"
#include "conform/skin/skinner.hpp"
#include "kinds/scene.hpp"

namespace conform::scenes {
namespace {

// The built-in scene `arm-track`, the defaults of this kind (`conform scenes --show arm-track`).
constexpr const char* kArmTrackJson = R"json({
  "scene": "arm-track",
  "description": "A btMultiBody arm (spherical shoulder, revolute elbow; upper arm 0.30 m, forearm 0.25 m) whose torque-limited joint motors follow the closed-form CGA IK solution for a figure-eight and then random waypoints; the procedural arm's skin follows the physical bones through CGA skinning. Runs with and without gravity compensation on the same targets.",
  "seed": 7,
  "model": { "resolution": 1 },
  "arm": {
    "upper_mass": 2.0, "fore_mass": 1.5, "fore_com": 0.14,
    "shoulder_max_torque": 8, "elbow_max_torque": 4,
    "kp": 0.5, "swivel": 0.0, "gravity_compensation": "both"
  },
  "targets": {
    "center": [0.0, -0.25, 0.30],
    "figure_eight": { "width": 0.30, "height": 0.15, "period": 4, "duration": 8 },
    "waypoints": { "count": 6, "move": 0.8, "hold": 0.8,
                   "min_radius": 0.28, "max_radius": 0.50, "cone_deg": 30 }
  },
  "physics": { "dt": 0.016666666666666666, "substeps": 4, "solver_iterations": 10,
               "gravity": [0, -9.81, 0] },
  "outputs": { "metrics_every": 1, "frames_every": 60, "plots": true }
})json";

using Clock = std::chrono::steady_clock;
using Vec3 = Eigen::Vector3d;
constexpr double kPi = std::numbers::pi;

struct ArmTrackSettings {
  int resolution = 1;
  double upper = 0.30, fore = 0.25;                      // m (the procedural arm's)
  double upper_mass = 2.0, fore_mass = 1.5;              // kg (forearm and hand lumped)
  double fore_com = 0.14;                                // elbow → forearm+hand centre of mass, m
  double shoulder_max_torque = 8, elbow_max_torque = 4;  // N·m
  double kp = 0.5;    // motor position gain: fraction of the joint error removed per substep
  double swivel = 0;  // rad
  std::string compensation = "both";  // on, off, both
  Vec3 center{0, -0.25, 0.30};        // figure-eight centre, m
  double eight_width = 0.30, eight_height = 0.15, eight_period = 4, eight_duration = 8;
  int waypoints = 6;
  double move = 0.8, hold = 0.8;  // s per waypoint
  double min_radius = 0.28, max_radius = 0.50, cone_deg = 30;
};

// The target path: figure-eight (phase 0), then smooth moves between random waypoints, each
// followed by a hold (phase 1 moving, phase 2 holding).
class TargetPath {
 public:
  TargetPath(const ArmTrackSettings& s, std::uint64_t seed) : s_(s) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u01(0, 1);
    const Vec3 axis = s.center.normalized();
    const Vec3 e1 = axis.unitOrthogonal(), e2 = axis.cross(e1);
    const double cos_cone = std::cos(s.cone_deg * kPi / 180);
    points_.push_back(at(s.eight_duration));  // the figure-eight's end
    for (int i = 0; i < s.waypoints; ++i) {
      // Uniform on the spherical cap, radius uniform in the shell.
      const double c = 1 - u01(rng) * (1 - cos_cone), phi = 2 * kPi * u01(rng);
      const double sn = std::sqrt(std::max(0.0, 1 - c * c));
      const double r = s.min_radius + (s.max_radius - s.min_radius) * u01(rng);
      points_.push_back(r * (c * axis + sn * (std::cos(phi) * e1 + std::sin(phi) * e2)));
    }
  }
  double length() const { return s_.eight_duration + s_.waypoints * (s_.move + s_.hold); }

  /// Target at time t and its phase.
  Vec3 at(double t, int* phase = nullptr) const {
    if (t <= s_.eight_duration || points_.empty()) {
      if (phase) *phase = 0;
      const double w = 2 * kPi * std::min(t, s_.eight_duration) / s_.eight_period;
      return s_.center +
             Vec3(0.5 * s_.eight_width * std::sin(w), 0.5 * s_.eight_height * std::sin(2 * w), 0);
    }
    const double u = t - s_.eight_duration, slot = s_.move + s_.hold;
    const int i = std::min(static_cast<int>(u / slot), s_.waypoints - 1);
    const double local = std::min(u - i * slot, slot);
    if (local >= s_.move) {
      if (phase) *phase = 2;
      return points_[static_cast<std::size_t>(i) + 1];
    }
    if (phase) *phase = 1;
    const double a = local / s_.move, smooth = a * a * (3 - 2 * a);
    return (1 - smooth) * points_[static_cast<std::size_t>(i)] +
           smooth * points_[static_cast<std::size_t>(i) + 1];
  }
  /// True in the second half of a waypoint hold (the arm has had time to settle).
  bool settled(double t) const {
    if (t <= s_.eight_duration) return false;
    const double u = t - s_.eight_duration, slot = s_.move + s_.hold;
    if (u >= s_.waypoints * slot) return true;
    const double local = u - std::floor(u / slot) * slot;
    return local >= s_.move + 0.5 * s_.hold;
  }

 private:
  ArmTrackSettings s_;
  std::vector<Vec3> points_;
};

// One physical arm in its own world.
class PhysicalArm {
 public:
  PhysicalArm(const ArmTrackSettings& s, const CommonSettings& c, bool compensate)
      : s_(s), compensate_(compensate), sub_dt_(c.dt / c.substeps) {
    world_ =
        std::make_unique<btMultiBodyDynamicsWorld>(&dispatcher_, &broadphase_, &solver_, &config_);
    world_->setGravity(bullet::to_bt(c.gravity));
    world_->getSolverInfo().m_numIterations = c.solver_iterations;
    gravity_ = c.gravity;
    // Links: COM frames; link 0's pivot is the shoulder (origin), link 1's the elbow.
    const double r = 0.04;  // segment radius for the inertia of a solid cylinder
    const auto inertia = [r](double m, double len) {
      const double ia = m * (3 * r * r + len * len) / 12;
      return btVector3(btScalar(ia), btScalar(ia), btScalar(0.5 * m * r * r));
    };
    body_ = std::make_unique<btMultiBody>(2, btScalar(0), btVector3(0, 0, 0), true, false);
    body_->setBaseWorldTransform(btTransform::getIdentity());
    body_->setupSpherical(0, btScalar(s.upper_mass), inertia(s.upper_mass, s.upper), -1,
                          btQuaternion::getIdentity(), btVector3(0, 0, 0),
                          btVector3(0, 0, btScalar(s.upper / 2)), true);
    body_->setupRevolute(1, btScalar(s.fore_mass), inertia(s.fore_mass, s.fore + 0.08), 0,
                         btQuaternion::getIdentity(), btVector3(1, 0, 0),
                         btVector3(0, 0, btScalar(s.upper / 2)),
                         btVector3(0, 0, btScalar(s.fore_com)), true);
    body_->finalizeMultiDof();
    body_->setLinearDamping(0);
    body_->setAngularDamping(0);
    body_->setHasSelfCollision(false);
    world_->addMultiBody(body_.get());
    // Bullet's multibody solver groups motor rows by the simulation islands of the links'
    // colliders: without colliders the motors are never solved. Capsules that collide with
    // nothing (filter mask 0) give every link an island.
    upper_shape_ = std::make_unique<btCapsuleShapeZ>(btScalar(r), btScalar(s.upper - 2 * r));
    fore_shape_ = std::make_unique<btCapsuleShapeZ>(btScalar(r), btScalar(s.fore));
    btCollisionShape* shapes[2] = {upper_shape_.get(), fore_shape_.get()};
    for (int i = 0; i < 2; ++i) {
      auto col = std::make_unique<btMultiBodyLinkCollider>(body_.get(), i);
      col->setCollisionShape(shapes[i]);
      world_->addCollisionObject(col.get(), btBroadphaseProxy::DefaultFilter, 0);
      body_->getLink(i).m_collider = col.get();
      colliders_.push_back(std::move(col));
    }
    shoulder_ = std::make_unique<btMultiBodySphericalJointMotor>(
        body_.get(), 0, btScalar(s.shoulder_max_torque * sub_dt_));
    elbow_ = std::make_unique<btMultiBodyJointMotor>(body_.get(), 1, 0, btScalar(0),
                                                     btScalar(s.elbow_max_torque * sub_dt_));
    world_->addMultiBodyConstraint(shoulder_.get());
    world_->addMultiBodyConstraint(elbow_.get());
  }
  ~PhysicalArm() {
    world_->removeMultiBodyConstraint(elbow_.get());
    world_->removeMultiBodyConstraint(shoulder_.get());
    for (auto& col : colliders_) world_->removeCollisionObject(col.get());
    world_->removeMultiBody(body_.get());
  }

  /// Places the arm on an IK solution at rest.
  void place(const ik::Solution<double>& sol) {
    const btScalar q[4] = {btScalar(sol.qs.x()), btScalar(sol.qs.y()), btScalar(sol.qs.z()),
                           btScalar(sol.qs.w())};
    const btScalar zero[3] = {0, 0, 0};
    body_->setJointPosMultiDof(0, q);
    body_->setJointVelMultiDof(0, zero);
    body_->setJointPos(1, btScalar(elbow_angle(sol)));
    body_->setJointVel(1, 0);
    btAlignedObjectArray<btQuaternion> w2l;
    btAlignedObjectArray<btVector3> origins;
    body_->forwardKinematics(w2l, origins);
    body_->updateCollisionObjectWorldTransforms(w2l, origins);
  }

  static double elbow_angle(const ik::Solution<double>& sol) {
    return 2 * std::atan2(sol.qe.x(), sol.qe.w());
  }

  /// One substep towards `sol` (elbow velocity feed-forward `elbow_rate`).
  void step(const ik::Solution<double>& sol, double elbow_rate) {
    const Eigen::Quaterniond& q = sol.qs;
    // The spherical motor's error row is scaled by the solver's ERP as well; the revolute
    // motor's is not. Both then remove the fraction kp of the error per substep.
    shoulder_->setPositionTarget(
        btQuaternion(btScalar(q.x()), btScalar(q.y()), btScalar(q.z()), btScalar(q.w())),
        btScalar(s_.kp / world_->getSolverInfo().m_erp));
    elbow_->setPositionTarget(btScalar(elbow_angle(sol)), btScalar(s_.kp));
    elbow_->setVelocityTarget(btScalar(elbow_rate), 1);
    if (compensate_) add_gravity_compensation();
    world_->stepSimulation(btScalar(sub_dt_), 0);  // exactly one internal step; forces cleared
  }

  Vec3 shoulder() const { return Vec3::Zero(); }
  Vec3 elbow() const { return world(0, Vec3(0, 0, s_.upper / 2)); }
  Vec3 wrist() const { return world(1, Vec3(0, 0, s_.fore - s_.fore_com)); }
  Vec3 world(int link, const Vec3& local) const {
    return bullet::from_bt(body_->localPosToWorld(link, bullet::to_bt(local)));
  }
  Eigen::Matrix3d rotation(int link) const {
    const btMatrix3x3 m = body_->localFrameToWorld(link, btMatrix3x3::getIdentity());
    Eigen::Matrix3d r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) r(i, j) = m[i][j];
    return r;
  }
  Eigen::Quaterniond shoulder_rotation() const {
    const btScalar* q = body_->getJointPosMultiDof(0);
    return Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized();
  }
  double elbow_position() const { return body_->getJointPos(1); }

 private:
  // τ = −Σ (p_i − pivot) × m_i g: the shoulder carries both links, the elbow the forearm.
  // Spherical joint torques are in link 0's frame; the revolute one is about its axis.
  void add_gravity_compensation() {
    const Vec3 c0 = world(0, Vec3::Zero()), c1 = world(1, Vec3::Zero());
    const Vec3 f0 = s_.upper_mass * gravity_, f1 = s_.fore_mass * gravity_;
    const Vec3 tau_s = -(c0.cross(f0) + c1.cross(f1));
    const Vec3 local = rotation(0).transpose() * tau_s;
    for (int k = 0; k < 3; ++k) body_->addJointTorqueMultiDof(0, k, btScalar(local[k]));
    const Vec3 axis = rotation(1).col(0);
    body_->addJointTorque(1, btScalar(-((c1 - elbow()).cross(f1)).dot(axis)));
  }

  ArmTrackSettings s_;
  bool compensate_;
  double sub_dt_;
  Vec3 gravity_;
  btDefaultCollisionConfiguration config_;
  btCollisionDispatcher dispatcher_{&config_};
  btDbvtBroadphase broadphase_;
  btMultiBodyConstraintSolver solver_;
  std::unique_ptr<btMultiBodyDynamicsWorld> world_;
  std::unique_ptr<btMultiBody> body_;
  std::unique_ptr<btCollisionShape> upper_shape_, fore_shape_;
  std::vector<std::unique_ptr<btMultiBodyLinkCollider>> colliders_;
  std::unique_ptr<btMultiBodySphericalJointMotor> shoulder_;
  std::unique_ptr<btMultiBodyJointMotor> elbow_;
};

struct ErrorStats {
  double sum2 = 0, max = 0, settled_sum = 0;
  long n = 0, settled_n = 0;
  void add(double e, bool settled) {
    sum2 += e * e, max = std::max(max, e), ++n;
    if (settled) settled_sum += e, ++settled_n;
  }
  Json json() const {
    return {{"rms_error", n ? std::sqrt(sum2 / n) : 0.0},
            {"max_error", max},
            {"steady_state_error", settled_n ? settled_sum / settled_n : 0.0}};
  }
};

// The procedural arm's skin posed from a physical arm's joints by CGA skinning. Vertices moved
// by one link only — upper arm (bone 0 alone) or forearm+hand (bones 1, 2, which the fixed
// wrist joint keeps rigid with the forearm) — must land on Bullet's link transforms of their
// rest positions; pose_from() returns the largest miss.
class SkinFollower {
 public:
  explicit SkinFollower(const ArmTrackSettings& s)
      : s_(s),
        arm_(make_arm(s.resolution)),
        skinner_(arm_.skeleton, arm_.mesh.rest, skin::InfluenceLists::from_mesh(arm_.mesh)),
        pose_(skin::Pose::rest(arm_.skeleton)) {
    skinner_.set_threads(s_.resolution > 2 ? 0 : 1);  // a few thousand vertices: one thread
    for (std::int32_t v = 0; v < arm_.mesh.vertex_count(); ++v) {
      double w0 = 0, w12 = 0;
      for (int k = 0; k < mesh::kMaxInfluences; ++k) {
        const double w = arm_.mesh.weights(k, v);
        (arm_.mesh.bones(k, v) == 0 ? w0 : w12) += w;
      }
      if (w0 > 1 - 1e-12) rigid_.emplace_back(v, 0);
      if (w12 > 1 - 1e-12) rigid_.emplace_back(v, 1);
    }
  }
  const mesh::SkinnedMesh& mesh() const { return arm_.mesh; }

  double pose_from(const PhysicalArm& a) {
    pose_.set_local(0, a.shoulder_rotation(), Vec3::Zero());
    pose_.set_local(1, Eigen::Quaterniond(Eigen::AngleAxisd(a.elbow_position(), Vec3::UnitX())),
                    Vec3(0, 0, s_.upper));
    skinner_.skin(pose_, skin::SkinMode::cga);
    skinner_.write(arm_.mesh.current);
    // Skin vs Bullet's links: link frames have their origin at the centre of mass.
    double worst = 0;
    const Eigen::Matrix3d r0 = a.rotation(0), r1 = a.rotation(1);
    const Vec3 o0 = a.world(0, Vec3::Zero()), o1 = a.world(1, Vec3::Zero());
    for (const auto& [v, link] : rigid_) {
      const Vec3 x = arm_.mesh.rest.col(v);
      const Vec3 expect = link == 0 ? Vec3(o0 + r0 * (x - Vec3(0, 0, s_.upper / 2)))
                                    : Vec3(o1 + r1 * (x - Vec3(0, 0, s_.upper + s_.fore_com)));
      worst = std::max(worst, (arm_.mesh.current.col(v) - expect).norm());
    }
    return worst;
  }

 private:
  static skin::Arm make_arm(int resolution) {
    skin::ArmOptions mo;
    mo.resolution = resolution;
    return skin::make_arm(mo);
  }

  const ArmTrackSettings& s_;
  skin::Arm arm_;
  skin::Skinner<double> skinner_;
  skin::Pose pose_;
  std::vector<std::pair<std::int32_t, int>> rigid_;
};

class ArmTrack final : public Scene {
 public:
  ArmTrack(const Json& scene, const std::string& name, int steps_override) {
    Reader root(scene, "", resolved_);
    Reader model = root.object("model");
    s_.resolution = model.integer("resolution", 1, 1, 8);
    model.finish();
    Reader arm = root.object("arm");
    s_.upper_mass = arm.number("upper_mass", s_.upper_mass, 0.01, 100);
    s_.fore_mass = arm.number("fore_mass", s_.fore_mass, 0.01, 100);
    s_.fore_com = arm.number("fore_com", s_.fore_com, 0.01, 0.33);
    s_.shoulder_max_torque = arm.number("shoulder_max_torque", s_.shoulder_max_torque, 0, 1e4);
    s_.elbow_max_torque = arm.number("elbow_max_torque", s_.elbow_max_torque, 0, 1e4);
    s_.kp = arm.number("kp", s_.kp, 1e-3, 1);
    s_.swivel = arm.number("swivel", s_.swivel, -kPi, kPi);
    s_.compensation = arm.text("gravity_compensation", "both", {"on", "off", "both"});
    arm.finish();
    Reader targets = root.object("targets");
    s_.center = targets.vec3("center", s_.center);
    if (s_.center.norm() < 0.1 || s_.center.norm() > 0.5)
      targets.fail("center", resolved_["targets"]["center"],
                   "must be 0.1–0.5 m from the shoulder (the arm reaches 0.55 m)");
    Reader eight = targets.object("figure_eight");
    s_.eight_width = eight.number("width", s_.eight_width, 0, 0.6);
    s_.eight_height = eight.number("height", s_.eight_height, 0, 0.6);
    s_.eight_period = eight.number("period", s_.eight_period, 0.1, 100);
    s_.eight_duration = eight.number("duration", s_.eight_duration, 0, 1000);
    eight.finish();
    Reader way = targets.object("waypoints");
    s_.waypoints = way.integer("count", s_.waypoints, 0, 10000);
    s_.move = way.number("move", s_.move, 0.01, 100);
    s_.hold = way.number("hold", s_.hold, 0.01, 100);
    s_.min_radius = way.number("min_radius", s_.min_radius, 0.05, 0.55);
    s_.max_radius = way.number("max_radius", s_.max_radius, s_.min_radius, 0.55);
    s_.cone_deg = way.number("cone_deg", s_.cone_deg, 0, 180);
    way.finish();
    targets.finish();
    const double length = s_.eight_duration + s_.waypoints * (s_.move + s_.hold);
    common_ = read_common(root, name, std::max(length, 0.1), steps_override);
    root.finish();
  }

  Json run(RunOutput& out) override {
    const CommonSettings& c = common_;
    TrackRun r(s_, c);
    out.open_metrics({"t", "phase", "target_x", "target_y", "target_z", "wrist_x", "wrist_y",
                      "wrist_z", "error", "error_no_compensation", "elbow_angle", "elbow_target",
                      "skin_offset"});
    const auto loop_start = Clock::now();
    r.skin.pose_from(*r.arms[0]);
    out.frame("arm", 0, r.skin.mesh());
    for (int step = 1; step <= c.steps; ++step) {
      std::vector<ik::Solution<double>> subs(static_cast<std::size_t>(c.substeps));
      std::vector<double> rates(static_cast<std::size_t>(c.substeps));
      r.ik_s += seconds([&] { solve_substeps(r, step, subs, rates); });
      r.physics_s += seconds([&] {
        for (auto& a : r.arms)
          for (int k = 0; k < c.substeps; ++k)
            a->step(subs[static_cast<std::size_t>(k)], rates[static_cast<std::size_t>(k)]);
      });
      measure(r, step, out);
      if (out.frame_step(step)) out.frame("arm", step, r.skin.mesh());
      out.progress(step, c.steps);
    }
    const double loop_s = std::chrono::duration<double>(Clock::now() - loop_start).count();
    const Json metrics = summary(r, ik_ns_per_solve(r));
    add_plots(out);
    out.finish(resolved_, metrics, timings(r), c.steps, c.steps * c.dt, loop_s);
    return metrics;
  }

 private:
  // One run: the target path, the physical arms (with and/or without gravity compensation)
  // placed on the IK solution of its start, the skin following the first arm, and the tallies.
  struct TrackRun {
    const CommonSettings& c;
    TargetPath path;
    ik::Arm<double> arm;
    SkinFollower skin;
    std::vector<std::unique_ptr<PhysicalArm>> arms;
    std::vector<bool> compensated;
    ik::Solution<double> prev;  // the last substep's solution (for the elbow rate)
    std::vector<ErrorStats> stats, phase_stats;
    double max_skin_offset = 0;
    double physics_s = 0, skin_s = 0, ik_s = 0;
    long ik_solves = 0, unreachable = 0;
    std::vector<Vec3> targets_seen;

    TrackRun(const ArmTrackSettings& s, const CommonSettings& common)
        : c(common), path(s, common.seed), arm(ik_arm(s)), skin(s) {
      if (s.compensation != "off")
        arms.push_back(std::make_unique<PhysicalArm>(s, c, true)), compensated.push_back(true);
      if (s.compensation != "on")
        arms.push_back(std::make_unique<PhysicalArm>(s, c, false)), compensated.push_back(false);
      prev = ik::solve(arm, path.at(0), s.swivel);
      for (auto& a : arms) a->place(prev);
      const Vec3 fk_wrist = arms[0]->wrist();
      if ((fk_wrist - path.at(0)).norm() > 1e-4)
        throw std::runtime_error(
            "arm-track: the multibody placed on the IK solution misses the target by " +
            std::to_string((fk_wrist - path.at(0)).norm()) + " m");
      stats.resize(arms.size());
      phase_stats.resize(3);
      targets_seen.reserve(static_cast<std::size_t>(c.steps) * c.substeps);
    }
    static ik::Arm<double> ik_arm(const ArmTrackSettings& s) {
      ik::Arm<double> a;
      a.upper = s.upper;
      a.fore = s.fore;
      return a;
    }
  };

  template <class F>
  static double seconds(F&& f) {
    const auto t0 = Clock::now();
    f();
    return std::chrono::duration<double>(Clock::now() - t0).count();
  }

  // The IK solution and elbow rate of every substep, the targets interpolated along the path.
  void solve_substeps(TrackRun& r, int step, std::vector<ik::Solution<double>>& subs,
                      std::vector<double>& rates) const {
    const CommonSettings& c = common_;
    const double sub_dt = c.dt / c.substeps;
    for (int k = 0; k < c.substeps; ++k) {
      const auto i = static_cast<std::size_t>(k);
      const double t = (step - 1) * c.dt + (k + 1) * sub_dt;
      const Vec3 target = r.path.at(t);
      r.targets_seen.push_back(target);
      subs[i] = ik::solve(r.arm, target, s_.swivel);
      ++r.ik_solves;
      if (ik::moved_target(subs[i].status)) ++r.unreachable;
      rates[i] = (PhysicalArm::elbow_angle(subs[i]) - PhysicalArm::elbow_angle(r.prev)) / sub_dt;
      r.prev = subs[i];
    }
  }

  // Tracking errors at the end of the step, the skin posed from the first arm, a metrics row.
  void measure(TrackRun& r, int step, RunOutput& out) const {
    const CommonSettings& c = common_;
    const double t = step * c.dt;
    int phase = 0;
    const Vec3 target = r.path.at(t, &phase);
    const bool settled = r.path.settled(t);
    double errors[2] = {0, 0};
    for (std::size_t i = 0; i < r.arms.size(); ++i) {
      errors[i] = (r.arms[i]->wrist() - target).norm();
      r.stats[i].add(errors[i], settled);
    }
    r.phase_stats[static_cast<std::size_t>(phase)].add(errors[0], settled);
    double offset = 0;
    r.skin_s += seconds([&] { offset = r.skin.pose_from(*r.arms[0]); });
    r.max_skin_offset = std::max(r.max_skin_offset, offset);
    if (step % c.metrics_every == 0 || step == c.steps) {
      const bool both = s_.compensation == "both";
      const Vec3 w = r.arms[0]->wrist();
      const double elbow_target = PhysicalArm::elbow_angle(ik::solve(r.arm, target, s_.swivel));
      const double row[] = {t,
                            double(phase),
                            target.x(),
                            target.y(),
                            target.z(),
                            w.x(),
                            w.y(),
                            w.z(),
                            r.compensated[0] ? errors[0] : (both ? errors[1] : std::nan("")),
                            !r.compensated[0] ? errors[0] : (both ? errors[1] : std::nan("")),
                            r.arms[0]->elbow_position(),
                            elbow_target,
                            offset};
      out.metrics().row(row);
    }
  }

  // IK cost: the recorded targets solved again in a tight loop (≥ 20 ms of work).
  double ik_ns_per_solve(const TrackRun& r) const {
    long solves = 0;
    double check = 0;
    const auto t0 = Clock::now();
    double elapsed = 0;
    do {
      for (const Vec3& p : r.targets_seen) check += ik::solve(r.arm, p, s_.swivel).qs.w();
      solves += static_cast<long>(r.targets_seen.size());
      elapsed = std::chrono::duration<double>(Clock::now() - t0).count();
    } while (elapsed < 0.02 && !r.targets_seen.empty());
    if (!std::isfinite(check)) throw std::runtime_error("arm-track: IK produced NaN");
    return solves ? 1e9 * elapsed / solves : 0;
  }

  static Json summary(const TrackRun& r, double ik_ns) {
    const std::size_t primary = 0;
    Json metrics = r.stats[primary].json();
    metrics["gravity_compensation"] = bool(r.compensated[primary]);
    for (std::size_t i = 0; i < r.arms.size(); ++i)
      metrics[r.compensated[i] ? "with_gravity_compensation" : "without_gravity_compensation"] =
          r.stats[i].json();
    metrics["figure_eight_rms_error"] = r.phase_stats[0].json()["rms_error"];
    metrics["waypoint_moves_rms_error"] = r.phase_stats[1].json()["rms_error"];
    metrics["waypoint_holds_rms_error"] = r.phase_stats[2].json()["rms_error"];
    metrics["steady_state_definition"] =
        "mean wrist-target distance over the second half of every waypoint hold";
    metrics["ik_ns_per_solve"] = ik_ns;
    metrics["ik_solves"] = r.ik_solves;
    metrics["ik_targets_moved"] = r.unreachable;
    metrics["skin_max_offset_from_bones"] = r.max_skin_offset;
    metrics["units"] = "metres (errors), nanoseconds (ik_ns_per_solve)";
    return metrics;
  }

  static void add_plots(RunOutput& out) {
    // On a log scale: the two errors differ by a factor of about 2 and would lie on top of
    // each other on a linear one.
    Plot error{"tracking_error",
               "arm-track: wrist distance from the IK target",
               "time [s]",
               "wrist error [mm] (log scale)",
               {{"metrics.csv", "t", "error", "with gravity compensation", "lines", 1e3},
                {"metrics.csv", "t", "error_no_compensation", "without gravity compensation",
                 "lines", 1e3}},
               {}};
    error.log_y = true;
    out.add_plot(std::move(error));
    out.add_plot({"trajectory",
                  "arm-track: target and wrist (x–y projection)",
                  "x [m]",
                  "y [m]",
                  {{"metrics.csv", "target_x", "target_y", "target", "lines"},
                   {"metrics.csv", "wrist_x", "wrist_y", "wrist (first arm)", "lines"}},
                  {}});
  }

  Json timings(const TrackRun& r) const {
    const CommonSettings& c = common_;
    return {{"physics_ms_per_step", 1e3 * r.physics_s / c.steps},
            {"skinning_ms_per_step", 1e3 * r.skin_s / c.steps},
            {"ik_ms_per_step", 1e3 * r.ik_s / c.steps},
            {"arms_simulated", r.arms.size()},
            {"skin_vertices", r.skin.mesh().vertex_count()}};
  }

  ArmTrackSettings s_;
};

std::unique_ptr<Scene> make_arm_track(const Json& scene, const std::string& name,
                                      int steps_override) {
  return std::make_unique<ArmTrack>(scene, name, steps_override);
}

const SceneRegistration kArmTrackRegistration{
    {"arm-track",
     "btMultiBody arm driven by CGA IK along a figure-eight and random waypoints, skin by CGA "
     "skinning; tracking error with/without gravity compensation",
     kArmTrackJson, &make_arm_track, 1, "rms_error,max_error"}};

}  // namespace
}  // namespace conform::scenes
