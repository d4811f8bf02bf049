// `tear-opening`: the skinned arm under pretension is torn by a scalpel stroke along the
// forearm; the same stroke is run twice on the same pose:
//   physics    — a SkinnedSoftBody (Bullet soft body skinned by CGA, links pre-tensioned);
//                the wound opens by itself because its links are shorter at rest than made;
//   geometric  — the same tear on the posed mesh alone (Algorithm 2), opened by step 6 (the
//                borders moved apart by a prescribed sine taper once the stroke ends).
// Measured over time: the gap-width profile along the tear, the largest opening and the opened
// area; at the end an elliptical fit of the physical profile (a slit in a stretched membrane
// opens as an ellipse).
#include <chrono>
#include <cmath>
#include <numbers>
#include <sstream>

#include "conform/skin/procedural_arm.hpp"
#include "conform/skin/skinner.hpp"
#include "scene.hpp"
#include "soft_scene.hpp"

namespace conform::scenes {
namespace {

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
    tear.finish();
    Reader geo = root.object("geometric");
    amount_ = geo.number("amount", 0.01, 0, 1);
    geo.finish();
    Reader prof = root.object("profiles");
    snapshots_ = prof.integer("snapshots", 6, 1, 100);
    bins_ = prof.integer("points", 41, 3, 10000);
    prof.finish();
    common_ = read_common(root, name, 3.0, steps_override);
    root.finish();
  }

