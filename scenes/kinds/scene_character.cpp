// The scene `character`: a user's own rigged model (any file assimp reads) plays its animation
// through CGA skinning as a Bullet soft body, and is cut, torn and drilled while it plays
// (character_edits.hpp places the edits on the model). Reported: the soft nodes' distance from
// their skinned targets, the first step's speed against the animation's, every edit, and the
// gap across the seams that the import's weld closed (vertices of the file at one rest
// position), relative to the model's diagonal. The tear's physical opening is compared with
// its geometric one, as tear-opening does on the arm: the same samples on the animated mesh
// alone (skinned, no physics; geometric_tear.hpp), opened by Algorithm 2 step 6 once the stroke
// is done; their gap-width profiles over time (opening_profiles.hpp).
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>

#include "conform/io/import.hpp"
#include "conform/io/weld_model.hpp"
#include "kinds/character_edits.hpp"
#include "kinds/edit_placement.hpp"
#include "kinds/event_time.hpp"
#include "kinds/falling_pieces.hpp"
#include "kinds/geometric_tear.hpp"
#include "kinds/model_frame.hpp"
#include "kinds/opening_profiles.hpp"
#include "kinds/scene.hpp"
#include "kinds/soft_scene.hpp"

namespace conform::scenes {
namespace {

// The built-in scene `character`, the defaults of this kind (`conform scenes --show character`).
constexpr const char* kCharacterJson = R"json({
  "scene": "character",
  "description": "huesitos.fbx from Debian's assimp-testmodels (9 bones, animated) plays its animation through CGA skinning as a Bullet soft body with the membrane skin (material.model = bullet_links for Bullet's links; nodes close to one bone ride it, blended regions follow their skinned targets softly) and, while it plays, a limb is cut off with a capped cut, torn by a scalpel stroke and drilled through with a tube; the welded seams are measured for gaps. Units: the model is brought to metres, Y up, at import: model.units_per_metre file units make a metre (\"file\": the unit the file states, FBX's UnitScaleFactor, else metres: glTF's unit, Collada's once imported, and the one X, SMD and MD5 files are taken in, since they state none), model.up (y or z) is the file's up axis (z is turned to y). Edits are aimed at a limb of the model (its bind pose): by default the limb (a bone and every bone below it) where a trial on the skinned model without physics caps the cut, extends the tear and lands the drill best, else the one each edit's bone names (summary.json: limb). The cut is the limb's cross-section at cut.along (a fraction of its length from its root), bounded to that section; the tear's stroke runs on the limb's outer (tear.side: away from the model's centre) or inner side from tear.along over tear.length metres (0: 40 % of the limb), its blade crossing the skin tear.depth limb radii either side; the drill goes through the limb at drill.along, across its axis and its outward side, of radius drill.radius_of_limb limb radii. Each edit is held by the skin as it is at that moment (rings of the limb's vertices, a point of a face), not by a bone. Given cut.point, tear.from or drill.tip, that edit is placed in the bind pose's bounding box instead (its limb keys are then unused): cut.point, cut.seed, tear.from, tear.to, drill.tip and drill.base as fractions of the box, tear.blade_a and tear.blade_b as fractions of its size, drill.radius as a fraction of its diagonal, cut.normal in its axes (after model.up), carried by one bone (cut.bone, tear.bone, drill.bone, or the dominant bone of the nearest vertex). material.margin is in metres, physics.gravity in m/s^2; every length in summary.json is in metres. model.animation = none plays the bind pose (what a model without animation does). cut.region = nearest cuts only the section of the plane nearest the limb's axis (in the box: cut.seed, by default cut.point), everywhere the unbounded plane. cut.release lets the pieces the cut severs fall (released from skinning; a closed, capped piece keeps its volume with the bulk modulus cut.volume_modulus, Pa) onto the ground (ground.enabled; ground.height in metres, by default the bind pose's lowest point), which only released pieces meet (summary.json: released_pieces, metrics.csv: released_lowest_m, falling.png). The tear's physical opening is compared with a geometric copy: the same stroke on the animated mesh alone (CGA-skinned, no physics; the cut and the drill are not applied to it), opened by Algorithm 2 step 6 once the stroke ends by geometric.amount, a fraction of the bind pose's diagonal (summary.json: metrics.physics and metrics.geometric, max_opening in metres); profiles.points positions along the tear, profiles.snapshots profile snapshots (profiles.csv, profile_history.csv, geometric_*.ply frames, two-panel pictures). The pictures are coloured by the gap across the lips (render.scalar = gap): an imported model's rest positions are in its mesh space, whose scale need not be the bind pose's, so an edge strain against them (stretch) would not be the skin's.",
  "seed": 1,
  "duration": 1.56,
  "model": { "file": "/usr/share/assimp/models/FBX/huesitos.fbx", "animation": "0",
             "units_per_metre": "file", "up": "y", "weld": true },
  "material": { "model": "membrane", "link_stiffness": 0.02, "target_stiffness": 2000, "target_damping": 20,
                "kinematic_weight": 0.95, "damping": 0.01 },
  "cut": { "at": 0.3, "along": 0.85, "cap": true, "region": "nearest", "release": true,
           "volume_modulus": 100000 },
  "ground": { "enabled": true },
  "tear": { "at": 0.5, "duration": 0.4, "samples": 12, "along": 0.2, "length": 0,
            "side": "outer", "depth": 0.5 },
  "drill": { "at": 1.1, "along": 0.5, "radius_of_limb": 0.3, "tube": true },
  "geometric": { "amount": 0.01 },
  "profiles": { "snapshots": 6, "points": 41 },
  "physics": { "dt": 0.016666666666666666, "substeps": 2, "solver_iterations": 10,
               "gravity": [0, -9.81, 0] },
  "outputs": { "metrics_every": 1, "frames_every": 30, "plots": true },
  "render": { "scalar": "gap" }
})json";

