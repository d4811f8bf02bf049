// The soft-body scenes of the arm with one topology event, on the Conform plugin (the
// character scene, a user's model, is scene_character.cpp):
//   cut        — a planar cut through the forearm of the moving arm; both pieces keep
//                simulating under gravity, the hand piece stays skinned to its bones;
//   drill      — a hole drilled through the upper arm, then the arm moves; the hole's rim
//                stays on the skin (its nodes stay on their skinned targets).
// Every scene reports how far nodes are from their skinned targets ("offset"), the measure of
// following the skin.
#include <chrono>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>

#include "conform/mesh/analysis.hpp"
#include "conform/skin/procedural_arm.hpp"
#include "conform/skin/skinner.hpp"
#include "kinds/event_time.hpp"
#include "kinds/falling_pieces.hpp"
#include "kinds/scene.hpp"
#include "kinds/soft_scene.hpp"

namespace conform::scenes {
namespace {

// What cut and drill share, each default written once: the seed and duration, the arm (its
// resolution, motion and material), then, closing the file, the step and the outputs.
constexpr std::string_view kArmJson = R"json(
  "seed": 1,
  "duration": 3.0,
  "model": { "resolution": 1 },
  "pose": { "shoulder_swing_deg": 20, "elbow_deg": 10, "elbow_swing_deg": 40, "period": 2 },
  "material": { "target_stiffness": 4000, "target_damping": 40, "kinematic_weight": 2,
                "damping": 0.02 },)json";
constexpr std::string_view kArmRunJson = R"json(
  "physics": { "dt": 0.016666666666666666, "substeps": 2, "solver_iterations": 10,
               "gravity": [0, -9.81, 0] },
  "outputs": { "metrics_every": 1, "frames_every": 30, "plots": true }
})json";
// The built-in scene `cut`, the defaults of this kind (`conform scenes --show cut`).
const std::string kCutJson = join_scene_json({R"json({
  "scene": "cut",
  "description": "The moving procedural arm as a CGA-skinned Bullet soft body (every node pulled toward its skinned target) is cut through the forearm by a plane; both pieces keep simulating under gravity and the hand piece keeps following the wrist and hand bones. With cut.release the hand piece is released from skinning instead and falls (a capped piece, cut.cap, keeps its volume with the bulk modulus cut.volume_modulus, Pa) onto the ground (ground.enabled, its top at ground.height, m), which only released pieces meet.",)json",
                                              kArmJson, R"json(
  "cut": { "at": 0.5, "point": [0, 0, 0.4234], "normal": [0, 0.05, 1], "cap": false,
           "release": false, "volume_modulus": 100000 },
  "ground": { "enabled": false, "height": -0.5 },)json",
                                              kArmRunJson});
// The built-in scene `drill`, the defaults of this kind (`conform scenes --show drill`).
const std::string kDrillJson = join_scene_json({R"json({
  "scene": "drill",
  "description": "A cylindrical drill (radius 12 mm) goes through both walls of the upper arm of the CGA-skinned soft arm; the arm then swings and flexes, and the rim nodes are measured against their skinned targets.",)json",
                                                kArmJson, R"json(
  "drill": { "at": 0.5, "tip": [0.1, 0.0031, 0.1512], "base": [-0.1, 0.0031, 0.1512],
             "radius": 0.012 },)json",
                                                kArmRunJson});
using Clock = std::chrono::steady_clock;
using Vec3 = Eigen::Vector3d;
constexpr double kPi = std::numbers::pi;

