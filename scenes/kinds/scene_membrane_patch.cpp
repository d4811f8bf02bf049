// `membrane-patch`: the skin membrane's dynamics against a damped oscillator. A square patch on
// its foundation (the attachment to its targets, which stay where the patch was built), moved
// in its plane by patch.offset and released, under gravity: every node moves alike, the
// membrane stays unstrained, and per unit area
//   rho_A u'' = -k u - c u' + rho_A g,
// so the patch rings at f = sqrt(k / rho_A) / 2 pi with the damping ratio c / (2 sqrt(k rho_A))
// and comes to rest sagged by rho_A g / k (k_n along the patch's normal). The scene sets its own
// step from patch.steps_per_period, so that the backward-Euler step's own damping (about
// pi / steps_per_period in damping ratio) stays small against the physical one.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

#include "conform/mesh/primitives.hpp"
#include "conform/skin/skeleton.hpp"
#include "kinds/scene.hpp"
#include "kinds/soft_scene.hpp"

namespace conform::scenes {
namespace {

using Clock = std::chrono::steady_clock;

// The built-in scene `membrane-patch` (`conform scenes --show membrane-patch`).
constexpr const char* kMembranePatchJson = R"json({
  "scene": "membrane-patch",
  "description": "A square patch of skin membrane (SI units) on its foundation, displaced in its plane by patch.offset and released under gravity along its plane: it rings at sqrt(k / rho_A) / 2 pi with the damping ratio c / (2 sqrt(k rho_A)) and sags by rho_A g / k. The scene sets its own step (patch.steps_per_period).",
  "duration": 0.25,
  "patch": { "size": 0.1, "cells": 8, "offset": [0.001, 0, 0], "steps_per_period": 1000 },
  "material": { "prestress": [0, 0], "attachment_stiffness": 400000,
                "attachment_normal_stiffness": 40000000, "attachment_damping": 160,
                "relative_tolerance": 1e-10 },
  "physics": { "gravity": [0, -9.81, 0] },
  "outputs": { "metrics_every": 10, "frames_every": 0, "plots": true }
})json";

skin::Skeleton one_bone() {
  skin::Skeleton s;
  s.joints.push_back({"root", -1, skin::Versor::identity()});
  s.bones.push_back({"root", 0, skin::Versor::identity()});
  return s;
}

// The closed-form oscillator of the patch's uniform motion, from the settings.
struct Reference {
  double frequency_hz = 0, damping_ratio = 0, sag = 0;
  Eigen::Vector3d sag_vector = Eigen::Vector3d::Zero();  // m: rho_A g_t / k_t + rho_A g_n / k_n
};

Reference reference(const membrane::SkinMaterial& m, const Eigen::Vector3d& gravity) {
  Reference r;
  const double k = m.attachment_stiffness, rho = m.areal_density;
  r.frequency_hz = std::sqrt(k / rho) / (2 * std::numbers::pi);
  r.damping_ratio = m.attachment_damping / (2 * std::sqrt(k * rho));
  const Eigen::Vector3d n = Eigen::Vector3d::UnitZ();  // the patch's normal
  const Eigen::Vector3d g_n = gravity.dot(n) * n, g_t = gravity - g_n;
  r.sag_vector = rho * g_t / k;
  if (g_n.norm() > 0) r.sag_vector += rho * g_n / m.attachment_normal_stiffness;
  r.sag = gravity.norm() > 0 ? r.sag_vector.dot(gravity.normalized()) : 0.0;
  return r;
}

// Frequency and damping ratio of a ringing signal u(t) sampled every dt, about 0: the upward
// zero crossings give the period, the logarithmic decrement of the positive peaks the damping
// ratio. Only the part above `floor` x the first peak is used (below it the signal is rounding).
struct Ringing {
  double frequency_hz = 0, damping_ratio = 0;
  int periods = 0;
};