using Clock = std::chrono::steady_clock;

// The fastest node after the first step and the fastest target motion over it (m/s).
struct FirstStep {
  double node_speed = 0, target_speed = 0;
};

FirstStep first_step(const bullet::SkinnedSoftBody& body,
                     const std::vector<Eigen::Vector3d>& start_targets, double dt) {
  FirstStep f;
  for (std::int32_t v = 0; v < body.vertex_count(); ++v) {
    if (body.detached(v)) continue;
    f.node_speed = std::max(f.node_speed, body.velocity(v).norm());
    f.target_speed = std::max(
        f.target_speed, (body.target(v) - start_targets[static_cast<std::size_t>(v)]).norm() / dt);
  }
  return f;
}

// The mesh instance (index in model.meshes: a mesh placed twice is two objects) each vertex of
// the imported model came from.
std::vector<std::int32_t> file_mesh_of_vertices(const io::SkinnedModel& model) {
  std::vector<std::int32_t> mesh_of(static_cast<std::size_t>(model.mesh.vertex_count()), -1);
  for (std::size_t i = 0; i < model.meshes.size(); ++i)
    std::fill_n(mesh_of.begin() + model.meshes[i].first_vertex, model.meshes[i].vertex_count,
                std::int32_t(i));
  return mesh_of;
}

// What the run carries from step to step.
struct RunState {
  double worst_offset = 0, mean_offset_sum = 0, worst_seam_gap = 0;
  FirstStep first{};
  Json cut, tear, drill;
  PlacedCut cut_at;  // where the edits land, in the bind pose
  PlacedDrill drill_at;
  bool cut_done = false, drill_done = false;
  double edit_ms = 0, physics_ms = 0;
  FallingPieces falling;     // the pieces the cut severs (cut.release)
  Ground* ground = nullptr;  // what they fall onto (ground.enabled)
  // The membrane's solve, sampled at each step's last substep.
  long newton_sum = 0, cg_sum = 0;
  int newton_max = 0, unconverged = 0;
  double worst_relative_residual = 0;
  void tally(const membrane::SolveReport& r) {
    newton_sum += r.newton_iterations, cg_sum += r.cg_iterations;
    newton_max = std::max(newton_max, r.newton_iterations);
    unconverged += !r.converged;
    worst_relative_residual = std::max(worst_relative_residual, r.relative_residual);
  }
  Json solver(int steps) const {
    return {{"sampled", "each step's last substep"},
            {"newton_mean", double(newton_sum) / steps},
            {"newton_max", newton_max},
            {"cg_mean", double(cg_sum) / steps},
            {"unconverged_steps", unconverged},
            {"worst_relative_residual", worst_relative_residual}};
  }
};

