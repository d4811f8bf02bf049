// `membrane-slit`: the skin membrane against linear elastic fracture mechanics. A flat sheet,
// pinned at its border and pre-stressed by material.prestress = [sigma_xx, sigma_yy] along its
// axes, is slit through its centre (a TopologyChange applied to the live Bullet soft body) and
// settles; LEFM (plane stress) gives an elliptic opening of maximum 4 sigma_n a / E (4 sigma_n a H
// for the anisotropic fibre-reinforced law, H of Sih, Paris & Irwin: membrane_check.hpp), sigma_n
// the pre-stress normal to the slit (slit_sheet.hpp). Reports w_max, the profile's R^2 against the
// ellipse, the LEFM value and the membrane solver's residual. With a foundation
// (material.attachment_stiffness k > 0) and a slit much longer than its decay length
// l = sqrt(E'' t / k), E'' = E / (1 - nu^2) (4 E / 3 neo-Hookean), the opening tends to
// 2 sigma_n l / E'' instead (metrics.foundation_w_max; absent when k = 0: a summary holds finite
// numbers only).
//
// The run must reach the static equilibrium: each step stops as soon as its residual is below
// the tolerance, so a state whose out-of-balance force per node area is below it stays put. On
// this large, unattached sheet that frozen error is a smooth far-field displacement of order
// tolerance x W^2 / (E t), comparable to the opening at relative_tolerance 1e-3 (a slit along
// the lower of two pre-stresses froze 5 % short). Hence 1e-4, and `settled_at`: the last step
// in which the solver moved the sheet.
#include <chrono>
#include <cmath>
#include <numbers>

#include "conform/membrane/slit_sheet.hpp"
#include "kinds/event_time.hpp"
#include "kinds/membrane_check.hpp"
#include "kinds/scene.hpp"
#include "kinds/soft_scene.hpp"

namespace conform::scenes {
namespace {

using Clock = std::chrono::steady_clock;

// The built-in scene `membrane-slit` (`conform scenes --show membrane-slit`).
const std::string kMembraneSlitJson =
    join_scene_json({R"json({
  "scene": "membrane-slit",
  "description": "A square sheet of skin membrane (SI units) pinned at its border and pre-stressed by material.prestress = [sigma_xx, sigma_yy] along its axes is slit through its centre by a topology change on the live Bullet soft body; it settles, and its opening is compared with linear elastic fracture mechanics (plane stress): w_max = 4 sigma_n a / E (4 sigma_n a H with the fibre-reinforced law, the slit along or across its fibres).",
  "duration": 1.0,
  "sheet": { "width": 1.2, "resolution": 0.0025, "tip_refinement": 16 },
  "slit": { "length": 0.05, "angle_deg": 0, "at": 0.1 },)json",
                     kPinnedSheetMaterialJson, kSheetCheckPhysicsJson, R"json(
  "outputs": { "metrics_every": 1, "frames_every": 0, "plots": true }
})json"});

class MembraneSlit final : public Scene {
 public:
  MembraneSlit(const Json& scene, const std::string& name, int steps_override) {
    Reader root(scene, "", resolved_);
    read_slit_sheet(root, options_);
    Reader slit = root.object("slit");
    options_.slit_length = slit.number("length", 0.05, 1e-4, 10);
    options_.slit_angle = slit.number("angle_deg", 0, -360, 360) * std::numbers::pi / 180;
    at_ = slit.number("at", 0.1, 0, 1e5);
    slit.finish();
    bullet::Material d;
    d.skin.prestress = {400, 400};
    d.skin.prestress_axis = Eigen::Vector3d::UnitX();  // prestress = [sigma_xx, sigma_yy]
    d.skin.attachment_stiffness = 0;                   // a free membrane held by its border
    d.skin.attachment_normal_stiffness = 0;
    d.solver.relative_tolerance = 1e-4;  // see the top of this file
    d.solver.max_cg_iterations = 4000;
    material_ = read_material(root, d);
    common_ = read_common(root, name, 1.0, steps_override);
    root.finish();
    try {
      options_.validate();
    } catch (const std::invalid_argument& e) {
      throw SceneError("sheet", "", e.what());
    }
    if (material_.model != bullet::MaterialModel::membrane)
      throw SceneError("material.model", "\"bullet_links\"",
                       "membrane-slit measures the membrane; Bullet's links have no modulus");
    const Eigen::Vector3d slit_direction(std::cos(options_.slit_angle),
                                         std::sin(options_.slit_angle), 0);
    if (!material_axes_aligned(material_.skin, slit_direction))
      throw SceneError("slit.angle_deg",
                       std::to_string(options_.slit_angle * 180 / std::numbers::pi),
                       "with the anisotropic fibre-reinforced law, LEFM's closed form here needs "
                       "the slit along a material axis (along or across the pre-stress axis)");
  }

