// `membrane-edge`: the cut against a membrane on an elastic foundation. A flat square sheet
// of skin on its foundation (the attachment to its skinned targets, k > 0; border free),
// pre-stressed by material.prestress = [sigma_xx, sigma_yy] along its axes, is severed along
// the plane x = 0 at cut.at by the plugin's own planar cut on the live Bullet soft body, and
// settles. Each lip retracts away from the cut (membrane_check.hpp, plane stress):
//   u(d) = u0 exp(-d / l),  u0 = sigma_xx l / E'',  l = sqrt(E'' t / k),  E'' = E / (1 - nu^2),
// d the distance from the edge. With an isotropic in-plane foundation the solution is
// one-dimensional away from the cut's ends, so it is measured on the row y = 0 (mid-edge).
// Reports both lips' retraction at the edge, the decay length fitted to log u(d) and the
// closed forms.
//
// Defaults: the skin's own material (E 0.42 MPa, nu 0.48, t 1.5 mm, k 4e5 Pa/m: l = 4.5 cm);
// pre-stress 400 Pa keeps the strain at 1e-3 (linear elasticity's small strain). Elements of
// sheet.resolution = 4 mm (l / 11) within 4 l of the cut and 2 l of the mid-edge row, growing
// by 1.2 beyond. The sheet is sheet.decay_lengths = 20 l wide: its free border retracts under
// the pre-stress before the cut and so lowers the stress the cut releases at x = 0 by
// 2 sigma exp(-W / 2 l) (measured: 1.9 % low at W = 10 l, 0.16 % at 20 l). The displacement
// is measured from the state just before the cut (superposition: the border's own retraction
// is taken away). Measured at the defaults: retraction 0.998, decay length 1.000 of the closed
// forms; with the element size halved, 0.9998 and 1.0000.
#include <algorithm>
#include <chrono>
#include <cmath>

#include "kinds/edge_sheet.hpp"
#include "kinds/event_time.hpp"
#include "kinds/membrane_check.hpp"
#include "kinds/scene.hpp"
#include "kinds/soft_scene.hpp"

namespace conform::scenes {
namespace {

using Clock = std::chrono::steady_clock;

// The built-in scene `membrane-edge` (`conform scenes --show membrane-edge`).
const std::string kMembraneEdgeJson = join_scene_json({R"json({
  "scene": "membrane-edge",
  "description": "A square sheet of skin membrane (SI units) on its foundation (attachment_stiffness k), border free, pre-stressed by material.prestress = [sigma_xx, sigma_yy] along its axes, is cut along the plane x = 0 by the plugin's planar cut on the live Bullet soft body; it settles, and each lip's retraction at mid-edge is compared with the membrane on an elastic foundation (plane stress): u(d) = u0 exp(-d / l), u0 = sigma_xx l / E'', l = sqrt(E'' t / k), E'' = E / (1 - nu^2) (4 E / 3 for the incompressible neo-Hookean law: the law's modulus of a strain across the edge with none along it).",
  "duration": 0.5,
  "sheet": { "decay_lengths": 20, "resolution": 0.004, "fine_across": 4, "fine_along": 2, "grading": 1.2 },
  "cut": { "at": 0.1 },
  "measure": { "fit_floor": 0.05 },
  "material": { "prestress": [400, 400], "prestress_axis": [1, 0, 0], "youngs_modulus": 420000, "poisson_ratio": 0.48,
                "thickness": 0.0015, "attachment_stiffness": 400000,
                "attachment_normal_stiffness": 40000000, "wrinkling": false, "relative_tolerance": 1e-06, "max_cg_iterations": 4000 },)json",
                                                       kSheetCheckPhysicsJson, R"json(
  "outputs": { "metrics_every": 1, "frames_every": 0, "plots": true }
})json"});

// The retraction along the mid-edge row: per lip, distances from the edge (rest |x|) and
// displacements away from the cut since just before it, nearest the edge first.
struct EdgeProfile {
  std::vector<double> d, left, right;
};

// log u = log A - d / L, least squares over the points of both lips with u >= floor x (their
// edge retraction): L, or 0 with fewer than 3 such points.
double fit_decay_length(const EdgeProfile& p, double floor) {
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (const auto* u : {&p.left, &p.right}) {
    if (u->empty()) continue;
    const double cut_off = floor * u->front();
    for (std::size_t i = 0; i < u->size() && (*u)[i] >= cut_off && (*u)[i] > 0; ++i) {
      const double x = p.d[i], y = std::log((*u)[i]);
      n += 1, sx += x, sy += y, sxx += x * x, sxy += x * y;
    }
  }
  const double det = n * sxx - sx * sx;
  if (n < 3 || det <= 0) return 0;
  const double slope = (n * sxy - sx * sy) / det;
  return slope < 0 ? -1 / slope : 0;
}

class MembraneEdge final : public Scene {
 public:
  MembraneEdge(const Json& scene, const std::string& name, int steps_override) {
    Reader root(scene, "", resolved_);
    Reader sheet = root.object("sheet");
    decay_lengths_ = sheet.number("decay_lengths", 20, 4, 100);
    options_.element_size = sheet.number("resolution", 4e-3, 1e-5, 1);
    fine_across_ = sheet.number("fine_across", 4, 0, 50);
    fine_along_ = sheet.number("fine_along", 2, 0, 50);
    options_.grading = sheet.number("grading", 1.2, 1, 2);
    sheet.finish();
    Reader cut = root.object("cut");
    at_ = cut.number("at", 0.1, 0, 1e5);
    cut.finish();
    Reader measure = root.object("measure");
    fit_floor_ = measure.number("fit_floor", 0.05, 1e-6, 0.9);
    measure.finish();
    bullet::Material d;
    d.skin.prestress = {400, 400};
    d.skin.prestress_axis = Eigen::Vector3d::UnitX();  // prestress = [sigma_xx, sigma_yy]
    d.skin.wrinkling = false;                          // the closed form is linear elasticity
    d.solver.relative_tolerance = 1e-6;  // frozen error ~ tol x sigma / k, << the fitted tail
    d.solver.max_cg_iterations = 4000;
    material_ = read_material(root, d);
    common_ = read_common(root, name, 0.5, steps_override);
    root.finish();
    check_settings();
  }

