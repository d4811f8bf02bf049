// `tear-opening`: the skinned arm under tension is torn by a scalpel stroke along the forearm;
// the same stroke is run twice on the same pose:
//   physics    — a SkinnedSoftBody (Bullet soft body skinned by CGA) whose skin is the
//                pre-stressed membrane (Material::skin, SI units) attached to the skinned
//                targets; the wound opens by itself because the skin is under tension
//                (material.model = "bullet_links" runs Bullet's pre-tensioned links instead);
//   geometric  — the same tear on the posed mesh alone (Algorithm 2), opened by step 6 (the
//                borders moved apart by a prescribed sine taper once the stroke ends).
// Measured over time: the gap-width profile along the tear, the largest opening and the opened
// area; at the end an elliptical fit of the physical profile (a slit in a stretched membrane
// opens as an ellipse). pose.flex_deg flexes the elbow after the stroke (the physical wound
// follows the pose, the geometric one does not); tear.direction = "across" turns the incision
// around the limb, across skin-tension lines given by material.prestress / prestress_axis.
// tear.growth lets the physical tear grow by itself once the stroke is done, where the energy
// release rate at a tip reaches material.toughness (Material::growth, tear_growth.hpp).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <numbers>
#include <sstream>

#include "conform/skin/procedural_arm.hpp"
#include "conform/skin/skinner.hpp"
#include "kinds/event_time.hpp"
#include "kinds/geometric_tear.hpp"
#include "kinds/opening_profiles.hpp"
#include "kinds/scene.hpp"
#include "kinds/soft_scene.hpp"

namespace conform::scenes {
namespace {

// The built-in scene `tear-opening`, the defaults of this kind (`conform scenes --show
// tear-opening`).
constexpr const char* kTearOpeningJson = R"json({
  "scene": "tear-opening",
  "description": "The procedural arm as a CGA-skinned Bullet soft body whose skin is a pre-stressed membrane in SI units (human skin: E 0.42 MPa, 1.5 mm, 10 % pre-strain) attached to the skinned targets, torn along the forearm by a scalpel stroke; the same stroke on the posed mesh alone is opened by Algorithm 2 step 6. Compares the gap-width profiles over time. tear.growth lets the physical incision grow by itself once the stroke is done, where its energy release rate reaches material.toughness. material.model = bullet_links runs Bullet's pre-tensioned links instead (the link keys below).",
  "seed": 1,
  "duration": 3.0,
  "model": { "resolution": 1 },
  "pose": { "elbow_deg": 0, "flex_deg": 0, "flex_at": 1.5, "flex_duration": 0.5 },
  "material": {
    "model": "membrane",
    "law": "neo-hookean", "youngs_modulus": 420000, "poisson_ratio": 0.48, "thickness": 0.0015, "areal_density": 1.65,
    "prestress": [80800, 80800], "prestress_axis": [0, 0, 1],
    "attachment_stiffness": 400000, "attachment_normal_stiffness": 40000000,
    "attachment_damping": 1600, "wrinkling": true, "relative_tolerance": 0.0012,
    "pretension": 0.2, "link_stiffness": 0.9, "damping": 0.02, "density": 1.1,
    "target_stiffness": 4000, "target_damping": 40, "kinematic_weight": 2,
    "position_iterations": 4, "margin": 0.005
  },
  "tear": {
    "at": 0.5, "duration": 0.5, "samples": 40,
    "from": [0, 0.0023, 0.3712], "to": [0, 0.0023, 0.4912],
    "blade_a": [0.09, 0, 0], "blade_b": [0.005, 0, 0], "direction": "along",
    "growth": false, "growth_radius": 0.015
  },
  "geometric": { "amount": 0.01 },
  "profiles": { "snapshots": 6, "points": 41 },
  "physics": { "dt": 0.016666666666666666, "substeps": 1, "solver_iterations": 10,
               "gravity": [0, -9.81, 0] },
  "outputs": { "metrics_every": 1, "frames_every": 30, "plots": true }
})json";

using Clock = std::chrono::steady_clock;
using Vec3 = Eigen::Vector3d;