// The arm's motion: the shoulder swings about x, the elbow flexes, with one period.
struct ArmMotion {
  double shoulder_deg = 20, elbow_deg = 10, elbow_swing_deg = 40, period = 2, upper = 0.30;
  void read(Reader& root) {
    Reader r = root.object("pose");
    shoulder_deg = r.number("shoulder_swing_deg", shoulder_deg, 0, 90);
    elbow_deg = r.number("elbow_deg", elbow_deg, 0, 150);
    elbow_swing_deg = r.number("elbow_swing_deg", elbow_swing_deg, 0, 150);
    period = r.number("period", period, 0.05, 1000);
    r.finish();
  }
  void pose(const skin::Pose& rest, double t, skin::Pose& p) const {
    p = rest;
    const double w = 2 * kPi * t / period, rad = kPi / 180;
    p.set_local(
        0, Eigen::Quaterniond(Eigen::AngleAxisd(shoulder_deg * rad * std::sin(w), Vec3::UnitX())),
        Vec3::Zero());
    const double elbow = elbow_deg + elbow_swing_deg * 0.5 * (1 - std::cos(w));
    p.set_local(1, Eigen::Quaterniond(Eigen::AngleAxisd(elbow * rad, Vec3::UnitX())),
                Vec3(0, 0, upper));
  }
};

// A rest-space point carried by `bone` of the arm to time t (its skinning versor M B).
Vec3 carried(const skin::Skeleton& sk, const ArmMotion& motion, double t, int bone, const Vec3& x) {
  skin::Pose p;
  motion.pose(skin::Pose::rest(sk), t, p);
  std::vector<skin::Versor> global(static_cast<std::size_t>(sk.joint_count()));
  std::vector<skin::Versor> versors(static_cast<std::size_t>(sk.bone_count()));
  skin::global_versors(sk, p, global);
  skin::skinning_versors(sk, global, versors);
  return versors[static_cast<std::size_t>(bone)].apply(x);
}

bullet::Material arm_material() {
  bullet::Material m;
  m.kinematic_weight = 2;  // every node soft, pulled to its target
  m.target_stiffness = 4000;
  m.target_damping = 40;
  m.damping = 0.02;
  return m;
}

skin::Arm posed_arm(int resolution, const ArmMotion& motion) {
  skin::ArmOptions mo;
  mo.resolution = resolution;
  skin::Arm arm = skin::make_arm(mo);
  skin::Pose pose;
  motion.pose(skin::Pose::rest(arm.skeleton), 0, pose);
  skin::Skinner<double> skinner(arm.skeleton, arm.mesh.rest,
                                skin::InfluenceLists::from_mesh(arm.mesh));
  skinner.set_threads(1);
  skinner.skin(pose, skin::SkinMode::cga);
  skinner.write(arm.mesh.current);
  return arm;
}

// cut and drill share the loop: the arm moves, one event at `at`, offsets measured.
class ArmEventScene : public Scene {
 public:
  enum class Kind { cut, drill };
  ArmEventScene(Kind kind, const Json& scene, const std::string& name, int steps_override)
      : kind_(kind) {
    Reader root(scene, "", resolved_);
    Reader model = root.object("model");
    resolution_ = model.integer("resolution", 1, 1, 8);
    model.finish();
    motion_.read(root);
    material_ = read_material(root, arm_material());
    Reader ev = root.object(kind == Kind::cut ? "cut" : "drill");
    at_ = ev.number("at", 0.5, 0, 1e5);
    if (kind == Kind::cut) {
      point_ = ev.vec3("point", Vec3(0, 0, 0.4234));
      normal_ = ev.vec3("normal", Vec3(0, 0.05, 1));
      if (normal_.norm() < 1e-9) ev.fail("normal", Json{0, 0, 0}, "must not be zero");
      cap_ = ev.boolean("cap", false);
      sever_ = read_sever(ev, {false, 1e5});
    } else {
      tip_ = ev.vec3("tip", Vec3(0.1, 0.0031, 0.1512));
      base_ = ev.vec3("base", Vec3(-0.1, 0.0031, 0.1512));
      radius_ = ev.number("radius", 0.012, 1e-4, 0.1);
      if ((tip_ - base_).norm() < 1e-9)
        ev.fail("tip", Json{tip_.x(), tip_.y(), tip_.z()}, "must differ from base");
    }
    ev.finish();
    // Under the arm's lowest reach (0.7 m at a 20 degree swing: 0.24 m below the shoulder).
    if (kind == Kind::cut) ground_ = read_ground(root, {false, -0.5});
    common_ = read_common(root, name, 3.0, steps_override);
    root.finish();
  }

