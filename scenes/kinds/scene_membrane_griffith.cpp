// `membrane-griffith`: the skin tears by itself, checked against Griffith. A flat sheet pinned
// at its border, with a straight slit of half-length a at slit.angle_deg to x, is loaded by a
// border stretch ramped in time: the remote stress sigma_yy = load.preload + load.rate t along y
// and sigma_xx = load.ratio sigma_yy, the border held at the law's small-strain strains for them
// (PlaneModuli; the sheet runs at strains of 1e-3, where the law is linear elasticity). Each step
// solves the static equilibrium (membrane::CrackedSheet, core only: no Bullet body) and grows the
// tears where the energy release rate reaches the toughness (crack_growth.hpp). Reports the
// remote stress normal to the slit at the first growth step (onset_stress) against Griffith's
// sqrt(E G_c / (pi a)) (plane stress), the first growth direction against the maximum
// tangential stress criterion for the slit's mode mix, and the length grown over time.
//
// The toughness here (0.1 J/m^2) is 1e4 below skin's: with skin's own, a centimetre slit would
// start to grow at about half of E (skin_material.hpp), far outside linear fracture mechanics.
#include <chrono>
#include <cmath>
#include <numbers>
#include <optional>

#include "conform/membrane/crack_growth.hpp"
#include "conform/membrane/slit_sheet.hpp"
#include "kinds/membrane_check.hpp"
#include "kinds/scene.hpp"
#include "kinds/soft_scene.hpp"

namespace conform::scenes {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kDeg = std::numbers::pi / 180;

// The built-in scene `membrane-griffith` (`conform scenes --show membrane-griffith`).
constexpr const char* kMembraneGriffithJson = R"json({
  "scene": "membrane-griffith",
  "description": "A square sheet of skin membrane pinned at its border, with a straight slit, is stretched at its border (remote sigma_yy = load.preload + load.rate t, sigma_xx = load.ratio sigma_yy); the slit's tips grow where the energy release rate reaches the toughness, in the direction of the maximum tangential stress. Onset against Griffith's sqrt(E G_c / (pi a)), the first kink against the MTS angle.",
  "duration": 1.0,
  "sheet": { "width": 1.2, "resolution": 0.0025, "tip_refinement": 16 },
  "slit": { "half_length": 0.025, "angle_deg": 0 },
  "load": { "preload": 0, "rate": 1000, "ratio": 0 },
  "growth": { "domain_radius": 0.5, "step_length": 0.01, "max_extensions": 64 },
  "material": { "law": "neo-hookean", "prestress": [0, 0], "youngs_modulus": 420000, "thickness": 0.0015,
                "toughness": 0.1, "attachment_stiffness": 0, "attachment_normal_stiffness": 0,
                "wrinkling": false, "relative_tolerance": 1e-07, "max_cg_iterations": 20000 },
  "physics": { "dt": 0.01, "substeps": 1, "gravity": [0, 0, 0] },
  "outputs": { "metrics_every": 1, "frames_every": 0, "plots": true }
})json";

// The remote stress of the ramp at time t and the border strains that give it.
struct Load {
  double preload = 0, rate = 1000, ratio = 0;
  double sigma_yy(double t) const { return preload + rate * t; }
  // [e_xx, e_yy] of the plane-stress moduli for [ratio s, s], s = sigma_yy.
  Eigen::Vector2d strains(const membrane::PlaneModuli& c, double s) const {
    Eigen::Matrix2d stiffness;
    stiffness << c.c11, c.c12, c.c12, c.c22;
    return stiffness.inverse() * Eigen::Vector2d(ratio * s, s);
  }
};