  Json run(RunOutput& out) override;

 private:
  void check_settings() {
    if (material_.model != bullet::MaterialModel::membrane)
      throw SceneError("material.model", "\"bullet_links\"",
                       "membrane-edge measures the membrane; Bullet's links have no modulus");
    const double k = material_.skin.attachment_stiffness;
    if (!(k > 0))
      throw SceneError("material.attachment_stiffness", std::to_string(k),
                       "must be > 0: membrane-edge measures the sheet on its foundation");
    if (!material_axes_aligned(material_.skin, Eigen::Vector3d::UnitX()))
      throw SceneError("material.prestress_axis", "",
                       "membrane-edge's closed form needs the cut's normal (x) along a material "
                       "axis of the anisotropic law (the axis along x or y)");
    const double l = foundation(material_.skin, Eigen::Vector3d::UnitX()).decay_length;
    if (options_.element_size > 0.5 * l)
      throw SceneError("sheet.resolution", std::to_string(options_.element_size),
                       "at most half the decay length sqrt(E'' t / k) = " + std::to_string(l));
    options_.width = decay_lengths_ * l;
    options_.fine_across = fine_across_ * l;
    options_.fine_along = fine_along_ * l;
    if (options_.element_size > 0.05 * options_.width)
      throw SceneError("sheet.resolution", std::to_string(options_.element_size),
                       "at most sheet.decay_lengths x l / 20 (20 elements across the sheet)");
    if (options_.width / options_.element_size > 2e3)
      throw SceneError("sheet.resolution", std::to_string(options_.element_size),
                       "too fine for sheet.decay_lengths (more than 2000 elements across)");
  }

