// `membrane-hole`: the drill against Kirsch. A flat sheet pinned at its border (30 hole radii
// away, graded mesh: the sheet of membrane-slit without its slit), pre-stressed by
// material.prestress = [sigma_xx, sigma_yy] along its axes, is drilled through at hole.at by the
// project's own drill on the live Bullet soft body, and settles. Kirsch's small-strain solution
// for a traction-free round hole made in a pre-stressed plate (plane stress) grows its
// semi-axes by
//   da_x / a = (2 sigma_xx - (1 - nu) sigma_yy) / E,  da_y / a = (2 sigma_yy - (1 - nu) sigma_xx) /
//   E
// (the change from the stressed plate without the hole; the border at 30 radii lowers it by
// well under 1 %). Reports the measured growths (a fit u_r / a = g0 + g2 cos 2 theta +
// g2' sin 2 theta over the rim's vertices), the Kirsch values and the solver's residual.
#include <chrono>
#include <cmath>
#include <numbers>

#include <Eigen/Dense>

#include "conform/membrane/slit_sheet.hpp"
#include "kinds/membrane_check.hpp"
#include "kinds/scene.hpp"
#include "kinds/soft_scene.hpp"

namespace conform::scenes {
namespace {

using Clock = std::chrono::steady_clock;

// The built-in scene `membrane-hole` (`conform scenes --show membrane-hole`).
const std::string kMembraneHoleJson =
    join_scene_json({R"json({
  "scene": "membrane-hole",
  "description": "A square sheet of skin membrane (SI units) pinned at its border 30 hole radii away and pre-stressed by material.prestress = [sigma_xx, sigma_yy] along its axes is drilled through its centre by the project's drill on the live Bullet soft body; it settles, and the growth of the hole's semi-axes is compared with Kirsch's solution (plane stress): da_x / a = (2 sigma_xx - (1 - nu) sigma_yy) / E.",
  "duration": 1.0,
  "sheet": { "radii": 30, "resolution": 0.00125 },
  "hole": { "radius": 0.01, "at": 0.1 },)json",
                     kPinnedSheetMaterialJson, kSheetCheckPhysicsJson, R"json(
  "outputs": { "metrics_every": 1, "frames_every": 0, "plots": false }
})json"});

struct RimFit {
  double growth_x = 0, growth_y = 0;  // relative change of the semi-axes
  int vertices = 0;
};

// Least squares u_r / a = g0 + g2 cos 2 theta + g3 sin 2 theta over the rim's vertices (rest
// radius within 2 % of a element from a), u = position - rest.
RimFit fit_rim(const bullet::SkinnedSoftBody& body, double a, double h) {
  const mesh::SkinnedMesh& m = body.mesh();
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  RimFit fit;
  for (std::int32_t v = 0; v < body.vertex_count(); ++v) {
    const Eigen::Vector3d rest = m.rest.col(v);
    const double r = std::hypot(rest.x(), rest.y());
    if (std::abs(r - a) > 0.02 * h || body.detached(v)) continue;
    const Eigen::Vector3d er(rest.x() / r, rest.y() / r, 0);
    const double ur = (body.position(v) - rest).dot(er) / a, t = std::atan2(rest.y(), rest.x());
    const Eigen::Vector3d phi(1, std::cos(2 * t), std::sin(2 * t));
    normal += phi * phi.transpose();
    rhs += phi * ur;
    ++fit.vertices;
  }
  if (fit.vertices < 6) throw std::runtime_error("membrane-hole: the drill left no rim to measure");
  const Eigen::Vector3d g = normal.ldlt().solve(rhs);
  fit.growth_x = g[0] + g[1];
  fit.growth_y = g[0] - g[1];
  return fit;
}

class MembraneHole final : public Scene {
 public:
  MembraneHole(const Json& scene, const std::string& name, int steps_override) {
    Reader root(scene, "", resolved_);
    Reader sheet = root.object("sheet");
    const double radii = sheet.number("radii", 30, 4, 200);
    h_ = sheet.number("resolution", 1.25e-3, 1e-5, 1);
    sheet.finish();
    Reader hole = root.object("hole");
    radius_ = hole.number("radius", 0.01, 1e-4, 10);
    at_ = hole.number("at", 0.1, 0, 1e5);
    hole.finish();
    if (h_ > 0.5 * radius_)
      throw SceneError("sheet.resolution", std::to_string(h_), "at most hole.radius / 2");
    // The slit sheet's graded grid, fine (h) within 2 radii of the centre; no slit.
    options_.width = 2 * radii * radius_;
    options_.slit_length = 2 * radius_;
    options_.element_size = h_;
    options_.tip_refinement = 1;
    options_.fine_zone = 2;
    bullet::Material d;
    d.skin.prestress = {400, 400};
    d.skin.prestress_axis = Eigen::Vector3d::UnitX();  // prestress = [sigma_xx, sigma_yy]
    d.skin.attachment_stiffness = 0;                   // a free membrane held by its border
    d.skin.attachment_normal_stiffness = 0;
    d.skin.wrinkling = false;  // Kirsch is linear elasticity: the hoop stress may be compressive
    d.solver.relative_tolerance = 1e-4;
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
                       "membrane-hole measures the membrane; Bullet's links have no modulus");
    if (!membrane::small_strain_moduli(material_.skin).isotropic())
      throw SceneError("material.law", "\"fibre-reinforced\"",
                       "membrane-hole compares with Kirsch's solution for an isotropic plate; "
                       "the fibre-reinforced law is anisotropic");
  }