// The tear's physical opening against its geometric copy, with the largest of each so far.
struct TearCompare {
  GeometricTear geo;
  OpeningProfiles profiles;
  Profile phys, geom;
  double max_phys = 0, max_geom = 0, ms = 0;  // ms: posing (skinning) and opening the copy
  TearCompare(const mesh::SkinnedMesh& bind_mesh, OpeningProfiles kept)
      : geo(bind_mesh, mesh::TearOptions{}), profiles(std::move(kept)) {}

  // Both profiles now (each kept as it was while its tear has under two points).
  void measure(const bullet::SkinnedSoftBody& body) {
    const mesh::Tear* pt = body.tear();
    if (pt && pt->path_length() >= 2) phys = physical_profile(body);
    if (geo.tear().path_length() >= 2) geom = geo.profile();
    max_phys = std::max(max_phys, phys.max);
    max_geom = std::max(max_geom, geom.max);
  }
};

class Character final : public Scene {
 public:
  Character(const Json& scene, const std::string& name, int steps_override) {
    Reader root(scene, "", resolved_);
    Reader model = root.object("model");
    file_ = model.text("file", "/usr/share/assimp/models/FBX/huesitos.fbx");
    if (file_.rfind("arm", 0) != 0 && !std::filesystem::exists(file_))
      model.fail("file", Json(file_), "no such file");
    animation_ = model.text("animation", "0");
    // A number, or "file" (also when absent): the unit the file states (FBX), else metres.
    if (model.is_text("units_per_metre") || !model.has("units_per_metre"))
      model.text("units_per_metre", "file", {"file"});
    else
      frame_.units_per_metre = model.number("units_per_metre", 1, 1e-6, 1e6);
    frame_.up = model.text("up", "y", {"y", "z"});
    import_.strict_weights = model.boolean("strict_weights", false);
    weld_ = model.boolean("weld", true);
    // Seam copies whose bone weights differ: welded with their mean weights (closed seams), or
    // kept apart as the file has them (mesh/weld.hpp).
    import_.weld_options.differing_weights =
        model.text("seam_weights", "mean", {"mean", "keep_apart"}) == "mean"
            ? mesh::DifferingWeights::mean
            : mesh::DifferingWeights::keep_apart;
    import_.isolate = true;  // a corrupt file must not kill or corrupt the run
    import_.weld = false;    // welded here, to keep the file's seams for the gap measure
    model.finish();
    bullet::Material d;
    // The membrane skin, in its rest state the bind pose; Bullet's links are an option, with
    // the link fields below.
    d.model = bullet::MaterialModel::membrane;
    d.kinematic_weight = 0.95;  // nodes near one bone ride it; blended regions jiggle
    // The animation stretches the skin (edge lengths change), which stiff links at bind-pose
    // rest lengths would fight: soft links, and a firm pull toward the skinned targets.
    d.link_stiffness = 0.02;
    d.target_stiffness = 2000;
    d.target_damping = 20;
    d.damping = 0.01;
    material_ = read_material(root, d);
    cut_ = read_cut(root);
    tear_ = read_tear(root);
    drill_ = read_drill(root);
    ground_ = read_ground(root, {true, std::numeric_limits<double>::quiet_NaN()});
    // The geometric copy's opening, a fraction of the bind pose's diagonal (as every length
    // placed on the model), and the profiles kept of both openings (tear-opening's keys).
    compare_ = read_comparison_keys(root);
    common_ = read_common(root, name, 3.0, steps_override);
    root.finish();
  }