class TearOpening final : public Scene {
 public:
  TearOpening(const Json& scene, const std::string& name, int steps_override) {
    Reader root(scene, "", resolved_);
    Reader model = root.object("model");
    resolution_ = model.integer("resolution", 1, 1, 8);
    model.finish();
    Reader pose = root.object("pose");
    // The stroke is in world space: with a flexed elbow, move it with the forearm.
    elbow_deg_ = pose.number("elbow_deg", 0, 0, 150);
    // After the stroke the elbow may flex: the physical wound follows the pose.
    flex_deg_ = pose.number("flex_deg", 0, -150, 150);
    flex_at_ = pose.number("flex_at", 1.5, 0, 1e5);
    flex_duration_ = pose.number("flex_duration", 0.5, 1e-3, 1e5);
    if (elbow_deg_ + flex_deg_ < 0 || elbow_deg_ + flex_deg_ > 150)
      pose.fail("flex_deg", flex_deg_, "elbow_deg + flex_deg must stay in [0, 150]");
    pose.finish();
    bullet::Material d;
    d.pretension = 0.2;
    d.kinematic_weight = 2;     // nothing kinematic: every node follows its target softly
    d.target_stiffness = 4000;  // sag under gravity g/k = 2.5 mm
    d.target_damping = 40;
    d.damping = 0.02;
    d.position_iterations = 4;
    material_ = read_material(root, d);
    Reader tear = root.object("tear");
    Stroke s;
    s.at = 0.5, s.duration = 0.5, s.samples = 40;
    s.from = Vec3(0, 0.0023, 0.3712), s.to = Vec3(0, 0.0023, 0.4912);  // off the vertex columns
    s.blade_a = Vec3(0.09, 0, 0), s.blade_b = Vec3(0.005, 0, 0);       // crosses the +x wall only
    stroke_ = read_stroke(tear, s);
    // "across": the same incision turned a quarter around the limb axis (circumferential),
    // e.g. across the principal pre-stress of skin-tension lines.
    across_ = tear.text("direction", "along", {"along", "across"}) == "across";
    if (across_) {
      const Vec3 centre = 0.5 * (stroke_.from + stroke_.to);
      const double half = 0.5 * (stroke_.to - stroke_.from).norm();
      stroke_.from = centre - half * Vec3::UnitY();
      stroke_.to = centre + half * Vec3::UnitY();
    }
    material_.growth.enabled = tear.boolean("growth", false);
    material_.growth.domain_radius = tear.number("growth_radius", 0.015, 1e-4, 1);
    if (material_.growth.enabled && material_.model != bullet::MaterialModel::membrane)
      tear.fail("growth", true, "needs material.model = membrane (Griffith on its energy)");
    tear.finish();
    compare_ = read_comparison_keys(root);  // geometric.amount in metres
    common_ = read_common(root, name, 3.0, steps_override);
    root.finish();
  }

  Json run(RunOutput& out) override {
    const CommonSettings& c = common_;
    require_before_end(c, "tear.at", stroke_.at, "the tear's last sample (tear.at + tear.duration)",
                       stroke_.time(stroke_.samples - 1));
    if (flex_deg_ != 0) require_before_end(c, "pose.flex_at", flex_at_, "the flex", flex_at_);
    skin::Pose pose;
    TearRun r(posed_arm(pose), pose, c, material_,
              OpeningProfiles(compare_.points, compare_.snapshots, stroke_.at, c.steps, c.dt));
    out.warn_material(r.body);
    r.body.set_pose_source(flexing_pose(pose));
    out.open_metrics({"t", "physics_tear_points", "geometric_tear_points", "physics_max_opening",
                      "geometric_max_opening", "physics_area", "geometric_area",
                      "physics_profile_r2", "geometric_profile_r2", "pieces",
                      "physics_newton_iterations", "physics_cg_iterations", "physics_residual",
                      "physics_energy_release_rate", "physics_grown_length"});
    r.profiles.open_history(out);
    const Lips no_lips_yet;
    out.body_frame("physics", 0, r.body, &no_lips_yet);
    const auto loop_start = Clock::now();
    for (int step = 1; step <= c.steps; ++step) {
      r.physics_ms += milliseconds([&] { r.world.step(); });
      const double t = step * c.dt;
      note_solve(r, t);
      r.tear_ms += milliseconds([&] { advance_stroke(r, t); });  // edits only between steps
      if (r.next == stroke_.samples) grow(r, t);
      r.measure_ms += milliseconds([&] { measure(r, step, t, out); });
      const bool frame = out.frame_step(step);
      if (frame || out.offers_pictures()) {
        r.body.sync_mesh();
        const Lips lips = tear_lips(r.body.tear());
        if (frame) {
          out.body_frame("physics", step, r.body, &lips);
          out.frame("geometric", step, r.geo.mesh());
        }
        out.picture(step,
                    {{"physics", &r.body.mesh(), lips, gap_caption(r.phys)},
                     {"geometric", &r.geo.mesh(), tear_lips(&r.geo.tear()), gap_caption(r.geom)}},
                    frame);
      }
      out.progress(step, c.steps);
    }
    const double loop_s = std::chrono::duration<double>(Clock::now() - loop_start).count();
    check_torn(r);
    r.profiles.write(out);
    std::vector<PlotEvent> events = {
        {stroke_.at, "stroke starts"},
        {stroke_.time(stroke_.samples - 1), "stroke ends, geometric opened"}};
    if (flex_deg_ != 0) events.push_back({flex_at_, "elbow flexes"});
    r.profiles.add_plots(out,
                         {"tear-opening", "physics (pre-stressed skin membrane in Bullet)",
                          "geometric (Algorithm 2 step 6)", "geometric (step 6)"},
                         events);
    const Json metrics = summary(r);
    out.finish(resolved_, metrics, timings(r), c.steps, c.steps * c.dt, loop_s);
    return metrics;
  }