  // The mid-edge row's retraction since `before` (its x positions just before the cut, by
  // rest x); `side` of a vertex: +1 / -1 for the lips at x > 0 / x < 0.
  EdgeProfile measure(const bullet::SkinnedSoftBody& body, const std::vector<std::int32_t>& row,
                      const std::vector<std::int8_t>& side,
                      const std::vector<double>& before) const {
    EdgeProfile p;
    std::vector<std::pair<double, double>> left, right;  // (d, u)
    for (const std::int32_t v : row) {
      const double x = body.mesh().rest(0, v);
      const auto i =
          std::lower_bound(sheet_.xs.begin(), sheet_.xs.end(), x - 1e-12) - sheet_.xs.begin();
      const double u = body.position(v).x() - before[std::size_t(i)];
      (side[std::size_t(v)] > 0 ? right : left).emplace_back(std::abs(x), side[std::size_t(v)] * u);
    }
    std::sort(left.begin(), left.end());
    std::sort(right.begin(), right.end());
    for (std::size_t i = 0; i < std::min(left.size(), right.size()); ++i) {
      p.d.push_back(right[i].first);
      p.left.push_back(left[i].second);
      p.right.push_back(right[i].second);
    }
    return p;
  }

  Json summarise(RunOutput& out, const EdgeProfile& p, const membrane::SolveReport& last,
                 double physics_ms, double loop_s, std::int32_t nodes);

