#include "kinds/soft_scene.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "conform/bullet/convert.hpp"

namespace conform::scenes {

SoftWorld::SoftWorld(const CommonSettings& c)
    : bullet::SoftWorld(bullet::to_bt(c.gravity)), dt(c.dt / c.substeps), substeps(c.substeps) {
  world.getSolverInfo().m_numIterations = c.solver_iterations;
  plugin = std::make_unique<bullet::Plugin>(world);
}

void SoftWorld::step() {
  ++steps_done;
  try {
    bullet::SoftWorld::step(dt, substeps);
  } catch (const bullet::NonFiniteState& e) {
    throw std::runtime_error("step " + std::to_string(steps_done) + ": " + e.what());
  }
}

OffsetStats offsets(const bullet::SkinnedSoftBody& body,
                    const std::vector<std::int32_t>& vertices) {
  OffsetStats s;
  const auto add = [&](std::int32_t v) {
    const bullet::PieceId piece = body.piece_of(v);
    if (!piece.is_null() && body.piece_released(piece)) return;  // no longer skinned
    const double d = (body.position(v) - body.target(v)).norm();
    s.mean += d, s.max = std::max(s.max, d), ++s.n;
  };
  if (vertices.empty())
    for (std::int32_t v = 0; v < body.vertex_count(); ++v) add(v);
  else
    for (const std::int32_t v : vertices) add(v);
  if (s.n) s.mean /= double(s.n);
  return s;
}

bool finite_nodes(const bullet::SkinnedSoftBody& body) {
  for (std::int32_t v = 0; v < body.vertex_count(); ++v)
    if (!body.position(v).allFinite()) return false;
  return true;
}

// An enumerated key: its value's name among `names` (fallback's name by default).
template <typename Enum, std::size_t N>
Enum choose(Reader& r, const std::string& key,
            const std::array<std::pair<Enum, const char*>, N>& names, Enum fallback) {
  std::string fallback_name = names[0].second, list;
  for (const auto& [value, name] : names) {
    list += (list.empty() ? "" : ", ") + std::string(name);
    if (value == fallback) fallback_name = name;
  }
  const std::string chosen = r.text(key, fallback_name);
  for (const auto& [value, name] : names)
    if (chosen == name) return value;
  r.fail(key, Json(chosen), "must be one of: " + list);
  return fallback;
}

// The membrane's fields (SI units; skin_material.hpp has their ranges and sources).
void read_skin(Reader& r, const bullet::Material& d, bullet::Material& m) {
  membrane::SkinMaterial& k = m.skin;
  const membrane::SkinMaterial& e = d.skin;
  k.youngs_modulus = r.number("youngs_modulus", e.youngs_modulus, 1, 1e10);
  k.poisson_ratio = r.number("poisson_ratio", e.poisson_ratio, 0, 0.4999);
  k.thickness = r.number("thickness", e.thickness, 1e-6, 1);
  k.areal_density = r.number("areal_density", e.areal_density, 1e-6, 1e4);
  k.prestress = r.pair("prestress", e.prestress, 0, 0.5 * k.youngs_modulus);
  k.prestress_axis = r.vec3("prestress_axis", e.prestress_axis);
  using Field = membrane::SkinMaterial::DirectionField;
  const std::array<std::pair<Field, const char*>, 3> fields = {
      {{Field::axis, "axis"},
       {Field::along_bones, "along-bones"},
       {Field::around_bones, "around-bones"}}};
  k.prestress_field = choose(r, "prestress_field", fields, e.prestress_field);
  if (!(k.prestress_axis.norm() > 0))
    r.fail("prestress_axis", Json::array({0, 0, 0}), "must be a non-zero direction");
  k.attachment_stiffness = r.number("attachment_stiffness", e.attachment_stiffness, 0, 1e12);
  k.attachment_normal_stiffness =
      r.number("attachment_normal_stiffness", e.attachment_normal_stiffness, 0, 1e12);
  k.attachment_damping = r.number("attachment_damping", e.attachment_damping, 0, 1e9);
  k.wrinkling = r.boolean("wrinkling", e.wrinkling);
  k.toughness = r.number("toughness", e.toughness, 1e-9, 1e6);
  using Law = membrane::SkinMaterial::Law;
  const std::array<std::pair<Law, const char*>, 3> laws = {
      {{Law::stvk, "stvk"},
       {Law::neo_hookean, "neo-hookean"},
       {Law::fibre_reinforced, "fibre-reinforced"}}};
  k.law = choose(r, "law", laws, e.law);
  k.fibre_stiffness = r.number("fibre_stiffness", e.fibre_stiffness, 0, 1e10);
  k.fibre_nonlinearity = r.number("fibre_nonlinearity", e.fibre_nonlinearity, 1e-6, 100);
  if (r.has("tolerance"))
    r.fail("tolerance", r.number("tolerance", 0),
           "was an absolute residual in Pa; the membrane's stopping test is now "
           "\"relative_tolerance\", dimensionless (the residual over the pre-stress, e.g. 1.2e-3)");
  m.solver.relative_tolerance =
      r.number("relative_tolerance", d.solver.relative_tolerance, 1e-12, 1);
  m.solver.max_newton_iterations =
      r.integer("max_newton_iterations", d.solver.max_newton_iterations, 1, 10000);
  m.solver.max_cg_iterations =
      r.integer("max_cg_iterations", d.solver.max_cg_iterations, 1, 1000000);
  m.solver.threads = r.integer("solver_threads", d.solver.threads, 1, 256);
  m.solver.cg_relative_tolerance =
      r.number("cg_relative_tolerance", d.solver.cg_relative_tolerance, 1e-6, 0.9);
  m.solver.local_fraction = r.number("local_fraction", d.solver.local_fraction, 0, 0.99);
}

bullet::Material read_material(Reader& root, const bullet::Material& d) {
  Reader r = root.object("material");
  bullet::Material m;
  const std::string model =
      r.text("model", d.model == bullet::MaterialModel::membrane ? "membrane" : "bullet_links",
             {"membrane", "bullet_links"});
  m.model =
      model == "membrane" ? bullet::MaterialModel::membrane : bullet::MaterialModel::bullet_links;
  read_skin(r, d, m);
  m.link_stiffness = r.number("link_stiffness", d.link_stiffness, 1e-4, 1);
  m.damping = r.number("damping", d.damping, 0, 0.999);
  m.pretension = r.number("pretension", d.pretension, 0, 0.9);
  m.density = r.number("density", d.density, 1e-4, 1e4);
  m.target_stiffness = r.number("target_stiffness", d.target_stiffness, 0, 1e7);
  m.target_damping = r.number("target_damping", d.target_damping, 0, 1e5);
  m.kinematic_weight = r.number("kinematic_weight", d.kinematic_weight, 0, 2);
  m.position_iterations = r.integer("position_iterations", d.position_iterations, 1, 200);
  m.margin = r.number("margin", d.margin, 0, 1);
  // m/s: a runaway stops the run (the library's default, no bound, is for worlds of any unit).
  m.max_speed = r.number("max_speed", std::isinf(d.max_speed) ? 100.0 : d.max_speed, 1e-6, 1e12);
  r.finish();
  // The membrane ignores the link fields. The kind's own values for them (its links option)
  // stay out of the body; a value the scene file changes reaches it, and the body names it in its
  // material_warnings.
  if (m.model == bullet::MaterialModel::membrane) {
    const bullet::Material none;
    for (const bullet::MaterialField& f : bullet::kLinkOnlyFields)
      if (m.*f.value == d.*f.value) m.*f.value = none.*f.value;
  }
  return m;
}

mesh::ScalpelSample Stroke::sample(int i) const {
  const double u = samples > 1 ? double(i) / (samples - 1) : 0.0;
  const Eigen::Vector3d p = (1 - u) * from + u * to;
  return {time(i), p + blade_a, p + blade_b};
}

Stroke read_stroke(Reader& r, const Stroke& d) {
  Stroke s;
  s.at = r.number("at", d.at, 0, 1e5);
  s.duration = r.number("duration", d.duration, 0, 1e5);
  s.samples = r.integer("samples", d.samples, 2, 100000);
  s.from = r.vec3("from", d.from);
  s.to = r.vec3("to", d.to);
  s.blade_a = r.vec3("blade_a", d.blade_a);
  s.blade_b = r.vec3("blade_b", d.blade_b);
  if ((s.blade_a - s.blade_b).norm() < 1e-6)
    r.fail("blade_b", r.has("blade_b") ? Json{s.blade_b.x(), s.blade_b.y(), s.blade_b.z()} : Json(),
           "the blade's two ends must differ");
  return s;
}

void fit_ellipse(Profile& p) {
  double fw = 0, ff = 0, mean = 0;
  std::vector<double> f(p.s.size());
  for (std::size_t i = 0; i < p.s.size(); ++i) {
    const double u = 2 * p.s[i] - 1;
    f[i] = std::sqrt(std::max(0.0, 1 - u * u));
    fw += f[i] * p.w[i], ff += f[i] * f[i], mean += p.w[i];
  }
  if (p.s.empty() || ff <= 0) return;
  mean /= double(p.s.size());
  p.fit_max = fw / ff;
  double res = 0, tot = 0;
  for (std::size_t i = 0; i < p.s.size(); ++i) {
    res += std::pow(p.w[i] - p.fit_max * f[i], 2);
    tot += std::pow(p.w[i] - mean, 2);
  }
  p.r2 = tot > 0 ? 1 - res / tot : 0;
}

std::vector<double> resample(const Profile& p, const std::vector<double>& at) {
  std::vector<double> out(at.size(), 0.0);
  for (std::size_t k = 0; k < at.size(); ++k) {
    const double s = at[k];
    for (std::size_t i = 1; i < p.s.size(); ++i) {
      if (s < p.s[i - 1] || s > p.s[i]) continue;
      const double span = p.s[i] - p.s[i - 1];
      const double a = span > 0 ? (s - p.s[i - 1]) / span : 0;
      out[k] = (1 - a) * p.w[i - 1] + a * p.w[i];
      break;
    }
  }
  return out;
}

}  // namespace conform::scenes