  Json run(RunOutput& out) override {
    CommonSettings c = common_;
    require_edits_before_end(c);
    io::SkinnedModel model = io::load_model(file_, import_);
    // From here on the model is in metres, Y up: Bullet, gravity, the margin and every
    // length reported are in metres whatever the file's units.
    to_scene_frame(model, frame_of(model));
    const Eigen::Matrix3Xd file_rest = model.mesh.rest;
    const std::vector<mesh::Face> file_faces = model.mesh.faces;
    const std::vector<std::int32_t> mesh_of = file_mesh_of_vertices(model);
    const mesh::WeldResult weld =
        weld_ ? io::weld_model(model, import_.weld_options) : mesh::WeldResult{};
    for (const auto& w : model.warnings)
      std::cerr << "warning: " << model.source << ": " << w << "\n";
    const skin::Animation* animation = chosen_animation(model);
    SoftWorld w(c);
    bullet::SkinnedSoftBody& body = w.plugin->add_skinned_body(model, material_);
    out.warn_material(body);
    // No loop: this animation's last key is not its first, and the wrap would be a jump.
    if (animation)
      body.play(*animation, skin::Blend::log, false);
    else
      body.set_pose(skin::Pose::rest(model.skeleton));  // the bind pose; physics still acts
    // The first substep would start the body on the animation's first pose by itself; the
    // snap does it now, so that frame 0 and the start targets below are of that pose.
    body.snap_to_pose();
    const BindPose bind(model.mesh);
    const SeamGap seams(file_rest, file_faces, mesh_of, weld.vertex_map);
    RunState s;
    const std::int32_t aim =
        auto_aim(model.mesh, bind, model.skeleton, animation, cut_, tear_, drill_);
    if (cut_.enabled) s.cut_at = place_cut(cut_, bind, model.skeleton, aim);
    if (drill_.enabled) s.drill_at = place_drill(drill_, bind, model.skeleton, aim);
    TearRun tear(tear_, tear_.enabled ? place_tear(tear_, bind, model.skeleton, aim) : PlacedTear{},
                 bind);
    std::optional<TearCompare> compare;
    if (tear_.enabled)
      compare.emplace(model.mesh, OpeningProfiles(compare_.points, compare_.snapshots, tear_.at,
                                                  c.steps, c.dt));
    std::vector<Eigen::Vector3d> start_targets(static_cast<std::size_t>(body.vertex_count()));
    for (std::int32_t v = 0; v < body.vertex_count(); ++v)
      start_targets[static_cast<std::size_t>(v)] = body.target(v);
    std::int32_t kinematic = 0;
    for (std::int32_t v = 0; v < body.vertex_count(); ++v) kinematic += body.kinematic(v);
    out.open_metrics(metrics_columns(compare.has_value()));
    if (compare) compare->profiles.open_history(out);
    std::optional<Ground> ground;
    if (ground_.enabled) {
      // By default under the bind pose's lowest point: what the character stands on.
      ground_.height = std::isnan(ground_.height) ? bind.lo.y() : ground_.height;
      ground.emplace(w, ground_.height, 0.5 * (bind.lo + bind.hi), bind.diagonal());
      s.ground = &*ground;
    }
    const Lips no_lips_yet;  // with a tear, the gap is 0 until it starts
    out.body_frame("character", 0, body, compare ? &no_lips_yet : nullptr);
    const auto loop_start = Clock::now();
    for (int step = 1; step <= c.steps; ++step) {
      const auto tp = Clock::now();
      w.step();
      s.physics_ms += std::chrono::duration<double, std::milli>(Clock::now() - tp).count();
      if (material_.model == bullet::MaterialModel::membrane) s.tally(body.last_solve());
      if (step == 1) s.first = first_step(body, start_targets, c.dt);
      const auto te = Clock::now();
      edit(body, bind, tear, compare ? &*compare : nullptr, step * c.dt, s);
      s.edit_ms += std::chrono::duration<double, std::milli>(Clock::now() - te).count();
      measure(body, seams, bind, tear, compare ? &*compare : nullptr, step, c, s, out);
      if (out.frame_step(step) || (compare && out.offers_pictures()))
        write_frame(body, compare ? &*compare : nullptr, step, out);
      out.progress(step, c.steps);
    }
    const double loop_s = std::chrono::duration<double>(Clock::now() - loop_start).count();
    if (!finite_nodes(body)) throw std::runtime_error("the soft body blew up (non-finite nodes)");
    if (tear_.enabled) s.tear = tear.summary(body);
    Json metrics = summarize(body, model, animation, weld, seams, bind, kinematic, c, s);
    if (material_.model == bullet::MaterialModel::membrane) metrics["solver"] = s.solver(c.steps);
    Json timings = {{"model_vertices", model.mesh.vertex_count()},
                    {"physics_ms_per_step", s.physics_ms / c.steps},
                    {"edits_ms", s.edit_ms}};
    add_plots(out);
    if (releases()) out.add_plot(falling_plot("character", ground_.enabled, cut_.at));
    if (compare) {
      add_comparison(*compare, body, bind, metrics);
      timings["geometric_copy_ms"] = compare->ms;
      compare->profiles.write(out);
      compare->profiles.add_plots(
          out,
          {"character", "physics (Bullet soft body)",
           "geometric (skinned mesh, Algorithm 2 step 6)", "geometric (step 6)"},
          {{tear_.at, "stroke starts"},
           {tear_.time(tear_.samples - 1), "stroke ends, geometric opened"}});
    }
    out.finish(resolved_, metrics, timings, c.steps, c.steps * c.dt, loop_s);
    return metrics;
  }