 private:
  // Everything one run keeps: the same posed arm torn twice, as a mesh alone (geometric) and
  // as a soft body (physics), and what is measured along the way.
  struct TearRun {
    skin::Arm arm;
    GeometricTear geo;  // the geometric run: the mesh alone
    SoftWorld world;    // the physics run
    double build_ms = 0;
    bullet::SkinnedSoftBody& body;
    OpeningProfiles profiles;
    int next = 0;  // the next stroke sample
    Profile phys, geom;
    double max_phys = 0, max_geom = 0, tear_ms = 0, measure_ms = 0, physics_ms = 0;
    int tear_steps = 0;
    // The tear's own growth: G at its tips at the last judgement and over the run, J/m^2.
    double g_now = 0, g_max = 0, growth_ms = 0, growth_onset = -1;
    double growth_mass_error = 0, growth_momentum_error = 0;  // relative, worst growth step
    std::vector<bullet::TipGrowth> last_tips;                 // the last judgement of the tips
    int growth_steps = 0;
    double worst_residual = 0, before_flex = -1;  // the membrane's solves; the opening then
    int unconverged = 0;

    TearRun(skin::Arm posed, const skin::Pose& pose, const CommonSettings& c,
            const bullet::Material& material, OpeningProfiles kept)
        : arm(std::move(posed)),
          geo(arm.mesh, lips()),
          world(c),
          body(add_body(world, arm, material, build_ms)),
          profiles(std::move(kept)) {
      body.set_pose(pose);
      body.begin_tear(lips());
    }
    // Both runs tear with the same smooth lips (tear.hpp).
    static mesh::TearOptions lips() {
      mesh::TearOptions o;
      o.smooth_lips = true;
      return o;
    }
    static bullet::SkinnedSoftBody& add_body(SoftWorld& w, const skin::Arm& arm,
                                             const bullet::Material& material, double& ms) {
      bullet::SkinnedSoftBody* body = nullptr;
      ms = milliseconds(
          [&] { body = &w.plugin->add_skinned_body(arm.mesh, arm.skeleton, material); });
      return *body;
    }
  };

  template <class F>
  static double milliseconds(F&& f) {
    const auto t0 = Clock::now();
    f();
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  }

  // The arm with its elbow flexed; both runs start from this posed (skinned) arm.
  skin::Arm posed_arm(skin::Pose& pose) const {
    skin::ArmOptions mo;
    mo.resolution = resolution_;
    skin::Arm arm = skin::make_arm(mo);
    pose = skin::Pose::rest(arm.skeleton);
    pose.set_local(
        1,
        Eigen::Quaterniond(Eigen::AngleAxisd(elbow_deg_ * std::numbers::pi / 180, Vec3::UnitX())),
        Vec3(0, 0, mo.upper_arm));
    skin::Skinner<double> skinner(arm.skeleton, arm.mesh.rest,
                                  skin::InfluenceLists::from_mesh(arm.mesh));
    skinner.set_threads(1);
    skinner.skin(pose, skin::SkinMode::cga);
    skinner.write(arm.mesh.current);
    return arm;
  }

  // The posed arm, its elbow flexing by flex_deg over flex_duration from flex_at (smoothstep).
  std::function<void(double, skin::Pose&)> flexing_pose(const skin::Pose& start) const {
    const double upper_arm = skin::ArmOptions{}.upper_arm;
    return [=, this](double time, skin::Pose& out) {
      out = start;
      const double u = std::clamp((time - flex_at_) / flex_duration_, 0.0, 1.0);
      const double deg = elbow_deg_ + flex_deg_ * u * u * (3 - 2 * u);
      out.set_local(
          1, Eigen::Quaterniond(Eigen::AngleAxisd(deg * std::numbers::pi / 180, Vec3::UnitX())),
          Vec3(0, 0, upper_arm));
    };
  }