  EdgeSheetOptions options_;
  EdgeSheet sheet_;
  bullet::Material material_;
  double decay_lengths_ = 20, fine_across_ = 4, fine_along_ = 2, at_ = 0.1, fit_floor_ = 0.05;
  double settled_at_ = 0;
  Json cut_event_;
};

// Which lip each vertex is on after the cut: the side of the faces it belongs to.
std::vector<std::int8_t> lip_sides(const mesh::SkinnedMesh& m) {
  std::vector<std::int8_t> side(std::size_t(m.vertex_count()), 0);
  for (const mesh::Face& f : m.faces) {
    const double cx = (m.rest(0, f[0]) + m.rest(0, f[1]) + m.rest(0, f[2])) / 3;
    for (const std::int32_t v : f) side[std::size_t(v)] = cx > 0 ? 1 : -1;
  }
  return side;
}

Json MembraneEdge::run(RunOutput& out) {
  const CommonSettings& c = common_;
  require_before_end(c, "cut.at", at_, "the cut", at_);
  sheet_ = make_edge_sheet(options_);
  SoftWorld w(c);
  bullet::SkinnedSoftBody& body = w.plugin->add_skinned_body(sheet_.mesh, one_bone(), material_);
  out.open_metrics({"t", "edge_retraction", "residual", "newton_iterations", "cg_iterations"});
  std::vector<std::int32_t> row = sheet_.mid_row;
  std::vector<std::int8_t> side;
  std::vector<double> before;  // the row's x positions just before the cut, by grid column
  bool cut = false;
  EdgeProfile profile;
  membrane::SolveReport last;
  double physics_ms = 0;
  out.body_frame("sheet", 0, body);
  const auto loop_start = Clock::now();
  for (int step = 1; step <= c.steps; ++step) {
    const double t = step * c.dt;
    const auto tp = Clock::now();
    w.step();
    physics_ms += std::chrono::duration<double, std::milli>(Clock::now() - tp).count();
    if (!cut && event_due(t, at_)) {  // between steps: the plugin's planar cut
      for (const std::int32_t v : sheet_.mid_row) before.push_back(body.position(v).x());
      const std::int32_t count = body.vertex_count();
      const mesh::CutResult r = body.cut(
          cga::Plane<double>::from_normal_point(Eigen::Vector3d::UnitX(), Eigen::Vector3d::Zero()));
      if (r.status != mesh::CutStatus::Cut)
        throw std::runtime_error("membrane-edge: the cut missed the sheet: " + r.message);
      for (std::int32_t v = count; v < body.vertex_count(); ++v)
        if (std::abs(body.mesh().rest(1, v)) < 1e-12) row.push_back(v);
      body.sync_mesh();
      side = lip_sides(body.mesh());
      cut_event_ = {{"crossed_edges", r.crossed_edges},
                    {"snapped_vertices", r.snapped_vertices},
                    {"new_vertices", body.vertex_count() - count},
                    {"pieces", body.piece_count()}};
      cut = true;
    }
    last = body.last_solve();
    if (cut) {
      profile = measure(body, row, side, before);
      if (last.newton_iterations > 0) settled_at_ = t;
    }
    if (step % c.metrics_every == 0 || step == c.steps) {
      const double u0 = profile.d.empty() ? 0 : 0.5 * (profile.left[0] + profile.right[0]);
      const double r[] = {t, u0, last.residual, double(last.newton_iterations),
                          double(last.cg_iterations)};
      out.metrics().row(r);
    }
    if (out.frame_step(step)) {
      body.sync_mesh();
      out.body_frame("sheet", step, body);
    }
    out.progress(step, c.steps);
  }
  const double loop_s = std::chrono::duration<double>(Clock::now() - loop_start).count();
  if (profile.d.empty() || profile.d[0] != 0)
    throw std::runtime_error("membrane-edge: no lip vertex on the mid-edge row at the cut");
  return summarise(out, profile, last, physics_ms, loop_s, body.vertex_count());
}

Json MembraneEdge::summarise(RunOutput& out, const EdgeProfile& p,
                             const membrane::SolveReport& last, double physics_ms, double loop_s,
                             std::int32_t nodes) {
  const CommonSettings& c = common_;
  const Foundation f = foundation(material_.skin, Eigen::Vector3d::UnitX());
  const double sigma = prestress_across(material_.skin, Eigen::Vector3d::UnitX());  // cut x = 0
  const double u0 = f.retraction(sigma), l = f.decay_length;
  {
    RunOutput::Csv csv = out.open_csv(
        "profile.csv", {"d", "retraction_left", "retraction_right", "foundation_retraction"});
    for (std::size_t i = 0; i < p.d.size(); ++i) {
      const double r[] = {p.d[i], p.left[i], p.right[i], u0 * std::exp(-p.d[i] / l)};
      csv.row(r);
    }
  }
  out.add_plot(
      {"profile",
       "membrane-edge: retraction of the lips at mid-edge against the foundation",
       "distance from the edge [m]",
       "retraction [m]",
       {{"profile.csv", "d", "retraction_left", "left lip (x < 0)", "linespoints"},
        {"profile.csv", "d", "retraction_right", "right lip (x > 0)", "linespoints"},
        {"profile.csv", "d", "foundation_retraction", "foundation: u0 exp(-d / l)", "lines"}},
       {}});
  out.add_plot({"convergence",
                "membrane-edge: retraction at mid-edge over time",
                "time [s]",
                "retraction [m]",
                {{"metrics.csv", "t", "edge_retraction", "mean of the lips", "lines"}},
                {}});
  const double mean = 0.5 * (p.left[0] + p.right[0]);
  const double fitted = fit_decay_length(p, fit_floor_);
  Json metrics = {{"edge_retraction", mean},
                  {"edge_retraction_left", p.left[0]},
                  {"edge_retraction_right", p.right[0]},
                  {"decay_length", fitted},
                  {"foundation_retraction", u0},
                  {"foundation_decay_length", l},
                  {"plane_modulus", f.plane_modulus},
                  {"sigma_n", sigma},
                  {"cut", cut_event_},
                  {"nodes", nodes},
                  {"faces", sheet_.mesh.face_count()},
                  {"sheet_width", options_.width}};
  // The ratios only where there is something to compare (a summary holds finite numbers only).
  if (u0 > 0) metrics["retraction_over_foundation"] = mean / u0;
  if (fitted > 0) metrics["decay_length_over_foundation"] = fitted / l;
  metrics.update(solver_metrics(last, settled_at_, c));
  metrics["units"] =
      "metres, pascals; retraction: displacement of the mid-edge row away from the cut since "
      "just before it; decay_length: fitted to log u(d) where u >= measure.fit_floor x the "
      "edge's; residual: largest nodal force per node area, Pa; settled_at: s, the last step in "
      "which the solver moved the sheet";
  Json timings = {{"physics_ms_per_step", physics_ms / c.steps}};
  out.finish(resolved_, metrics, timings, c.steps, c.steps * c.dt, loop_s);
  return metrics;
}

std::unique_ptr<Scene> make_membrane_edge(const Json& scene, const std::string& name,
                                          int steps_override) {
  return std::make_unique<MembraneEdge>(scene, name, steps_override);
}

const SceneRegistration kMembraneEdgeRegistration{
    {"membrane-edge",
     "the cut against the foundation: a pre-stressed sheet on its foundation cut along x = 0 "
     "retracts by sigma l / E'' at the edge, decaying as exp(-d / l), l = sqrt(E'' t / k)",
     kMembraneEdgeJson.c_str(), &make_membrane_edge, 8,
     "retraction_over_foundation,decay_length_over_foundation"}};

}  // namespace

}  // namespace conform::scenes