 private:
  // metrics.csv's columns, in the order measure() writes them.
  std::vector<std::string> metrics_columns(bool compare) const {
    std::vector<std::string> columns{"t",      "offset_mean_m", "offset_max_m", "seam_gap_rel",
                                     "pieces", "nodes"};
    if (releases()) columns.push_back("released_lowest_m");
    if (compare)
      columns.insert(columns.end(), {"physics_max_opening", "geometric_max_opening", "physics_area",
                                     "geometric_area"});
    return columns;
  }

  // The file's units: model.units_per_metre, else the file's own (model_frame.hpp).
  ModelFrame frame_of(const io::SkinnedModel& model) {
    ModelFrame frame = frame_;
    if (frame_.units_per_metre > 0) {
      units_source_ = "model.units_per_metre";
    } else {
      const FileUnits units = file_units(model, file_);
      frame.units_per_metre = units.units_per_metre;
      units_source_ = units.source;
    }
    units_per_metre_ = frame.units_per_metre;
    return frame;
  }

  // The animation played, or none (the bind pose): when model.animation is "none", or by
  // itself, with a note, when the file has no animation at all (a static or posed model).
  const skin::Animation* chosen_animation(const io::SkinnedModel& model) const {
    if (animation_ == "none") return nullptr;
    if (model.animations.empty() && animation_ == "0") {
      std::cerr << "note: " << file_
                << " has no animation: it plays its bind pose (model.animation = \"none\")\n";
      return nullptr;
    }
    const int a = model.find_animation(animation_);
    if (a < 0)
      throw std::runtime_error(file_ + ": no animation '" + animation_ + "' (" +
                               std::to_string(model.animations.size()) +
                               " animations; \"none\" plays the bind pose)");
    return &model.animations[static_cast<std::size_t>(a)];
  }

  bool releases() const { return cut_.enabled && cut_.sever.release; }

  // Every enabled edit happens before the last step (else it would be skipped unsaid).
  void require_edits_before_end(const CommonSettings& c) const {
    if (cut_.enabled) require_before_end(c, "cut.at", cut_.at, "the cut", cut_.at);
    if (tear_.enabled)
      require_before_end(c, "tear.at", tear_.at, "the tear's last sample (tear.at + tear.duration)",
                         tear_.time(tear_.samples - 1));
    if (drill_.enabled) require_before_end(c, "drill.at", drill_.at, "the drill", drill_.at);
  }

  // The edits due at time t (between steps, at the body's last pose).
  void edit(bullet::SkinnedSoftBody& body, const BindPose& bind, TearRun& tear,
            TearCompare* compare, double t, RunState& s) const {
    if (cut_.enabled && !s.cut_done && event_due(t, cut_.at)) {
      s.falling.before_cut(body);
      s.cut = apply_cut(body, bind, s.cut_at, cut_);
      s.cut_done = true;
      if (s.cut["status"] != "cut") std::cerr << "warning: the cut missed the model\n";
      if (releases() && s.cut["status"] == "cut")
        s.cut["released"] = s.falling.release_severed(body, cut_.sever.volume_modulus, s.ground);
    }
    if (tear_.enabled) advance_tear(body, bind, tear, compare, t);
    if (drill_.enabled && !s.drill_done && event_due(t, drill_.at)) {
      s.drill = apply_drill(body, bind, s.drill_at, drill_);
      s.drill_done = true;
      if (s.drill["status"] != "drilled") std::cerr << "warning: the drill missed the model\n";
    }
  }