  Json run(RunOutput& out) override {
    const CommonSettings& c = common_;
    mesh::ArmOptions mo;
    mo.resolution = resolution_;
    mesh::Arm arm = mesh::make_arm(mo);
    skin::Pose pose = skin::Pose::rest(arm.skeleton);
    pose.set_local(
        1,
        Eigen::Quaterniond(Eigen::AngleAxisd(elbow_deg_ * std::numbers::pi / 180, Vec3::UnitX())),
        Vec3(0, 0, mo.upper_arm));
    {  // Both runs start from the posed (skinned) arm.
      skin::Skinner<double> skinner(arm.skeleton, arm.mesh.rest,
                                    skin::InfluenceLists::from_mesh(arm.mesh));
      skinner.set_threads(1);
      skinner.skin(pose, skin::SkinMode::cga);
      skinner.write(arm.mesh.current);
    }
    // Geometric run: the mesh alone.
    mesh::SkinnedMesh geo = arm.mesh;
    mesh::Adjacency geo_adjacency(geo);
    mesh::Tear geo_tear(geo, geo_adjacency);
    // Physics run.
    SoftWorld w(c);
    const auto t_build = Clock::now();
    bullet::SkinnedSoftBody& body = w.plugin->add_skinned_body(arm.mesh, arm.skeleton, material_);
    body.set_pose(pose);
    const double build_ms =
        std::chrono::duration<double, std::milli>(Clock::now() - t_build).count();

    // The stroke's points along the rest-space tear, and the times the profile is kept.
    std::vector<double> bins(static_cast<std::size_t>(bins_));
    for (int i = 0; i < bins_; ++i) bins[static_cast<std::size_t>(i)] = double(i) / (bins_ - 1);
    const double end_time = c.steps * c.dt;
    std::vector<int> snapshot_steps;
    for (int k = 0; k < snapshots_; ++k) {
      // Denser early on: the opening changes fastest while the stroke runs.
      const double u = double(k + 1) / snapshots_;
      const double t = stroke_.at + (end_time - stroke_.at) * u * u;
      snapshot_steps.push_back(std::clamp(static_cast<int>(std::lround(t / c.dt)), 1, c.steps));
    }
    std::vector<std::vector<double>> snap_physics, snap_geometric;
    std::vector<double> snap_times;

    out.open_metrics({"t", "physics_tear_points", "geometric_tear_points", "physics_max_opening",
                      "geometric_max_opening", "physics_area", "geometric_area",
                      "physics_profile_r2", "geometric_profile_r2", "pieces"});
    RunOutput::Csv history =
        out.open_csv("profile_history.csv", {"t", "s", "physics_width", "geometric_width"});
    int next = 0;
    bool opened = false;
    Profile phys, geom;
    double max_phys = 0, max_geom = 0, tear_ms = 0, measure_ms = 0, physics_ms = 0;
    int tear_steps = 0;
    const auto rest_of = [](const mesh::SkinnedMesh& m) {
      return [&m](std::int32_t v) { return Vec3(m.rest.col(v)); };
    };
    out.frame("physics", 0, body.mesh());
    const auto loop_start = Clock::now();
    for (int step = 1; step <= c.steps; ++step) {
      const auto tp = Clock::now();
      w.step();
      physics_ms += std::chrono::duration<double, std::milli>(Clock::now() - tp).count();
      const double t = step * c.dt;
      // Topology edits only between steps.
      const auto tt = Clock::now();
      while (next < stroke_.samples && stroke_.time(next) <= t + 1e-12) {
        const mesh::ScalpelSample sample = stroke_.sample(next);
        body.tear_advance(sample);
        geo_tear.advance(sample);
        ++next, ++tear_steps;
      }
      if (next == stroke_.samples && !opened) {
        geo_tear.open(amount_);  // Algorithm 2 step 6, once the stroke is done
        opened = true;
      }
      tear_ms += std::chrono::duration<double, std::milli>(Clock::now() - tt).count();
      const auto tm = Clock::now();
      const mesh::Tear* pt = body.tear();
      if (pt && pt->path_length() >= 2)
        phys = measure_profile(
            pt->left_border(), pt->right_border(), [&](std::int32_t v) { return body.position(v); },
            rest_of(body.mesh()));
      if (geo_tear.path_length() >= 2)
        geom = measure_profile(
            geo_tear.left_border(), geo_tear.right_border(),
            [&](std::int32_t v) { return Vec3(geo.current.col(v)); }, rest_of(geo));
      max_phys = std::max(max_phys, phys.max);
      max_geom = std::max(max_geom, geom.max);
      if (step % c.metrics_every == 0 || step == c.steps) {
        const double row[] = {t,
                              double(pt ? pt->path_length() : 0),
                              double(geo_tear.path_length()),
                              phys.max,
                              geom.max,
                              phys.area,
                              geom.area,
                              phys.r2,
                              geom.r2,
                              double(body.piece_count())};
        out.metrics().row(row);
        if (next > 0) {
          const auto pw = resample(phys, bins), gw = resample(geom, bins);
          for (std::size_t i = 0; i < bins.size(); ++i) {
            const double h[] = {t, bins[i], pw[i], gw[i]};
            history.row(h);
          }
        }
      }
      for (const int s : snapshot_steps)
        if (s == step) {
          snap_times.push_back(t);
          snap_physics.push_back(resample(phys, bins));
          snap_geometric.push_back(resample(geom, bins));
        }
      measure_ms += std::chrono::duration<double, std::milli>(Clock::now() - tm).count();
      if ((c.frames_every > 0 && step % c.frames_every == 0) || step == c.steps) {
        body.sync_mesh();
        out.frame("physics", step, body.mesh());
        out.frame("geometric", step, geo);
      }
      out.progress(step, c.steps);
    }
    const double loop_s = std::chrono::duration<double>(Clock::now() - loop_start).count();
    const mesh::Tear* pt = body.tear();
    if (!pt || pt->path_length() < 2) {
      body.sync_mesh();
      const auto& x = body.mesh().current;
      std::ostringstream box;
      box << "skin bounding box [" << x.rowwise().minCoeff().transpose() << "] – ["
          << x.rowwise().maxCoeff().transpose() << "] m";
      throw std::runtime_error("tear-opening: the scalpel never tore the physical skin (" +
                               (pt ? pt->message() : std::string("no tear")) + "; " + box.str() +
                               ")");
    }
    if (geo_tear.path_length() < 2)
      throw std::runtime_error("tear-opening: the scalpel never tore the mesh (" +
                               geo_tear.message() + ")");

    // Profiles side by side: one column per snapshot time.
    std::vector<std::string> cols{"s"};
    char name[48];
    for (const double t : snap_times) {
      std::snprintf(name, sizeof name, "physics_%.2fs", t);
      cols.push_back(name);
    }
    for (const double t : snap_times) {
      std::snprintf(name, sizeof name, "geometric_%.2fs", t);
      cols.push_back(name);
    }
    {
      RunOutput::Csv profiles = out.open_csv("profiles.csv", cols);
      for (std::size_t i = 0; i < bins.size(); ++i) {
        std::vector<double> row{bins[i]};
        for (const auto& p : snap_physics) row.push_back(p[i]);
        for (const auto& g : snap_geometric) row.push_back(g[i]);
        profiles.row(row);
      }
    }
    Plot side{"profiles", "tear-opening: gap-width profile along the tear over time", "", "", {},
              {}};
    Plot left{"",
              "physics (pre-tensioned soft body)",
              "position along the tear (0 = start, 1 = tip)",
              "gap width [m]",
              {},
              {}};
    Plot right{"",
               "geometric (Algorithm 2 step 6)",
               "position along the tear (0 = start, 1 = tip)",
               "gap width [m]",
               {},
               {}};
    for (std::size_t k = 0; k < snap_times.size(); ++k) {
      std::snprintf(name, sizeof name, "t = %.2f s", snap_times[k]);
      left.series.push_back({"profiles.csv", "s", cols[1 + k], name, "lines"});
      right.series.push_back({"profiles.csv", "s", cols[1 + snap_times.size() + k], name, "lines"});
    }
    side.panels = {left, right};
    out.add_plot(side);
    out.add_plot({"opening",
                  "tear-opening: largest gap width",
                  "time [s]",
                  "largest gap width [m]",
                  {{"metrics.csv", "t", "physics_max_opening", "physics", "lines"},
                   {"metrics.csv", "t", "geometric_max_opening", "geometric (step 6)", "lines"}},
                  {}});
    out.add_plot({"area",
                  "tear-opening: opened area",
                  "time [s]",
                  "opened area [m^2]",
                  {{"metrics.csv", "t", "physics_area", "physics", "lines"},
                   {"metrics.csv", "t", "geometric_area", "geometric (step 6)", "lines"}},
                  {}});

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
    metrics["physics"] = part(phys, max_phys, *pt);
    metrics["geometric"] = part(geom, max_geom, geo_tear);
    metrics["geometric"]["amount"] = amount_;
    metrics["pieces"] = body.piece_count();
    metrics["nodes"] = body.vertex_count();
    metrics["units"] = "metres, square metres; profile_r2 of w_max*sqrt(1-(2s-1)^2)";
    Json timings = {{"physics_ms_per_step", physics_ms / c.steps},
                    {"tear_ms_total", tear_ms},
                    {"tear_ms_per_sample", tear_steps ? tear_ms / tear_steps : 0.0},
                    {"measure_ms_per_step", measure_ms / c.steps},
                    {"build_ms", build_ms},
                    {"vertices", arm.mesh.vertex_count()},
                    {"faces", arm.mesh.face_count()}};
    out.finish(resolved_, metrics, timings, c.steps, c.steps * c.dt, loop_s);
    return metrics;
  }

 private:
  int resolution_ = 1;
  double elbow_deg_ = 0;
  bullet::Material material_;
  Stroke stroke_;
  double amount_ = 0.01;
  int snapshots_ = 6, bins_ = 41;
};

}  // namespace

std::unique_ptr<Scene> make_tear_opening(const Json& scene, const std::string& name,
                                         int steps_override) {
  return std::make_unique<TearOpening>(scene, name, steps_override);
}

}  // namespace conform::scenes