  // The membrane's solve of the step just taken (its worst residual, unconverged substeps) and
  // the opening as it stood before the elbow flexed.
  void note_solve(TearRun& r, double t) const {
    const membrane::SolveReport& solve = r.body.last_solve();
    r.worst_residual = std::max(r.worst_residual, solve.residual);
    r.unconverged += material_.model == bullet::MaterialModel::membrane && !solve.converged;
    if (t <= flex_at_ + 1e-12) r.before_flex = r.phys.max;
  }

  // The stroke's samples due by time t cut both runs; Algorithm 2 step 6 opens the geometric
  // tear once the stroke is done.
  void advance_stroke(TearRun& r, double t) const {
    while (r.next < stroke_.samples && event_due(t, stroke_.time(r.next))) {
      const mesh::ScalpelSample sample = stroke_.sample(r.next);
      r.body.tear_advance(sample);
      r.geo.advance(sample);
      ++r.next, ++r.tear_steps;
    }
    if (r.next == stroke_.samples && !r.geo.opened()) r.geo.open(compare_.amount);
  }

  // Griffith's growth of the physical tear (nothing unless tear.growth): its tips' G, and when
  // it first grew.
  void grow(TearRun& r, double t) const {
    if (!material_.growth.enabled) return;
    const double mass = r.body.total_mass();
    const Vec3 momentum = r.body.momentum();
    bullet::TearGrowthReport report;
    r.growth_ms += milliseconds([&] { report = r.body.grow_tear(); });
    if (report.grown > 0) {  // a growth step conserves mass and momentum like any edit
      r.growth_mass_error =
          std::max(r.growth_mass_error, std::abs(r.body.total_mass() - mass) / mass);
      r.growth_momentum_error =
          std::max(r.growth_momentum_error, (r.body.momentum() - momentum).norm() /
                                                std::max(r.body.momentum_scale(), 1e-300));
    }
    ++r.growth_steps;
    r.g_now = 0;
    for (const bullet::TipGrowth& tip : report.tips)
      r.g_now = std::max(r.g_now, tip.energy_release_rate);
    if (!report.tips.empty()) r.last_tips = report.tips;
    r.g_max = std::max(r.g_max, r.g_now);
    if (report.grown > 0 && r.growth_onset < 0) r.growth_onset = t;
  }

  // Both profiles now; a metrics row, the profile history and the snapshots when due.
  void measure(TearRun& r, int step, double t, RunOutput& out) const {
    const mesh::Tear* pt = r.body.tear();
    if (pt && pt->path_length() >= 2) r.phys = physical_profile(r.body);
    if (r.geo.tear().path_length() >= 2) r.geom = r.geo.profile();
    r.max_phys = std::max(r.max_phys, r.phys.max);
    r.max_geom = std::max(r.max_geom, r.geom.max);
    if (step % common_.metrics_every == 0 || step == common_.steps) {
      const membrane::SolveReport& solve = r.body.last_solve();  // the step's last substep
      const double row[] = {t,
                            double(pt ? pt->path_length() : 0),
                            double(r.geo.tear().path_length()),
                            r.phys.max,
                            r.geom.max,
                            r.phys.area,
                            r.geom.area,
                            r.phys.r2,
                            r.geom.r2,
                            double(r.body.piece_count()),
                            double(solve.newton_iterations),
                            double(solve.cg_iterations),
                            solve.residual,
                            r.g_now,
                            r.body.tear_grown_length()};
      out.metrics().row(row);
      if (r.next > 0) r.profiles.history_row(t, r.phys, r.geom);
    }
    r.profiles.snapshot(step, t, r.phys, r.geom);
  }

  // A run whose scalpel never tore a run measured nothing: an error naming what it missed.
  static void check_torn(TearRun& r) {
    const mesh::Tear* pt = r.body.tear();
    if (!pt || pt->path_length() < 2) {
      r.body.sync_mesh();
      const auto& x = r.body.mesh().current;
      std::ostringstream box;
      box << "skin bounding box [" << x.rowwise().minCoeff().transpose() << "] – ["
          << x.rowwise().maxCoeff().transpose() << "] m";
      throw std::runtime_error("tear-opening: the scalpel never tore the physical skin (" +
                               (pt ? pt->message() : std::string("no tear")) + "; " + box.str() +
                               ")");
    }
    if (r.geo.tear().path_length() < 2)
      throw std::runtime_error("tear-opening: the scalpel never tore the mesh (" +
                               r.geo.tear().message() + ")");
  }