  Json run(RunOutput& out) override {
    const CommonSettings& c = common_;
    skin::Arm arm = posed_arm(resolution_, motion_);
    SoftWorld w(c);
    bullet::SkinnedSoftBody& body = w.plugin->add_skinned_body(arm.mesh, arm.skeleton, material_);
    out.warn_material(body);
    const skin::Pose rest = skin::Pose::rest(arm.skeleton);
    const ArmMotion motion = motion_;
    body.set_pose_source([motion, rest](double t, skin::Pose& p) { motion.pose(rest, t, p); });

    const bool is_cut = kind_ == Kind::cut;
    require_before_end(c, is_cut ? "cut.at" : "drill.at", at_, is_cut ? "the cut" : "the drill",
                       at_);
    out.open_metrics(metric_columns());
    std::optional<Ground> ground;
    if (ground_.enabled) ground.emplace(w, ground_.height, Vec3(0, 0, 0.35), 1.0);
    FallingPieces falling;
    bool done = false;
    int holes = 0;
    double event_ms = 0, physics_ms = 0;
    Json event;
    std::vector<std::int32_t> special, others;  // hand (cut) or rim (drill) vertices; the rest
    OffsetStats worst_special{}, all_special{};
    long special_samples = 0;
    out.body_frame("arm", 0, body);
    const auto loop_start = Clock::now();
    for (int step = 1; step <= c.steps; ++step) {
      const auto tp = Clock::now();
      w.step();
      physics_ms += std::chrono::duration<double, std::milli>(Clock::now() - tp).count();
      const double t = step * c.dt;
      if (!done && event_due(t, at_)) {
        done = true;
        const auto te = Clock::now();
        if (is_cut) falling.before_cut(body);
        event = is_cut ? cut_at(body, arm, t, special, others)
                       : drill_at(body, arm, t, holes, special, others);
        if (sever_.release)
          event["released"] =
              falling.release_severed(body, sever_.volume_modulus, ground ? &*ground : nullptr);
        event_ms = std::chrono::duration<double, std::milli>(Clock::now() - te).count();
        continue;  // offsets are measured once the plugin has skinned the new vertices
      }
      const OffsetStats all = offsets(body, {});
      falling.measure(body, ground ? &*ground : nullptr);
      // The hand piece (or the rim) and the rest do not exist before the event: blank, not 0.
      constexpr double absent = RunOutput::Csv::kAbsent;
      OffsetStats sp{absent, absent}, rs{absent, absent};
      if (!special.empty() && !falling.any()) {  // a released hand is not skinned
        sp = offsets(body, special);
        rs = offsets(body, others);
        worst_special.max = std::max(worst_special.max, sp.max);
        all_special.mean += sp.mean, ++special_samples;
      }
      if (step % c.metrics_every == 0 || step == c.steps) {
        std::vector<double> row{t,
                                is_cut ? double(body.piece_count()) : double(holes),
                                all.mean,
                                all.max,
                                sp.mean,
                                sp.max,
                                is_cut ? rs.mean : double(special.size()),
                                double(body.vertex_count())};
        if (sever_.release) row.push_back(falling.any() ? falling.lowest() : absent);
        out.metrics().row(row);
      }
      if (out.frame_step(step)) {
        body.sync_mesh();
        out.body_frame("arm", step, body);
      }
      out.progress(step, c.steps);
    }
    const double loop_s = std::chrono::duration<double>(Clock::now() - loop_start).count();
    if (!finite_nodes(body)) throw std::runtime_error("the soft body blew up (non-finite nodes)");
    Json metrics = summary(body, event, all_special, worst_special, special_samples);
    if (sever_.release) metrics["released_pieces"] = falling.summary();
    if (is_cut) metrics["ground"] = ground_summary(ground_);
    add_plot(out);
    Json timings = {{"physics_ms_per_step", physics_ms / c.steps}, {"event_ms", event_ms}};
    out.finish(resolved_, metrics, timings, c.steps, c.steps * c.dt, loop_s);
    return metrics;
  }