class MembraneGriffith final : public Scene {
 public:
  MembraneGriffith(const Json& scene, const std::string& name, int steps_override) {
    Reader root(scene, "", resolved_);
    read_slit_sheet(root, options_);
    Reader slit = root.object("slit");
    options_.slit_length = 2 * slit.number("half_length", 0.025, 5e-5, 5);
    options_.slit_angle = slit.number("angle_deg", 0, -90, 90) * kDeg;
    slit.finish();
    Reader load = root.object("load");
    load_.preload = load.number("preload", 0, 0, 1e9);
    load_.rate = load.number("rate", 1000, 1e-6, 1e9);
    load_.ratio = load.number("ratio", 0, -1, 1);
    load.finish();
    Reader growth = root.object("growth");
    domain_fraction_ = growth.number("domain_radius", 0.5, 0.05, 0.95);
    growth_.step_length = growth.number("step_length", 0.01, 1e-6, 10);
    growth_.max_extensions = growth.integer("max_extensions", 64, 1, 100000);
    growth.finish();
    material_ = read_material(root, defaults());
    common_ = read_common(root, name, 1.0, steps_override);
    root.finish();
    validate();
  }

  Json run(RunOutput& out) override {
    const CommonSettings& c = common_;
    const membrane::SkinMaterial& m = material_.skin;
    membrane::CrackedSheet sheet = make_sheet();
    const membrane::PlaneModuli moduli = membrane::small_strain_moduli(m);
    out.open_metrics({"t", "sigma_yy", "sigma_n", "g_max", "g_over_toughness", "grown_length",
                      "extensions", "residual"});
    frame(out, sheet, 0);
    const auto loop_start = Clock::now();
    double previous_sigma = 0, grown = 0;
    int step = 1;
    for (; step <= c.steps; ++step) {
      const double t = step * c.dt, sigma = load_.sigma_yy(t);
      load_border(sheet, moduli, sigma, previous_sigma);
      previous_sigma = sigma;
      const membrane::SolveReport solved = sheet.solve();
      const membrane::GrowthReport g = sheet.grow(growth_);
      grown += g.grown;
      const double g_max = largest_g(g);
      if (!g.extensions.empty() && !onset_) record_onset(g, t, sigma, sheet);
      const double row[] = {t,
                            sigma,
                            sigma_n(sigma),
                            g_max,
                            g_max / m.toughness,
                            grown,
                            double(g.extensions.size()),
                            g.extensions.empty() ? solved.residual : g.solve.residual};
      if (step % c.metrics_every == 0 || step == c.steps) out.metrics().row(row);
      if (c.frames_every > 0 && step % c.frames_every == 0) frame(out, sheet, step);
      out.progress(step, c.steps);
      if (all_stopped(sheet)) break;  // both tears reached the border: nothing more to grow
    }
    const int steps_run = std::min(step, c.steps);
    frame(out, sheet, steps_run);
    const double loop_s = std::chrono::duration<double>(Clock::now() - loop_start).count();
    return summarise(out, sheet, grown, steps_run, loop_s);
  }

 private:
  static bullet::Material defaults() {
    bullet::Material d;
    d.skin.prestress = {0, 0};  // the load is the border stretch
    d.skin.prestress_axis = Eigen::Vector3d::UnitX();
    d.skin.toughness = 0.1;  // LEFM's regime: see the top of this file
    d.skin.attachment_stiffness = 0;
    d.skin.attachment_normal_stiffness = 0;
    d.skin.wrinkling = false;            // LEFM is linear elasticity: the sheet carries compression
    d.solver.relative_tolerance = 1e-7;  // of E (no pre-stress): 0.04 Pa against ~700 Pa
    d.solver.max_cg_iterations = 20000;
    return d;
  }

  void validate() {
    try {
      options_.validate();
    } catch (const std::invalid_argument& e) {
      throw SceneError("sheet", "", e.what());
    }
    const membrane::SkinMaterial& m = material_.skin;
    if (m.prestress[0] != 0 || m.prestress[1] != 0)
      throw SceneError("material.prestress", Json(m.prestress).dump(),
                       "must be [0, 0]: membrane-griffith loads the sheet by its border");
    if (!membrane::small_strain_moduli(m).isotropic())
      throw SceneError("material.law", "\"fibre-reinforced\"",
                       "membrane-griffith's closed forms are those of an isotropic plate");
    if (material_.model != bullet::MaterialModel::membrane)
      throw SceneError("material.model", "\"bullet_links\"",
                       "membrane-griffith measures the membrane; Bullet's links have no modulus");
  }