  // The tear on the body and on its geometric copy, which is first posed as the body's last
  // pose (the animation's: the skeleton owes nothing to the physics) and opened by
  // geometric.amount of the diagonal once the stroke is done.
  void advance_tear(bullet::SkinnedSoftBody& body, const BindPose& bind, TearRun& tear,
                    TearCompare* compare, double t) const {
    if (!compare) {
      if (!tear.done()) tear.advance(body, t);
      return;
    }
    const auto t0 = Clock::now();
    compare->geo.repose(body.skeleton(), body.pose(), body.world_transform());
    compare->ms += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    if (!tear.done()) tear.advance(body, t, &compare->geo);
    if (tear.done() && !compare->geo.opened()) compare->geo.open(compare_.amount * bind.diagonal());
  }

  void measure(const bullet::SkinnedSoftBody& body, const SeamGap& seams, const BindPose& bind,
               const TearRun& tear, TearCompare* compare, int step, const CommonSettings& c,
               RunState& s, RunOutput& out) const {
    const OffsetStats o = offsets(body, {});
    s.worst_offset = std::max(s.worst_offset, o.max), s.mean_offset_sum += o.mean;
    const double gap = seams.measure(body) / bind.diagonal();
    s.worst_seam_gap = std::max(s.worst_seam_gap, gap);
    const double t = step * c.dt;
    if (compare) compare->measure(body);
    s.falling.measure(body, s.ground);
    if (step % c.metrics_every == 0 || step == c.steps) {
      std::vector<double> row{
          t, o.mean, o.max, gap, double(body.piece_count()), double(body.vertex_count())};
      if (releases()) row.push_back(s.falling.any() ? s.falling.lowest() : RunOutput::Csv::kAbsent);
      if (compare) {
        const TearCompare& k = *compare;
        row.insert(row.end(), {k.phys.max, k.geom.max, k.phys.area, k.geom.area});
        if (tear.started()) compare->profiles.history_row(t, k.phys, k.geom);
      }
      out.metrics().row(row);
    }
    if (compare) compare->profiles.snapshot(step, t, compare->phys, compare->geom);
  }

  // On a frame step the body's frame and, with the comparison, the geometric copy's; with the
  // comparison, on every step, their picture (the pictures go where the wound changes).
  static void write_frame(bullet::SkinnedSoftBody& body, const TearCompare* compare, int step,
                          RunOutput& out) {
    const bool frame = out.frame_step(step);
    body.sync_mesh();
    const Lips lips = tear_lips(body.tear());
    if (frame) out.body_frame("character", step, body, compare ? &lips : nullptr);
    if (!compare) return;
    if (frame) out.frame("geometric", step, compare->geo.mesh());
    // The physical panel is named as its frames, so run.glb keeps one sequence of the body.
    out.picture(step,
                {{"character", &body.mesh(), lips, gap_caption(compare->phys)},
                 {"geometric", &compare->geo.mesh(), tear_lips(&compare->geo.tear()),
                  gap_caption(compare->geom)}},
                frame);
  }

  // metrics.physics and metrics.geometric: each opening at the end and its largest over the
  // run (metres), the opened area and the profile's elliptical fit (the rest length of
  // tear-opening is left out: an imported model's rest space need not be in metres).
  void add_comparison(const TearCompare& k, const bullet::SkinnedSoftBody& body,
                      const BindPose& bind, Json& m) const {
    const auto part = [](const Profile& p, double largest, const mesh::Tear* tear) {
      return Json{{"max_opening", p.max},         {"max_opening_over_time", largest},
                  {"opened_area", p.area},        {"profile_r2", p.r2},
                  {"profile_fit_max", p.fit_max}, {"tear_points", tear ? tear->path_length() : 0}};
    };
    m["physics"] = part(k.phys, k.max_phys, body.tear());
    m["geometric"] = part(k.geom, k.max_geom, &k.geo.tear());
    m["geometric"]["amount"] = compare_.amount;                      // of the bind pose's diagonal
    m["geometric"]["amount_m"] = compare_.amount * bind.diagonal();  // metres
    m["physics_over_geometric_max_opening"] = k.geom.max > 0 ? k.phys.max / k.geom.max : 0.0;
    m["opening_units"] = "metres, square metres; profile_r2 of w_max*sqrt(1-(2s-1)^2)";
  }