  Json run(RunOutput& out) override {
    const CommonSettings& c = common_;
    require_before_end(c, "slit.at", at_, "the slit", at_);
    const membrane::SlitSheet sheet = membrane::make_slit_sheet(options_);
    SoftWorld w(c);
    bullet::SkinnedSoftBody& body = w.plugin->add_skinned_body(sheet.mesh, one_bone(), material_);
    body.set_pinned(flagged_vertices(sheet.border));
    out.open_metrics({"t", "w_max", "residual", "newton_iterations", "cg_iterations"});
    const double a = 0.5 * options_.slit_length;
    const auto measure = [&] {
      Eigen::Matrix3Xd x(3, body.vertex_count());
      for (std::int32_t v = 0; v < body.vertex_count(); ++v) x.col(v) = body.position(v);
      return membrane::slit_opening(sheet, x);
    };
    bool slit = false;
    double physics_ms = 0;
    std::vector<double> w_now;
    out.body_frame("sheet", 0, body);
    const auto loop_start = Clock::now();
    for (int step = 1; step <= c.steps; ++step) {
      const double t = step * c.dt;
      const auto tp = Clock::now();
      w.step();
      physics_ms += std::chrono::duration<double, std::milli>(Clock::now() - tp).count();
      if (!slit && event_due(t, at_)) {  // between steps: the slit, as a topology change
        body.sync_mesh();
        body.apply(sheet.slit);
        slit = true;
      }
      const membrane::SolveReport& r = body.last_solve();
      if (slit) w_now = measure();
      if (slit && r.newton_iterations > 0) settled_at_ = t;
      const double w_max = w_now.empty() ? 0.0 : membrane::fit_ellipse(sheet.lip_s, w_now, a).w_max;
      if (step % c.metrics_every == 0 || step == c.steps) {
        const double row[] = {t, w_max, r.residual, double(r.newton_iterations),
                              double(r.cg_iterations)};
        out.metrics().row(row);
      }
      if (slit && step == c.steps) last_ = r;
      if (out.frame_step(step)) {
        body.sync_mesh();
        out.body_frame("sheet", step, body);
      }
      out.progress(step, c.steps);
    }
    const double loop_s = std::chrono::duration<double>(Clock::now() - loop_start).count();
    return summarise(out, sheet, w_now, physics_ms, loop_s);
  }

 private:
  Json summarise(RunOutput& out, const membrane::SlitSheet& sheet, const std::vector<double>& w,
                 double physics_ms, double loop_s) {
    const CommonSettings& c = common_;
    const double a = 0.5 * options_.slit_length;
    const double sigma_n = prestress_across(material_.skin, sheet.slit_normal);
    // LEFM's Griffith crack: 4 sigma_n a H, H = 1 / E for an isotropic law (plane stress).
    const bool along_first =
        std::abs(sheet.slit_direction.dot(sheet_first_axis(material_.skin))) > 0.5;
    const double lefm =
        4 * sigma_n * a *
        crack_compliance(membrane::small_strain_moduli(material_.skin), along_first);
    const membrane::EllipseFit fit = membrane::fit_ellipse(sheet.lip_s, w, a);
    {
      RunOutput::Csv profile = out.open_csv("profile.csv", {"s", "width", "lefm_width"});
      for (std::size_t i = 0; i < w.size(); ++i) {
        const double u = sheet.lip_s[i] / a;
        const double row[] = {sheet.lip_s[i], w[i], lefm * std::sqrt(std::max(0.0, 1 - u * u))};
        profile.row(row);
      }
    }
    out.add_plot({"profile",
                  "membrane-slit: opening along the slit against LEFM",
                  "position along the slit [m]",
                  "opening [m]",
                  {{"profile.csv", "s", "width", "membrane (Bullet nodes)", "linespoints"},
                   {"profile.csv", "s", "lefm_width", "LEFM 4 sigma_n a H", "lines"}},
                  {}});
    out.add_plot({"convergence",
                  "membrane-slit: largest opening over time",
                  "time [s]",
                  "largest opening [µm]",
                  {{"metrics.csv", "t", "w_max", "w_max (membrane)", "lines", 1e6}},
                  {}});
    Json metrics = {{"w_max", fit.w_max},
                    {"profile_r2", fit.r2},
                    {"lefm_w_max", lefm},
                    {"w_max_over_lefm", lefm > 0 ? fit.w_max / lefm : 0.0},
                    {"sigma_n", sigma_n},
                    {"nodes", sheet.mesh.vertex_count() + int(sheet.slit.new_vertices.size())},
                    {"faces", sheet.mesh.face_count()},
                    {"units",
                     "metres, pascals; residual: largest nodal force per node area, Pa; "
                     "relative_residual: residual / the larger pre-stress; settled_at: s, the "
                     "last step in which the solver moved the sheet (settled: before the end); "
                     "foundation_w_max: only with a foundation"}};
    metrics.update(solver_metrics(last_, settled_at_, c));
    // On a foundation a slit much longer than l = sqrt(E'' t / k) opens at its middle as two
    // straight edges, each retracting by sigma_n l / E'' (membrane_check.hpp).
    if (const Foundation f = foundation(material_.skin, sheet.slit_normal); f.decay_length > 0) {
      metrics["foundation_w_max"] = 2 * f.retraction(sigma_n);
      metrics["w_max_over_foundation"] = fit.w_max / (2 * f.retraction(sigma_n));
      metrics["foundation_decay_length"] = f.decay_length;
    }
    Json timings = {{"physics_ms_per_step", physics_ms / c.steps}};
    out.finish(resolved_, metrics, timings, c.steps, c.steps * c.dt, loop_s);
    return metrics;
  }

  membrane::SlitSheetOptions options_;
  bullet::Material material_;
  double at_ = 0.1;
  membrane::SolveReport last_;  // the last step's (the slit is always before it)
  double settled_at_ = 0;
};

std::unique_ptr<Scene> make_membrane_slit(const Json& scene, const std::string& name,
                                          int steps_override) {
  return std::make_unique<MembraneSlit>(scene, name, steps_override);
}

const SceneRegistration kMembraneSlitRegistration{
    {"membrane-slit",
     "the skin membrane against LEFM: a pinned, pre-stressed sheet slit through its centre "
     "opens as an ellipse of maximum 4 sigma_n a / E",
     kMembraneSlitJson.c_str(), &make_membrane_slit, 5, "w_max_over_lefm,w_max"}};

}  // namespace

}  // namespace conform::scenes