  Json run(RunOutput& out) override {
    const CommonSettings& c = common_;
    const membrane::SlitSheet sheet = membrane::make_slit_sheet(options_);
    SoftWorld w(c);
    bullet::SkinnedSoftBody& body = w.plugin->add_skinned_body(sheet.mesh, one_bone(), material_);
    body.set_pinned(flagged_vertices(sheet.border));
    out.open_metrics({"t", "growth_x", "growth_y", "residual", "newton_iterations"});
    bool drilled = false;
    RimFit fit;
    membrane::SolveReport last;
    double physics_ms = 0, settled_at = 0;
    int rim_vertices = 0;
    const auto loop_start = Clock::now();
    for (int step = 1; step <= c.steps; ++step) {
      const double t = step * c.dt;
      const auto tp = Clock::now();
      w.step();
      physics_ms += std::chrono::duration<double, std::milli>(Clock::now() - tp).count();
      if (!drilled && t >= at_) {  // between steps: the drill, through the sheet's plane
        body.sync_mesh();
        const mesh::DrillResult r =
            body.drill({Eigen::Vector3d(0, 0, radius_), Eigen::Vector3d(0, 0, -radius_), radius_});
        if (r.holes != 1)
          throw std::runtime_error("membrane-hole: the drill made " + std::to_string(r.holes) +
                                   " holes (" + r.message + ")");
        rim_vertices = r.rim_vertices + r.snapped_rim_vertices;
        drilled = true;
      }
      last = body.last_solve();
      if (drilled) {
        fit = fit_rim(body, radius_, h_);
        if (last.newton_iterations > 0) settled_at = t;
      }
      if (step % c.metrics_every == 0 || step == c.steps) {
        const double row[] = {t, fit.growth_x, fit.growth_y, last.residual,
                              double(last.newton_iterations)};
        out.metrics().row(row);
      }
      out.progress(step, c.steps);
    }
    const double loop_s = std::chrono::duration<double>(Clock::now() - loop_start).count();
    if (!drilled)
      throw std::runtime_error("membrane-hole: the run ended (" + std::to_string(c.steps * c.dt) +
                               " s) before hole.at = " + std::to_string(at_) + " s");
    // The isotropic law's small-strain E and nu (nu = 1/2 for the neo-Hookean law).
    const membrane::PlaneModuli m = membrane::small_strain_moduli(material_.skin);
    const double nu = m.c12 / m.c22, e = m.c11 - m.c12 * nu;
    const double sxx = prestress_across(material_.skin, Eigen::Vector3d::UnitX()),
                 syy = prestress_across(material_.skin, Eigen::Vector3d::UnitY());
    const double kx = (2 * sxx - (1 - nu) * syy) / e, ky = (2 * syy - (1 - nu) * sxx) / e;
    Json metrics = {{"hole_growth_x", fit.growth_x},
                    {"hole_growth_y", fit.growth_y},
                    {"kirsch_growth_x", kx},
                    {"kirsch_growth_y", ky},
                    {"growth_x_over_kirsch", kx != 0 ? fit.growth_x / kx : 0.0},
                    {"growth_y_over_kirsch", ky != 0 ? fit.growth_y / ky : 0.0},
                    {"rim_vertices", rim_vertices},
                    {"rim_vertices_fitted", fit.vertices},
                    {"nodes", body.vertex_count()},
                    {"units",
                     "growths: relative change of the hole's semi-axes along x and y; residual: "
                     "largest nodal force per node area, Pa; settled_at: s, the last step in "
                     "which the solver moved the sheet"}};
    metrics.update(solver_metrics(last, settled_at, c));
    Json timings = {{"physics_ms_per_step", physics_ms / c.steps}};
    out.finish(resolved_, metrics, timings, c.steps, c.steps * c.dt, loop_s);
    return metrics;
  }

 private:
  membrane::SlitSheetOptions options_;
  bullet::Material material_;
  double h_ = 1.25e-3, radius_ = 0.01, at_ = 0.1;
};

std::unique_ptr<Scene> make_membrane_hole(const Json& scene, const std::string& name,
                                          int steps_override) {
  return std::make_unique<MembraneHole>(scene, name, steps_override);
}

const SceneRegistration kMembraneHoleRegistration{
    {"membrane-hole",
     "the drill against Kirsch: a hole drilled in a pinned, pre-stressed sheet grows its "
     "semi-axes by (2 sigma_xx - (1 - nu) sigma_yy) / E and the same swapped",
     kMembraneHoleJson.c_str(), &make_membrane_hole, 7,
     "growth_x_over_kirsch,growth_y_over_kirsch"}};

}  // namespace

}  // namespace conform::scenes