  // metrics.csv's columns: the hand (cut) or the rim (drill), and the released pieces' lowest
  // node when the cut releases them.
  std::vector<std::string> metric_columns() const {
    const std::string what = kind_ == Kind::cut ? "hand" : "rim";
    std::vector<std::string> columns{"t",
                                     kind_ == Kind::cut ? "pieces" : "holes",
                                     "offset_mean",
                                     "offset_max",
                                     what + "_offset_mean",
                                     what + "_offset_max",
                                     kind_ == Kind::cut ? "rest_offset_mean" : "rim_vertices",
                                     "nodes"};
    if (sever_.release) columns.push_back("released_lowest_m");
    return columns;
  }

  // The cut at time t, its plane given in the rest arm and moved with the forearm (bone 1);
  // `special` gets the hand piece's vertices (the piece of the finger tips), `others` the rest.
  Json cut_at(bullet::SkinnedSoftBody& body, const skin::Arm& arm, double t,
              std::vector<std::int32_t>& special, std::vector<std::int32_t>& others) const {
    const std::int32_t fingertip = arm.mesh.vertex_count() - 1;  // the hand's pole
    const std::int32_t before = body.vertex_count();
    mesh::CutOptions options;
    options.cap = cap_;
    const Vec3 p = carried(arm.skeleton, motion_, t, 1, point_);
    const Vec3 n = carried(arm.skeleton, motion_, t, 1, point_ + normal_.normalized()) - p;
    const auto r = body.cut(cga::Plane<double>::from_normal_point(n.normalized(), p), options);
    Json event = {{"status", r.status == mesh::CutStatus::Cut ? "cut" : "missed"},
                  {"crossed_edges", r.crossed_edges},
                  {"new_vertices", body.vertex_count() - before},
                  {"capped_loops", r.capped_loops}};
    if (r.status != mesh::CutStatus::Cut) throw std::runtime_error("cut: the plane missed the arm");
    const mesh::Pieces pieces = mesh::label_pieces(body.mesh());
    std::vector<std::int32_t> piece_of(static_cast<std::size_t>(body.vertex_count()), -1);
    for (std::int32_t f = 0; f < body.mesh().face_count(); ++f)
      for (const std::int32_t v : body.mesh().faces[static_cast<std::size_t>(f)])
        piece_of[static_cast<std::size_t>(v)] = pieces.face_piece[static_cast<std::size_t>(f)];
    const std::int32_t hand = piece_of[static_cast<std::size_t>(fingertip)];
    for (std::int32_t v = 0; v < body.vertex_count(); ++v)
      (piece_of[static_cast<std::size_t>(v)] == hand ? special : others).push_back(v);
    event["hand_piece_vertices"] = special.size();
    return event;
  }

  // The drill at time t, given in the rest arm and moved with the upper arm (bone 0);
  // `special` gets the rim (vertices on the cylinder when drilled: new and snapped ones).
  Json drill_at(bullet::SkinnedSoftBody& body, const skin::Arm& arm, double t, int& holes,
                std::vector<std::int32_t>& special, std::vector<std::int32_t>& others) const {
    const std::int32_t before = body.vertex_count();
    const mesh::DrillTool tool{carried(arm.skeleton, motion_, t, 0, tip_),
                               carried(arm.skeleton, motion_, t, 0, base_), radius_};
    const auto r = body.drill(tool);
    Json event = {{"holes", r.holes},
                  {"rim_vertices", r.rim_vertices},
                  {"removed_area", r.removed_area},
                  {"refinements", r.refinements},
                  {"new_vertices", body.vertex_count() - before}};
    holes = r.holes;
    if (r.holes == 0) throw std::runtime_error("drill: the drill missed the arm: " + r.message);
    for (std::int32_t v = 0; v < body.vertex_count(); ++v) {
      const double d = std::sqrt(mesh::axis_distance_squared(tool, body.position(v)));
      (std::abs(d - radius_) < 0.02 * radius_ ? special : others).push_back(v);
    }
    event["rim_nodes"] = special.size();
    return event;
  }