  double half_length() const { return 0.5 * options_.slit_length; }
  Eigen::Vector3d slit_direction() const {
    return {std::cos(options_.slit_angle), std::sin(options_.slit_angle), 0};
  }
  // The remote stress normal to the slit and along it (shear), for sigma_yy = s.
  double sigma_n(double s) const {
    const double c = std::cos(options_.slit_angle), sn = std::sin(options_.slit_angle);
    return s * (load_.ratio * sn * sn + c * c);
  }
  double tau(double s) const {
    const double c = std::cos(options_.slit_angle), sn = std::sin(options_.slit_angle);
    return s * (1 - load_.ratio) * sn * c;
  }

  membrane::CrackedSheet make_sheet() {
    membrane::SlitSheet slit = membrane::make_slit_sheet(options_);
    mesh::apply(slit.mesh, slit.slit);
    std::vector<std::uint8_t> fixed(slit.border);
    fixed.resize(std::size_t(slit.mesh.vertex_count()), 0);
    const Eigen::Vector3d e = slit_direction();
    std::vector<membrane::CrackTip> tips;
    for (const double sign : {1.0, -1.0}) {
      const Eigen::Vector3d at = sign * half_length() * e;
      std::int32_t best = 0;
      for (std::int32_t v = 1; v < slit.mesh.vertex_count(); ++v)
        if ((slit.mesh.rest.col(v) - at).norm() < (slit.mesh.rest.col(best) - at).norm()) best = v;
      tips.push_back({best, sign * e});
    }
    growth_.domain.domain_radius = domain_fraction_ * half_length();
    return {std::move(slit.mesh), std::move(fixed), tips, material_.skin, material_.solver};
  }

  // The border at the strains of sigma_yy = s; the free nodes' displacements scaled from the
  // last load's (the sheet is linear here, so Newton starts next to the solution).
  void load_border(membrane::CrackedSheet& sheet, const membrane::PlaneModuli& moduli, double s,
                   double previous) const {
    Eigen::Matrix3Xd& x = sheet.positions();
    const double scale = previous > 0 ? s / previous : 1.0;
    const Eigen::Vector2d eps = load_.strains(moduli, s);
    for (Eigen::Index v = 0; v < x.cols(); ++v) {
      const Eigen::Vector3d r = sheet.mesh().rest.col(v);
      if (sheet.fixed()[std::size_t(v)])
        x.col(v) = r + Eigen::Vector3d(eps.x() * r.x(), eps.y() * r.y(), 0);
      else
        x.col(v) = r + scale * (x.col(v) - r);
    }
  }

  static double largest_g(const membrane::GrowthReport& g) {
    double most = 0;
    for (const membrane::TipEvaluation& e : g.first)
      most = std::max(most, e.fracture.energy_release_rate);
    return most;
  }

  static bool all_stopped(const membrane::CrackedSheet& sheet) {
    for (const membrane::GrowingTip& t : sheet.tips())
      if (!t.stopped) return false;
    return true;
  }

  void record_onset(const membrane::GrowthReport& g, double t, double sigma,
                    const membrane::CrackedSheet& sheet) {
    const membrane::TipEvaluation& first = g.extensions.front();
    const membrane::GrowingTip& tip = sheet.tips()[std::size_t(first.tip)];
    const Eigen::Vector3d e = slit_direction() * (first.tip == 0 ? 1.0 : -1.0);
    const Eigen::Vector3d chord = tip.path.at(1) - tip.path.at(0);
    const double turn = std::atan2(e.cross(chord).z(), e.dot(chord));
    // The kink is measured toward N x e, N the faces' normal: turned to the z axis's frame.
    const double up = membrane::sheet_normal(sheet.mesh(), tip.tip.vertex).z() > 0 ? 1.0 : -1.0;
    onset_ = Json{{"time", t},
                  {"sigma_yy", sigma},
                  {"stress", sigma_n(sigma)},
                  {"kink_deg", up * first.kink / kDeg},
                  {"path_kink_deg", turn / kDeg},
                  {"g", first.fracture.energy_release_rate},
                  {"k1", first.fracture.k1},
                  {"k2", first.fracture.k2}};
  }