Ringing analyse_ringing(const std::vector<double>& u, double dt, double floor) {
  Ringing r;
  std::vector<double> crossings, peaks;
  double first_peak = 0;
  for (std::size_t i = 1; i + 1 < u.size(); ++i) {
    if (u[i] > 0 && u[i] >= u[i - 1] && u[i] > u[i + 1]) {  // a positive peak: parabola
      const double a = u[i - 1], b = u[i], c = u[i + 1], den = a - 2 * b + c;
      const double peak = den < 0 ? b - 0.125 * (a - c) * (a - c) / den : b;
      if (peaks.empty()) first_peak = peak;
      if (peak < floor * first_peak) break;
      peaks.push_back(peak);
    }
    if (u[i] <= 0 && u[i + 1] > 0 && !peaks.empty())  // upward crossings after the first peak
      crossings.push_back(dt * (double(i) + u[i] / (u[i] - u[i + 1])));
  }
  if (crossings.size() >= 2) {
    r.periods = int(crossings.size()) - 1;
    r.frequency_hz = r.periods / (crossings.back() - crossings.front());
  }
  if (peaks.size() >= 2) {
    const double delta = std::log(peaks.front() / peaks.back()) / double(peaks.size() - 1);
    r.damping_ratio = delta / std::sqrt(4 * std::numbers::pi * std::numbers::pi + delta * delta);
  }
  return r;
}

class MembranePatch final : public Scene {
 public:
  MembranePatch(const Json& scene, const std::string& name, int steps_override) {
    for (const char* key : {"dt", "substeps"})
      if (scene.contains("physics") && scene["physics"].is_object() &&
          scene["physics"].contains(key))
        throw SceneError(std::string("physics.") + key, show(scene["physics"][key]),
                         "membrane-patch sets its own step: use patch.steps_per_period");
    Reader root(scene, "", resolved_);
    Reader patch = root.object("patch");
    size_ = patch.number("size", 0.1, 1e-3, 10);
    cells_ = patch.integer("cells", 8, 1, 200);
    offset_ = patch.vec3("offset", Eigen::Vector3d(1e-3, 0, 0), 0.5 * size_);
    if (std::abs(offset_.z()) > 0 || !(offset_.norm() > 0))
      patch.fail("offset", Json{offset_.x(), offset_.y(), offset_.z()},
                 "must be a non-zero displacement in the patch's plane (z = 0)");
    steps_per_period_ = patch.integer("steps_per_period", 1000, 20, 1000000);
    patch.finish();
    bullet::Material d;
    d.skin.prestress = {0, 0};  // free edges: a pre-stress would pull them in
    d.skin.attachment_damping = 160;
    d.solver.relative_tolerance = 1e-10;
    material_ = read_material(root, d);
    if (material_.model != bullet::MaterialModel::membrane)
      throw SceneError("material.model", "\"bullet_links\"",
                       "membrane-patch measures the membrane's dynamics");
    if (!(material_.skin.attachment_stiffness > 0))
      throw SceneError("material.attachment_stiffness", show(material_.skin.attachment_stiffness),
                       "must be > 0: the foundation is what the patch rings on");
    const double duration = scene.value("duration", 0.25);
    common_ = read_common(root, name, duration, steps_override);
    root.finish();
    ref_ = reference(material_.skin, common_.gravity);
    common_.dt = 1 / (ref_.frequency_hz * steps_per_period_);
    common_.substeps = 1;
    if (steps_override <= 0) common_.steps = std::max(1, int(std::lround(duration / common_.dt)));
    resolved_["physics"]["dt"] = common_.dt;  // echoed as run
    resolved_["physics"]["substeps"] = 1;
  }