  Json summary(const TearRun& r) const {
    const auto part = [](const Profile& p, double largest, const mesh::Tear& tear) {
      return Json{{"max_opening", p.max},
                  {"max_opening_over_time", largest},
                  {"opened_area", p.area},
                  {"profile_r2", p.r2},
                  {"profile_fit_max", p.fit_max},
                  {"tear_length_rest", p.length},
                  {"tear_points", tear.path_length()}};
    };
    Json metrics;
    metrics["physics"] = part(r.phys, r.max_phys, *r.body.tear());
    metrics["geometric"] = part(r.geom, r.max_geom, r.geo.tear());
    metrics["geometric"]["amount"] = compare_.amount;
    const membrane::SolveReport& solve = r.body.last_solve();
    metrics["physics"]["residual"] = solve.residual;                    // Pa, the last substep's
    metrics["physics"]["relative_residual"] = solve.relative_residual;  // over the pre-stress
    metrics["physics"]["residual_max"] = r.worst_residual;
    metrics["physics"]["unconverged_substeps"] = r.unconverged;
    metrics["physics"]["newton_iterations"] = solve.newton_iterations;
    metrics["physics"]["cg_iterations"] = solve.cg_iterations;
    metrics["physics"]["max_opening_before_flex"] = r.before_flex;
    metrics["physics"]["growth"] = material_.growth.enabled;
    metrics["physics"]["grown_length"] = r.body.tear_grown_length();
    metrics["physics"]["max_energy_release_rate"] = r.g_max;
    metrics["physics"]["toughness"] = material_.skin.toughness;
    metrics["physics"]["growth_onset_time"] = r.growth_onset;
    metrics["physics"]["tips"] = tips_json(r.last_tips);
    metrics["physics"]["growth_mass_error"] = r.growth_mass_error;
    metrics["physics"]["growth_momentum_error"] = r.growth_momentum_error;
    metrics["physics"]["material"] =
        material_.model == bullet::MaterialModel::membrane ? "membrane" : "bullet_links";
    metrics["tear_direction"] = across_ ? "across" : "along";
    metrics["pieces"] = r.body.piece_count();
    metrics["nodes"] = r.body.vertex_count();
    metrics["units"] = "metres, square metres; profile_r2 of w_max*sqrt(1-(2s-1)^2)";
    return metrics;
  }

  // Each tip's last judgement: G (J/m^2), K_I and K_II (Pa m^1/2), the kink (degrees).
  static Json tips_json(const std::vector<bullet::TipGrowth>& tips) {
    Json out = Json::array();
    for (const bullet::TipGrowth& t : tips)
      out.push_back({{"vertex", t.vertex},
                     {"energy_release_rate", t.energy_release_rate},
                     {"k1", t.k1},
                     {"k2", t.k2},
                     {"kink_deg", t.kink * 180 / std::numbers::pi},
                     {"domain_radius", t.domain_radius},
                     {"stopped", t.stopped}});
    return out;
  }

  Json timings(const TearRun& r) const {
    const CommonSettings& c = common_;
    return {{"physics_ms_per_step", r.physics_ms / c.steps},
            {"tear_ms_total", r.tear_ms},
            {"tear_ms_per_sample", r.tear_steps ? r.tear_ms / r.tear_steps : 0.0},
            {"measure_ms_per_step", r.measure_ms / c.steps},
            {"growth_ms_per_judgement", r.growth_steps ? r.growth_ms / r.growth_steps : 0.0},
            {"build_ms", r.build_ms},
            {"vertices", r.arm.mesh.vertex_count()},
            {"faces", r.arm.mesh.face_count()}};
  }

  int resolution_ = 1;
  double elbow_deg_ = 0, flex_deg_ = 0, flex_at_ = 1.5, flex_duration_ = 0.5;
  bool across_ = false;
  bullet::Material material_;
  Stroke stroke_;
  ComparisonKeys compare_;
};

std::unique_ptr<Scene> make_tear_opening(const Json& scene, const std::string& name,
                                         int steps_override) {
  return std::make_unique<TearOpening>(scene, name, steps_override);
}

const SceneRegistration kTearOpeningRegistration{
    {"tear-opening",
     "the skinned arm's pre-stressed skin torn by a scalpel: physical opening (membrane in Bullet) "
     "vs "
     "the geometric opening of Algorithm 2 step 6, profiles over time (default scene)",
     kTearOpeningJson, &make_tear_opening, 0, "physics.max_opening,geometric.max_opening"}};

}  // namespace
}  // namespace conform::scenes