  void frame(RunOutput& out, const membrane::CrackedSheet& sheet, int step) const {
    mesh::SkinnedMesh shown = sheet.mesh();
    shown.current = sheet.positions();
    out.frame("sheet", step, shown);
  }

  Json summarise(RunOutput& out, const membrane::CrackedSheet& sheet, double grown, int steps,
                 double loop_s) {
    const membrane::SkinMaterial& m = material_.skin;
    const double a = half_length(), E = m.youngs_modulus;
    // Griffith (plane stress): G = pi a sigma^2 / E = G_c. With shear on the slit, G = pi a
    // (sigma_n^2 + tau^2) / E: the normal stress at onset is lower by sqrt(1 + (tau/sigma_n)^2).
    const double griffith = std::sqrt(E * m.toughness / (std::numbers::pi * a));
    const double shear_ratio = sigma_n(1) != 0 ? tau(1) / sigma_n(1) : 0.0;
    const double griffith_mixed = griffith / std::sqrt(1 + shear_ratio * shear_ratio);
    // MTS for the slit's LEFM mode mix: K_I = sigma_n sqrt(pi a), K_II = tau sqrt(pi a).
    const double mts = membrane::mts_kink_angle(sigma_n(1), tau(1)) / kDeg;
    Json metrics = {{"griffith_stress", griffith},
                    {"griffith_stress_mixed", griffith_mixed},
                    {"mts_kink_deg", mts},
                    {"grown_length", grown},
                    {"tips_stopped_at_border", all_stopped(sheet)},
                    {"nodes", sheet.mesh().vertex_count()},
                    {"faces", sheet.mesh().face_count()},
                    {"units",
                     "metres, pascals, degrees; onset_stress: the remote stress normal to the "
                     "slit at the first growth step; kink_deg: the first growth direction "
                     "(the MTS direction of the measured K_I, K_II) from the slit's; "
                     "path_kink_deg: the first extension's chord on the mesh"}};
    if (onset_) {
      const Json& o = *onset_;
      metrics["onset_stress"] = o["stress"];
      metrics["onset_sigma_yy"] = o["sigma_yy"];
      metrics["onset_time"] = o["time"];
      metrics["onset_over_griffith"] = o["stress"].get<double>() / griffith;
      metrics["onset_over_griffith_mixed"] = o["stress"].get<double>() / griffith_mixed;
      metrics["kink_deg"] = o["kink_deg"];
      metrics["path_kink_deg"] = o["path_kink_deg"];
      metrics["onset_g"] = o["g"];
      metrics["onset_k1"] = o["k1"];
      metrics["onset_k2"] = o["k2"];
    }
    out.add_plot({"grown_length",
                  "membrane-griffith: length grown over time",
                  "time [s]",
                  "grown length (both tips) [mm]",
                  {{"metrics.csv", "t", "grown_length", "grown length", "lines", 1e3}},
                  {}});
    out.add_plot({"energy_release",
                  "membrane-griffith: energy release rate over the toughness",
                  "time [s]",
                  "G / G_c",
                  {{"metrics.csv", "t", "g_over_toughness", "largest G / G_c", "lines"}},
                  {}});
    out.finish(resolved_, metrics, Json::object(), steps, steps * common_.dt, loop_s);
    return metrics;
  }

  membrane::SlitSheetOptions options_;
  Load load_;
  membrane::GrowthSettings growth_;
  double domain_fraction_ = 0.5;  // growth.domain_radius, in units of a
  bullet::Material material_;
  std::optional<Json> onset_;
};

std::unique_ptr<Scene> make_membrane_griffith(const Json& scene, const std::string& name,
                                              int steps_override) {
  return std::make_unique<MembraneGriffith>(scene, name, steps_override);
}

const SceneRegistration kMembraneGriffithRegistration{
    {"membrane-griffith",
     "the skin tears by itself: a slit in a sheet stretched at its border grows where the energy "
     "release rate reaches the toughness; onset against Griffith, kink against the MTS angle",
     kMembraneGriffithJson, &make_membrane_griffith, 9,
     "onset_over_griffith,kink_deg,mts_kink_deg"}};

}  // namespace

}  // namespace conform::scenes