  Json run(RunOutput& out) override {
    const CommonSettings& c = common_;
    mesh::SkinnedMesh sheet = mesh::make_sheet(cells_, cells_, size_, size_);
    sheet.bones.setZero();  // wholly on the one bone, which stays put: the targets are rest
    sheet.weights.setZero();
    sheet.weights.row(0).setOnes();
    for (Eigen::Index v = 0; v < sheet.current.cols(); ++v) sheet.current.col(v) += offset_;
    SoftWorld w(c);
    bullet::SkinnedSoftBody& body = w.plugin->add_skinned_body(sheet, one_bone(), material_);
    out.open_metrics({"t", "u_offset", "u_gravity", "residual", "newton_iterations"});
    const Eigen::Vector3d along = offset_.normalized();
    const Eigen::Vector3d down =
        c.gravity.norm() > 0 ? Eigen::Vector3d(c.gravity.normalized()) : Eigen::Vector3d::Zero();
    std::vector<double> u_offset;  // the mean displacement along the offset, every step
    u_offset.reserve(std::size_t(c.steps));
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    double physics_ms = 0, worst_relative = 0;
    out.body_frame("patch", 0, body);
    const auto loop_start = Clock::now();
    for (int step = 1; step <= c.steps; ++step) {
      const auto tp = Clock::now();
      w.step();
      physics_ms += std::chrono::duration<double, std::milli>(Clock::now() - tp).count();
      mean.setZero();
      for (std::int32_t v = 0; v < body.vertex_count(); ++v)
        mean += body.position(v) - body.target(v);
      mean /= double(body.vertex_count());
      u_offset.push_back(mean.dot(along));
      const membrane::SolveReport& r = body.last_solve();
      worst_relative = std::max(worst_relative, r.relative_residual);
      if (step % c.metrics_every == 0 || step == c.steps) {
        const double row[] = {step * c.dt, mean.dot(along), mean.dot(down), r.residual,
                              double(r.newton_iterations)};
        out.metrics().row(row);
      }
      if (out.frame_step(step)) {
        body.sync_mesh();
        out.body_frame("patch", step, body);
      }
      out.progress(step, c.steps);
    }
    const double loop_s = std::chrono::duration<double>(Clock::now() - loop_start).count();
    return summarise(out, u_offset, mean, worst_relative, physics_ms, loop_s);
  }

 private:
  Json summarise(RunOutput& out, std::vector<double> u, const Eigen::Vector3d& final_mean,
                 double worst_relative, double physics_ms, double loop_s) {
    const CommonSettings& c = common_;
    const double rest = u.empty() ? 0.0 : u.back();  // where the ringing ends (the sag's part)
    for (double& value : u) value -= rest;
    const Ringing ring = analyse_ringing(u, c.dt, 1e-3);
    const Eigen::Vector3d down =
        c.gravity.norm() > 0 ? Eigen::Vector3d(c.gravity.normalized()) : Eigen::Vector3d::Zero();
    const double sag = final_mean.dot(down);
    const auto ratio = [](double a, double b) { return b != 0 ? a / b : 0.0; };
    out.add_plot({"ringing",
                  "membrane-patch: mean displacement along the offset and along gravity",
                  "time [s]",
                  "displacement [m]",
                  {{"metrics.csv", "t", "u_offset", "along patch.offset", "lines"},
                   {"metrics.csv", "t", "u_gravity", "along gravity", "lines"}},
                  {}});
    Json metrics = {{"frequency_hz", ring.frequency_hz},
                    {"reference_frequency_hz", ref_.frequency_hz},
                    {"frequency_ratio", ratio(ring.frequency_hz, ref_.frequency_hz)},
                    {"damping_ratio", ring.damping_ratio},
                    {"reference_damping_ratio", ref_.damping_ratio},
                    {"damping_ratio_ratio", ratio(ring.damping_ratio, ref_.damping_ratio)},
                    {"periods_measured", ring.periods},
                    {"sag", sag},
                    {"reference_sag", ref_.sag},
                    {"sag_ratio", ratio(sag, ref_.sag)},
                    {"dt", c.dt},
                    {"relative_residual_max", worst_relative},
                    {"units",
                     "metres, hertz; frequency_hz is the measured (damped) ringing, "
                     "sqrt(1 - zeta^2) below reference_frequency_hz = sqrt(k / rho_A) / 2 pi"}};
    Json timings = {{"physics_ms_per_step", physics_ms / c.steps}};
    out.finish(resolved_, metrics, timings, c.steps, c.steps * c.dt, loop_s);
    return metrics;
  }

  bullet::Material material_;
  Reference ref_;
  double size_ = 0.1;
  int cells_ = 8;
  Eigen::Vector3d offset_{1e-3, 0, 0};
  int steps_per_period_ = 1000;
};

std::unique_ptr<Scene> make_membrane_patch(const Json& scene, const std::string& name,
                                           int steps_override) {
  return std::make_unique<MembranePatch>(scene, name, steps_override);
}

const SceneRegistration kMembranePatchRegistration{
    {"membrane-patch",
     "the skin membrane's dynamics: a patch on its foundation, released from an offset under "
     "gravity, rings at sqrt(k / rho_A) / 2 pi and sags by rho_A g / k",
     kMembranePatchJson, &make_membrane_patch, 6, "frequency_ratio,damping_ratio_ratio,sag_ratio"}};

}  // namespace

}  // namespace conform::scenes