  Json summarize(const bullet::SkinnedSoftBody& body, const io::SkinnedModel& model,
                 const skin::Animation* animation, const mesh::WeldResult& weld,
                 const SeamGap& seams, const BindPose& bind, std::int32_t kinematic,
                 const CommonSettings& c, const RunState& s) const {
    Json m = {{"model", file_},
              {"units_per_metre", units_per_metre_},
              {"units_per_metre_from", units_source_},
              {"animation", animation ? animation->name : "none (bind pose)"},
              // The first step's fastest node against the fastest motion of the skinned targets
              // over that step (the animation itself), m/s.
              {"first_step_max_node_speed_m_s", s.first.node_speed},
              {"first_step_max_target_speed_m_s", s.first.target_speed},
              {"animation_duration_s", animation ? animation->duration() : 0.0},
              {"vertices", model.mesh.vertex_count()},
              {"faces", model.mesh.face_count()},
              {"bones", model.skeleton.bone_count()},
              // The bind pose's bounding box in the scene's frame (metres, Y up).
              {"bind_pose_lo_m", {bind.lo.x(), bind.lo.y(), bind.lo.z()}},
              {"bind_pose_size_m",
               {bind.hi.x() - bind.lo.x(), bind.hi.y() - bind.lo.y(), bind.hi.z() - bind.lo.z()}},
              {"kinematic_nodes", kinematic},
              {"final_vertices", body.vertex_count()},
              {"pieces", body.piece_count()},
              {"secondary_motion_mean_m", s.mean_offset_sum / c.steps},
              {"secondary_motion_max_m", s.worst_offset},
              {"seams",
               {{"welded", weld_},
                {"file_vertices_at_seams", seams.file_vertices()},
                {"positions", seams.positions()},
                {"open_positions", seams.open_positions()},
                {"touching_positions", seams.touching_positions()},
                {"merged_vertices", weld.merged},
                {"mean_weight_positions", std::int64_t(weld.averaged.size())},
                {"kept_apart_vertices", weld.kept_apart},
                // The largest distance, over the run, between body vertices standing for file
                // vertices at one rest position, relative to the bind pose's bounding-box diagonal.
                {"max_gap_rel", s.worst_seam_gap},
                {"diagonal_m", bind.diagonal()}}},
              {"units",
               "metres, seconds (the file's coordinates / model.units_per_metre, turned Y up "
               "when model.up is z); secondary motion = distance of a node from its "
               "CGA-skinned target; edit placements are fractions of the bind pose's box"}};
    if (cut_.enabled) m["cut"] = s.cut;
    if (releases()) m["released_pieces"] = s.falling.summary();
    m["ground"] = ground_summary(ground_);
    if (tear_.enabled) m["tear"] = s.tear;
    if (drill_.enabled) m["drill"] = s.drill;
    return m;
  }

  static void add_plots(RunOutput& out) {
    out.add_plot({"secondary_motion",
                  "character: soft-body secondary motion",
                  "time [s]",
                  "distance from skinned target [m]",
                  {{"metrics.csv", "t", "offset_mean_m", "mean over nodes", "lines"},
                   {"metrics.csv", "t", "offset_max_m", "largest", "lines"}},
                  {}});
    out.add_plot({"seam_gap",
                  "character: largest gap across the file's seams",
                  "time [s]",
                  "gap / model diagonal",
                  {{"metrics.csv", "t", "seam_gap_rel", "largest seam gap", "lines"}},
                  {}});
  }

  std::string file_, animation_;
  io::ImportOptions import_;
  bool weld_ = true;
  ModelFrame frame_{0, "y"};  // units_per_metre 0: from the file
  double units_per_metre_ = 0;
  std::string units_source_;
  bullet::Material material_;
  CutEdit cut_;
  TearEdit tear_;
  DrillEdit drill_;
  GroundSettings ground_;
  ComparisonKeys compare_;  // geometric.amount is a fraction of the bind pose's diagonal
};

std::unique_ptr<Scene> make_character(const Json& scene, const std::string& name, int steps) {
  return std::make_unique<Character>(scene, name, steps);
}

const SceneRegistration kCharacterRegistration{
    {"character",
     "a real rigged model (assimp) plays its animation through CGA skinning with soft-body "
     "secondary motion, and is cut, torn and drilled while it plays",
     kCharacterJson, &make_character, 4, "secondary_motion_max_m"}};

}  // namespace
}  // namespace conform::scenes