  Json summary(const bullet::SkinnedSoftBody& body, const Json& event,
               const OffsetStats& all_special, const OffsetStats& worst_special,
               long special_samples) const {
    const OffsetStats final_all = offsets(body, {});
    Json metrics;
    metrics["event"] = event;
    metrics["pieces"] = body.piece_count();
    metrics["nodes"] = body.vertex_count();
    metrics["offset_mean"] = final_all.mean;
    metrics["offset_max"] = final_all.max;
    const std::string what = kind_ == Kind::cut ? "hand" : "rim";
    metrics[what + "_offset_mean_over_time"] =
        special_samples ? all_special.mean / special_samples : 0.0;
    metrics[what + "_offset_max_over_time"] = worst_special.max;
    metrics["units"] = "metres: offset = distance of a node from its CGA-skinned target";
    return metrics;
  }

  void add_plot(RunOutput& out) const {
    const bool is_cut = kind_ == Kind::cut;
    const std::string what = is_cut ? "hand" : "rim", name = is_cut ? "hand piece" : "hole rim";
    // In mm; the piece's lines start at the event (blank before it), which a dashed line marks.
    Plot plot("offsets",
              std::string(is_cut ? "cut" : "drill") + ": distance of nodes from their targets",
              "time [s]", "distance from the CGA-skinned target [mm]", {});
    plot.series = {{"metrics.csv", "t", "offset_mean", "all nodes (mean)", "lines", 1e3},
                   {"metrics.csv", "t", what + "_offset_mean", name + " (mean)", "lines", 1e3},
                   {"metrics.csv", "t", what + "_offset_max", name + " (max)", "lines", 1e3}};
    plot.events = {{at_, is_cut ? "cut" : "drill"}};
    out.add_plot(std::move(plot));
    if (sever_.release) out.add_plot(falling_plot("cut", ground_.enabled, at_));
  }

 private:
  Kind kind_;
  int resolution_ = 1;
  ArmMotion motion_;
  bullet::Material material_;
  double at_ = 0.5;
  Vec3 point_, normal_, tip_, base_;
  double radius_ = 0.01;
  bool cap_ = false;
  SeverSettings sever_;    // cut.release: the hand piece falls (the cut's parts but the largest)
  GroundSettings ground_;  // what it falls onto
};

std::unique_ptr<Scene> make_cut(const Json& scene, const std::string& name, int steps) {
  return std::make_unique<ArmEventScene>(ArmEventScene::Kind::cut, scene, name, steps);
}
std::unique_ptr<Scene> make_drill(const Json& scene, const std::string& name, int steps) {
  return std::make_unique<ArmEventScene>(ArmEventScene::Kind::drill, scene, name, steps);
}
const SceneRegistration kCutRegistration{
    {"cut",
     "a planar cut through the forearm of the moving soft arm; the pieces keep simulating under "
     "gravity, the hand piece stays skinned to its bones",
     kCutJson.c_str(), &make_cut, 2, "offset_max,offset_mean"}};
const SceneRegistration kDrillRegistration{
    {"drill",
     "a hole drilled through the upper arm, then the arm moves; the hole's rim stays on the skin",
     kDrillJson.c_str(), &make_drill, 3, "offset_max,offset_mean"}};
}  // namespace
}  // namespace conform::scenes
